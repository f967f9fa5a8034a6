#include "pliant/host/diagnose/model_run.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "pliant/core/deformability.hpp"

namespace pliant::host {
namespace {

// Unit normal of the support: the direction in which the fixed particles' rest positions
// spread least (a line in 2D, a plane in 3D), turned to point toward the object's centroid.
// Zero when there are fewer than `dim` fixed particles or they do not span a line / plane.
std::vector<double> support_normal_of(const Recording& recording) {
  const int dim = recording.dimension;
  std::vector<double> normal(static_cast<std::size_t>(dim), 0.0);
  if (static_cast<int>(recording.fixed.size()) < dim) return normal;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  Eigen::Vector3d object = Eigen::Vector3d::Zero();
  auto point = [&](int id) {
    Eigen::Vector3d p = Eigen::Vector3d::Zero();
    for (int d = 0; d < dim; ++d) p(d) = recording.rest_positions[static_cast<std::size_t>(id * dim + d)];
    return p;
  };
  for (int id : recording.fixed) mean += point(id);
  mean /= static_cast<double>(recording.fixed.size());
  for (int id = 0; id < recording.particle_count; ++id) object += point(id);
  object /= static_cast<double>(recording.particle_count);
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (int id : recording.fixed) {
    const Eigen::Vector3d q = point(id) - mean;
    scatter += q * q.transpose();
  }
  const Eigen::Matrix3d block = scatter;
  Eigen::Vector3d n = Eigen::Vector3d::Zero();
  if (dim == 2) {
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen(block.topLeftCorner<2, 2>());
    if (!(eigen.eigenvalues()(1) > 0)) return normal;
    n.head<2>() = eigen.eigenvectors().col(0);
  } else {
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(block);
    if (!(eigen.eigenvalues()(1) > 1e-6 * eigen.eigenvalues()(2))) return normal;  // collinear supports
    n = eigen.eigenvectors().col(0);
  }
  if (n.dot(object - mean) < 0) n = -n;
  for (int d = 0; d < dim; ++d) normal[static_cast<std::size_t>(d)] = n(d);
  return normal;
}

template <int Dim>
struct SimulatorImpl {
  std::unique_ptr<HostMsmModel<Dim>> model;
  std::vector<unsigned char> state_block;

  SimulatorImpl(const Recording& recording, const MsmSetupOptions& setup) {
    model = build_msm_model<Dim>(recording, setup);
    state_block.resize(msm_state_workspace_size(model->model));
  }

