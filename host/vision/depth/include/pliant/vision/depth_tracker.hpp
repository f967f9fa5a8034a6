// Depth tracker: the particles of an MSM model fitted, frame by frame, to the point cloud of a
// depth camera, with the core MSM-regularised tracker (core/include/pliant/core/tracker.hpp)
// carrying the particles the camera cannot see.
//
// Per frame (update):
//   1. the depth image becomes a point cloud in the camera frame (depth_cloud.hpp) and a
//      nanoflann kd-tree is built over it;
//   2. the MSM prediction of the frame is computed exactly as the core tracker will compute it
//      (a copy of the tracker's state stepped with the same model, parameters and tool targets);
//   3. each predicted particle is looked for in the cloud. It gets no observation this frame
//      (ParticleView says why) when it is fixed or driven (held), not on the object's surface
//      (interior), outside the image or region (out_of_view), without a valid depth near its
//      pixel (no_depth), farther than visibility_margin_m behind the depth at its pixel
//      (behind_surface: hidden by an occluder, the tool or the object itself), its outward
//      normal turned away from the camera ray (facing_away), no cloud point within gate_m
//      (no_point), or the local surface normal of its nearest points differs from its own
//      (normal_mismatch: the points belong to another surface, e.g. an occluder's side);
//   4. a visible particle's observation is, for point_to_plane, its prediction projected onto
//      the plane fitted (PCA) to its plane_neighbours nearest points (only the motion along the
//      surface normal is measured; along the surface the model's prediction stands, as in the
//      STEPE point-to-plane tracking), or for nearest_point the mean of those points; a
//      per-particle reference offset measured on still frames (calibrate) is subtracted;
//   5. Tukey's biweight on the correspondence distances (robust scale: the median distance,
//      never below depth_noise_m) gives each observation a confidence; beyond the cutoff an
//      observation is dropped (down_weighted);
//   6. the core tracker predicts, weighs the observations against the prediction and the
//      neighbourhood's coherent motion, corrects, and moves the unobserved particles by shape
//      matching, so an occluded particle follows its cluster.
//
// Frames: the model, the particles and the tool targets are in the world frame (the
// recording's, m); the cloud is in the camera frame; config.camera_to_world links them.
// Units: metres, seconds.
//
// Memory: the constructor allocates everything sized by the model and the image (cloud
// capacity, state copy, per-particle arrays). Per frame, the only allocation is nanoflann's:
// building the kd-tree frees and re-mallocs its node pool (about 8 bytes per point in 8 KiB
// blocks; nanoflann 1.4 cannot take an external pool), and its index array grows the first
// time a frame has more points than any before. Nothing else allocates (no operator new at
// all: tests/vision/depth/depth_allocation_test.cpp). Per frame O(points + particles x
// (log points + plane_neighbours) + the core tracker's cost).
// Thread safety: one tracker per thread; the model must outlive the tracker and not change.
// Errors: the constructor and update throw DepthError for malformed input (bad intrinsics,
// image of the wrong size, bad options, a model that is not 3D-initialised); a frame without
// any valid depth is not an error (a prediction-only frame, counted in empty_frames).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "pliant/core/tracker.hpp"
#include "pliant/vision/depth_cloud.hpp"
#include "pliant/vision/depth_image.hpp"

namespace pliant::vision {

enum class Correspondence : std::uint8_t {
  point_to_plane,  ///< the prediction projected onto the local plane of the cloud (normal motion only)
  nearest_point,   ///< the mean of its nearest cloud points (noisier; sees some motion along the surface)
};

/// Why a particle did or did not get an observation in the last frame.
enum class ParticleView : std::uint8_t {
  observed = 0,     ///< an observation went to the core tracker (which may still weigh it 0)
  held,             ///< fixed or driven this frame: its position is known
  interior,         ///< not on the surface (zero rest normal): never seen by a depth camera
  out_of_view,      ///< behind the camera, or projecting outside the image or the region
  no_depth,         ///< no valid depth within depth_window pixels of its projection
  behind_surface,   ///< more than visibility_margin_m behind the depth at its pixel (occluded)
  facing_away,      ///< outward normal more than max_view_angle_deg from the direction to the camera
  no_point,         ///< no cloud point within gate_m (or fewer than 3 for the plane)
  normal_mismatch,  ///< the local cloud normal is more than max_normal_angle_deg from its own
  down_weighted,    ///< correspondence distance beyond the Tukey cutoff
};
inline constexpr int kParticleViewCount = 10;

/// Short name of a ParticleView ("behind_surface", ...).
const char* particle_view_name(ParticleView view) noexcept;

struct DepthTrackerConfig {
  DepthToCloudOptions cloud;  ///< conversion of every frame (scale, stride, region, range)
  /// Pose of the camera in the world frame: x_world = camera_to_world * x_camera (m). Must be
  /// a rigid transform (rotation part orthonormal).
  Eigen::Isometry3d camera_to_world = Eigen::Isometry3d::Identity();
  Correspondence correspondence = Correspondence::point_to_plane;
  int plane_neighbours = 12;           ///< k nearest points for the local plane and normal, 3..64
  double gate_m = 0;                   ///< >= 0; 0: 0.5 x the model's spacing
  double visibility_margin_m = 0;      ///< >= 0; 0: 0.5 x the model's spacing
  int depth_window = 2;                ///< 0..16 px: half-width of the window searched for a valid depth
  double max_view_angle_deg = 80.0;    ///< (0, 90]
  double max_normal_angle_deg = 60.0;  ///< (0, 180]
  double depth_noise_m = 1e-3;         ///< > 0: floor of the correspondence scale (the sensor's depth sd)
  double tukey_c = 4.685;              ///< > 0, in robust-scale units
  int leaf_max_size = 16;              ///< 1..256, kd-tree leaf size
  TrackerConfig tracker;               ///< the core tracker's settings (validated by tracker_init)
};

/// Counts of one frame.
struct DepthFrameReport {
  Status status = Status::ok;                     ///< the core tracker's (no_observations: nothing usable; counted)
  std::size_t points = 0;                         ///< cloud points
  int observed = 0;                               ///< particles given an observation (== by_view[observed])
  std::array<int, kParticleViewCount> by_view{};  ///< particles per ParticleView
  double median_distance_m = 0;                   ///< median correspondence distance of the candidates (0: none)
  double correspondence_scale_m = 0;              ///< robust scale behind the Tukey weights
};

/// Monotonic totals since construction (reset() keeps them).
struct DepthTrackerCounters {
  std::uint64_t frames = 0;          ///< update calls that reached the core tracker
  std::uint64_t empty_frames = 0;    ///< frames without a valid depth pixel (prediction only)
  std::uint64_t refused_frames = 0;  ///< frames the core refused (bad dt or tool ids): state unchanged
  std::array<std::uint64_t, kParticleViewCount> by_view{};  ///< particle-frames per ParticleView
};

/// Outward unit normals of the rest shape from the particles alone: for each particle, the
/// direction from the centroid of its rest neighbours within radius_factor x spacing to the
/// particle, when that centroid lies at least surface_offset x spacing away; otherwise zero
/// (interior: a particle surrounded on all sides). Init time, O(N^2). Suits volumetric particle
/// sets (lattices, mesh nodes); a one-layer shell needs normals from elsewhere (seed_particles).
std::vector<Eigen::Vector3d> estimate_rest_normals(const MsmModel<3, double>& model, double radius_factor = 1.5,
                                                   double surface_offset = 0.2);

class DepthTracker {
 public:
  using Vec = Eigen::Vector3d;

