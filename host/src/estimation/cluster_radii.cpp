#include "pliant/host/cluster_radii.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <utility>

namespace pliant::host {
namespace {

// Pair distances in units of the spacing that fall in (lo, hi], sorted.
std::vector<double> pair_distances_in(const std::vector<double>& rest, int dim, double spacing, double lo, double hi) {
  std::vector<double> found;
  const auto d_count = static_cast<std::size_t>(dim);
  const std::size_t n = rest.size() / d_count;
  const double lo_squared = lo * lo * spacing * spacing;
  const double hi_squared = hi * hi * spacing * spacing;
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n; ++j) {
      double squared = 0;
      for (std::size_t d = 0; d < d_count; ++d) {
        const double delta = rest[i * d_count + d] - rest[j * d_count + d];
        squared += delta * delta;
      }
      if (squared > lo_squared && squared <= hi_squared) found.push_back(std::sqrt(squared) / spacing);
    }
  }
  std::sort(found.begin(), found.end());
  return found;
}

// Runs of distances, each starting where a distance exceeds the one before it by more than
// `merge` (relative): [first, last] of each. A lattice's noisy rest shape spreads each of its
// distances into a dense run, which stays one.
std::vector<std::pair<double, double>> distance_runs(const std::vector<double>& sorted, double merge) {
  std::vector<std::pair<double, double>> runs;
  for (double d : sorted) {
    if (runs.empty() || d > runs.back().second * (1 + merge)) {
      runs.emplace_back(d, d);
    } else {
      runs.back().second = d;
    }
  }
  return runs;
}

}  // namespace

std::vector<double> membership_radii(const std::vector<double>& rest, int dim, double spacing, double lo, double hi,
                                     int max_count, double merge) {
  if (dim < 1 || !(spacing > 0) || !(hi > lo) || max_count < 1) return {};
  const auto runs = distance_runs(pair_distances_in(rest, dim, spacing, lo, hi), merge);
  // Between the end of one run and the start of the next the clusters are those of neither lo
  // nor hi (before the first run they are lo's, after the last hi's).
  std::vector<double> radii;
  for (std::size_t j = 0; j + 1 < runs.size(); ++j) radii.push_back(0.5 * (runs[j].second + runs[j + 1].first));
  if (radii.size() <= static_cast<std::size_t>(max_count)) return radii;
  std::vector<double> spread;
  for (int k = 0; k < max_count; ++k) {
    const double position = (k + 0.5) * static_cast<double>(radii.size()) / max_count;
    spread.push_back(radii[std::min(radii.size() - 1, static_cast<std::size_t>(position))]);
  }
  return spread;
}

}  // namespace pliant::host
