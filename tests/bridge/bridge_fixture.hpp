// Test helpers for pliant.h: lattice objects, configs and instances in std::vector memory.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

#include "pliant.h"

namespace pliant::bridge_test {

#if defined(PLIANT_BRIDGE_SCALAR_DOUBLE) && PLIANT_BRIDGE_SCALAR_DOUBLE
using Scalar = double;
#else
using Scalar = float;
#endif

inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
inline constexpr double kInf = std::numeric_limits<double>::infinity();

/// A lattice object nx x ny (x nz), ids x fastest, spacing h metres.
struct LatticeObject {
  std::uint32_t dim = 3;
  int nx = 4, ny = 4, nz = 3;
  double h = 0.01;
  std::vector<float> rest;
  std::vector<std::int32_t> drivable;
  std::vector<std::uint8_t> fixed;
  std::vector<std::int32_t> jaw_a, jaw_b;

  LatticeObject(std::uint32_t dimension, int x, int y, int z, double spacing = 0.01)
      : dim(dimension), nx(x), ny(y), nz(dimension == 3 ? z : 1), h(spacing) {
    for (int k = 0; k < nz; ++k) {
      for (int j = 0; j < ny; ++j) {
        for (int i = 0; i < nx; ++i) {
          rest.push_back(static_cast<float>(h * i));
          rest.push_back(static_cast<float>(h * j));
          if (dim == 3) rest.push_back(static_cast<float>(h * k));
        }
      }
    }
    for (int k = 0; k < nz; ++k) {
      for (int j = 0; j < ny; ++j) {
        jaw_a.push_back(id(0, j, k));
        jaw_b.push_back(id(nx - 1, j, k));
      }
    }
  }
  int id(int i, int j, int k) const { return (k * ny + j) * nx + i; }
  std::uint32_t count() const { return static_cast<std::uint32_t>(nx * ny * nz); }
  /// Both jaw faces drivable (a squeeze along x).
  void drive_jaws() {
    drivable = jaw_a;
    drivable.insert(drivable.end(), jaw_b.begin(), jaw_b.end());
  }

  /// Defaults, this object, a squeeze along x with the jaw faces, a small prediction table.
  pliant_config_t config() const {
    pliant_config_t c;
    (void)pliant_config_init_default(&c);
    c.dim = dim;
    c.particle_count = count();
    c.rest_positions = rest.data();
    c.drivable_ids = drivable.empty() ? nullptr : drivable.data();
    c.drivable_count = static_cast<std::uint32_t>(drivable.size());
    c.fixed = fixed.empty() ? nullptr : fixed.data();
    c.guard.squeeze_axis[0] = 1.0;
    c.guard.jaw_a_ids = jaw_a.data();
    c.guard.jaw_a_count = static_cast<std::uint32_t>(jaw_a.size());
    c.guard.jaw_b_ids = jaw_b.data();
    c.guard.jaw_b_count = static_cast<std::uint32_t>(jaw_b.size());
    c.guard.prediction_beta_points = 6;
    c.guard.prediction_closure_points = 12;
    return c;
  }
};

/// An instance in vector memory; `status` is init's answer.
struct Instance {
  std::vector<unsigned char> block;
  pliant_t* pliant = nullptr;
  std::size_t bytes = 0;
  pliant_status_t status = PLIANT_ERROR_NOT_INITIALIZED;

  explicit Instance(const pliant_config_t& config, std::size_t offset = 0) {
    status = pliant_workspace_size(&config, &bytes);
    if (status != PLIANT_OK) return;
    block.assign(bytes + offset, 0);
    status = pliant_init(block.data() + offset, bytes, &config, &pliant);
  }
  Instance(const Instance&) = delete;
  Instance& operator=(const Instance&) = delete;

  pliant_counters_t counters() const {
    pliant_counters_t c{};
    (void)pliant_get_counters(pliant, &c);
    return c;
  }
};

/// A guard input with every source fresh and valid at `now` (deformation and estimate from
/// the bridge unless changed).
inline pliant_guard_input_t fresh_input(double now, double width_m, double force_n) {
  pliant_guard_input_t in;
  (void)pliant_guard_input_init(&in);
  in.now_s = now;
  in.gripper.stamp_s = now;
  in.gripper.width_m = width_m;
  in.gripper.force_n = force_n;
  in.gripper.valid = true;
  in.wrench.stamp_s = now;
  for (double& w : in.wrench.wrench) w = 0;
  in.wrench.wrench[2] = -1.0 + 1e-3 * std::sin(1e3 * now);
  in.wrench.valid = true;
  return in;
}

}  // namespace pliant::bridge_test
