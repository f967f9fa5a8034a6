#include "command_track.hpp"

#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <sstream>
#include <stdexcept>

#include <opencv2/core/utils/logger.hpp>

#include "exit_status.hpp"
#include "progress_bar.hpp"
#include "pliant/vision/webcam_error.hpp"
#include "pliant/vision/webcam_recording.hpp"
#include "pliant/vision/webcam_tracker.hpp"

namespace pliant::cli {
namespace {

namespace webcam = vision::webcam;

// An image sequence has no rate of its own; this one is assumed unless --fps says otherwise.
constexpr double kSequenceFps = 30.0;

std::string number(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", value);
  return text;
}

std::string id_list(const std::vector<int>& ids) {
  std::string text;
  for (int id : ids) text += (text.empty() ? "" : ",") + std::to_string(id);
  return text.empty() ? "none" : text;
}

}  // namespace

TrackCommand::TrackCommand(CLI::App& parent) {
  app_ =
      parent.add_subcommand("track", "Track particles on an object in a video by optical flow into a recording (px)");
  app_->footer(
      "Particles are seeded on a grid in the region of the first frame, advected by the dense flow averaged "
      "over a window around each (forward-backward and appearance checked), and corrected by the "
      "MSM-regularised tracker. The support and the driven (tool) particle are detected from the motion "
      "unless given. Exit status: 0 ok, 1 runtime failure, 2 bad options or unusable input (unreadable "
      "video, empty region, frames of different sizes); nothing is written unless tracking succeeds.");
  app_->add_option("INPUT", input_, "Video file, printf-style image pattern (frames/f_%04d.png) or glob (frames/*.png)")
      ->required();
  auto* roi =
      app_->add_option("--roi", roi_, "Region of the first frame: x,y,width,height in pixels")->type_name("X,Y,W,H");
  auto* mask =
      app_->add_option("--mask", mask_, "Region as a mask image (non-zero inside), the frames' size")->type_name("PNG");
  roi->excludes(mask);
  mask->excludes(roi);
  app_->add_option("--grid", grid_, "Particle grid ROWSxCOLS (default 4x8 when --spacing is not given)")
      ->type_name("RxC");
  app_->add_option("--spacing", spacing_px_, "Particle spacing in pixels (with --grid: that grid at this spacing)")
      ->type_name("PX");
  app_->add_option("--flow", flow_, "Dense optical flow: dis (fast) or farneback (as in the MSM paper)")
      ->type_name("dis|farneback")
      ->capture_default_str();
  app_->add_option("--rate", rate_hz_, "Resample to this frame rate in Hz (default: every frame)")->type_name("HZ");
  app_->add_option("--fps", fps_hz_, "Frame rate of the input (default: the video's own; 30 for images)")
      ->type_name("HZ");
  app_->add_option("--window", window_px_, "Flow averaging window around each particle, pixels (eq. 14)")
      ->type_name("PX")
      ->capture_default_str();
  app_->add_option("--refine-window", refine_window_px_,
                   "Lucas-Kanade window that refines each advected particle at full resolution, px (0: off)")
      ->type_name("PX")
      ->capture_default_str();
  app_->add_option("--flow-margin", flow_margin_px_,
                   "Dense flow only within this many pixels of the particles (-1: the whole frame)")
      ->type_name("PX")
      ->capture_default_str();
  app_->add_option("--fb-threshold", fb_threshold_px_, "Largest forward-backward flow error of an observation, px")
      ->type_name("PX")
      ->capture_default_str();
  app_->add_option("--min-similarity", min_similarity_,
                   "Least correlation of a particle's patch with its appearance when last seen")
      ->type_name("S")
      ->capture_default_str();
  app_->add_option("--track-beta", track_beta_, "msm_beta of the tracker's prior for unseen particles, [0, 1]")
      ->type_name("B")
      ->capture_default_str();
  app_->add_option("--support", support_, "Support (fixed) particles: auto, none, top, bottom, left, right or ids")
      ->type_name("SPEC")
      ->capture_default_str();
  app_->add_option("--driven", driven_, "Driven (tool) particle: auto, an id, or X,Y pixels in the first frame")
      ->type_name("SPEC")
      ->capture_default_str();
  app_->add_option("-o,--output", output_, "Recording directory to create (must not exist or be empty)")
      ->type_name("REC")
      ->required();
  app_->add_flag("-q,--quiet", quiet_, "No progress bar");
}

int TrackCommand::run() const {
  // Every failure is reported in one line of our own; OpenCV's warnings would only add noise.
  cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_ERROR);
  try {
    if (roi_.empty() && mask_.empty()) throw UsageError("give the region: --roi x,y,w,h or --mask PNG");
    webcam::TrackOptions options;
    options.flow = webcam::parse_flow_method(flow_);
    options.advection.window_px = window_px_;
    options.advection.refine_window_px = refine_window_px_;
    options.advection.flow_margin_px = flow_margin_px_;
    options.advection.fb_threshold_px = fb_threshold_px_;
    options.advection.min_similarity = min_similarity_;
    options.advection.refresh_similarity = std::max(options.advection.refresh_similarity, min_similarity_);
    options.tracker_msm_beta = track_beta_;
    options.support = webcam::parse_support(support_);
    options.driven = webcam::parse_driven(driven_);
    webcam::check_track_options(options);
    webcam::GridSpec grid;
    if (!grid_.empty()) grid = webcam::parse_grid(grid_);
    grid.spacing_px = spacing_px_;
    if (grid_.empty() && spacing_px_ == 0) grid = webcam::parse_grid("4x8");
    const webcam::Region region = roi_.empty() ? webcam::read_mask(mask_) : webcam::parse_roi(roi_);
    webcam::check_output_directory(output_);

    const auto source = webcam::open_frame_source(input_, fps_hz_, kSequenceFps);
    webcam::FrameReader reader(*source, rate_hz_);
    webcam::TrackResult result;
    {
      ProgressBar bar("tracking", !quiet_);
      options.progress = &ProgressBar::callback;
      options.progress_context = &bar;
      result = webcam::track_particles(reader, region, grid, options);
    }
    webcam::write_track_recording(result, output_);

    std::size_t unobserved = 0;
    for (std::uint8_t used : result.observed) unobserved += used == 0 ? 1 : 0;
    const webcam::ParticleRoles& roles = result.roles;
    std::ostringstream out;
    out << "wrote " << output_ << ": " << result.particle_count() << " particles (" << result.grid.rows << "x"
        << result.grid.cols << " grid) x " << result.frame_count() << " frames at " << number(result.rate_hz) << " Hz, "
        << webcam::flow_method_name(result.options.flow) << " flow\n";
    out << "support: " << id_list(roles.support)
        << (roles.support_detected ? std::string(" (detected: ") + webcam::grid_side_name(roles.support_side) + " side)"
                                   : std::string(" (given)"))
        << "\ndriven: " << roles.driven << (roles.driven_detected ? " (detected: largest motion " : " (given; motion ")
        << number(std::round(10 * result.motion_px[static_cast<std::size_t>(roles.driven)]) / 10) << " px)\n";
    out << "unobserved particle-frames: " << unobserved << " of " << result.observed.size() << "\n";
    std::cout << out.str();
    std::cout.flush();
    if (!std::cout) throw std::runtime_error("cannot write to standard output");
    return exit_ok;
  } catch (const webcam::InputError& e) {
    throw UsageError(e.what());
  }
}

void register_track_command(CliRegistry& registry) {
  registry.commands.push_back({"track", [](CLI::App& parent) { return std::make_unique<TrackCommand>(parent); }});
}

}  // namespace pliant::cli
