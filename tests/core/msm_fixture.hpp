// Test helpers: lattices and MSM objects living in std::vector memory.
#pragma once

#include <cstdint>
#include <vector>

#include "pliant/core/msm.hpp"
#include "pliant/core_testing/press_grid.hpp"

namespace pliant::test {

/// Regular lattice, ids x-fastest: id = (z * ny + y) * nx + x. Spacing `h`, particle 0 at the
/// origin (core_testing's press grid).
template <int Dim, typename Scalar>
std::vector<Scalar> lattice(int nx, int ny, int nz, double h) {
  core_testing::PressGrid grid;
  grid.extents[0] = nx;
  grid.extents[1] = ny;
  grid.extents[2] = nz;
  grid.spacing = h;
  return core_testing::grid_rest<Dim, Scalar>(grid);
}

/// A model and one state, with their memory.
template <int Dim, typename Scalar>
struct MsmFixture {
  std::vector<unsigned char> model_block;
  std::vector<unsigned char> state_block;
  MsmModel<Dim, Scalar> model;
  MsmState<Dim, Scalar> state;
  Status status = Status::not_initialized;

  explicit MsmFixture(const MsmModelConfig<Dim, Scalar>& config) {
    model_block.resize(msm_model_workspace_size(config) + 1);
    Arena arena(model_block.data(), model_block.size());
    status = msm_model_init(arena, config, model);
    if (status != Status::ok) return;
    state_block.resize(msm_state_workspace_size(model));
    Arena state_arena(state_block.data(), state_block.size());
    status = msm_state_init(state_arena, model, state);
  }
};

/// Config over `rest` with the given fixed ids and one drivable id (or -1).
template <int Dim, typename Scalar>
struct ConfigBuilder {
  std::vector<Scalar> rest;
  std::vector<std::uint8_t> fixed;
  std::vector<int> drivable;
  MsmModelConfig<Dim, Scalar> config() const {
    MsmModelConfig<Dim, Scalar> c;
    c.particle_count = static_cast<int>(rest.size()) / Dim;
    c.rest_positions = rest.data();
    c.fixed = fixed.empty() ? nullptr : fixed.data();
    c.drivable_ids = drivable.empty() ? nullptr : drivable.data();
    c.drivable_count = static_cast<int>(drivable.size());
    return c;
  }
};

}  // namespace pliant::test
