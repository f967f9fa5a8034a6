// Test helpers for the grasp guard: soft objects as MSM models (every particle drivable, none
// fixed, as grasp_guard_init requires) and a guard built on them, all in std::vector memory.
#pragma once

#include <cstdint>
#include <vector>

#include "msm_fixture.hpp"
#include "pliant/core/grasp_guard.hpp"

namespace pliant::test {

/// Lattice points at spacing h inside a disc (2D) or ball (3D) of radius r_cells x h.
template <int Dim, typename Scalar>
std::vector<Scalar> ball_rest(int r_cells, double h) {
  std::vector<Scalar> rest;
  const int zr = Dim == 3 ? r_cells : 0;
  for (int z = -zr; z <= zr; ++z) {
    for (int y = -r_cells; y <= r_cells; ++y) {
      for (int x = -r_cells; x <= r_cells; ++x) {
        if (x * x + y * y + z * z > r_cells * r_cells) continue;
        rest.push_back(static_cast<Scalar>(h * x));
        rest.push_back(static_cast<Scalar>(h * y));
        if (Dim == 3) rest.push_back(static_cast<Scalar>(h * z));
      }
    }
  }
  return rest;
}

/// An object model (all particles drivable) and optionally a guard on it.
template <int Dim, typename Scalar>
struct GuardedObject {
  using Vec = Eigen::Matrix<Scalar, Dim, 1>;
  std::vector<Scalar> rest;
  std::vector<int> all;
  std::vector<unsigned char> model_block;
  std::vector<unsigned char> guard_block;
  MsmModel<Dim, Scalar> model;
  GraspGuard<Dim, Scalar> guard;
  Status model_status = Status::not_initialized;

  explicit GuardedObject(std::vector<Scalar> rest_positions) : rest(std::move(rest_positions)) {
    const int n = static_cast<int>(rest.size()) / Dim;
    for (int i = 0; i < n; ++i) all.push_back(i);
    MsmModelConfig<Dim, Scalar> config;
    config.particle_count = n;
    config.rest_positions = rest.data();
    config.drivable_ids = all.data();
    config.drivable_count = n;
    model_block.resize(msm_model_workspace_size(config));
    Arena arena(model_block.data(), model_block.size());
    model_status = model_block.empty() ? Status::invalid_argument : msm_model_init(arena, config, model);
  }
  GuardedObject(const GuardedObject&) = delete;
  GuardedObject& operator=(const GuardedObject&) = delete;

  int particle_count() const { return static_cast<int>(rest.size()) / Dim; }

  static Vec x_axis() {
    Vec axis = Vec::Zero();
    axis(0) = Scalar(1);
    return axis;
  }

  Status build_guard(const GraspGuardConfig& config, const GraspObject<Dim, Scalar>& object) {
    if (model_status != Status::ok) return model_status;
    guard_block.assign(grasp_guard_workspace_size(model, config), 0);
    Arena arena(guard_block.data(), guard_block.size());
    return grasp_guard_init(arena, model, object, config, guard);
  }
  Status build_guard(const GraspGuardConfig& config) {
    GraspObject<Dim, Scalar> object;
    object.squeeze_axis = x_axis();
    return build_guard(config, object);
  }
};

}  // namespace pliant::test