  std::vector<double> run(const Recording& recording, const std::vector<double>& normal,
                          const ModelSettings& settings) {
    using Vec = Eigen::Matrix<double, Dim, 1>;
    const MsmModel<Dim, double>& m = model->model;
    const int n = recording.particle_count;
    const int frames = recording.frame_count();
    Arena arena(state_block.data(), state_block.size());
    MsmState<Dim, double> state;
    require_ok(msm_state_init(arena, m, state), "simulation state");

    MsmParams<Dim, double> params = base_params<Dim>(recording, settings.msm_alpha);
    params.msm_beta = settings.msm_beta;
    if (!settings.extra_gravity.empty()) {
      for (int d = 0; d < Dim; ++d) params.gravity(d) += settings.extra_gravity[static_cast<std::size_t>(d)];
    }
    params.velocity_damping = settings.velocity_damping;
    params.plastic_yield = settings.plastic_yield;
    params.plastic_creep = settings.plastic_creep;
    params.plastic_max = settings.plastic_max;
    params.relaxation_fraction = settings.relaxation_fraction;
    params.relaxation_time_s = settings.relaxation_time_s;
    params.stiffening = settings.stiffening;
    if (settings.support_friction >= 0) {
      params.support_friction = settings.support_friction;
      for (int d = 0; d < Dim; ++d) params.support_normal(d) = normal[static_cast<std::size_t>(d)];
    }
    std::vector<double> cluster_beta;
    if (!settings.particle_beta.empty()) {
      if (static_cast<int>(settings.particle_beta.size()) != n) {
        throw std::runtime_error("particle_beta needs one value per particle");
      }
      cluster_beta.assign(static_cast<std::size_t>(m.cluster_count), settings.msm_beta);
      for (int c = 0; c < m.cluster_count; ++c) {
        double sum = 0;
        for (int k = m.cluster_begin[c]; k < m.cluster_begin[c + 1]; ++k) {
          sum += settings.particle_beta[static_cast<std::size_t>(m.members[k])];
        }
        const int members = m.cluster_begin[c + 1] - m.cluster_begin[c];
        if (members > 0) cluster_beta[static_cast<std::size_t>(c)] = std::clamp(sum / members, 0.0, 1.0);
      }
      params.cluster_beta = cluster_beta.data();
    }

    std::vector<double> out(static_cast<std::size_t>(frames) * static_cast<std::size_t>(n) * Dim);
    auto record = [&](int frame) {
      for (int i = 0; i < n; ++i) {
        for (int d = 0; d < Dim; ++d) {
          out[(static_cast<std::size_t>(frame) * static_cast<std::size_t>(n) + static_cast<std::size_t>(i)) * Dim +
              static_cast<std::size_t>(d)] = state.position[i](d);
        }
      }
    };
    // Driven targets: a window's particle follows its observation, holding the last observed
    // position (or where it was when the window opened) through occlusions. `starts` keeps where
    // each target begins the frame interval, for the interpolated targets of several steps.
    const std::vector<DrivenWindow>& windows = model->driven;
    std::vector<Vec> held(windows.size(), Vec::Zero());
    std::vector<unsigned char> active(windows.size(), 0);
    std::vector<int> ids;
    std::vector<Vec> targets;
    std::vector<Vec> starts;
    auto gather = [&](int frame) {
      ids.clear();
      targets.clear();
      starts.clear();
      const double t = recording.frame_times_s[static_cast<std::size_t>(frame)];
      for (std::size_t w = 0; w < windows.size(); ++w) {
        const DrivenWindow& window = windows[w];
        if (!window.active_at(t)) {
          active[w] = 0;
          continue;
        }
        if (active[w] == 0) held[w] = state.position[window.id];
        active[w] = 1;
        starts.push_back(held[w]);
        if (recording.observed(frame, window.id)) {
          for (int d = 0; d < Dim; ++d) held[w](d) = recording.position(frame, window.id, d);
        }
        ids.push_back(window.id);
        targets.push_back(held[w]);
      }
    };
    const int steps = settings.steps_per_frame;
    std::vector<Vec> step_targets;
    auto step = [&](const MsmStepInput<Dim, double>& input) {
      const Status status = msm_step(m, params, input, state);
      if (status == Status::invalid_argument || status == Status::not_initialized) {
        require_ok(status, "simulation step");
      }
    };
    gather(0);
    record(0);
    for (int k = 1; k < frames; ++k) {
      gather(k);
      const double dt = recording.frame_times_s[static_cast<std::size_t>(k)] -
                        recording.frame_times_s[static_cast<std::size_t>(k - 1)];
      MsmStepInput<Dim, double> input;
      input.dt = dt / steps;
      if (steps == 1) {
        input.driven = {ids.data(), targets.data(), static_cast<int>(ids.size())};
        step(input);
      } else {
        step_targets.resize(targets.size());
        input.driven = {ids.data(), step_targets.data(), static_cast<int>(ids.size())};
        for (int j = 1; j <= steps; ++j) {
          const double share = static_cast<double>(j) / steps;
          for (std::size_t c = 0; c < targets.size(); ++c)
            step_targets[c] = starts[c] + (targets[c] - starts[c]) * share;
          step(input);
        }
      }
      record(k);
    }
    return out;
  }
};

}  // namespace

struct RecordingSimulator::Impl2 : SimulatorImpl<2> {
  using SimulatorImpl<2>::SimulatorImpl;
};
struct RecordingSimulator::Impl3 : SimulatorImpl<3> {
  using SimulatorImpl<3>::SimulatorImpl;
};

RecordingSimulator::RecordingSimulator(const Recording& recording, const MsmSetupOptions& setup)
    : recording_(recording), support_normal_(support_normal_of(recording)) {
  if (recording.dimension == 2) {
    impl2_ = std::make_unique<Impl2>(recording, setup);
  } else if (recording.dimension == 3) {
    impl3_ = std::make_unique<Impl3>(recording, setup);
  } else {
    throw std::runtime_error("dimension must be 2 or 3");
  }
}

RecordingSimulator::~RecordingSimulator() = default;

std::vector<double> RecordingSimulator::simulate(const ModelSettings& settings) const {
  if (settings.steps_per_frame < 1 || settings.steps_per_frame > max_steps_per_frame) {
    throw std::runtime_error("steps per frame must be 1.." + std::to_string(max_steps_per_frame));
  }
  if (settings.support_friction >= 0) {
    double length = 0;
    for (double v : support_normal_) length += v * v;
    if (!(length > 0.5))
      throw std::runtime_error("support friction needs fixed particles spanning a support line or plane");
  }
  return impl2_ ? impl2_->run(recording_, support_normal_, settings)
                : impl3_->run(recording_, support_normal_, settings);
}

const std::vector<double>& RecordingSimulator::rest() const {
  return impl2_ ? impl2_->model->rest : impl3_->model->rest;
}

int RecordingSimulator::cluster_count() const {
  return impl2_ ? impl2_->model->model.cluster_count : impl3_->model->model.cluster_count;
}

std::vector<unsigned char> compared_pairs(const Recording& recording) {
  const int n = recording.particle_count;
  const int frames = recording.frame_count();
  std::vector<unsigned char> mask(static_cast<std::size_t>(frames) * static_cast<std::size_t>(n), 0);
  for (int k = 0; k < frames; ++k) {
    const double t = recording.frame_times_s[static_cast<std::size_t>(k)];
    for (int i = 0; i < n; ++i)
      mask[static_cast<std::size_t>(k) * static_cast<std::size_t>(n) + static_cast<std::size_t>(i)] =
          recording.observed(k, i) ? 1 : 0;
    for (const DrivenWindow& window : recording.driven) {
      if (window.active_at(t))
        mask[static_cast<std::size_t>(k) * static_cast<std::size_t>(n) + static_cast<std::size_t>(window.id)] = 0;
    }
  }
  return mask;
}

}  // namespace pliant::host
