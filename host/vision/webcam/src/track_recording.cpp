// Recording v1 output of a tracked video, written atomically.
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>

#include "pliant/vision/webcam_error.hpp"
#include "pliant/vision/webcam_recording.hpp"

namespace pliant::vision::webcam {
namespace {

namespace fs = std::filesystem;

constexpr const char* kTrackFile = "track.csv";

const char* track_status_name(std::uint8_t status) {
  switch (static_cast<TrackStatus>(status)) {
    case TrackStatus::observed: return "observed";
    case TrackStatus::predicted: return "predicted";
    case TrackStatus::lost: return "lost";
  }
  return "unknown";
}

// Shortest text that reads back to the same double ("nan" for NaN).
std::string number(double value) {
  if (std::isnan(value)) return "nan";
  char text[40];
  std::snprintf(text, sizeof text, "%.17g", value);
  double back = 0;
  for (int precision = 6; precision < 17; ++precision) {
    char shorter[40];
    std::snprintf(shorter, sizeof shorter, "%.*g", precision, value);
    if (std::sscanf(shorter, "%lf", &back) == 1 && back == value) return shorter;
  }
  return text;
}

std::string number(float value) {
  if (std::isnan(value)) return "nan";
  char text[40];
  for (int precision = 6; precision <= 9; ++precision) {
    std::snprintf(text, sizeof text, "%.*g", precision, static_cast<double>(value));
    float back = 0;
    if (std::sscanf(text, "%f", &back) == 1 && back == value) break;
  }
  return text;
}

}  // namespace

host::Recording track_recording(const TrackResult& result, const std::string& name) {
  const int n = result.particle_count();
  const int frames = result.frame_count();
  host::Recording rec;
  rec.name = name;
  rec.dimension = 2;
  rec.length_unit = "px";
  rec.particle_count = n;
  rec.masses.assign(static_cast<std::size_t>(n), 1.0);
  rec.fixed = result.roles.support;
  host::DrivenWindow driven;
  driven.id = result.roles.driven;
  rec.driven.push_back(driven);
  rec.files["particles"] = "particles.csv";
  rec.files["track"] = kTrackFile;
  rec.frame_times_s = result.times_s;
  rec.positions.assign(static_cast<std::size_t>(frames) * static_cast<std::size_t>(n) * 2,
                       std::numeric_limits<double>::quiet_NaN());
  for (int f = 0; f < frames; ++f) {
    for (int i = 0; i < n; ++i) {
      const std::size_t k = result.at(f, i);
      if (result.observed[k] == 0 && i != result.roles.driven) continue;
      rec.positions[2 * k] = result.tracked[k].x;
      rec.positions[2 * k + 1] = result.tracked[k].y;
    }
  }
  const TrackOptions& o = result.options;
  nlohmann::json track = nlohmann::json::object();
  track["source"] = result.source;
  track["source_fps_hz"] = result.source_fps_hz;
  track["rate_hz"] = result.rate_hz;
  track["flow"] = flow_method_name(o.flow);
  track["window_px"] = o.advection.window_px;
  track["refine_window_px"] = o.advection.refine_window_px;
  track["forward_backward"] = o.advection.forward_backward;
  track["fb_threshold_px"] = o.advection.fb_threshold_px;
  track["min_similarity"] = o.advection.min_similarity;
  track["patch_px"] = o.advection.patch_px;
  track["search_radius_px"] = o.advection.search_radius_px;
  track["tracker_msm_beta"] = o.tracker_msm_beta;
  track["grid"] = {{"rows", result.grid.rows},
                   {"cols", result.grid.cols},
                   {"spacing_px", {result.grid.spacing_x_px, result.grid.spacing_y_px}}};
  track["support"] = result.roles.support_detected
                         ? std::string("detected: ") + grid_side_name(result.roles.support_side) + " side"
                         : std::string("given");
  track["driven"] = result.roles.driven_detected ? "detected: largest motion on the boundary" : "given";
  std::size_t unobserved = 0;
  for (std::uint8_t used : result.observed) unobserved += used == 0 ? 1 : 0;
  track["unobserved_particle_frames"] = unobserved;
  rec.meta["camera"] = std::to_string(result.frame_size.width) + "x" + std::to_string(result.frame_size.height) +
                       " @ " + number(result.source_fps_hz) + " Hz";
  rec.meta["track"] = track;
  host::finalize_recording(rec);
  return rec;
}

std::string track_csv_text(const TrackResult& result) {
  std::ostringstream out;
  out << "t,id,x,y,observed,status,check,fb_error_px,similarity\n";
  for (int f = 0; f < result.frame_count(); ++f) {
    const std::string t = number(result.times_s[static_cast<std::size_t>(f)]);
    for (int i = 0; i < result.particle_count(); ++i) {
      const std::size_t k = result.at(f, i);
      out << t << ',' << i << ',' << number(result.tracked[k].x) << ',' << number(result.tracked[k].y) << ','
          << static_cast<int>(result.observed[k]) << ',' << track_status_name(result.status[k]) << ','
          << observation_kind_name(static_cast<ObservationKind>(result.check[k])) << ','
          << number(result.fb_error_px[k]) << ',' << number(result.similarity[k]) << '\n';
    }
  }
  return out.str();
}

void check_output_directory(const std::string& directory) {
  if (directory.empty()) throw InputError("no output directory given");
  std::error_code error;
  const fs::file_status status = fs::status(directory, error);
  if (!fs::exists(status)) return;
  if (!fs::is_directory(status)) throw InputError(directory + " exists and is not a directory");
  const bool empty = fs::is_empty(directory, error);
  if (error) throw std::runtime_error("cannot read " + directory + ": " + error.message());
  if (!empty) throw InputError(directory + " is not empty; give a new directory for the recording");
}

void write_track_recording(const TrackResult& result, const std::string& directory) {
  check_output_directory(directory);
  fs::path target = fs::path(directory).lexically_normal();
  if (!target.has_filename()) target = target.parent_path();  // "rec/" -> "rec"
  const host::Recording recording = track_recording(result, target.filename().string());
  const std::string track_text = track_csv_text(result);
  std::error_code error;
  if (target.has_parent_path()) {
    fs::create_directories(target.parent_path(), error);
    if (error) throw std::runtime_error("cannot create " + target.parent_path().string() + ": " + error.message());
  }
  fs::path temp = target;
  temp += ".pliant-tmp-" + std::to_string(getpid());
  fs::remove_all(temp, error);
  try {
    host::write_recording(recording, temp.string());
    const fs::path track_path = temp / kTrackFile;
    std::ofstream out(track_path, std::ios::binary);
    out << track_text;
    out.flush();
    if (!out) throw std::runtime_error("cannot write " + track_path.string());
  } catch (...) {
    fs::remove_all(temp, error);
    throw;
  }
  fs::rename(temp, target, error);
  if (error) {
    const std::string cause = error.message();
    fs::remove_all(temp, error);
    throw std::runtime_error("cannot move the recording into " + directory + ": " + cause);
  }
}

}  // namespace pliant::vision::webcam
