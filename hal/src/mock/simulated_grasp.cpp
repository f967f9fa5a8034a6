#include "pliant/hal/mock/simulated_grasp.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>

namespace pliant::hal {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::vector<double> lattice(const SimulatedObjectConfig& o) {
  std::vector<double> rest;
  const double h = o.spacing_m;
  auto push = [&](double x, double y, double z) {
    rest.push_back(x);
    rest.push_back(y);
    rest.push_back(z);
  };
  switch (o.shape) {
    case ObjectShape::box:
      for (int z = 0; z < o.nz; ++z) {
        for (int y = 0; y < o.ny; ++y) {
          for (int x = 0; x < o.nx; ++x) {
            push(h * (x - 0.5 * (o.nx - 1)), h * (y - 0.5 * (o.ny - 1)), h * (z - 0.5 * (o.nz - 1)));
          }
        }
      }
      break;
    case ObjectShape::cylinder:
      for (int z = 0; z < o.nz; ++z) {
        for (int y = -o.nx; y <= o.nx; ++y) {
          for (int x = -o.nx; x <= o.nx; ++x) {
            if (x * x + y * y <= o.nx * o.nx) push(h * x, h * y, h * (z - 0.5 * (o.nz - 1)));
          }
        }
      }
      break;
    case ObjectShape::ball:
      for (int z = -o.nx; z <= o.nx; ++z) {
        for (int y = -o.nx; y <= o.nx; ++y) {
          for (int x = -o.nx; x <= o.nx; ++x) {
            if (x * x + y * y + z * z <= o.nx * o.nx) push(h * x, h * y, h * z);
          }
        }
      }
      break;
  }
  return rest;
}

bool valid_object(const SimulatedObjectConfig& o) {
  const bool dims = o.shape == ObjectShape::box
                        ? (o.nx >= 2 && o.ny >= 2 && o.nz >= 2 && o.nx <= 64 && o.ny <= 64 && o.nz <= 64)
                    : o.shape == ObjectShape::cylinder ? (o.nx >= 1 && o.nx <= 32 && o.nz >= 2 && o.nz <= 64)
                                                       : (o.nx >= 1 && o.nx <= 32);
  return dims && std::isfinite(o.spacing_m) && o.spacing_m > 0 && o.msm_beta >= 0 && o.msm_beta <= 1 &&
         std::isfinite(o.stiffness_n_per_m) && o.stiffness_n_per_m > 0 && std::isfinite(o.stiffening) &&
         o.stiffening >= 0;
}

}  // namespace

