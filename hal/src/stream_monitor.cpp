#include "pliant/hal/stream_monitor.hpp"

#include <cmath>
#include <cstring>

namespace pliant::hal {
namespace {

constexpr std::uint64_t kFnvOffset = 14695981039346656037ull;
constexpr std::uint64_t kFnvPrime = 1099511628211ull;

std::uint64_t payload_hash(const double* values, int count) noexcept {
  std::uint64_t hash = kFnvOffset;
  for (int i = 0; i < count; ++i) {
    std::uint64_t bits = 0;
    std::memcpy(&bits, values + i, sizeof bits);
    for (int byte = 0; byte < 8; ++byte) {
      hash ^= (bits >> (8 * byte)) & 0xffu;
      hash *= kFnvPrime;
    }
  }
  return hash;
}

}  // namespace

HalStatus StreamMonitor::configure(const StreamMonitorConfig& config) noexcept {
  if (!(config.max_interval_s > 0) || config.frozen_repeats < 0 || !(config.max_non_finite_fraction >= 0) ||
      config.max_non_finite_fraction > 1) {
    return HalStatus::invalid_argument;
  }
  config_ = config;
  reset();
  return HalStatus::ok;
}

void StreamMonitor::reset() noexcept {
  has_previous_ = false;
  repeats_ = 0;
}

std::uint32_t StreamMonitor::check(const SampleHeader& header, const double* values, int count) noexcept {
  if (values == nullptr || count < 0) count = 0;
  ++counters_.samples;
  std::uint32_t flags = 0;
  int non_finite = 0;
  for (int i = 0; i < count; ++i) non_finite += std::isfinite(values[i]) ? 0 : 1;
  const bool stamp_finite = std::isfinite(header.stamp_s);
  if (!stamp_finite || static_cast<double>(non_finite) > config_.max_non_finite_fraction * count) {
    flags |= kStreamNonFinite;
    ++counters_.non_finite;
  }
  const std::uint64_t hash = payload_hash(values, count);
  if (has_previous_) {
    if (header.sequence > previous_sequence_ + 1) {
      flags |= kStreamSequenceGap;
      ++counters_.gaps;
      counters_.dropped += header.sequence - previous_sequence_ - 1;
    }
    if (stamp_finite) {
      if (header.stamp_s == previous_stamp_s_) {
        flags |= kStreamStampStall;
        ++counters_.stalls;
      } else if (header.stamp_s < previous_stamp_s_) {
        flags |= kStreamStampBackwards;
        ++counters_.backwards;
      } else if (header.stamp_s - previous_stamp_s_ > config_.max_interval_s) {
        flags |= kStreamStampJump;
        ++counters_.jumps;
      }
    }
    repeats_ = hash == previous_hash_ ? repeats_ + 1 : 0;
    if (config_.frozen_repeats > 0 && repeats_ >= config_.frozen_repeats) {
      flags |= kStreamFrozen;
      ++counters_.frozen;
    }
  }
  if ((flags & kStreamFaultMask) != 0) ++counters_.flagged;
  has_previous_ = true;
  previous_sequence_ = header.sequence;
  if (stamp_finite) previous_stamp_s_ = header.stamp_s;
  previous_hash_ = hash;
  return flags;
}

}  // namespace pliant::hal
