#include "command_record.hpp"

#include <time.h>  // gmtime_r

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <vector>

#include <nlohmann/json.hpp>

#include "atomic_write.hpp"
#include "cli_registry.hpp"
#include "exit_status.hpp"
#include "pliant/hal/clock.hpp"
#include "pliant/host/recording.hpp"
#include "record_capture.hpp"
#include "record_device_spec.hpp"
#include "record_devices.hpp"
#include "record_output.hpp"
#include "record_particles.hpp"
#include "record_track.hpp"
#include "record_writer.hpp"

namespace pliant::cli {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

std::string number(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", value);
  return text;
}

std::string utc_now() {
  const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm parts{};
  gmtime_r(&now, &parts);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", &parts);
  return text;
}

json hal_counters(const hal::DeviceCounters& c) {
  return {{"reads", c.reads},
          {"samples", c.samples},
          {"no_data", c.no_data},
          {"dropped", c.dropped},
          {"fault_samples", c.fault_samples},
          {"faults", c.faults()},
          {"timeouts", c.timeouts},
          {"disconnected", c.disconnected},
          {"bus_off", c.bus_off},
          {"device_faults", c.device_faults},
          {"io_errors", c.io_errors},
          {"disconnects", c.disconnects},
          {"reconnects", c.reconnects}};
}

json stream_counters(const StreamCounters& c) {
  return {{"recorded", c.recorded},
          {"non_finite", c.non_finite},
          {"out_of_order", c.out_of_order},
          {"fault_flagged", c.fault_flagged},
          {"queue_full", c.queue_full}};
}

const StreamCounters& counters_of(const RecordWriter& writer, DeviceRole role) {
  switch (role) {
    case DeviceRole::color: return writer.color_counters();
    case DeviceRole::depth: return writer.depth_counters();
    case DeviceRole::ft: return writer.wrench_counters();
    case DeviceRole::gripper: return writer.gripper_counters();
  }
  return writer.wrench_counters();
}

// The specs given, parsed, in the order color, depth, ft, gripper.
std::vector<DeviceSpec> parse_specs(const std::string& color, const std::string& depth, const std::string& ft,
                                    const std::string& gripper) {
  std::vector<DeviceSpec> specs;
  const std::pair<DeviceRole, const std::string*> given[] = {
      {DeviceRole::color, &color}, {DeviceRole::depth, &depth}, {DeviceRole::ft, &ft}, {DeviceRole::gripper, &gripper}};
  for (const auto& [role, text] : given) {
    if (text->empty()) continue;
    try {
      specs.push_back(parse_device_spec(role, *text));
    } catch (const DeviceSpecError& e) {
      throw UsageError(e.what());
    }
    check_driver_built(specs.back());
  }
  return specs;
}

bool has_role(const std::vector<DeviceSpec>& specs, DeviceRole role) {
  for (const DeviceSpec& s : specs) {
    if (s.role == role) return true;
  }
  return false;
}

// `text` with every byte that is not part of valid UTF-8 replaced by '?': recording.json is UTF-8,
// and a spec may name a file in another encoding.
std::string utf8_text(const std::string& text) {
  std::string out;
  std::size_t i = 0;
  while (i < text.size()) {
    const auto c = static_cast<unsigned char>(text[i]);
    std::size_t length = c < 0x80 ? 1 : (c >> 5) == 0x6 ? 2 : (c >> 4) == 0xe ? 3 : (c >> 3) == 0x1e ? 4 : 0;
    bool valid = length > 0 && i + length <= text.size() && !(length == 2 && c < 0xc2);
    for (std::size_t k = 1; valid && k < length; ++k) {
      valid = (static_cast<unsigned char>(text[i + k]) & 0xc0) == 0x80;
    }
    if (valid && length >= 3) {  // no overlong forms, no surrogates, nothing above U+10FFFF
      const auto c1 = static_cast<unsigned char>(text[i + 1]);
      if (length == 3) valid = !(c == 0xe0 && c1 < 0xa0) && !(c == 0xed && c1 >= 0xa0);
      if (length == 4) valid = !(c == 0xf0 && c1 < 0x90) && !(c == 0xf4 && c1 >= 0x90) && c <= 0xf4;
    }
    if (!valid) {
      out += '?';
      ++i;
      continue;
    }
    out.append(text, i, length);
    i += length;
  }
  return out;
}

// Why gripper.csv is left out, or empty when it is written (spec: width in length_unit, force
// finite in every row).
std::string gripper_csv_omission(const std::vector<GripperRow>& rows, const std::string& length_unit) {
  if (rows.empty()) return "no gripper reading";
  if (length_unit != "m") return "the recording is in " + length_unit + " and the gripper width in m";
  for (const GripperRow& r : rows) {
    if (!std::isfinite(r.force_n)) return "the gripper does not sense grip force (see gripper_state.csv)";
  }
  return std::string();
}

}  // namespace

