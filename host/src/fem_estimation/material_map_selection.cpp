// Choosing the number of material control points by BIC (material_map_selection.hpp).
#include "pliant/host/fem/material_map_selection.hpp"

#include <algorithm>
#include <cmath>
#include <ctime>
#include <limits>
#include <stdexcept>
#include <string>

#include "pliant/host/fem/material_map.hpp"

namespace pliant::host::fem {

namespace {

std::size_t uz(int i) { return static_cast<std::size_t>(i); }

constexpr int kJudgingSubstepFactor = 4;

void check_options(const MaterialMapSelectionOptions& o) {
  if (o.counts.empty()) throw std::invalid_argument("material map selection: no control-point count to try");
  for (std::size_t i = 0; i < o.counts.size(); ++i) {
    if (o.counts[i] < 1 || (i > 0 && o.counts[i] <= o.counts[i - 1])) {
      throw std::invalid_argument("material map selection: counts must be >= 1 and ascending");
    }
  }
  if (o.patience < 1) throw std::invalid_argument("material map selection: patience must be >= 1");
  if (!(o.undetermined_relative_sd > 0)) {
    throw std::invalid_argument("material map selection: undetermined_relative_sd must be > 0");
  }
}

/// Residual sum of squares and pooled lag-1 autocorrelation over frames of the fitted model's
/// residuals, on the coordinates the estimator fits (observed free nodes, frames 1..F-1).
struct ResidualSeries {
  double sum_of_squares = 0;
  long count = 0;
  double lag1 = 0;
};

ResidualSeries residual_series(const FemRecordingProblem& problem, const TrajectoryEstimate& fit,
                               TrajectorySimulationOptions simulation) {
  simulation.substeps *= kJudgingSubstepFactor;
  const std::vector<Eigen::VectorXd> simulated =
      simulate_trajectory(problem, fit.element_youngs_modulus_pa, fit.rayleigh_alpha, fit.rayleigh_beta, simulation);
  const int n = problem.mesh.point_count();
  std::vector<bool> constrained(uz(n), false);
  for (int node : problem.fixed_nodes) constrained[uz(node)] = true;
  for (int node : problem.frames.front().driven_nodes) constrained[uz(node)] = true;
  // The previous frame's residual per coordinate (NaN when that frame did not observe it).
  Eigen::VectorXd previous = Eigen::VectorXd::Constant(3 * n, std::numeric_limits<double>::quiet_NaN());
  ResidualSeries out;
  double lagged_product = 0, lagged_square = 0;
  for (std::size_t f = 1; f < problem.frames.size(); ++f) {
    Eigen::VectorXd current = Eigen::VectorXd::Constant(3 * n, std::numeric_limits<double>::quiet_NaN());
    for (int node : problem.frames[f].observed_nodes) {
      if (constrained[uz(node)]) continue;
      for (int d = 0; d < 3; ++d) {
        const int i = 3 * node + d;
        const double r = simulated[f][i] - problem.frames[f].observed_position_m[i];
        current[i] = r;
        out.sum_of_squares += r * r;
        ++out.count;
        if (std::isfinite(previous[i])) {
          lagged_product += r * previous[i];
          lagged_square += previous[i] * previous[i];
        }
      }
    }
    previous = current;
  }
  out.lag1 = lagged_square > 0 ? lagged_product / lagged_square : 0.0;
  return out;
}

double design_effect(double lag1) {
  const double rho = std::clamp(lag1, 0.0, 0.98);
  return (1 + rho) / (1 - rho);
}

double bic(const MaterialMapCandidate& c, double design) {
  const double n = static_cast<double>(c.residual_count);
  const double effective = std::max(1.0, n / design);
  const double mean_square = std::max(c.residual_rms_m * c.residual_rms_m, std::numeric_limits<double>::min());
  return effective * std::log(mean_square) + c.parameters * std::log(effective);
}

/// Recomputes every BIC with the design effect of the best-fitting candidate; returns the index
/// of the lowest.
int rescore(std::vector<MaterialMapCandidate>& candidates, double& design) {
  const auto best_fit = std::min_element(candidates.begin(), candidates.end(), [](const auto& a, const auto& b) {
    return a.residual_rms_m < b.residual_rms_m;
  });
  design = design_effect(best_fit->lag1_correlation);
  int lowest = 0;
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    candidates[i].bic = bic(candidates[i], design);
    if (candidates[i].bic < candidates[uz(lowest)].bic) lowest = static_cast<int>(i);
  }
  return lowest;
}

/// The modulus of `fit`'s field at each point: that of the element whose rest centroid is
/// nearest (the start of a finer map, continued from a coarser one).
std::vector<double> field_at(const FemRecordingProblem& problem, const TrajectoryEstimate& fit,
                             const std::vector<Eigen::Vector3d>& points_m) {
  const std::vector<Eigen::Vector3d> centroids = element_centroids(problem.mesh);
  std::vector<double> values;
  for (const Eigen::Vector3d& p : points_m) {
    std::size_t nearest = 0;
    for (std::size_t e = 1; e < centroids.size(); ++e) {
      if ((centroids[e] - p).squaredNorm() < (centroids[nearest] - p).squaredNorm()) nearest = e;
    }
    values.push_back(fit.element_youngs_modulus_pa[static_cast<Eigen::Index>(nearest)]);
  }
  return values;
}

std::vector<int> undetermined_points(const TrajectoryEstimate& fit, double relative_sd) {
  std::vector<int> out;
  for (std::size_t i = 0; i < fit.control_youngs_modulus_pa.size(); ++i) {
    const double sd = fit.control_youngs_modulus_sd_pa[i];
    if (!std::isfinite(sd) || sd > relative_sd * fit.control_youngs_modulus_pa[i]) out.push_back(static_cast<int>(i));
  }
  return out;
}

}  // namespace

