// Test support: the block_press scenario (a 5 x 5 x 4 particle block, 10 mm spacing, bottom
// fixed, top centre pressed 6 mm; known msm_beta) filmed by a simulated depth camera: the
// deformed lattice's surface, the table it stands on and the tool (a 3 mm prism pressing the top
// centre) rendered into 640 x 480 depth images with Gaussian noise, optionally with a bar moving
// between the camera and the block.
#pragma once

#include <cmath>
#include <random>
#include <vector>

#include "pliant/host/scenarios.hpp"
#include "pliant/vision/depth_cloud.hpp"
#include "synthetic_depth.hpp"

namespace pliant::vision::test {

struct PressScene {
  static constexpr int kNx = 5, kNy = 5, kNz = 4;
  host::ScenarioResult truth;
  host::Recording plan;  ///< rest frame and the tool's trajectory only (what a robot knows)
  PinholeIntrinsics intrinsics{525.0, 525.0, 319.5, 239.5, 640, 480};
  Eigen::Isometry3d camera_to_world = Eigen::Isometry3d::Identity();
  DepthToCloudOptions cloud;  ///< scale 0.1 mm, region around the block
  double noise_m = 0.5e-3;
  bool occluder = false;
  int tool = 0;

  explicit PressScene(double msm_beta = 0.5, double noise = 0.5e-3, bool with_occluder = false)
      : noise_m(noise), occluder(with_occluder) {
    host::ScenarioOptions options;
    options.msm_beta = msm_beta;
    truth = host::make_scenario("block_press", options);
    tool = truth.recording.driven.front().id;
    plan = truth.recording;
    const int n = plan.particle_count;
    for (int f = 1; f < plan.frame_count(); ++f) {
      for (int i = 0; i < n; ++i) {
        if (i == tool) continue;
        for (int d = 0; d < 3; ++d) plan.positions[static_cast<std::size_t>((f * n + i) * 3 + d)] = std::nan("");
      }
    }
    // An oblique view from the front right, 0.29 m from the block: the top, front (-y) and
    // right (+x) faces are visible; the back, left, bottom and interior particles are not.
    camera_to_world = look_at({0.14, -0.16, 0.22}, {0.02, 0.02, 0.012}, {0, 0, 1});
    cloud.depth_scale_m = 1e-4;
    cloud.region = region_around_block(20);
  }

  int frames() const { return truth.recording.frame_count(); }
  double dt(int frame) const {
    return truth.recording.frame_times_s[static_cast<std::size_t>(frame)] -
           truth.recording.frame_times_s[static_cast<std::size_t>(frame - 1)];
  }
  Eigen::Vector3d truth_at(int frame, int id) const {
    const host::Recording& r = truth.recording;
    return {r.position(frame, id, 0), r.position(frame, id, 1), r.position(frame, id, 2)};
  }

  // Pixel box of the block at rest (with the tool's lower part), padded.
  PixelRect region_around_block(int pad) const {
    DepthRenderer renderer(intrinsics, camera_to_world);
    double u0 = 1e9, v0 = 1e9, u1 = -1e9, v1 = -1e9;
    for (int c = 0; c < 8; ++c) {
      const Eigen::Vector3d corner((c & 1) ? 0.04 : 0.0, (c & 2) ? 0.04 : 0.0, (c & 4) ? 0.045 : 0.0);
      const Eigen::Vector2d p = renderer.project(corner);
      u0 = std::min(u0, p.x());
      u1 = std::max(u1, p.x());
      v0 = std::min(v0, p.y());
      v1 = std::max(v1, p.y());
    }
    PixelRect r;
    r.u0 = std::max(0, static_cast<int>(u0) - pad);
    r.v0 = std::max(0, static_cast<int>(v0) - pad);
    r.width = std::min(intrinsics.width - r.u0, static_cast<int>(u1 - u0) + 2 * pad);
    r.height = std::min(intrinsics.height - r.v0, static_cast<int>(v1 - v0) + 2 * pad);
    return r;
  }

  // Lateral position of the occluding bar's axis at a frame: it crosses the view between frames
  // 10 and 100, halfway between the camera and the block.
  bool bar_at(int frame, Eigen::Vector3d& centre) const {
    if (!occluder || frame < 10 || frame > 100) return false;
    const Eigen::Vector3d eye = camera_to_world.translation();
    const Eigen::Vector3d middle = 0.5 * (eye + Eigen::Vector3d(0.02, 0.02, 0.015));
    const Eigen::Vector3d right = camera_to_world.linear().col(0);
    const double s = -0.02 + 0.04 * (frame - 10) / 90.0;
    centre = middle + s * right;
    return true;
  }

  void render(int frame, DepthRenderer& renderer) const {
    renderer.clear();
    const host::Recording& r = truth.recording;
    const double* x =
        r.positions.data() + static_cast<std::size_t>(frame) * static_cast<std::size_t>(r.particle_count) * 3;
    renderer.add(lattice_surface(x, kNx, kNy, kNz));
    renderer.add(Triangle{{-0.06, -0.06, 0}, {0.10, -0.06, 0}, {0.10, 0.10, 0}});  // the table
    renderer.add(Triangle{{-0.06, -0.06, 0}, {0.10, 0.10, 0}, {-0.06, 0.10, 0}});
    renderer.add_prism(truth_at(frame, tool), 0.003, 0.08);
    Eigen::Vector3d bar = Eigen::Vector3d::Zero();
    if (bar_at(frame, bar)) {
      renderer.add_box(bar + Eigen::Vector3d(-0.003, -0.003, -0.15), bar + Eigen::Vector3d(0.003, 0.003, 0.15));
    }
  }

  DepthImage image(int frame, std::mt19937& rng) const {
    DepthRenderer renderer(intrinsics, camera_to_world);
    render(frame, renderer);
    return renderer.image(cloud.depth_scale_m, noise_m, rng);
  }
};

}  // namespace pliant::vision::test
