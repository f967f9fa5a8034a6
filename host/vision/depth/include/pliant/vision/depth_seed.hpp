// Particles seeded on a point cloud: when no model of the object exists, its visible surface
// becomes the particle set (a one-layer shell).
//
// Host code: allocates; throws DepthError for bad arguments.
#pragma once

#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "pliant/host/recording.hpp"
#include "pliant/vision/depth_cloud.hpp"

namespace pliant::vision {

struct SeededParticles {
  std::vector<Eigen::Vector3d> positions;  ///< world frame, m
  std::vector<Eigen::Vector3d> normals;    ///< world frame, unit, pointing toward the camera (outward)
};

/// One particle per cubic voxel of edge `spacing_m` (aligned with the camera frame's axes)
/// holding at least `min_points` (>= 3) cloud points: the cloud point nearest the voxel's mean,
/// with the normal of the plane fitted (PCA) to the voxel's points, turned toward the camera.
/// Ordered by voxel (z, then y, then x in the camera frame), so a cloud gives the same seeds
/// every time. Crop the cloud first (DepthToCloudOptions region and depth range) so that only
/// the object is seeded. Throws DepthError when spacing_m is not finite > 0, min_points < 3, or
/// no voxel qualifies.
SeededParticles seed_particles(const DepthCloud& cloud, double spacing_m,
                               const Eigen::Isometry3d& camera_to_world = Eigen::Isometry3d::Identity(),
                               int min_points = 8);

/// A plan recording (see depth_recording.hpp) whose only frame, at t_s, is the seeds: no fixed
/// and no driven particle (add them to the result before tracking if the scene has them).
host::Recording seeded_plan(const SeededParticles& seeds, double t_s);

}  // namespace pliant::vision
