// A regular particle grid standing on a support: the object of the simulated presses.
//
// Ids run x fastest: id = (z * ny + y) * nx + x (2D: z = 0). Particle (x, y, z) rests at
// origin + spacing * (sign_x x, sign_y y, sign_z z), in the model's length unit. The layer at
// index 0 along `support_axis` stands on the support (fixed); the tool presses the top layer.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace pliant::core_testing {

struct PressGrid {
  int extents[3] = {8, 4, 1};    ///< particles along x, y, z, each >= 1 (z ignored in 2D)
  double spacing = 1.0;          ///< particle spacing, length unit, > 0
  double origin[3] = {0, 0, 0};  ///< rest position of particle 0
  double sign[3] = {1, 1, 1};    ///< +1 or -1 per axis (-1: image rows, y pointing down)
  int support_axis = 1;          ///< axis whose index-0 layer is fixed; < Dim
};

/// Particle count of the grid in Dim dimensions.
template <int Dim>
int grid_particle_count(const PressGrid& grid) {
  return grid.extents[0] * grid.extents[1] * (Dim == 3 ? grid.extents[2] : 1);
}

/// Grid index of particle `id` along `axis`.
template <int Dim>
int grid_index(const PressGrid& grid, int id, int axis) {
  if (axis == 0) return id % grid.extents[0];
  if (axis == 1) return (id / grid.extents[0]) % grid.extents[1];
  return id / (grid.extents[0] * grid.extents[1]);
}

/// Rest positions, particle-major [particle][axis], computed in double and cast to Scalar.
template <int Dim, typename Scalar>
std::vector<Scalar> grid_rest(const PressGrid& grid) {
  const int n = grid_particle_count<Dim>(grid);
  std::vector<Scalar> rest;
  rest.reserve(static_cast<std::size_t>(n) * Dim);
  for (int id = 0; id < n; ++id) {
    for (int d = 0; d < Dim; ++d) {
      rest.push_back(
          static_cast<Scalar>(grid.origin[d] + (grid.sign[d] * grid.spacing) * grid_index<Dim>(grid, id, d)));
    }
  }
  return rest;
}

/// 1 for the particles on the support (index 0 along support_axis), else 0; [particle].
template <int Dim>
std::vector<std::uint8_t> grid_support(const PressGrid& grid) {
  const int n = grid_particle_count<Dim>(grid);
  std::vector<std::uint8_t> fixed(static_cast<std::size_t>(n), 0);
  for (int id = 0; id < n; ++id)
    fixed[static_cast<std::size_t>(id)] = grid_index<Dim>(grid, id, grid.support_axis) == 0;
  return fixed;
}

/// The top-centre particle: last index along support_axis, index extent / 2 along the others.
template <int Dim>
int grid_top_centre(const PressGrid& grid) {
  int index[3] = {grid.extents[0] / 2, grid.extents[1] / 2, Dim == 3 ? grid.extents[2] / 2 : 0};
  index[grid.support_axis] = grid.extents[grid.support_axis] - 1;
  return (index[2] * grid.extents[1] + index[1]) * grid.extents[0] + index[0];
}

}  // namespace pliant::core_testing