HalStatus SimulatedGrasp::configure(const SimulatedGraspConfig& config) {
  configured_ = false;
  const SimulatedGraspConfig& c = config;
  if (!valid_object(c.object) || !(std::isfinite(c.period_s) && c.period_s > 0) || c.max_steps_per_period < 1 ||
      !(std::isfinite(c.settle_tolerance) && c.settle_tolerance > 0) ||
      !(std::isfinite(c.jaw_max_speed_m_per_s) && c.jaw_max_speed_m_per_s > 0) || !std::isfinite(c.max_width_m) ||
      !(c.max_closure_fraction > 0 && c.max_closure_fraction < 1) || c.max_catch_up_periods < 1 ||
      !(std::isnan(c.initial_width_m) || std::isfinite(c.initial_width_m))) {
    return HalStatus::invalid_argument;
  }
  rest_ = lattice(c.object);
  const int n = static_cast<int>(rest_.size() / 3);
  if (n < 8) return HalStatus::invalid_argument;
  double low = rest_[0], high = rest_[0];
  for (int i = 0; i < n; ++i) {
    low = std::min(low, rest_[3 * static_cast<std::size_t>(i)]);
    high = std::max(high, rest_[3 * static_cast<std::size_t>(i)]);
  }
  if (!(c.max_width_m > high - low)) return HalStatus::invalid_argument;
  if (std::isfinite(c.initial_width_m) && (c.initial_width_m > c.max_width_m || c.initial_width_m < 0)) {
    return HalStatus::invalid_argument;
  }

  all_ids_.resize(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) all_ids_[static_cast<std::size_t>(i)] = i;
  MsmModelConfig<3, double> mc;
  mc.particle_count = n;
  mc.rest_positions = rest_.data();
  mc.drivable_ids = all_ids_.data();
  mc.drivable_count = n;
  model_block_.assign(msm_model_workspace_size(mc), 0);
  if (model_block_.empty()) return HalStatus::invalid_argument;
  Arena model_arena(model_block_.data(), model_block_.size());
  if (msm_model_init(model_arena, mc, model_) != Status::ok) return HalStatus::invalid_argument;
  state_block_.assign(msm_state_workspace_size(model_), 0);
  Arena state_arena(state_block_.data(), state_block_.size());
  if (msm_state_init(state_arena, model_, state_) != Status::ok) return HalStatus::invalid_argument;

  // Each cluster's span: the range of its A_qq^+ (flat clusters have a null direction that must
  // not count as a stretch of 0).
  span_.assign(static_cast<std::size_t>(model_.cluster_count), Eigen::Matrix3d::Identity());
  for (int k = 0; k < model_.cluster_count; ++k) {
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
    solver.compute(model_.cluster_aqq_inverse[k]);
    const double largest = solver.eigenvalues().cwiseAbs().maxCoeff();
    Eigen::Matrix3d projector = Eigen::Matrix3d::Zero();
    for (int d = 0; d < 3; ++d) {
      if (std::abs(solver.eigenvalues()(d)) > 1e-5 * largest) {
        projector += solver.eigenvectors().col(d) * solver.eigenvectors().col(d).transpose();
      }
    }
    span_[static_cast<std::size_t>(k)] = projector;
  }

  const auto count = static_cast<std::size_t>(n);
  side_.assign(count, 0);
  anchor_.assign(count, Vec::Zero());
  anchor_closure_.assign(count, 0.0);
  initial_contact_.assign(count, 0);
  driven_ids_.assign(count, 0);
  driven_targets_.assign(count, Vec::Zero());
  previous_.assign(count, Vec::Zero());
  low_ = low;
  high_ = high;
  extent_m_ = high - low;
  for (int i = 0; i < n; ++i) {
    const double x = model_.rest[i](0);
    const double band = 0.25 * model_.spacing;
    initial_contact_[static_cast<std::size_t>(i)] = x <= low + band ? 1 : (x >= high - band ? 2 : 0);
  }
  tolerance_m_ = c.settle_tolerance * model_.spacing;
  config_ = c;
  params_ = MsmParams<3, double>{};
  params_.msm_beta = c.object.msm_beta;
  // Momentum (1 - damping per unit step): the same acceleration as the guard's relaxation; the
  // fixed point does not depend on it.
  params_.velocity_damping = 1.0 - (0.5 + 0.4 * c.object.msm_beta);
  counters_ = SimulatedGraspCounters{};
  configured_ = true;
  reset();
  return HalStatus::ok;
}

void SimulatedGrasp::reset() noexcept {
  if (!configured_) return;
  msm_state_reset(model_, state_);
  const auto n = static_cast<std::size_t>(model_.particle_count);
  for (std::size_t i = 0; i < n; ++i) {
    side_[i] = 0;
    anchor_closure_[i] = 0;
  }
  time_s_ = clock_.now_s();
  width_m_ = std::isfinite(config_.initial_width_m) ? config_.initial_width_m : config_.max_width_m;
  width_m_ = std::clamp(width_m_, min_width_m(), config_.max_width_m);
  target_width_m_ = width_m_;
  speed_m_per_s_ = 0;
  force_limit_n_ = std::numeric_limits<double>::infinity();
  moving_ = false;
  object_detected_ = false;
  actuator_fault_ = false;
  in_contact_ = false;
  settled_ = true;
  force_n_ = force_at(closure_m());
  strain_ = 0;
  peak_strain_ = 0;
}

