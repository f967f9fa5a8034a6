#include "command_track_depth.hpp"

#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <limits>
#include <stdexcept>
#include <vector>

#include "exit_status.hpp"
#include "output_directory.hpp"
#include "track_depth_input.hpp"
#include "pliant/host/recording.hpp"
#include "pliant/vision/depth_recording.hpp"
#include "pliant/vision/depth_seed.hpp"
#include "pliant/vision/depth_text.hpp"

namespace pliant::cli {
namespace {

constexpr int max_rounds = 10;

std::string number(double value, const char* format = "%.4g") {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, format, value);
  return buffer;
}

}  // namespace

TrackDepthCommand::TrackDepthCommand(CLI::App& parent) {
  app_ = parent.add_subcommand("track-depth", "Track a depth image sequence into a 3D recording");
  app_->footer(
      "PLAN is a 3D recording in metres giving the particles' rest shape (its first frame or mesh), the fixed "
      "support, the driven tool particle and its trajectory on the depth frames' clock; without one, "
      "--seed-spacing seeds particles on the first frame's surface. DEPTH is a list of 16-bit PNG depth frames "
      "(TUM RGB-D depth.txt: 'timestamp filename' lines; or the depth_frames.csv of `pliant record`, which "
      "also gives the scale and intrinsics) or an OpenNI .oni recording. Writes a recording with one frame per "
      "depth frame; see docs/vision_depth.md. Exit status: 0 ok, 1 runtime failure, 2 bad options or malformed "
      "input.");
  // Two positionals, the first optional: CLI11 would give a lone argument to the first, so both
  // are taken as one list and split in run().
  app_->add_option("PLAN_DEPTH", positionals_,
                   "[PLAN] DEPTH: the plan recording directory (docs/spec/recording-v1.md; omitted with "
                   "--seed-spacing), then the depth frames (TUM list, pliant record depth_frames.csv, or .oni)")
      ->expected(1, 2)
      ->required();
  app_->add_option("--seed-spacing", seed_spacing_m_,
                   "No plan: seed one particle per cube of this edge (m) on the first frame's surface (crop with "
                   "--region and --min-depth/--max-depth); no support, no tool")
      ->type_name("M");
  app_->add_option("-o,--output", output_, "Recording directory to write (created if missing)")
      ->type_name("DIR")
      ->required();
  app_->add_option("--intrinsics", intrinsics_,
                   "Depth camera intrinsics in pixels (default: those depth_frames.csv or the .oni states)")
      ->type_name("FX,FY,CX,CY");
  app_->add_option("--units-per-metre", units_per_metre_,
                   "Raw depth units per metre (1000: millimetres; TUM: 5000; default: the input's scale, else 1000)")
      ->type_name("U")
      ->capture_default_str();
  app_->add_option("--camera-pose", camera_pose_,
                   "Camera pose in the plan's frame, x_plan = R(q) x_camera + t (default: identity, the plan is "
                   "in the camera frame)")
      ->type_name("TX,TY,TZ,QX,QY,QZ,QW");
  app_->add_option("--region", region_, "Pixel region of interest (default: the whole image)")->type_name("U0,V0,W,H");
  app_->add_option("--stride", stride_, "Use every N-th pixel along rows and columns")
      ->type_name("N")
      ->capture_default_str();
  app_->add_option("--min-depth", min_depth_m_, "Drop points nearer than this, m")
      ->type_name("M")
      ->capture_default_str();
  app_->add_option("--max-depth", max_depth_m_, "Drop points farther than this, m (0: no limit)")
      ->type_name("M")
      ->capture_default_str();
  app_->add_option("--correspondence", correspondence_,
                   "'plane': each particle's prediction projected onto the local surface plane (normal motion); "
                   "'point': the mean of its nearest cloud points")
      ->type_name("plane|point")
      ->capture_default_str();
  app_->add_option("--noise", noise_m_,
                   "Depth noise sd at the object's distance, m (floor of the correspondence scale)")
      ->type_name("M")
      ->capture_default_str();
  app_->add_option("--msm-beta", msm_beta_, "The tracker's prior msm_beta, in [0, 1]")
      ->type_name("B")
      ->capture_default_str();
  app_->add_option("--rounds", rounds_,
                   "Track, estimate msm_beta, track again with it as the prior, ... up to N rounds (1: track once)")
      ->type_name("N")
      ->capture_default_str();
  app_->add_option("--reference-frames", reference_frames_,
                   "Leading frames (before the tool moves) that calibrate per-particle offsets; 0: none")
      ->type_name("N")
      ->capture_default_str();
  app_->add_option("--time-offset", time_offset_s_, "Seconds added to the list's timestamps to reach the plan's clock")
      ->type_name("S")
      ->capture_default_str();
  app_->add_flag("--all-tracked", all_tracked_,
                 "Write every particle every frame (hidden ones as the model moves them); default: only particles "
                 "with a kept observation");
  app_->add_flag("--force", force_, "Write into a non-empty DIR, replacing files of the same names");
}

