#include "synthetic_depth.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace pliant::vision::test {

Eigen::Isometry3d look_at(const Eigen::Vector3d& eye, const Eigen::Vector3d& target, const Eigen::Vector3d& up) {
  const Eigen::Vector3d forward = (target - eye).normalized();
  const Eigen::Vector3d right = forward.cross(up).normalized();
  const Eigen::Vector3d down = forward.cross(right);
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear().col(0) = right;
  pose.linear().col(1) = down;
  pose.linear().col(2) = forward;
  pose.translation() = eye;
  return pose;
}

DepthRenderer::DepthRenderer(const PinholeIntrinsics& intrinsics, const Eigen::Isometry3d& camera_to_world)
    : k_(intrinsics), world_to_camera_(camera_to_world.inverse()) {
  clear();
}

void DepthRenderer::clear() {
  z_.assign(static_cast<std::size_t>(k_.width * k_.height), std::numeric_limits<double>::infinity());
}

Eigen::Vector2d DepthRenderer::project(const Eigen::Vector3d& world) const {
  const Eigen::Vector3d p = world_to_camera_ * world;
  return {k_.fx * p.x() / p.z() + k_.cx, k_.fy * p.y() / p.z() + k_.cy};
}

void DepthRenderer::add(const Triangle& t) {
  const Eigen::Vector3d a = world_to_camera_ * t.a;
  const Eigen::Vector3d b = world_to_camera_ * t.b;
  const Eigen::Vector3d c = world_to_camera_ * t.c;
  if (a.z() < 1e-3 || b.z() < 1e-3 || c.z() < 1e-3) return;
  const Eigen::Vector3d normal = (b - a).cross(c - a);
  auto pixel = [&](const Eigen::Vector3d& p) {
    return Eigen::Vector2d(k_.fx * p.x() / p.z() + k_.cx, k_.fy * p.y() / p.z() + k_.cy);
  };
  const Eigen::Vector2d pa = pixel(a), pb = pixel(b), pc = pixel(c);
  const double area = (pb - pa).x() * (pc - pa).y() - (pb - pa).y() * (pc - pa).x();
  if (std::abs(area) < 1e-12) return;
  const int u0 = std::max(0, static_cast<int>(std::floor(std::min({pa.x(), pb.x(), pc.x()}))));
  const int u1 = std::min(k_.width - 1, static_cast<int>(std::ceil(std::max({pa.x(), pb.x(), pc.x()}))));
  const int v0 = std::max(0, static_cast<int>(std::floor(std::min({pa.y(), pb.y(), pc.y()}))));
  const int v1 = std::min(k_.height - 1, static_cast<int>(std::ceil(std::max({pa.y(), pb.y(), pc.y()}))));
  auto edge = [](const Eigen::Vector2d& p, const Eigen::Vector2d& q, double x, double y) {
    return (q.x() - p.x()) * (y - p.y()) - (q.y() - p.y()) * (x - p.x());
  };
  const double tolerance = 1e-9 * std::abs(area);
  for (int v = v0; v <= v1; ++v) {
    for (int u = u0; u <= u1; ++u) {
      const double x = u, y = v;
      double w0 = edge(pb, pc, x, y), w1 = edge(pc, pa, x, y), w2 = edge(pa, pb, x, y);
      if (area < 0) {
        w0 = -w0;
        w1 = -w1;
        w2 = -w2;
      }
      if (w0 < -tolerance || w1 < -tolerance || w2 < -tolerance) continue;
      const Eigen::Vector3d ray((x - k_.cx) / k_.fx, (y - k_.cy) / k_.fy, 1.0);
      const double denominator = normal.dot(ray);
      if (std::abs(denominator) < 1e-15) continue;
      const double z = normal.dot(a) / denominator;
      double& stored = z_[static_cast<std::size_t>(v * k_.width + u)];
      if (z > 0 && z < stored) stored = z;
    }
  }
}

void DepthRenderer::add(const std::vector<Triangle>& triangles) {
  for (const Triangle& t : triangles) add(t);
}

void DepthRenderer::add_box(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  auto corner = [&](int i) {
    return Eigen::Vector3d((i & 1) ? hi.x() : lo.x(), (i & 2) ? hi.y() : lo.y(), (i & 4) ? hi.z() : lo.z());
  };
  static const int kFaces[6][4] = {{0, 1, 3, 2}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 3, 7, 5}};
  for (const auto& f : kFaces) {
    add(Triangle{corner(f[0]), corner(f[1]), corner(f[2])});
    add(Triangle{corner(f[0]), corner(f[2]), corner(f[3])});
  }
}

void DepthRenderer::add_prism(const Eigen::Vector3d& bottom, double radius, double height, int sides) {
  const double step = 2 * 3.14159265358979323846 / sides;
  const Eigen::Vector3d up(0, 0, height);
  for (int s = 0; s < sides; ++s) {
    const Eigen::Vector3d p = bottom + radius * Eigen::Vector3d(std::cos(s * step), std::sin(s * step), 0);
    const Eigen::Vector3d q = bottom + radius * Eigen::Vector3d(std::cos((s + 1) * step), std::sin((s + 1) * step), 0);
    add(Triangle{p, q, q + up});
    add(Triangle{p, q + up, p + up});
    add(Triangle{bottom, p, q});
    add(Triangle{bottom + up, p + up, q + up});
  }
}

DepthImage DepthRenderer::image(double depth_scale_m, double noise_sd_m, std::mt19937& rng) const {
  std::normal_distribution<double> noise(0.0, 1.0);
  DepthImage out;
  out.width = k_.width;
  out.height = k_.height;
  out.data.assign(z_.size(), 0);
  for (std::size_t i = 0; i < z_.size(); ++i) {
    if (!std::isfinite(z_[i])) continue;
    const double raw = std::round((z_[i] + noise_sd_m * noise(rng)) / depth_scale_m);
    if (raw >= 1 && raw <= 65535) out.data[i] = static_cast<std::uint16_t>(raw);
  }
  return out;
}

std::vector<Triangle> lattice_surface(const double* x, int nx, int ny, int nz) {
  auto at = [&](int i, int j, int k) {
    const double* p = x + 3 * ((k * ny + j) * nx + i);
    return Eigen::Vector3d(p[0], p[1], p[2]);
  };
  std::vector<Triangle> out;
  auto quad = [&](const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                  const Eigen::Vector3d& d) {
    out.push_back({a, b, c});
    out.push_back({a, c, d});
  };
  for (int k : {0, nz - 1}) {
    for (int j = 0; j + 1 < ny; ++j) {
      for (int i = 0; i + 1 < nx; ++i) quad(at(i, j, k), at(i + 1, j, k), at(i + 1, j + 1, k), at(i, j + 1, k));
    }
  }
  for (int j : {0, ny - 1}) {
    for (int k = 0; k + 1 < nz; ++k) {
      for (int i = 0; i + 1 < nx; ++i) quad(at(i, j, k), at(i + 1, j, k), at(i + 1, j, k + 1), at(i, j, k + 1));
    }
  }
  for (int i : {0, nx - 1}) {
    for (int k = 0; k + 1 < nz; ++k) {
      for (int j = 0; j + 1 < ny; ++j) quad(at(i, j, k), at(i, j + 1, k), at(i, j + 1, k + 1), at(i, j, k + 1));
    }
  }
  return out;
}

}  // namespace pliant::vision::test
