// depth_track_bench: the depth front end's speed (host/vision/depth), a plain program that prints
// its figures.
//
// 1. Depth image -> point cloud: a 640 x 480 frame, every pixel valid, at stride 1 and 2.
// 2. DepthTracker::update at the depth path's size: 1000 particles (the block_press scenario on
//    a 10 x 10 x 10 lattice at 10 mm, bottom layer fixed, top centre pressed 18 mm) filmed by a
//    simulated 640 x 480 depth camera 0.55 m away (the tests' z-buffer renderer, 0.5 mm noise);
//    the region of interest around the block holds about 20 000 points per frame. Timed per
//    frame: the whole update (cloud conversion, kd-tree build, MSM prediction, correspondences,
//    core tracker), and apart from it the conversion and the nanoflann build of the same cloud.
//    Frames are rendered before timing.
// Times: wall (steady clock) and CPU time of the thread, per frame; median, p90, max.
// Budget: update median <= 33.3 ms wall (30 Hz) on a 2-core machine.
// Flags: --frames N (default 90), --pliant_enforce_budgets (exit 2 on a missed budget).
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include <nanoflann.hpp>

#include "pliant/host/msm_setup.hpp"
#include "pliant/host/scenarios.hpp"
#include "pliant/vision/depth_recording.hpp"
#include "pliant/vision/depth_tracker.hpp"
#include "vision/depth/synthetic_depth.hpp"

#ifndef PLIANT_BENCH_BUILD_TYPE
#define PLIANT_BENCH_BUILD_TYPE "unknown"
#endif

namespace pliant::bench {
namespace {

using Clock = std::chrono::steady_clock;

double cpu_now() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

struct Timing {
  std::vector<double> wall, cpu;  // s
  template <typename F>
  void run(F&& f) {
    const double c0 = cpu_now();
    const auto w0 = Clock::now();
    f();
    wall.push_back(std::chrono::duration<double>(Clock::now() - w0).count());
    cpu.push_back(cpu_now() - c0);
  }
};

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5)];
}

void print(const char* name, const Timing& t) {
  std::printf("  %-34s wall median %7.3f ms  p90 %7.3f  max %7.3f | cpu median %7.3f ms  (%zu runs)\n", name,
              1e3 * quantile(t.wall, 0.5), 1e3 * quantile(t.wall, 0.9), 1e3 * quantile(t.wall, 1.0),
              1e3 * quantile(t.cpu, 0.5), t.wall.size());
}

struct CloudAdaptor {
  const std::vector<Eigen::Vector3f>* points = nullptr;
  std::size_t kdtree_get_point_count() const { return points->size(); }
  float kdtree_get_pt(std::size_t i, std::size_t d) const { return (*points)[i](static_cast<Eigen::Index>(d)); }
  template <class B>
  bool kdtree_get_bbox(B&) const {
    return false;
  }
};

