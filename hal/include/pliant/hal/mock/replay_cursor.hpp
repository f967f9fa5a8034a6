// pliant hal mocks: playback of one recorded channel (time-stamped rows of numbers), the part
// every replay device shares (replay_devices.hpp).
//
// A RecordedChannel is what a recording holds for one sensor: sample times t_s (seconds,
// finite, strictly increasing) and `width` values per sample. The caller owns it and keeps it
// alive and unchanged while a device replays it.
//
// Timing on the device's Clock, anchored at start(): sample k is stamped
//   anchor + (t_k - t_first) / speed
// where the anchor is chosen so that the first sample not yet delivered is due at the start()
// call (so stop/start pauses the recording instead of skipping it).
//   realtime  a read delivers the newest sample that is due and not yet taken; older ones it
//             never delivered are lost (a sequence gap: counted as dropped by the device), as
//             with a live sensor read too slowly.
//   stepped   each read delivers the next sample, whatever the clock says (stamps as above):
//             the whole recording, sample by sample, as fast as the caller reads.
// Sequence number of sample k: k + 1. After the last sample every read returns no_data and
// finished() is true.
//
// Faults: a FaultSchedule as the other mocks (fault_schedule.hpp). Read faults are decided at
// the time of the read; sample faults at the sample's stamp: drop, freeze_data, freeze_stamp,
// nan, stamp_jump, fault_bits (the device's word, default given at configure). occlude is the
// particle observer's own (replay_devices.hpp). Injections are counted per kind.
// Real-time safety: configure allocates (one row of `width` doubles); everything else is
// bounded, allocation-free and noexcept.
#pragma once

#include <cstdint>
#include <vector>

#include "pliant/hal/mock/fault_schedule.hpp"

namespace pliant::hal {

struct RecordedChannel {
  std::vector<double> t_s;     ///< sample times, s, strictly increasing
  std::vector<double> values;  ///< t_s.size() * width, sample-major
  int width = 0;               ///< values per sample (> 0)
  int count() const noexcept { return static_cast<int>(t_s.size()); }
};

enum class ReplayMode : std::uint8_t { realtime, stepped };

struct ReplayTiming {
  ReplayMode mode = ReplayMode::realtime;
  double speed = 1.0;  ///< recorded seconds per clock second, finite and > 0
};

/// One delivered sample: its values (a view into the cursor's row, valid until the next take)
/// and header fields.
struct ReplaySample {
  const double* values = nullptr;  ///< [width]
  double stamp_s = 0;
  std::uint64_t sequence = 0;
  std::uint32_t status_bits = 0;
  int index = -1;       ///< the recorded sample the values come from
  ActiveFaults faults;  ///< the sample faults active at its stamp (occlude is left to the caller)
};

class ReplayCursor {
 public:
  /// invalid_argument: empty channel, width <= 0, values of the wrong size, non-finite or
  /// non-increasing times, bad speed. unsupported: the schedule uses a kind outside `supported`.
  HalStatus configure(const RecordedChannel& channel, const ReplayTiming& timing, std::uint32_t supported,
                      std::uint32_t default_fault_bits);
  HalStatus set_schedule(const FaultSchedule& schedule) noexcept;
  HalStatus add_fault(const FaultEvent& event) noexcept;

  /// Anchors the playback so that the next sample is due at now_s.
  void start(double now_s) noexcept;
  /// The read fault active at now_s (disconnect, bus_off, timeout), counted; ok when none.
  HalStatus read_fault(double now_s) noexcept;
  /// The next sample per the timing mode, with sample faults applied (a dropped sample is
  /// counted and skipped: false). False when nothing is due or the channel is finished.
  bool take(double now_s, ReplaySample& out) noexcept;

  bool finished() const noexcept { return channel_ != nullptr && next_ >= channel_->count(); }
  /// When the next sample is due on the device clock; +infinity when finished or not started.
  double next_due_s() const noexcept;
  /// The recorded sample index of the last delivered sample (-1 before the first).
  int last_index() const noexcept { return last_index_; }
  /// Samples not yet delivered or skipped.
  int remaining() const noexcept { return channel_ == nullptr ? 0 : channel_->count() - next_; }
  void count(FaultKind kind) noexcept { ++counters_.injected[static_cast<int>(kind)]; }
  const FaultCounters& fault_counters() const noexcept { return counters_; }
  int width() const noexcept { return channel_ == nullptr ? 0 : channel_->width; }

 private:
  double stamp_of(int index) const noexcept;

  const RecordedChannel* channel_ = nullptr;
  ReplayTiming timing_;
  FaultSchedule schedule_;
  FaultCounters counters_;
  std::uint32_t supported_ = 0;
  std::uint32_t default_fault_bits_ = 0;
  std::vector<double> row_;  ///< the last delivered values (freeze_data repeats them)
  double anchor_s_ = 0;
  int next_ = 0;  ///< first sample not yet taken
  int last_index_ = -1;
  bool started_ = false;
  bool has_last_ = false;
  double last_stamp_s_ = 0;
  std::uint32_t last_status_ = 0;
};

}  // namespace pliant::hal
