// Cluster radii that change the radius layout's clusters, read off the rest shape.
//
// The radius layout (core msm_model.hpp) puts in a particle's cluster every particle within
// radius_factor x spacing of it. Its clusters therefore change only where radius_factor passes
// the distance of some pair of particles, in units of the spacing: on a regular lattice at a few
// values (sqrt 2, sqrt 3, 2, ...), on an irregular or curved body at many. A fixed list of radii
// misses memberships between its entries, and msm_beta then takes up the difference (a ring
// simulated with clusters of 1.91 spacings and fitted at 1.3 gave msm_beta 0.62 for 0.14).
// Host-only; allocates.
#pragma once

#include <vector>

namespace pliant::host {

/// Radius factors strictly between `lo` and `hi` whose clusters differ from those at `lo`, at
/// `hi` and from each other: the middle of every gap wider than `merge` (relative) between
/// consecutive pair distances (closer distances form one run: a noisy lattice's sqrt 2 stays
/// one membership change), ascending. When there are
/// more than `max_count`, that many spread evenly over them. `rest` holds particle_count x `dim`
/// coordinates; `spacing` > 0 is the layout's length unit (median nearest-neighbour distance).
/// O(N^2) time, O(pairs in range) memory.
std::vector<double> membership_radii(const std::vector<double>& rest, int dim, double spacing, double lo, double hi,
                                     int max_count, double merge = 0.005);

}  // namespace pliant::host