void SimulatedGrasp::command_move(double width_m, double speed_m_per_s, double force_limit_n) noexcept {
  if (!configured_ || !std::isfinite(width_m) || !(speed_m_per_s > 0) || std::isnan(force_limit_n)) return;
  target_width_m_ = std::clamp(width_m, min_width_m(), config_.max_width_m);
  speed_m_per_s_ = std::min(speed_m_per_s, config_.jaw_max_speed_m_per_s);
  force_limit_n_ = force_limit_n;
  object_detected_ = false;
  moving_ = target_width_m_ != width_m_;
}

void SimulatedGrasp::command_stop() noexcept {
  if (!configured_) return;
  target_width_m_ = width_m_;
  moving_ = false;
}

void SimulatedGrasp::command_open(double speed_m_per_s) noexcept {
  command_move(config_.max_width_m, speed_m_per_s, std::numeric_limits<double>::infinity());
}

double SimulatedGrasp::force_at(double closure_m) const noexcept {
  if (!(closure_m > 0)) return 0;
  return config_.object.stiffness_n_per_m * closure_m * (1 + config_.object.stiffening * closure_m / extent_m_);
}

int SimulatedGrasp::contact_count() const noexcept {
  int count = 0;
  for (std::int8_t s : side_) count += s != 0 ? 1 : 0;
  return count;
}

void SimulatedGrasp::sync() noexcept {
  if (!configured_) return;
  const double now = clock_.now_s();
  if (!std::isfinite(now)) return;
  const double period = config_.period_s;
  // Whole periods due, with a little slack for the rounding of stepped clocks.
  const double due = std::floor((now - time_s_) / period + 1e-6);
  if (!(due >= 1)) return;
  if (due > config_.max_catch_up_periods) {
    const double skipped = due - config_.max_catch_up_periods;
    counters_.skipped_periods += static_cast<std::uint64_t>(std::min(skipped, 9.0e15));
    time_s_ += skipped * period;
  }
  const int steps = static_cast<int>(std::min(due, static_cast<double>(config_.max_catch_up_periods)));
  for (int k = 0; k < steps; ++k) {
    time_s_ += period;
    step_period();
  }
}

void SimulatedGrasp::move_jaws() noexcept {
  if (actuator_fault_ || !moving_) return;
  // Closing stops at the force limit (the force of the previous period: the actuator's current).
  if (target_width_m_ < width_m_ && force_n_ >= force_limit_n_) {
    target_width_m_ = width_m_;
    moving_ = false;
    object_detected_ = true;
    ++counters_.force_stops;
    return;
  }
  const double step = speed_m_per_s_ * config_.period_s;
  const double gap = target_width_m_ - width_m_;
  if (std::abs(gap) <= step) {
    width_m_ = target_width_m_;
    moving_ = false;
  } else {
    width_m_ += gap > 0 ? step : -step;
  }
}

void SimulatedGrasp::update_contacts() noexcept {
  const int n = model_.particle_count;
  const double c = closure_m();
  if (!in_contact_ && c > 0) {
    in_contact_ = true;
    for (int i = 0; i < n; ++i) {
      const auto u = static_cast<std::size_t>(i);
      if (initial_contact_[u] == 0) continue;
      side_[u] = initial_contact_[u] == 1 ? std::int8_t{-1} : std::int8_t{1};
      anchor_[u] = state_.position[i];
      anchor_closure_[u] = 0;
    }
  }
  // Release where the jaw retreated past the point the particle joined at.
  bool any = false;
  for (int i = 0; i < n; ++i) {
    const auto u = static_cast<std::size_t>(i);
    if (side_[u] != 0 && c < anchor_closure_[u] - 1e-12) side_[u] = 0;
    any = any || side_[u] != 0;
  }
  if (!any) in_contact_ = false;
}

