// pliant hal: checks one device's sample stream for the faults a device does not report
// itself - dropped samples, stamps that stall, go backwards or jump, frozen (repeated) data and
// non-finite values - and turns them into status bits a consumer (e.g. the grasp guard) can act
// on in the cycle the sample arrives.
//
// Feed it every delivered sample (read() == ok) of one stream, in order:
//   std::uint32_t flags = monitor.check(sample.header, values, count);
// and OR the flags into the status word you pass on (they use bits 16-21, clear of every
// device's own bits). kStreamFaultMask holds the ones that mean the sample must not be trusted.
//
// Frozen data: a live sensor has noise in its low bits, so a payload repeated bit for bit
//   means the source stopped updating while its driver kept re-sending. The monitor keeps a
//   64-bit FNV-1a hash of the previous payload (no copy): a collision between two different
//   payloads (probability ~2^-64) would be a false alarm, never a missed freeze. Turn the check
//   off (frozen_repeats = 0) for noise-free sources such as simulations without noise.
// Real-time safety: check() is O(count), allocation-free, noexcept.
#pragma once

#include <cstdint>
#include <limits>

#include "pliant/hal/device.hpp"

namespace pliant::hal {

inline constexpr std::uint32_t kStreamSequenceGap = 1u << 16;     ///< samples were dropped before this one
inline constexpr std::uint32_t kStreamStampStall = 1u << 17;      ///< a new sample with the previous stamp
inline constexpr std::uint32_t kStreamStampBackwards = 1u << 18;  ///< stamp earlier than the previous one
inline constexpr std::uint32_t kStreamStampJump = 1u << 19;       ///< stamp step above max_interval_s
inline constexpr std::uint32_t kStreamFrozen = 1u << 20;          ///< payload identical to the previous one
inline constexpr std::uint32_t kStreamNonFinite = 1u << 21;       ///< non-finite stamp, or too many non-finite values
/// Flags meaning "do not trust this sample" (a sequence gap alone is informational: the drop is
/// counted, and a source that stops delivering goes stale at its consumer).
inline constexpr std::uint32_t kStreamFaultMask =
    kStreamStampStall | kStreamStampBackwards | kStreamStampJump | kStreamFrozen | kStreamNonFinite;

struct StreamMonitorConfig {
  /// A stamp step larger than this raises kStreamStampJump (e.g. 3 sample periods); +inf: off.
  double max_interval_s = std::numeric_limits<double>::infinity();
  /// Consecutive repeats of the payload that raise kStreamFrozen (1: the first repeat); 0: off.
  int frozen_repeats = 1;
  /// kStreamNonFinite when more than this fraction of the values is non-finite, [0, 1]
  /// (0: any; for particle frames, where NaN means unobserved, e.g. 0.5).
  double max_non_finite_fraction = 0;
};

struct StreamMonitorCounters {
  std::uint64_t samples = 0;  ///< samples checked
  std::uint64_t gaps = 0;     ///< samples after a sequence gap
  std::uint64_t dropped = 0;  ///< samples missing in those gaps
  std::uint64_t stalls = 0;
  std::uint64_t backwards = 0;
  std::uint64_t jumps = 0;
  std::uint64_t frozen = 0;
  std::uint64_t non_finite = 0;
  std::uint64_t flagged = 0;  ///< samples with any kStreamFaultMask flag
};

class StreamMonitor {
 public:
  StreamMonitor() noexcept = default;
  /// invalid_argument for max_interval_s not > 0 (NaN included), frozen_repeats < 0, or a
  /// fraction outside [0, 1]; the previous configuration is kept then.
  HalStatus configure(const StreamMonitorConfig& config) noexcept;
  /// Forgets the previous sample (a new stream); counters are kept.
  void reset() noexcept;
  /// Flags of one delivered sample; `values` may be null when count is 0.
  std::uint32_t check(const SampleHeader& header, const double* values, int count) noexcept;
  const StreamMonitorCounters& counters() const noexcept { return counters_; }
  const StreamMonitorConfig& config() const noexcept { return config_; }

 private:
  StreamMonitorConfig config_;
  StreamMonitorCounters counters_;
  bool has_previous_ = false;
  std::uint64_t previous_sequence_ = 0;
  double previous_stamp_s_ = 0;
  std::uint64_t previous_hash_ = 0;
  int repeats_ = 0;
};

}  // namespace pliant::hal