  /// `model`: the object's 3D MSM model in the world frame (m), at rest in the first frame;
  /// `params`: the prior's (msm_beta may be changed later through core().params).
  /// Rest normals default to estimate_rest_normals(model). Throws DepthError for invalid
  /// intrinsics or options, or when tracker_init refuses (message names the status).
  DepthTracker(const MsmModel<3, double>& model, const MsmParams<3, double>& params,
               const PinholeIntrinsics& intrinsics, const DepthTrackerConfig& config);
  ~DepthTracker();
  DepthTracker(const DepthTracker&) = delete;
  DepthTracker& operator=(const DepthTracker&) = delete;

  /// Replaces the rest normals (world frame, one per particle; zero = interior, never looked
  /// for; others are normalised). Throws DepthError on a wrong count or a non-finite entry.
  void set_rest_normals(const std::vector<Vec>& normals);

  /// Back to the rest shape (core tracker_reset); counters kept.
  void reset() noexcept;

  /// One frame `dt_s` seconds after the previous one, with this frame's tool targets (world
  /// frame; ids must be drivable). Throws DepthError for a malformed image (wrong size, null).
  DepthFrameReport update(const DepthImageView& depth, double dt_s, const MsmDrivenTargets<3, double>& driven);

  /// Reference offsets. A correspondence has a bias that depends on the local shape, not on
  /// the motion: the plane through a particle's nearest points on an edge or corner lies inside
  /// the edge, and a coarse model's particles sit a little off the real surface. calibrate()
  /// looks for every particle at its rest position (identity rotations) in a frame of the
  /// object at rest and adds observation - rest to a per-particle running mean b_i; update()
  /// then subtracts R_i b_i (R_i: the particle's cluster rotations) from each observation, so
  /// the tracker measures motion relative to the rest shape. Call it on frames where the
  /// object has not moved yet (before the tool touches it). A particle never seen by calibrate
  /// gets no offset. Returns the frame's correspondence counts.
  DepthFrameReport calibrate(const DepthImageView& depth);
  void clear_calibration() noexcept;
  /// Frames calibrate() has accumulated since construction or clear_calibration().
  int calibration_frames() const noexcept;
  /// Per-particle mean offset b_i (world, at rest; zero when never seen) [particle_count].
  const Vec* reference_offsets() const noexcept;

  /// Correspondences for the current tracked positions, without changing the state: how well
  /// the particles sit on this frame's cloud (e.g. frame 0 against the rest shape, an
  /// alignment and depth-scale check). Fills view(), observation() and distance().
  DepthFrameReport look(const DepthImageView& depth);

  const MsmModel<3, double>& model() const noexcept { return model_; }
  Tracker<3, double>& core() noexcept { return tracker_; }
  const Tracker<3, double>& core() const noexcept { return tracker_; }
  /// Tracked positions [particle_count], world frame (m).
  const Vec* positions() const noexcept { return tracker_.state.position; }
  /// Last frame's prediction [particle_count] (update only), world frame.
  const Vec* predicted() const noexcept;
  /// Last frame's observation per particle [particle_count] (NaN: none), world frame.
  const Vec* observation() const noexcept;
  /// Last frame's correspondence distance per particle (NaN: none), m.
  const double* distance() const noexcept;
  /// Last frame's confidence (Tukey weight) per particle, [0, 1].
  const double* confidence() const noexcept;
  const ParticleView* view() const noexcept;
  const Vec* rest_normals() const noexcept;
  const DepthCloud& cloud() const noexcept;
  const DepthTrackerConfig& config() const noexcept { return config_; }
  const DepthTrackerCounters& counters() const noexcept { return counters_; }

  struct Impl;  ///< implementation detail (buffers, kd-tree)

 private:
  const MsmModel<3, double>& model_;
  DepthTrackerConfig config_;
  PinholeIntrinsics intrinsics_;
  Tracker<3, double> tracker_;
  DepthTrackerCounters counters_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace pliant::vision
