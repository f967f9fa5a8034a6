#include "hil_supervisor.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "pliant/hal/guard_inputs.hpp"

namespace pliant::hil {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

}  // namespace

Supervisor::Supervisor(hal::Gripper& gripper, hal::ForceTorqueSensor& wrench, hal::ParticleObserver& observer,
                       const hal::Clock& clock, const SupervisorConfig& config)
    : gripper_(gripper), wrench_(wrench), observer_(observer), clock_(clock), config_(config) {
  (void)gripper_monitor_.configure(config.gripper_monitor);
  (void)wrench_monitor_.configure(config.wrench_monitor);
  (void)camera_monitor_.configure(config.camera_monitor);
}

hal::HalStatus Supervisor::start() {
  for (hal::Device* device : {static_cast<hal::Device*>(&gripper_), static_cast<hal::Device*>(&wrench_),
                              static_cast<hal::Device*>(&observer_)}) {
    const hal::HalStatus s = device->start();
    if (s != hal::HalStatus::ok) return s;
  }
  return hal::HalStatus::ok;
}

OnlineDeformabilityEstimate Supervisor::estimate() const {
  if (!estimator_.initialized()) return OnlineDeformabilityEstimate{};
  return online_deformability_estimate(estimator_);
}

void Supervisor::learn(const hal::ParticleFrame& frame) {
  const auto values = static_cast<std::size_t>(frame.particle_count) * 3;
  if (frame.dimension != 3 || frame.particle_count < 8 || frame.positions == nullptr) return;
  if (rest_sum_.empty()) {
    rest_sum_.assign(values, 0.0);
    rest_count_.assign(static_cast<std::size_t>(frame.particle_count), 0);
  }
  if (rest_sum_.size() != values) return;
  for (int i = 0; i < frame.particle_count; ++i) {
    const double* p = frame.positions + 3 * i;
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) continue;
    for (int d = 0; d < 3; ++d) rest_sum_[static_cast<std::size_t>(3 * i + d)] += p[d];
    ++rest_count_[static_cast<std::size_t>(i)];
  }
  ++rest_frames_seen_;
}

bool Supervisor::build() {
  const int n = static_cast<int>(rest_count_.size());
  rest_.assign(static_cast<std::size_t>(3 * n), 0.0);
  all_.resize(static_cast<std::size_t>(n));
  double low = std::numeric_limits<double>::infinity(), high = -low;
  for (int i = 0; i < n; ++i) {
    const auto u = static_cast<std::size_t>(i);
    if (rest_count_[u] == 0) return false;  // a particle never seen: no rest shape for it
    for (int d = 0; d < 3; ++d)
      rest_[3 * u + static_cast<std::size_t>(d)] = rest_sum_[3 * u + static_cast<std::size_t>(d)] / rest_count_[u];
    low = std::min(low, rest_[3 * u]);
    high = std::max(high, rest_[3 * u]);
    all_[u] = i;
  }
  visible_width_m_ = high - low;
  MsmModelConfig<3, double> mc;
  mc.particle_count = n;
  mc.rest_positions = rest_.data();
  mc.drivable_ids = all_.data();
  mc.drivable_count = n;
  model_block_.assign(msm_model_workspace_size(mc), 0);
  Arena model_arena(model_block_.data(), model_block_.size());
  if (model_block_.empty() || msm_model_init(model_arena, mc, model_) != Status::ok) return false;
  GraspObject<3, double> object;
  object.squeeze_axis = Vec(1, 0, 0);
  guard_block_.assign(grasp_guard_workspace_size(model_, config_.guard), 0);
  Arena guard_arena(guard_block_.data(), guard_block_.size());
  if (grasp_guard_init(guard_arena, model_, object, config_.guard, guard_) != Status::ok) return false;
  MsmParams<3, double> base;
  estimator_block_.assign(online_deformability_workspace_size(model_, config_.estimator), 0);
  Arena estimator_arena(estimator_block_.data(), estimator_block_.size());
  if (online_deformability_init(estimator_arena, model_, base, config_.estimator, estimator_) != Status::ok)
    return false;
  observed_.assign(static_cast<std::size_t>(n), Vec::Zero());
  driven_ids_.assign(static_cast<std::size_t>(n), 0);
  driven_targets_.assign(static_cast<std::size_t>(n), Vec::Zero());
  return true;
}

