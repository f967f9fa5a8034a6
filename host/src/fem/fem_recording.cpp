#include "pliant/host/fem/fem_recording.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace pliant::host::fem {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

bool window_active(const Recording& recording, int id, double t_s) {
  for (const DrivenWindow& w : recording.driven) {
    if (w.id == id && w.active_at(t_s)) return true;
  }
  return false;
}

// Position of `node` at frame f: observed, else interpolated between the nearest observed frames
// (held at the ends). False when the node is never observed.
bool position_at(const Recording& recording, int node, int frame, Eigen::Vector3d& out) {
  if (recording.observed(frame, node)) {
    for (int a = 0; a < 3; ++a) out(a) = recording.position(frame, node, a);
    return true;
  }
  int before = frame - 1;
  while (before >= 0 && !recording.observed(before, node)) --before;
  int after = frame + 1;
  while (after < recording.frame_count() && !recording.observed(after, node)) ++after;
  const bool has_before = before >= 0;
  const bool has_after = after < recording.frame_count();
  if (!has_before && !has_after) return false;
  Eigen::Vector3d a = Eigen::Vector3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  if (has_before) {
    for (int k = 0; k < 3; ++k) a(k) = recording.position(before, node, k);
  }
  if (has_after) {
    for (int k = 0; k < 3; ++k) b(k) = recording.position(after, node, k);
  }
  if (!has_before) {
    out = b;
  } else if (!has_after) {
    out = a;
  } else {
    const double t0 = recording.frame_times_s[static_cast<size_t>(before)];
    const double t1 = recording.frame_times_s[static_cast<size_t>(after)];
    const double t = recording.frame_times_s[static_cast<size_t>(frame)];
    const double s = (t - t0) / (t1 - t0);
    out = (1.0 - s) * a + s * b;
  }
  return true;
}

// Linear interpolation of the wrench at t; false outside the samples' span.
bool wrench_at(const std::vector<WrenchSample>& samples, double t, Eigen::Vector3d& force, Eigen::Vector3d& torque) {
  if (samples.empty() || t < samples.front().t_s || t > samples.back().t_s) return false;
  const auto upper = std::lower_bound(samples.begin(), samples.end(), t,
                                      [](const WrenchSample& s, double time) { return s.t_s < time; });
  const WrenchSample& hi = *upper;
  const WrenchSample& lo = upper == samples.begin() ? hi : *(upper - 1);
  const double span = hi.t_s - lo.t_s;
  const double s = span > 0.0 ? (t - lo.t_s) / span : 1.0;
  for (int a = 0; a < 3; ++a) {
    force(a) = (1.0 - s) * lo.force_n[a] + s * hi.force_n[a];
    torque(a) = (1.0 - s) * lo.torque_nm[a] + s * hi.torque_nm[a];
  }
  return true;
}

}  // namespace

bool FemRecordingProblem::is_known(const std::string& parameter) const {
  return std::find(known_parameters.begin(), known_parameters.end(), parameter) != known_parameters.end();
}

FemRecordingProblem fem_problem_from_recording(const Recording& recording, const FemRecordingDefaults& defaults) {
  const std::string label = "recording " + recording.name + ": ";
  if (recording.dimension != 3) throw std::invalid_argument(label + "the FEM needs a 3D recording");
  if (recording.length_unit != "m") {
    throw std::invalid_argument(label + "the FEM needs length_unit \"m\" (got \"" + recording.length_unit + "\")");
  }
  if (!recording.mesh) throw std::invalid_argument(label + "the FEM needs a tetrahedral mesh (mesh.vtk)");

  FemRecordingProblem problem;
  problem.name = recording.name;
  problem.mesh = *recording.mesh;
  const int n = recording.particle_count;

  FemMaterial& material = problem.material;
  material.poisson_ratio = defaults.poisson_ratio;
  material.density_kg_m3 = defaults.density_kg_m3;
  material.youngs_modulus_pa = defaults.youngs_modulus_pa;
  for (const auto& [key, value] : recording.material) {
    problem.known_parameters.push_back(key);
    if (key == "poisson_ratio") material.poisson_ratio = value;
    if (key == "density") material.density_kg_m3 = value;
    if (key == "youngs_modulus") material.youngs_modulus_pa = value;
    if (key == "rayleigh_alpha") material.rayleigh_alpha = value;
    if (key == "rayleigh_beta") material.rayleigh_beta = value;
  }
  if (recording.gravity && recording.gravity->size() == 3) {
    problem.gravity_declared = true;
    material.gravity_m_s2 = Eigen::Vector3d((*recording.gravity)[0], (*recording.gravity)[1], (*recording.gravity)[2]);
  }

  problem.fixed_nodes = recording.fixed;
  std::sort(problem.fixed_nodes.begin(), problem.fixed_nodes.end());
  if (!recording.wrench.empty()) {
    problem.applied_to = recording.wrench_applied_to;
    std::sort(problem.applied_to.begin(), problem.applied_to.end());
    problem.applied_to.erase(std::unique(problem.applied_to.begin(), problem.applied_to.end()),
                             problem.applied_to.end());
  }

  std::vector<int> driven_ids;
  for (const DrivenWindow& w : recording.driven) driven_ids.push_back(w.id);
  std::sort(driven_ids.begin(), driven_ids.end());
  driven_ids.erase(std::unique(driven_ids.begin(), driven_ids.end()), driven_ids.end());

  problem.frames.resize(static_cast<size_t>(recording.frame_count()));
  for (int f = 0; f < recording.frame_count(); ++f) {
    FemFrame& frame = problem.frames[static_cast<size_t>(f)];
    frame.time_s = recording.frame_times_s[static_cast<size_t>(f)];
    frame.observed_position_m = Eigen::VectorXd::Constant(3 * n, kNaN);
    for (int id = 0; id < n; ++id) {
      if (!recording.observed(f, id)) continue;
      frame.observed_nodes.push_back(id);
      for (int a = 0; a < 3; ++a) frame.observed_position_m(3 * id + a) = recording.position(f, id, a);
    }
    for (int id : driven_ids) {
      if (window_active(recording, id, frame.time_s)) frame.driven_nodes.push_back(id);
    }
    frame.driven_position_m.resize(3 * static_cast<Eigen::Index>(frame.driven_nodes.size()));
    for (size_t k = 0; k < frame.driven_nodes.size(); ++k) {
      Eigen::Vector3d p = Eigen::Vector3d::Zero();
      if (!position_at(recording, frame.driven_nodes[k], f, p)) {
        throw std::invalid_argument(label + "driven particle " + std::to_string(frame.driven_nodes[k]) +
                                    " is never observed");
      }
      frame.driven_position_m.segment<3>(3 * static_cast<Eigen::Index>(k)) = p;
    }
    frame.has_wrench =
        problem.has_wrench() && wrench_at(recording.wrench, frame.time_s, frame.wrench_force_n, frame.wrench_torque_nm);
  }
  return problem;
}

void keep_frames_until(FemRecordingProblem& problem, double last_time_s) {
  size_t keep = 0;
  while (keep < problem.frames.size() && problem.frames[keep].time_s <= last_time_s) ++keep;
  problem.frames.resize(std::max<size_t>(keep, std::min<size_t>(1, problem.frames.size())));
}

}  // namespace pliant::host::fem