int TrackDepthCommand::run() const {
  if (!(std::isfinite(units_per_metre_) && units_per_metre_ > 0)) throw UsageError("--units-per-metre must be > 0");
  if (stride_ < 1) throw UsageError("--stride must be >= 1");
  if (!(std::isfinite(min_depth_m_) && min_depth_m_ >= 0)) throw UsageError("--min-depth must be >= 0");
  if (!(std::isfinite(max_depth_m_) && max_depth_m_ >= 0)) throw UsageError("--max-depth must be >= 0");
  if (max_depth_m_ > 0 && !(max_depth_m_ > min_depth_m_)) throw UsageError("--max-depth must exceed --min-depth");
  if (!(std::isfinite(noise_m_) && noise_m_ > 0)) throw UsageError("--noise must be > 0");
  if (!(msm_beta_ >= 0 && msm_beta_ <= 1)) throw UsageError("--msm-beta must be in [0, 1]");
  if (rounds_ < 1 || rounds_ > max_rounds)
    throw UsageError("--rounds must be between 1 and " + std::to_string(max_rounds));
  if (reference_frames_ < 0) throw UsageError("--reference-frames must be >= 0");
  if (!std::isfinite(time_offset_s_)) throw UsageError("--time-offset must be finite");
  if (correspondence_ != "plane" && correspondence_ != "point")
    throw UsageError("--correspondence must be plane or point");
  const std::string plan_dir = positionals_.size() == 2 ? positionals_.front() : std::string();
  const std::string depth_path = positionals_.back();
  const bool seeding = app_->count("--seed-spacing") > 0;
  if (seeding && !(std::isfinite(seed_spacing_m_) && seed_spacing_m_ > 0))
    throw UsageError("--seed-spacing must be > 0 m");
  if (seeding && !plan_dir.empty()) throw UsageError("give either PLAN or --seed-spacing, not both");
  if (!seeding && plan_dir.empty()) throw UsageError("give PLAN (a recording of the particles) or --seed-spacing M");
  check_output_directory(output_, force_);

  host::Recording plan;
  if (!seeding) {
    plan = host::read_recording(plan_dir);
    for (const std::string& warning : plan.warnings) report_warning(warning);
  }

  try {
    const std::unique_ptr<DepthInput> input = open_depth_input(depth_path);
    const vision::DepthImageView first = input->frame(0);
    vision::PinholeIntrinsics intrinsics;
    if (!intrinsics_.empty()) {
      intrinsics = vision::parse_intrinsics(intrinsics_, first.width, first.height);
    } else if (std::isfinite(input->fx) && std::isfinite(input->fy) && std::isfinite(input->cx) &&
               std::isfinite(input->cy)) {
      intrinsics = vision::parse_intrinsics(number(input->fx, "%.17g") + "," + number(input->fy, "%.17g") + "," +
                                                number(input->cx, "%.17g") + "," + number(input->cy, "%.17g"),
                                            first.width, first.height);
    } else {
      throw UsageError(depth_path + ": the " + input->kind + " states no intrinsics; give --intrinsics FX,FY,CX,CY");
    }
    const bool scale_given = app_->count("--units-per-metre") > 0;
    const double depth_scale_m =
        !scale_given && std::isfinite(input->depth_scale_m) ? input->depth_scale_m : 1.0 / units_per_metre_;

    vision::DepthSequenceOptions options;
    options.msm_beta = msm_beta_;
    options.observed_only = !all_tracked_;
    options.reference_frames = reference_frames_;
    vision::DepthTrackerConfig& config = options.tracker;
    config.cloud.depth_scale_m = depth_scale_m;
    config.cloud.stride = stride_;
    config.cloud.min_depth_m = min_depth_m_;
    config.cloud.max_depth_m = max_depth_m_ > 0 ? max_depth_m_ : std::numeric_limits<double>::infinity();
    if (!region_.empty()) config.cloud.region = vision::parse_pixel_rect(region_);
    if (!camera_pose_.empty()) config.camera_to_world = vision::parse_camera_pose(camera_pose_);
    config.correspondence =
        correspondence_ == "plane" ? vision::Correspondence::point_to_plane : vision::Correspondence::nearest_point;
    config.depth_noise_m = noise_m_;

    std::vector<double> times;
    for (const double t : input->times_s()) times.push_back(t + time_offset_s_);
    const vision::DepthFrameSource frames = [&](int index) { return input->frame(index); };

    if (seeding) {
      // One particle per voxel of the first frame's cloud (cropped by the region and depth
      // range): a one-layer shell with the cloud's normals, clusters of nearest neighbours.
      vision::DepthCloud cloud;
      vision::depth_to_cloud(input->frame(0), intrinsics, config.cloud, cloud);
      const vision::SeededParticles seeds = vision::seed_particles(cloud, seed_spacing_m_, config.camera_to_world);
      plan = vision::seeded_plan(seeds, times.front());
      options.rest_normals = seeds.normals;
      options.setup.clusters.layout = ClusterLayout::k_nearest;
      std::cout << "seeded " << plan.particle_count << " particles " << number(1e3 * seed_spacing_m_) << " mm apart on "
                << cloud.points.size() << " points of the first frame\n";
    }

    vision::DepthSequenceResult result;
    std::vector<double> priors, estimates;
    if (rounds_ == 1) {
      result = vision::track_depth_sequence(plan, times, frames, intrinsics, options);
    } else {
      vision::DepthEstimateRounds loop =
          vision::track_and_estimate(plan, times, frames, intrinsics, options, host::EstimateOptions{}, rounds_);
      result = std::move(loop.tracked);
      priors = loop.priors;
      for (const host::EstimateReport& report : loop.estimates) estimates.push_back(report.result.msm_beta);
    }
    host::write_recording(result.recording, output_);

    // Summary.
    std::size_t points = 0;
    long observed = 0;
    for (const vision::DepthFrameReport& frame : result.frames) {
      points += frame.points;
      observed += frame.observed;
    }
    const double updates = static_cast<double>(std::max<std::size_t>(1, result.frames.size()));
    const auto& a = result.alignment;
    const int lookable = plan.particle_count - a.by_view[static_cast<std::size_t>(vision::ParticleView::held)] -
                         a.by_view[static_cast<std::size_t>(vision::ParticleView::interior)];
    std::cout << "read " << times.size() << " frames (" << input->kind << "), " << first.width << "x" << first.height
              << ", " << number(depth_scale_m * 1e3) << " mm per unit\n";
    std::cout << "wrote " << output_ << ": " << plan.particle_count << " particles x " << times.size() << " frames ("
              << (options.observed_only ? "observed positions only" : "every tracked position") << ")\n";
    std::cout << "first frame: " << a.observed << " of " << lookable
              << " surface particles found on the cloud, median distance " << number(1e3 * a.median_distance_m)
              << " mm\n";
    std::cout << "per frame: " << number(static_cast<double>(points) / updates, "%.0f") << " points, "
              << number(static_cast<double>(observed) / updates, "%.1f") << " particles observed; "
              << result.calibration_frames << " calibration frames, " << result.counters.empty_frames
              << " frames without depth, " << result.core.lost_events << " lost events\n";
    std::cout << "particle-frames by view:";
    for (int v = 0; v < vision::kParticleViewCount; ++v) {
      const std::uint64_t count = result.counters.by_view[static_cast<std::size_t>(v)];
      if (count > 0)
        std::cout << ' ' << vision::particle_view_name(static_cast<vision::ParticleView>(v)) << ' ' << count;
    }
    std::cout << '\n';
    for (std::size_t r = 0; r < estimates.size(); ++r) {
      std::cout << "round " << r + 1 << ": prior msm_beta " << number(priors[r]) << " -> estimate "
                << number(estimates[r]) << '\n';
    }
    if (lookable > 0 && a.observed * 4 < lookable) {
      report_warning(
          "few particles lie on the first frame's surface: check --camera-pose, --intrinsics and "
          "--units-per-metre");
    }
  } catch (const vision::DepthError& error) {
    throw UsageError(error.what());
  }
  std::cout.flush();
  if (!std::cout) throw std::runtime_error("cannot write to standard output");
  return exit_ok;
}

void register_track_depth_command(CliRegistry& registry) {
  registry.commands.push_back(
      {"track-depth", [](CLI::App& parent) { return std::make_unique<TrackDepthCommand>(parent); }});
}

}  // namespace pliant::cli
