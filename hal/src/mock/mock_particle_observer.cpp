#include "pliant/hal/mock/mock_particle_observer.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "sample_faults.hpp"

namespace pliant::hal {

using detail::SampleFate;

HalStatus MockParticleObserver::on_configure() {
  const MockParticleObserverConfig& c = config_;
  if (!plant_.configured()) return HalStatus::invalid_argument;
  if (!(std::isfinite(c.noise_m) && c.noise_m >= 0) || !(c.occlusion_fraction >= 0 && c.occlusion_fraction < 1) ||
      !(std::isfinite(c.latency_s) && c.latency_s >= 0) || !(std::isfinite(c.period_s) && c.period_s > 0) ||
      c.latency_s / c.period_s > 1000) {
    return HalStatus::invalid_argument;
  }
  const HalStatus s = stream_.configure(c.period_s, c.latency_s, kObserverFaults);
  if (s != HalStatus::ok) return s;
  stream_.clear_fault_counters();
  n_ = plant_.particle_count();
  slots_ = static_cast<int>(std::floor(c.latency_s / c.period_s)) + 2;
  const auto values = static_cast<std::size_t>(n_) * 3;
  captured_.assign(static_cast<std::size_t>(slots_) * values, 0.0);
  slot_index_.assign(static_cast<std::size_t>(slots_), -1);
  frame_.assign(values, std::numeric_limits<double>::quiet_NaN());
  occlusion_order_.resize(static_cast<std::size_t>(n_));
  for (int i = 0; i < n_; ++i) occlusion_order_[static_cast<std::size_t>(i)] = i;
  const SimulatedGrasp::Vec* rest = plant_.rest_positions();
  std::stable_sort(occlusion_order_.begin(), occlusion_order_.end(),
                   [rest](int a, int b) { return rest[a](1) > rest[b](1); });
  rng_.seed(c.seed);
  next_capture_ = 0;
  has_last_ = false;
  return HalStatus::ok;
}

HalStatus MockParticleObserver::on_start() noexcept {
  stream_.start(clock_.now_s());
  // Captures follow the stream's clock (it continues sequence numbers across stop/start).
  next_capture_ = static_cast<std::int64_t>(std::llround((clock_.now_s() - stream_.start_s()) / stream_.period_s()));
  for (std::int64_t& s : slot_index_) s = -1;
  return HalStatus::ok;
}

void MockParticleObserver::capture(double now_s) noexcept {
  const double newest = std::floor((now_s - stream_.start_s()) / stream_.period_s() + 1e-6);
  if (!(newest >= 0) || newest > 9.0e15 || newest < static_cast<double>(next_capture_)) return;
  const auto index = static_cast<std::int64_t>(newest);
  const auto slot = static_cast<std::size_t>(index % slots_);
  double* dst = captured_.data() + slot * static_cast<std::size_t>(n_) * 3;
  const SimulatedGrasp::Vec* x = plant_.positions();
  for (int i = 0; i < n_; ++i) {
    for (int d = 0; d < 3; ++d) dst[3 * i + d] = x[i](d);
  }
  slot_index_[slot] = index;
  next_capture_ = index + 1;
}

HalStatus MockParticleObserver::on_read(ParticleFrame& out) noexcept {
  plant_.sync();
  const double now = clock_.now_s();
  capture(now);
  const HalStatus link = stream_.read_fault(now);
  if (link != HalStatus::ok) return link;
  std::uint64_t index = 0, sequence = 0;
  double stamp = 0;
  if (!stream_.take(now, index, stamp, sequence)) return HalStatus::no_data;
  const auto slot = static_cast<std::size_t>(index % static_cast<std::uint64_t>(slots_));
  if (slot_index_[slot] != static_cast<std::int64_t>(index)) return HalStatus::no_data;  // capture missed: lost
  const ActiveFaults f = stream_.sample_faults(stamp);
  const SampleFate fate = detail::sample_fate(f, has_last_, stream_);
  if (fate == SampleFate::dropped) return HalStatus::no_data;
  SampleHeader header;
  int observed = n_;
  if (fate == SampleFate::repeat_previous) {
    header = last_header_;
    observed = last_observed_;
  } else {
    if (fate == SampleFate::previous_values) {
      header.status_bits = last_header_.status_bits;
      observed = last_observed_;
    } else {
      const double* src = captured_.data() + slot * static_cast<std::size_t>(n_) * 3;
      for (std::size_t k = 0; k < frame_.size(); ++k) frame_[k] = src[k] + config_.noise_m * normal_(rng_);
      double hidden = config_.occlusion_fraction;
      if (detail::take_fault(f, FaultKind::occlude, stream_)) {
        const double v = f.value[static_cast<int>(FaultKind::occlude)];
        hidden = std::max(hidden, std::isnan(v) ? 0.5 : v);
      }
      const int count = std::min(n_, static_cast<int>(std::lround(hidden * n_)));
      for (int k = 0; k < count; ++k) {
        const auto p = static_cast<std::size_t>(occlusion_order_[static_cast<std::size_t>(k)]);
        for (std::size_t d = 0; d < 3; ++d) frame_[3 * p + d] = std::numeric_limits<double>::quiet_NaN();
      }
      observed = n_ - count;
      header.status_bits = count > 0 ? kFramePartial : 0u;
    }
    header.stamp_s = stamp;
    if (detail::take_fault(f, FaultKind::nan, stream_)) {
      for (double& v : frame_) v = std::numeric_limits<double>::quiet_NaN();
      observed = 0;
    }
    detail::apply_stamp_and_status_faults(f, config_.fault_bits, stream_, header.stamp_s, header.status_bits);
  }
  header.sequence = sequence;
  last_header_ = header;
  last_observed_ = observed;
  has_last_ = true;
  out.header = header;
  out.dimension = 3;
  out.particle_count = n_;
  out.positions = frame_.data();
  out.observed_count = observed;
  return HalStatus::ok;
}

}  // namespace pliant::hal