// A new frame: strain for the guard, and the estimator's update driven by the particles that
// the frame shows at a jaw (the jaw planes from the latest gripper width), once the guard has
// seen contact: before that a jaw plane within the band is still outside the object, and moving
// the particles onto it would teach the estimator a stretch the object never had.
void Supervisor::on_frame(const hal::ParticleFrame& frame, std::uint32_t flags) {
  const int n = model_.particle_count;
  double strain = kNaN;
  std::uint32_t bits = frame.header.status_bits | flags;
  if (frame.dimension == 3 && frame.particle_count == n && frame.positions != nullptr) {
    for (int i = 0; i < n; ++i) {
      observed_[static_cast<std::size_t>(i)] =
          Vec(frame.positions[3 * i], frame.positions[3 * i + 1], frame.positions[3 * i + 2]);
    }
    GraspStrainMeasurement measured;
    if (grasp_guard_measure_strain(model_, guard_, observed_.data(), measured) == Status::ok) strain = measured.strain;
    // Only trustworthy frames teach the estimator (a frozen or stalled frame would bias it).
    const bool usable = (bits & (hal::kStreamFaultMask | hal::kFrameFaultMask)) == 0 &&
                        std::isfinite(frame.header.stamp_s) && has_frame_stamp_ &&
                        frame.header.stamp_s > last_frame_stamp_s_;
    if (usable) {
      int count = 0;
      if (have_width_ && in_contact_) {
        const double band = config_.contact_band * model_.spacing;
        const double plane_a = -0.5 * width_m_, plane_b = 0.5 * width_m_;
        for (int i = 0; i < n; ++i) {
          const Vec& x = observed_[static_cast<std::size_t>(i)];
          if (!x.allFinite()) continue;
          const bool at_a = x(0) <= plane_a + band;
          const bool at_b = x(0) >= plane_b - band;
          if (!at_a && !at_b) continue;
          Vec target = x;
          target(0) = at_a ? plane_a : plane_b;
          driven_ids_[static_cast<std::size_t>(count)] = i;
          driven_targets_[static_cast<std::size_t>(count)] = target;
          ++count;
        }
      }
      const double dt = frame.header.stamp_s - last_frame_stamp_s_;
      MsmDrivenTargets<3, double> driven;
      driven.ids = driven_ids_.data();
      driven.positions = driven_targets_.data();
      driven.count = count;
      (void)online_deformability_update(model_, estimator_, dt, driven, observed_.data());
      last_frame_stamp_s_ = frame.header.stamp_s;
      has_frame_stamp_ = true;
    }
  } else {
    bits |= hal::kFrameDeviceFault;  // a frame that does not fit the model cannot be measured
  }
  hal::update_deformation_sample(hal::HalStatus::ok, frame.header.stamp_s, strain, bits, input_.deformation);
  const OnlineDeformabilityEstimate e = online_deformability_estimate(estimator_);
  input_.estimate.stamp_s = frame.header.stamp_s;
  input_.estimate.msm_beta = e.msm_beta;
  input_.estimate.msm_beta_std = std::max(e.msm_beta_std, config_.beta_std_floor);
  input_.estimate.valid = std::isfinite(frame.header.stamp_s);
}

void Supervisor::write_move(double width_m, double speed_m_per_s, double force_n) {
  if (has_command_ && last_kind_ == hal::GripperCommandKind::move && std::abs(width_m - last_width_m_) < 2e-7 &&
      force_n == last_force_n_) {
    return;
  }
  const hal::HalStatus s = gripper_.move_to(width_m, speed_m_per_s, force_n);
  report_.command = s;
  report_.command_width_m = width_m;
  if (s != hal::HalStatus::ok) {
    has_command_ = false;  // retry next cycle
    return;
  }
  has_command_ = true;
  last_kind_ = hal::GripperCommandKind::move;
  last_width_m_ = width_m;
  last_force_n_ = force_n;
}

void Supervisor::write_stop() {
  if (has_command_ && last_kind_ == hal::GripperCommandKind::stop) return;
  const hal::HalStatus s = gripper_.freeze();
  report_.command = s;
  if (s != hal::HalStatus::ok) {
    has_command_ = false;
    return;
  }
  has_command_ = true;
  last_kind_ = hal::GripperCommandKind::stop;
}