RecordCommand::RecordCommand(CLI::App& parent) {
  app_ = parent.add_subcommand("record", "Record devices on one clock into a recording with its media");
  app_->footer(
      "Devices (KIND:LOCATION): --color v4l2:/dev/videoN|N, video:FILE, images:PATTERN, libcamera:any|ID; "
      "--depth openni2:any|URI, oni:FILE; --ft ati-can:IFACE@0xBASE, robotous-can:IFACE@0xCMD, "
      "ft300-rtu:DEV[@SLAVE], ft300-tcp:HOST:PORT[@SLAVE]; --gripper robotiq-rtu:DEV[@SLAVE], "
      "robotiq-tcp:HOST:PORT[@SLAVE].\n"
      "Particles: tracked in the colour video with --roi or --mask (px), else the gripper's two jaws (m). "
      "Recording stops at --duration, Ctrl-C, or when every file source has ended. The recording is written "
      "beside REC and renamed into place at the end: nothing is left behind on failure.\n"
      "Exit status: 0 ok, 1 runtime failure (a device cannot be opened, I/O), 2 bad options or device specs.");
  app_->add_option("--color", color_, "Colour camera or video")->type_name("SPEC");
  app_->add_option("--depth", depth_, "Depth camera or .oni recording")->type_name("SPEC");
  app_->add_option("--ft", ft_, "Force/torque sensor")->type_name("SPEC");
  app_->add_option("--gripper", gripper_, "Parallel gripper (read only: never commanded)")->type_name("SPEC");
  app_->add_option("--duration", duration_s_, "Stop after this many seconds (default: Ctrl-C or end of files)")
      ->type_name("S");
  auto* roi =
      app_->add_option("--roi", track_.roi, "Track particles in this region of the colour video")->type_name("X,Y,W,H");
  auto* mask =
      app_->add_option("--mask", track_.mask, "Track particles in this mask (non-zero inside)")->type_name("PNG");
  roi->excludes(mask);
  mask->excludes(roi);
  app_->add_option("--grid", track_.grid, "Particle grid ROWSxCOLS (as pliant track; default 4x8)")->type_name("RxC");
  app_->add_option("--spacing", track_.spacing_px, "Particle spacing in pixels")->type_name("PX");
  app_->add_option("--flow", track_.flow, "Dense optical flow: dis or farneback")
      ->type_name("dis|farneback")
      ->capture_default_str();
  app_->add_option("--support", track_.support, "Support particles: auto, none, top, bottom, left, right or ids")
      ->type_name("SPEC")
      ->capture_default_str();
  app_->add_option("--driven", track_.driven, "Driven particle: auto, an id, or X,Y pixels in the first frame")
      ->type_name("SPEC")
      ->capture_default_str();
  app_->add_flag("--tare", tare_, "Zero the force/torque sensor when the recording starts");
  app_->add_option("--gripper-stroke", gripper_stroke_m_,
                   "Robotiq opening at full stroke, m (2F-85: 0.085, 2F-140: 0.140)")
      ->type_name("M")
      ->capture_default_str()
      ->check(CLI::Range(0.001, 1.0));
  app_->add_option("-o,--output", output_, "Recording directory to create")->type_name("REC")->required();
  app_->add_flag("--force", force_, "Replace REC if it is a recording (or an empty directory)");
  app_->add_flag("-q,--quiet", quiet_, "No progress messages");
}

