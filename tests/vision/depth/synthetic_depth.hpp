// Test support: depth images of simple scenes with a known geometry, rendered by an exact
// z-buffer rasteriser (each pixel's depth is the ray-plane intersection of the nearest
// triangle), then noised and quantised like a sensor.
#pragma once

#include <cstdint>
#include <random>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "pliant/vision/depth_image.hpp"

namespace pliant::vision::test {

struct Triangle {
  Eigen::Vector3d a, b, c;  ///< world frame, m
};

/// Camera pose looking from `eye` at `target` with world `up` roughly up in the image
/// (optical frame: x right, y down, z forward).
Eigen::Isometry3d look_at(const Eigen::Vector3d& eye, const Eigen::Vector3d& target, const Eigen::Vector3d& up);

class DepthRenderer {
 public:
  DepthRenderer(const PinholeIntrinsics& intrinsics, const Eigen::Isometry3d& camera_to_world);
  void clear();                        ///< every pixel empty (infinite depth)
  void add(const Triangle& triangle);  ///< rasterised into the z-buffer
  void add(const std::vector<Triangle>& triangles);
  /// Axis-aligned box [low, high] (world).
  void add_box(const Eigen::Vector3d& low, const Eigen::Vector3d& high);
  /// Vertical (world z) prism of `sides` sides, radius r, from z = bottom to bottom + height, axis at (x, y).
  void add_prism(const Eigen::Vector3d& bottom_centre, double radius, double height, int sides = 12);
  /// The z-buffer as a sensor image: depth + N(0, noise_sd_m), quantised to depth_scale_m units
  /// (round to nearest), 0 where nothing was hit.
  DepthImage image(double depth_scale_m, double noise_sd_m, std::mt19937& rng) const;
  /// Exact depth (m) at pixel (u, v), infinity when empty.
  double depth(int u, int v) const { return z_[static_cast<std::size_t>(v * k_.width + u)]; }
  /// Pixel of a world point (u, v; may lie outside the image).
  Eigen::Vector2d project(const Eigen::Vector3d& world) const;

 private:
  PinholeIntrinsics k_;
  Eigen::Isometry3d world_to_camera_;
  std::vector<double> z_;
};

/// Boundary triangles of a deformed nx x ny x nz particle lattice (particle id
/// (z * ny + y) * nx + x, positions particle-major x y z): the six faces, each lattice quad
/// split into two triangles.
std::vector<Triangle> lattice_surface(const double* positions, int nx, int ny, int nz);

}  // namespace pliant::vision::test