void SimulatedGrasp::relax() noexcept {
  const int n = model_.particle_count;
  const double c = closure_m();
  int count = 0;
  for (int i = 0; i < n; ++i) {
    const auto u = static_cast<std::size_t>(i);
    state_.velocity[i].setZero();
    if (side_[u] == 0) continue;
    driven_ids_[static_cast<std::size_t>(count)] = i;
    Vec target = anchor_[u];
    target(0) += -static_cast<double>(side_[u]) * 0.5 * (c - anchor_closure_[u]);
    driven_targets_[static_cast<std::size_t>(count)] = target;
    ++count;
  }
  MsmStepInput<3, double> input;
  input.dt = 1.0;
  input.driven.ids = driven_ids_.data();
  input.driven.positions = driven_targets_.data();
  input.driven.count = count;
  int quiet = 0;
  int steps = 0;
  while (quiet < 2 && steps < config_.max_steps_per_period) {
    for (int i = 0; i < n; ++i) previous_[static_cast<std::size_t>(i)] = state_.position[i];
    if (msm_step(model_, params_, input, state_) != Status::ok) ++counters_.step_errors;
    ++steps;
    double move = 0;
    for (int i = 0; i < n; ++i)
      move = std::max(move, (state_.position[i] - previous_[static_cast<std::size_t>(i)]).norm());
    quiet = move <= tolerance_m_ ? quiet + 1 : 0;
  }
  counters_.msm_steps += static_cast<std::uint64_t>(steps);
  settled_ = quiet >= 2;
  if (!settled_) ++counters_.unsettled_periods;
  // Joins: free particles past a jaw plane stick to it.
  const double plane_a = -0.5 * width_m_;
  const double plane_b = 0.5 * width_m_;
  for (int i = 0; i < n; ++i) {
    const auto u = static_cast<std::size_t>(i);
    if (side_[u] != 0 || !in_contact_) continue;
    Vec& x = state_.position[i];
    if (x(0) >= plane_a && x(0) <= plane_b) continue;
    const bool jaw_a = x(0) < plane_a;
    x(0) = jaw_a ? plane_a : plane_b;
    state_.velocity[i].setZero();
    side_[u] = jaw_a ? std::int8_t{-1} : std::int8_t{1};
    anchor_[u] = x;
    anchor_closure_[u] = c;
    settled_ = false;
  }
}

void SimulatedGrasp::step_period() noexcept {
  ++counters_.periods;
  const double before = width_m_;
  move_jaws();
  update_contacts();
  // Nothing to do while the object rests untouched and the jaws stand still.
  if (in_contact_ || !settled_ || width_m_ != before) relax();
  force_n_ = force_at(closure_m());
  strain_ = max_strain(state_.position);
  peak_strain_ = std::max(peak_strain_, strain_);
}

double SimulatedGrasp::max_strain(const Vec* positions) const noexcept {
  if (!configured_ || positions == nullptr) return kNaN;
  double worst = 0;
  for (int k = 0; k < model_.cluster_count; ++k) {
    Vec centroid = Vec::Zero();
    double mass = 0;
    for (int m = model_.cluster_begin[k]; m < model_.cluster_begin[k + 1]; ++m) {
      const int j = model_.members[m];
      centroid += model_.mass[j] * positions[j];
      mass += model_.mass[j];
    }
    centroid /= mass;
    Eigen::Matrix3d apq = Eigen::Matrix3d::Zero();
    for (int m = model_.cluster_begin[k]; m < model_.cluster_begin[k + 1]; ++m) {
      const int j = model_.members[m];
      apq.noalias() += model_.mass[j] * (positions[j] - centroid) * model_.member_rest_offset[m].transpose();
    }
    const Eigen::Matrix3d a = apq * model_.cluster_aqq_inverse[k];
    const Eigen::Matrix3d& p = span_[static_cast<std::size_t>(k)];
    // Outside the span the stretch is set to 1 (no strain) by the identity on the null space.
    const Eigen::Matrix3d m = p * a.transpose() * a * p + (Eigen::Matrix3d::Identity() - p);
    // The iterative solver: the closed form loses ~1e-8 near the identity (repeated eigenvalues),
    // which is the rest state this ground truth must report as exactly unstrained.
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
    solver.compute(m, Eigen::EigenvaluesOnly);
    for (int d = 0; d < 3; ++d) {
      worst = std::max(worst, std::abs(std::sqrt(std::max(0.0, solver.eigenvalues()(d))) - 1.0));
    }
  }
  return worst;
}

}  // namespace pliant::hal