void Supervisor::command(const GraspGuardOutput& out) {
  const double force = std::isfinite(out.allowed_force_n) ? out.allowed_force_n : config_.guard.max_force_n;
  switch (out.verdict) {
    case GraspVerdict::ok: {
      double width = visible_width_m_ * (1 - config_.target_closure_fraction);
      double speed = config_.close_speed_m_per_s;
      if (phase_ == Phase::approach) {
        width = visible_width_m_ + config_.approach_gap_m;
        speed = config_.approach_speed_m_per_s;
        if (have_width_ && width_m_ <= width + config_.approach_tolerance_m) phase_ = Phase::squeeze;
      }
      if (phase_ == Phase::squeeze) {
        width = visible_width_m_ * (1 - config_.target_closure_fraction);
        speed = config_.close_speed_m_per_s;
        if (out.in_contact && std::isfinite(out.safe_width_m)) width = std::max(width, out.safe_width_m);
      }
      write_move(width, speed, force);
      break;
    }
    case GraspVerdict::limit:
      // Hold: close no further. Re-sent after a failed write, never re-opened by itself.
      write_stop();
      break;
    case GraspVerdict::stop:
      if (out.stop_action == StopAction::open) {
        const double contact = std::isfinite(out.contact_width_m) ? out.contact_width_m : visible_width_m_;
        write_move(contact + config_.open_margin_m, config_.open_speed_m_per_s, force);
      } else {
        write_stop();
      }
      break;
  }
  last_verdict_ = out.verdict;
}

const CycleReport& Supervisor::cycle() {
  report_ = CycleReport{};
  report_.cycle_start_at = std::chrono::steady_clock::now();
  report_.cycle = cycles_++;
  const double now = clock_.now_s();
  report_.now_s = now;

  // Reads: every device, every cycle (each returns at once).
  hal::GripperReading g;
  report_.gripper_read = gripper_.read(g);
  report_.gripper_sample_at = std::chrono::steady_clock::now();
  std::uint32_t g_flags = 0;
  if (report_.gripper_read == hal::HalStatus::ok) {
    const double values[3] = {g.width_m, g.force_n, g.current_a};
    g_flags = gripper_monitor_.check(g.header, values, 3);
    if (std::isfinite(g.width_m)) {
      width_m_ = g.width_m;
      have_width_ = true;
    }
  }
  hal::update_gripper_sample(report_.gripper_read, g, g_flags, input_.gripper);
  hal::WrenchReading w;
  report_.wrench_read = wrench_.read(w);
  std::uint32_t w_flags = 0;
  if (report_.wrench_read == hal::HalStatus::ok) w_flags = wrench_monitor_.check(w.header, w.wrench, 6);
  hal::update_wrench_sample(report_.wrench_read, w, w_flags, input_.wrench);
  hal::ParticleFrame frame;
  report_.frame_read = observer_.read(frame);
  report_.new_frame = report_.frame_read == hal::HalStatus::ok;

  if (phase_ == Phase::learning) {
    if (report_.new_frame) {
      (void)camera_monitor_.check(frame.header, frame.positions, frame.particle_count * frame.dimension);
      learn(frame);
      if (std::isfinite(frame.header.stamp_s)) {
        last_frame_stamp_s_ = frame.header.stamp_s;
        has_frame_stamp_ = true;
      }
      if (rest_frames_seen_ >= config_.rest_frames) {
        phase_ = build() ? Phase::approach : Phase::failed;
        // The last rest frame seeds the guard's camera and estimate samples (the estimator
        // itself starts with the next frame).
        if (phase_ == Phase::approach) on_frame(frame, 0);
      }
    }
    report_.phase = phase_;
    return report_;
  }
  if (phase_ == Phase::failed) {
    report_.phase = phase_;
    return report_;
  }

  if (report_.new_frame) {
    ++frames_;
    const std::uint32_t flags =
        camera_monitor_.check(frame.header, frame.positions, frame.particle_count * frame.dimension);
    on_frame(frame, flags);
  } else if (report_.frame_read != hal::HalStatus::no_data) {
    hal::update_deformation_sample(report_.frame_read, kNaN, kNaN, 0, input_.deformation);
  }
  input_.now_s = now;
  (void)grasp_guard_update(guard_, input_, report_.out);
  report_.verdict_at = std::chrono::steady_clock::now();
  in_contact_ = report_.out.in_contact;
  report_.guarded = true;
  command(report_.out);
  report_.cycle_end_at = std::chrono::steady_clock::now();
  report_.phase = phase_;
  return report_;
}

}  // namespace pliant::hil