int RecordCommand::run() const {
  const CliRegistry& parts = cli_registry();
  for (const auto& quiet : parts.quiet_logs) quiet();  // our own one-line messages only
  // 1. Everything that can be checked without a device.
  if (app_->count("--duration") > 0 && !(std::isfinite(duration_s_) && duration_s_ > 0)) {
    throw UsageError("--duration: must be a positive number of seconds, found " + number(duration_s_));
  }
  const std::vector<DeviceSpec> specs = parse_specs(color_, depth_, ft_, gripper_);
  if (specs.empty()) throw UsageError("give at least one device: --color, --depth, --ft or --gripper");
  const bool color = has_role(specs, DeviceRole::color);
  const bool frames = color || has_role(specs, DeviceRole::depth);
  if (frames && !parts.media) {
    throw UsageError("recording colour or depth frames needs OpenCV; install libopencv-dev and rebuild");
  }
  for (const char* option : {"--grid", "--spacing", "--flow", "--support", "--driven"}) {
    if (app_->count(option) > 0 && !track_.requested()) {
      throw UsageError(std::string(option) + " is a tracking option: give --roi or --mask too");
    }
  }
  const bool tracked = track_.requested();
  std::unique_ptr<VideoTracking> tracking;
  if (tracked) {
    if (!color) throw UsageError("--roi/--mask track the colour video: give --color too");
    if (!parts.tracking) {
      throw UsageError(
          "this pliant was built without the webcam front end (host/vision/webcam); install "
          "libopencv-dev and rebuild");
    }
    tracking = parts.tracking(track_);
  } else if (!has_role(specs, DeviceRole::gripper)) {
    throw UsageError(
        "no source of particles: give --color with --roi or --mask (particles tracked in the video), or "
        "--gripper (the jaws are the particles)");
  }

  // 2. The output, then the devices.
  OutputDirectory output(output_, force_);
  InterruptCatcher interrupts;
  hal::SteadyClock clock;
  DeviceOpenOptions open_options;
  open_options.tare = tare_;
  open_options.gripper_stroke_m = gripper_stroke_m_;
  std::vector<std::unique_ptr<RecordDevice>> devices;
  for (const DeviceSpec& spec : specs) {
    devices.push_back(open_device(spec, clock, open_options));
    if (InterruptCatcher::interrupted()) throw std::runtime_error("interrupted before the recording started");
  }
  std::vector<RecordDevice*> device_list;
  for (const auto& d : devices) device_list.push_back(d.get());

  // 3. The capture.
  const std::string started_utc = utc_now();
  const double t0 = clock.now_s();
  RecordWriter writer(output.partial(), t0, frames);
  CaptureOptions capture;
  capture.duration_s = duration_s_;
  if (tracking) {
    capture.on_first_color = [&tracking](const hal::ColorFrame& f) { tracking->check_frame_size(f.width, f.height); };
  }
  if (!quiet_) {
    std::cerr << "pliant record: recording " << specs.size() << " device(s) into " << output.target()
              << (duration_s_ > 0 ? " for " + number(duration_s_) + " s" : std::string()) << "; Ctrl-C stops\n";
  }
  const StopReason reason = run_capture(device_list, writer, clock, capture);
  const double recorded_s = clock.now_s() - t0;
  interrupts.release();  // from here Ctrl-C ends the process at once (docs/record.md)

  json devices_meta = json::object();
  for (const auto& d : devices) {
    const DeviceSpec& spec = d->spec();
    devices_meta[device_role_name(spec.role)] = {{"spec", utf8_text(spec.text)},
                                                 {"driver", d->driver()},
                                                 {"counters", hal_counters(d->device().counters())},
                                                 {"recorder", stream_counters(counters_of(writer, spec.role))},
                                                 {"driver_counters", d->driver_info()}};
  }
  std::vector<std::string> summary;
  for (const auto& d : devices) {
    const DeviceSpec& spec = d->spec();
    const hal::DeviceCounters& c = d->device().counters();
    const StreamCounters& s = counters_of(writer, spec.role);
    std::ostringstream line;
    line << "  " << device_role_option(spec.role) << " " << spec.text << ": " << s.recorded << " recorded, "
         << c.dropped << " dropped by the device, " << s.dropped() << " by the recorder, " << c.faults() << " faults";
    summary.push_back(line.str());
    if (s.recorded == 0) {
      report_warning(std::string(device_role_option(spec.role)) + " '" + spec.text + "' delivered nothing (" +
                     std::to_string(c.faults()) + " faults, " + std::to_string(c.timeouts) + " timeouts)");
    }
  }
  devices.clear();  // stop and release the devices before the post-processing
  writer.finish();

  // 4. The particles and the recording.
  host::Recording recording;
  std::string track_csv;
  if (tracking) {
    if (writer.color_times().size() < 2) {
      throw std::runtime_error("the colour source gave " + std::to_string(writer.color_times().size()) +
                               " frame(s); tracking needs at least 2");
    }
    recording = tracking->track((fs::path(output.partial()) / "color.avi").string(), writer.color_times(),
                                output.name(), track_csv, !quiet_);
    recording.meta["track"]["source"] = "color.avi";  // not the temporary directory it was tracked in
  }
  if (!tracked) recording = jaw_recording(writer.gripper(), output.name());
  if (!writer.wrench().empty()) {
    recording.wrench = writer.wrench();
    for (const host::DrivenWindow& w : recording.driven) recording.wrench_applied_to.push_back(w.id);
  }
  const std::string gripper_omitted = gripper_csv_omission(writer.gripper(), recording.length_unit);
  if (gripper_omitted.empty()) {
    for (const GripperRow& r : writer.gripper()) {
      host::GripperSample g;
      g.t_s = r.t_s;
      g.width = r.width_m;
      g.force_n = r.force_n;
      recording.gripper.push_back(g);
    }
  }
  for (const auto& [role, file] : writer.files()) recording.files[role] = file;
  json record_meta = {{"pliant_version", PLIANT_VERSION},
                      {"clock", "steady"},
                      {"started_utc", started_utc},
                      {"recorded_s", recorded_s},
                      {"stop", stop_reason_name(reason)},
                      {"particles", tracked ? "tracked in the colour video (px)" : "gripper jaws (m)"},
                      {"wrench_frame", "sensor"}};
  if (writer.color_fps() > 0) record_meta["color_video_fps"] = writer.color_fps();
  if (!gripper_omitted.empty() && !writer.gripper().empty()) record_meta["gripper_csv_omitted"] = gripper_omitted;
  if (tare_) record_meta["tare"] = true;
  recording.meta["record"] = record_meta;
  recording.meta["devices"] = devices_meta;
  host::write_recording(recording, output.partial());
  if (!track_csv.empty()) write_file_atomically((fs::path(output.partial()) / "track.csv").string(), track_csv);
  try {
    (void)host::read_recording(output.partial());
  } catch (const host::RecordingError& e) {
    throw std::runtime_error(std::string("internal error: the recording does not read back: ") + e.what());
  }
  output.commit();

  std::ostringstream out;
  out << "wrote " << output.target() << ": " << number(std::round(recorded_s * 100) / 100) << " s ("
      << stop_reason_name(reason) << "), " << recording.particle_count << " particles x " << recording.frame_count()
      << " frames (" << (tracked ? "tracked in the colour video" : "gripper jaws") << ")";
  if (!recording.wrench.empty()) out << ", " << recording.wrench.size() << " wrench samples";
  if (!writer.color_times().empty()) {
    out << ", " << writer.color_times().size() << " colour frames (color.avi at " << number(writer.color_fps())
        << " Hz)";
  }
  if (writer.depth_frame_count() > 0) out << ", " << writer.depth_frame_count() << " depth frames";
  out << "\n";
  for (const std::string& line : summary) out << line << "\n";
  if (!gripper_omitted.empty() && !writer.gripper().empty()) {
    out << "gripper.csv left out: " << gripper_omitted << "\n";
  }
  std::cout << out.str();
  std::cout.flush();
  if (!std::cout) throw std::runtime_error("cannot write to standard output");
  return exit_ok;
}

}  // namespace pliant::cli