MaterialMapSelection select_material_map(const FemRecordingProblem& problem,
                                         const TrajectoryEstimateOptions& fit_options,
                                         const MaterialMapSelectionOptions& options) {
  check_options(options);
  MaterialMapSelection out;
  std::vector<TrajectoryEstimate> fits;
  int worse_in_a_row = 0;
  for (int count : options.counts) {
    if (count > problem.mesh.tet_count()) break;
    TrajectoryEstimateOptions o = fit_options;
    o.control_points_m = place_control_points(problem.mesh, count);
    if (!fits.empty() && count > 1) {
      // Continued from the best map so far: a finer map starts where the coarser one ended, so
      // it cannot end worse by falling into another basin.
      const TrajectoryEstimate& best = fits[uz(out.chosen)];
      o.initial_control_youngs_modulus_pa = field_at(problem, best, o.control_points_m);
      o.initial_rayleigh_alpha = best.rayleigh_alpha;
      o.initial_rayleigh_beta = best.rayleigh_beta;
      o.warm_start = false;
    }
    const std::clock_t started = std::clock();
    TrajectoryEstimate fit = estimate_trajectory_parameters(problem, o);
    const ResidualSeries series = residual_series(problem, fit, o.simulation);
    MaterialMapCandidate c;
    c.control_points = count;
    c.parameters = static_cast<int>(fit.values.size());
    c.residual_count = static_cast<int>(series.count);
    c.residual_rms_m = series.count > 0 ? std::sqrt(series.sum_of_squares / static_cast<double>(series.count)) : 0.0;
    c.lag1_correlation = series.lag1;
    c.converged = fit.converged;
    c.cpu_time_s = static_cast<double>(std::clock() - started) / CLOCKS_PER_SEC;
    const int best_before = out.candidates.empty() ? -1 : out.chosen;
    out.candidates.push_back(c);
    fits.push_back(std::move(fit));
    out.chosen = rescore(out.candidates, out.design_effect);
    const bool improved = best_before < 0 || out.chosen == static_cast<int>(out.candidates.size()) - 1;
    worse_in_a_row = improved ? 0 : worse_in_a_row + 1;
    if (worse_in_a_row >= options.patience) break;
  }
  if (fits.empty()) {
    throw std::invalid_argument("material map selection: every count exceeds the mesh's tetrahedra");
  }
  out.estimate = std::move(fits[uz(out.chosen)]);
  out.undetermined = undetermined_points(out.estimate, options.undetermined_relative_sd);
  return out;
}

}  // namespace pliant::host::fem