int run(int argc, char** argv) {
  int frame_count = 90;
  bool enforce = false;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--frames") == 0 && i + 1 < argc) {
      frame_count = std::max(2, std::atoi(argv[++i]));
    } else if (std::strcmp(argv[i], "--pliant_enforce_budgets") == 0) {
      enforce = true;
    } else {
      std::fprintf(stderr, "usage: depth_track_bench [--frames N] [--pliant_enforce_budgets]\n");
      return 2;
    }
  }
  std::printf("depth_track_bench (build %s)\n", PLIANT_BENCH_BUILD_TYPE);

  // 1. Conversion of a full 640 x 480 frame.
  const vision::PinholeIntrinsics k{525.0, 525.0, 319.5, 239.5, 640, 480};
  {
    vision::DepthImage full{640, 480, std::vector<std::uint16_t>(640 * 480)};
    std::mt19937 rng(1);
    std::uniform_int_distribution<int> depth(500, 4000);
    for (auto& d : full.data) d = static_cast<std::uint16_t>(depth(rng));
    std::printf("\n1. depth image -> point cloud, 640 x 480, every pixel valid\n");
    for (const int stride : {1, 2}) {
      vision::DepthToCloudOptions options;
      options.stride = stride;
      vision::DepthCloud cloud;
      cloud.reserve(vision::cloud_capacity(640, 480, options));
      Timing t;
      std::size_t points = 0;
      for (int r = 0; r < 200; ++r) t.run([&] { points = vision::depth_to_cloud(full.view(), k, options, cloud); });
      const std::string name = "stride " + std::to_string(stride) + " (" + std::to_string(points) + " points)";
      print(name.c_str(), t);
    }
  }

  // 2. The tracker on 1000 particles and ~20k points.
  host::ScenarioOptions scenario_options;
  scenario_options.msm_beta = 0.5;
  scenario_options.block_grid = {10, 10, 10};
  const host::ScenarioResult truth = host::make_scenario("block_press", scenario_options);
  const host::Recording& r = truth.recording;
  const int n = r.particle_count;
  frame_count = std::min(frame_count, r.frame_count());
  const Eigen::Vector3d centre(0.045, 0.045, 0.045);
  const Eigen::Isometry3d camera =
      vision::test::look_at(centre + Eigen::Vector3d(0.24, -0.335, 0.365), centre, {0, 0, 1});
  vision::test::DepthRenderer renderer(k, camera);
  // Region: the block's rest box (with the lower part of the tool) projected, padded 10 px.
  double u0 = 1e9, v0 = 1e9, u1 = -1e9, v1 = -1e9;
  for (int c = 0; c < 8; ++c) {
    const Eigen::Vector2d p = renderer.project({(c & 1) ? 0.09 : 0.0, (c & 2) ? 0.09 : 0.0, (c & 4) ? 0.11 : 0.0});
    u0 = std::min(u0, p.x());
    u1 = std::max(u1, p.x());
    v0 = std::min(v0, p.y());
    v1 = std::max(v1, p.y());
  }
  vision::DepthTrackerConfig config;
  config.cloud.depth_scale_m = 1e-4;
  config.cloud.region = {std::max(0, static_cast<int>(u0) - 10), std::max(0, static_cast<int>(v0) - 10), 0, 0};
  config.cloud.region.width = std::min(640 - config.cloud.region.u0, static_cast<int>(u1 - u0) + 20);
  config.cloud.region.height = std::min(480 - config.cloud.region.v0, static_cast<int>(v1 - v0) + 20);
  config.camera_to_world = camera;
  config.depth_noise_m = 0.5e-3;

  std::vector<vision::DepthImage> frames;
  std::mt19937 rng(7);
  const int tool = r.driven.front().id;
  for (int f = 0; f < frame_count; ++f) {
    renderer.clear();
    renderer.add(vision::test::lattice_surface(r.positions.data() + static_cast<std::size_t>(f * n * 3), 10, 10, 10));
    renderer.add(vision::test::Triangle{{-0.1, -0.1, 0}, {0.2, -0.1, 0}, {0.2, 0.2, 0}});
    renderer.add(vision::test::Triangle{{-0.1, -0.1, 0}, {0.2, 0.2, 0}, {-0.1, 0.2, 0}});
    const double* tip = r.positions.data() + static_cast<std::size_t>((f * n + tool) * 3);
    renderer.add_prism({tip[0], tip[1], tip[2]}, 0.004, 0.1);
    frames.push_back(renderer.image(config.cloud.depth_scale_m, config.depth_noise_m, rng));
  }

  host::Recording plan = r;  // the tool's trajectory (the truth's other particles are not used)
  const auto model = host::build_msm_model<3>(plan, host::MsmSetupOptions{});
  MsmParams<3, double> params = host::base_params<3>(plan, 1.0);
  params.msm_beta = 0.5;
  vision::DepthTracker tracker(model->model, params, k, config);
  tracker.calibrate(frames[0].view());
  std::vector<int> ids;
  std::vector<Eigen::Vector3d> targets;
  Timing update, convert, build;
  std::size_t points = 0, observed = 0;
  vision::DepthCloud cloud;
  CloudAdaptor adaptor{&cloud.points};
  using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, CloudAdaptor>, CloudAdaptor, 3,
                                                   std::uint32_t>;
  Tree tree(
      3, adaptor,
      nanoflann::KDTreeSingleIndexAdaptorParams(16, nanoflann::KDTreeSingleIndexAdaptorFlags::SkipInitialBuildIndex));
  for (int f = 1; f < frame_count; ++f) {
    vision::driven_targets_at(plan, r.frame_times_s[static_cast<std::size_t>(f)], ids, targets);
    const MsmDrivenTargets<3, double> driven{ids.data(), targets.data(), static_cast<int>(ids.size())};
    const double dt = r.frame_times_s[static_cast<std::size_t>(f)] - r.frame_times_s[static_cast<std::size_t>(f - 1)];
    vision::DepthFrameReport report;
    update.run([&] { report = tracker.update(frames[static_cast<std::size_t>(f)].view(), dt, driven); });
    points += report.points;
    observed += static_cast<std::size_t>(report.observed);
    convert.run([&] { vision::depth_to_cloud(frames[static_cast<std::size_t>(f)].view(), k, config.cloud, cloud); });
    build.run([&] { tree.buildIndex(); });
  }
  const double frames_timed = static_cast<double>(frame_count - 1);
  std::printf(
      "\n2. DepthTracker::update: %d particles, %.0f points per frame (region %dx%d), %.0f particles observed "
      "per frame, %d frames\n",
      n, static_cast<double>(points) / frames_timed, config.cloud.region.width, config.cloud.region.height,
      static_cast<double>(observed) / frames_timed, frame_count - 1);
  print("update (whole frame)", update);
  print("  of which: cloud conversion", convert);
  print("  of which: nanoflann kd-tree build", build);
  const double median = quantile(update.wall, 0.5);
  const double rate = 1.0 / median;
  const bool met = median <= 1.0 / 30.0;
  std::printf("\nrate %.0f frames/s (median wall); budget >= 30 frames/s: %s\n", rate, met ? "met" : "MISSED");
  std::printf("(figures depend on the machine's load: other processes share its cores)\n");
  return enforce && !met ? 2 : 0;
}

}  // namespace
}  // namespace pliant::bench

int main(int argc, char** argv) { return pliant::bench::run(argc, argv); }
