#include "pliant/hal/mock/replay_devices.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace pliant::hal {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The read fault at the clock's time, or the next sample (no_data when none is due).
HalStatus next_sample(ReplayCursor& cursor, const Clock& clock, ReplaySample& sample) noexcept {
  const double now = clock.now_s();
  const HalStatus link = cursor.read_fault(now);
  if (link != HalStatus::ok) return link;
  return cursor.take(now, sample) ? HalStatus::ok : HalStatus::no_data;
}

void set_header(SampleHeader& header, const ReplaySample& sample, std::uint32_t status_bits) noexcept {
  header.stamp_s = sample.stamp_s;
  header.sequence = sample.sequence;
  header.status_bits = status_bits;
}

}  // namespace

// ---- force/torque

HalStatus ReplayForceTorque::on_configure() {
  if (channel_.width != 6) return HalStatus::invalid_argument;
  return cursor_.configure(channel_, timing_, kForceTorqueFaults, kFtSupplyLow | kFtAnyError);
}

HalStatus ReplayForceTorque::on_start() noexcept {
  cursor_.start(clock_.now_s());
  return HalStatus::ok;
}

HalStatus ReplayForceTorque::on_read(WrenchReading& out) noexcept {
  ReplaySample s;
  const HalStatus status = next_sample(cursor_, clock_, s);
  if (status != HalStatus::ok) return status;
  set_header(out.header, s, s.status_bits);
  std::copy(s.values, s.values + 6, out.wrench);
  return HalStatus::ok;
}

// ---- gripper

HalStatus ReplayGripper::on_configure() {
  if (channel_.width != 2) return HalStatus::invalid_argument;
  const HalStatus s = cursor_.configure(channel_, timing_, kGripperFaults,
                                        static_cast<std::uint32_t>(kGripperFaultOverCurrent) << kGripperFaultCodeShift);
  if (s != HalStatus::ok) return s;
  double widest = 0;
  for (int k = 0; k < channel_.count(); ++k) {
    const double w = channel_.values[2 * static_cast<std::size_t>(k)];
    if (std::isfinite(w)) widest = std::max(widest, w);
  }
  limits_ = GripperLimits{};
  limits_.min_width_m = 0;
  limits_.max_width_m = widest > 0 ? widest : limits_.max_width_m;
  return HalStatus::ok;
}

HalStatus ReplayGripper::on_start() noexcept {
  cursor_.start(clock_.now_s());
  return HalStatus::ok;
}

HalStatus ReplayGripper::on_read(GripperReading& out) noexcept {
  ReplaySample s;
  const HalStatus status = next_sample(cursor_, clock_, s);
  if (status != HalStatus::ok) return status;
  set_header(out.header, s, kGripperActivated | s.status_bits);
  out.width_m = s.values[0];
  out.force_n = s.values[1];
  out.current_a = kNaN;
  out.target_width_m = kNaN;
  return HalStatus::ok;
}

HalStatus ReplayGripper::on_write(const GripperCommand&) noexcept { return HalStatus::unsupported; }

// ---- particle observer

HalStatus ReplayParticleObserver::on_configure() {
  if ((dimension_ != 2 && dimension_ != 3) || channel_.width <= 0 || channel_.width % dimension_ != 0) {
    return HalStatus::invalid_argument;
  }
  const HalStatus s = cursor_.configure(channel_, timing_, kObserverFaults, kFrameDeviceFault);
  if (s != HalStatus::ok) return s;
  const int n = channel_.width / dimension_;
  frame_.assign(static_cast<std::size_t>(channel_.width), kNaN);
  occlusion_order_.resize(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) occlusion_order_[static_cast<std::size_t>(i)] = i;
  const double* first = channel_.values.data();
  const int dim = dimension_;
  auto y_of = [first, dim](int i) {
    const double y = first[static_cast<std::size_t>(i * dim + 1)];
    return std::isfinite(y) ? y : -std::numeric_limits<double>::infinity();
  };
  std::stable_sort(occlusion_order_.begin(), occlusion_order_.end(), [&](int a, int b) { return y_of(a) > y_of(b); });
  return HalStatus::ok;
}

HalStatus ReplayParticleObserver::on_start() noexcept {
  cursor_.start(clock_.now_s());
  return HalStatus::ok;
}

HalStatus ReplayParticleObserver::on_read(ParticleFrame& out) noexcept {
  ReplaySample s;
  const HalStatus status = next_sample(cursor_, clock_, s);
  if (status != HalStatus::ok) return status;
  std::copy(s.values, s.values + frame_.size(), frame_.begin());
  const int n = static_cast<int>(occlusion_order_.size());
  std::uint32_t bits = s.status_bits;
  if (s.faults.has(FaultKind::occlude)) {
    cursor_.count(FaultKind::occlude);
    const double v = s.faults.value[static_cast<int>(FaultKind::occlude)];
    const int hidden = std::min(n, static_cast<int>(std::lround((std::isnan(v) ? 0.5 : v) * n)));
    for (int k = 0; k < hidden; ++k) {
      const auto p = static_cast<std::size_t>(occlusion_order_[static_cast<std::size_t>(k)]);
      for (std::size_t d = 0; d < static_cast<std::size_t>(dimension_); ++d) {
        frame_[p * static_cast<std::size_t>(dimension_) + d] = kNaN;
      }
    }
    if (hidden > 0) bits |= kFramePartial;
  }
  int observed = 0;
  for (int i = 0; i < n; ++i) {
    bool finite = true;
    const std::size_t first = static_cast<std::size_t>(i) * static_cast<std::size_t>(dimension_);
    for (int d = 0; d < dimension_; ++d) finite = finite && std::isfinite(frame_[first + static_cast<std::size_t>(d)]);
    observed += finite ? 1 : 0;
  }
  set_header(out.header, s, bits);
  out.dimension = dimension_;
  out.particle_count = n;
  out.positions = frame_.data();
  out.observed_count = observed;
  return HalStatus::ok;
}

}  // namespace pliant::hal
