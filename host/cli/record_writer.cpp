#include "record_writer.hpp"

#include <charconv>
#include <cmath>
#include <filesystem>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "atomic_write.hpp"
#include "cli_registry.hpp"
#include "record_media.hpp"

namespace pliant::cli {
namespace {

namespace fs = std::filesystem;

constexpr const char* kGripperState = "gripper_state.csv";

std::string number(double value) {
  if (!std::isfinite(value)) return "nan";
  char text[40];
  const std::to_chars_result end = std::to_chars(text, text + sizeof text, value);
  return std::string(text, end.ptr);
}

const std::vector<double> kNoTimes;

// Stamp check shared by the streams: finite and after the previous kept one.
bool admit_stamp(double t, bool& have_last, double& last, StreamCounters& counters) {
  if (!std::isfinite(t)) {
    ++counters.non_finite;
    return false;
  }
  if (have_last && !(t > last)) {
    ++counters.out_of_order;
    return false;
  }
  have_last = true;
  last = t;
  return true;
}

}  // namespace

RecordWriter::RecordWriter(std::string directory, double t0_s, bool media)
    : directory_(std::move(directory)), t0_s_(t0_s) {
  if (media) {
    const CliRegistry& parts = cli_registry();
    if (!parts.media) throw std::logic_error("recording frames needs OpenCV, which this build lacks");
    media_ = parts.media(directory_);
  }
}

RecordWriter::~RecordWriter() = default;

bool RecordWriter::add_wrench(const hal::WrenchReading& reading) {
  const double t = reading.header.stamp_s - t0_s_;
  for (const double v : reading.wrench) {
    if (!std::isfinite(v)) {
      ++wrench_counters_.non_finite;
      return false;
    }
  }
  if ((reading.header.status_bits & hal::kFtFaultMask) != 0) {
    ++wrench_counters_.fault_flagged;
    return false;
  }
  bool have = !wrench_.empty();
  double last = have ? wrench_.back().t_s : 0.0;
  if (!admit_stamp(t, have, last, wrench_counters_)) return false;
  host::WrenchSample s;
  s.t_s = t;
  for (int i = 0; i < 3; ++i) {
    s.force_n[i] = reading.wrench[i];
    s.torque_nm[i] = reading.wrench[i + 3];
  }
  wrench_.push_back(s);
  ++wrench_counters_.recorded;
  return true;
}

bool RecordWriter::add_gripper(const hal::GripperReading& reading) {
  const double t = reading.header.stamp_s - t0_s_;
  if (!std::isfinite(reading.width_m)) {
    ++gripper_counters_.non_finite;
    return false;
  }
  bool have = !gripper_.empty();
  double last = have ? gripper_.back().t_s : 0.0;
  if (!admit_stamp(t, have, last, gripper_counters_)) return false;
  GripperRow row;
  row.t_s = t;
  row.width_m = reading.width_m;
  row.target_width_m = reading.target_width_m;
  row.force_n = reading.force_n;
  row.current_a = reading.current_a;
  row.status_bits = reading.header.status_bits;
  gripper_.push_back(row);
  ++gripper_counters_.recorded;
  return true;
}

bool RecordWriter::add_color(const hal::ColorFrame& frame) {
  if (!media_) throw std::logic_error("RecordWriter: colour frame without media");
  if ((frame.header.status_bits & hal::kFrameDeviceFault) != 0) {
    ++color_counters_.fault_flagged;
    return false;
  }
  const double t = frame.header.stamp_s - t0_s_;
  if (!admit_stamp(t, have_color_, last_color_t_, color_counters_)) return false;
  if (!media_->push_color(frame, t)) {
    ++color_counters_.queue_full;
    return false;
  }
  ++color_counters_.recorded;
  return true;
}

bool RecordWriter::add_depth(const hal::DepthFrame& frame) {
  if (!media_) throw std::logic_error("RecordWriter: depth frame without media");
  if ((frame.header.status_bits & hal::kFrameDeviceFault) != 0) {
    ++depth_counters_.fault_flagged;
    return false;
  }
  const double t = frame.header.stamp_s - t0_s_;
  if (!admit_stamp(t, have_depth_, last_depth_t_, depth_counters_)) return false;
  if (!media_->push_depth(frame, t)) {
    ++depth_counters_.queue_full;
    return false;
  }
  ++depth_counters_.recorded;
  return true;
}

std::string RecordWriter::media_error() const {
  if (media_) return media_->error();
  return std::string();
}

void RecordWriter::finish() {
  if (finished_) throw std::logic_error("RecordWriter::finish called twice");
  finished_ = true;
  if (media_) media_->finish();
  if (!gripper_.empty()) {
    std::ostringstream csv;
    csv << "t,width_m,target_width_m,force_n,current_a,status_bits\n";
    for (const GripperRow& r : gripper_) {
      csv << number(r.t_s) << ',' << number(r.width_m) << ',' << number(r.target_width_m) << ',' << number(r.force_n)
          << ',' << number(r.current_a) << ',' << r.status_bits << '\n';
    }
    write_file_atomically((fs::path(directory_) / kGripperState).string(), csv.str());
  }
}

const std::vector<double>& RecordWriter::color_times() const {
  if (media_) return media_->color_times();
  return kNoTimes;
}

double RecordWriter::color_fps() const {
  if (media_) return media_->color_fps();
  return 0;
}

int RecordWriter::color_width() const {
  if (media_) return media_->color_width();
  return 0;
}

int RecordWriter::color_height() const {
  if (media_) return media_->color_height();
  return 0;
}

std::size_t RecordWriter::depth_frame_count() const {
  if (media_) return media_->depth_rows().size();
  return 0;
}

std::uint64_t RecordWriter::color_size_mismatches() const {
  if (media_) return media_->size_mismatches();
  return 0;
}

std::map<std::string, std::string> RecordWriter::files() const {
  std::map<std::string, std::string> files;
  if (!color_times().empty()) {
    files["color_video"] = "color.avi";
    files["color_frames"] = "color_frames.csv";
  }
  if (depth_frame_count() > 0) files["depth_frames"] = "depth_frames.csv";
  if (!gripper_.empty()) files["gripper_state"] = kGripperState;
  return files;
}

}  // namespace pliant::cli
