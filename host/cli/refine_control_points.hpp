// `pliant refine --control-points auto|N|FILE`: where the material map's control points come from.
//
// auto (the default): as many as the data determine, chosen by select_material_map
// (material_map_selection.hpp: 1, 2, 4, ... points, the lowest BIC). N (a positive integer): place_control_points
// spreads N points over the mesh (material_map.hpp: farthest-point seeds, volume-weighted k-means on element
// centroids). FILE: one point per line, "x,y,z" or "x y z" in metres in the recording frame; blank lines and lines
// starting with '#' are skipped.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

namespace pliant::cli {

struct ControlPointSource {
  bool automatic = false;                 ///< "auto": the count is chosen by the data
  int count = 0;                          ///< > 0 when given as a number
  std::vector<Eigen::Vector3d> points_m;  ///< non-empty when given as a file
};

/// Upper bound on N and on the points of a file (each is an unknown of a trajectory fit).
constexpr int kMaxControlPoints = 64;

/// Parses the option's value. Throws UsageError naming the file and line for a malformed file, a
/// non-finite coordinate, no points, or more than kMaxControlPoints.
ControlPointSource parse_control_points(const std::string& value);

}  // namespace pliant::cli
