// `pliant record`: what the device loop hands over, put on the recording clock and kept or
// written.
//
// Time: t = (HAL stamp) - t0_s, seconds, with t0_s the clock reading taken when the devices were
// started; every device stamps on the same hal::Clock, so all files share one time axis.
// Per stream, a sample or frame is dropped (and counted) when
//   - its stamp is not finite, or a value is not (wrench, gripper width)       -> non_finite
//   - its stamp is not later than the previous kept one of that stream          -> out_of_order
//     (every file of a recording has strictly increasing t)
//   - wrench: a status bit in hal::kFtFaultMask (the sensor says "do not trust") -> fault_flagged
//     frames: hal::kFrameDeviceFault                                             -> fault_flagged
//   - colour/depth: the encoder thread is too far behind (record_media.hpp)     -> queue_full
// Gripper readings with a gripper fault code are kept (the width is still measured); their
// status bits are in gripper_state.csv.
//
// Kept in memory: wrench samples and gripper rows (the recording's wrench.csv, gripper.csv and
// particles are made from them at the end). Written at finish(): gripper_state.csv
// (t,width_m,target_width_m,force_n,current_a,status_bits; nan where the gripper does not
// report a value) and the media (record_media.hpp).
// Host code: allocates. Thread safety: one thread (the loop).
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "pliant/hal/camera.hpp"
#include "pliant/hal/force_torque.hpp"
#include "pliant/hal/gripper.hpp"
#include "pliant/host/recording.hpp"

namespace pliant::cli {

class MediaSink;

struct StreamCounters {
  std::uint64_t recorded = 0;       ///< kept (rows or frames handed to the encoder)
  std::uint64_t non_finite = 0;     ///< dropped: non-finite stamp or value
  std::uint64_t out_of_order = 0;   ///< dropped: stamp not after the previous kept one
  std::uint64_t fault_flagged = 0;  ///< dropped: fault status bits
  std::uint64_t queue_full = 0;     ///< dropped: encoder behind (frames only)
  std::uint64_t dropped() const { return non_finite + out_of_order + fault_flagged + queue_full; }
};

struct GripperRow {
  double t_s = 0;
  double width_m = 0;
  double target_width_m = 0;  ///< nan when unknown
  double force_n = 0;         ///< nan when the gripper does not sense force (Robotiq 2F)
  double current_a = 0;       ///< nan when not reported
  std::uint32_t status_bits = 0;
};

class RecordWriter {
 public:
  /// `directory` exists and is the recording being written. `media`: colour or depth frames
  /// will come (starts the encoder thread: the media part of cli_registry(); without it, that is
  /// without OpenCV in the build, std::logic_error: check cli_registry().media first).
  RecordWriter(std::string directory, double t0_s, bool media);
  ~RecordWriter();
  RecordWriter(const RecordWriter&) = delete;
  RecordWriter& operator=(const RecordWriter&) = delete;

  /// Each returns true when the sample or frame was kept.
  bool add_wrench(const hal::WrenchReading& reading);
  bool add_gripper(const hal::GripperReading& reading);
  bool add_color(const hal::ColorFrame& frame);
  bool add_depth(const hal::DepthFrame& frame);

  /// The encoder thread's first error (empty while none): the loop stops on it.
  std::string media_error() const;

  /// Finishes the media and writes gripper_state.csv (when gripper rows were kept). Throws
  /// std::runtime_error on I/O failure. Call once, after the last add_*.
  void finish();

  double t0_s() const { return t0_s_; }
  const std::vector<host::WrenchSample>& wrench() const { return wrench_; }
  const std::vector<GripperRow>& gripper() const { return gripper_; }
  const StreamCounters& wrench_counters() const { return wrench_counters_; }
  const StreamCounters& gripper_counters() const { return gripper_counters_; }
  const StreamCounters& color_counters() const { return color_counters_; }
  const StreamCounters& depth_counters() const { return depth_counters_; }

  // After finish(). Empty / 0 when no frame of that kind was written.
  const std::vector<double>& color_times() const;  ///< t of frame i of color.avi
  double color_fps() const;
  int color_width() const;
  int color_height() const;
  std::size_t depth_frame_count() const;
  std::uint64_t color_size_mismatches() const;
  /// Files written by finish(), by role: color_video, color_frames, depth_frames, gripper_state.
  std::map<std::string, std::string> files() const;

 private:
  std::string directory_;
  double t0_s_;
  std::unique_ptr<MediaSink> media_;  // null without frames
  std::vector<host::WrenchSample> wrench_;
  std::vector<GripperRow> gripper_;
  double last_color_t_ = 0, last_depth_t_ = 0;
  bool have_color_ = false, have_depth_ = false;
  StreamCounters wrench_counters_, gripper_counters_, color_counters_, depth_counters_;
  bool finished_ = false;
};

}  // namespace pliant::cli
