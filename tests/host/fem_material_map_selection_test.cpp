// select_material_map (material_map_selection.hpp): the number of control points comes from the
// data. A bar of two glued slabs is given a map (and each slab's modulus close to its truth);
// a uniform bar keeps one modulus, although larger maps fit its data better with the fit's own
// integrator (they absorb its error: with 4 substeps a 4-point map put the tip 9.5 % stiffer),
// because candidates are judged with 4 times the substeps; bad options are refused.
//
// The bars are simulated with 16 Newmark substeps and 3 Newton iterations per substep, the fits
// with 4 substeps and one linearised iteration, and the slab bar's piecewise-constant field is
// not what a Gaussian-kernel map can be: the data are not made by the fitted model.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <stdexcept>
#include <vector>

#include "pliant/host/fem/bar_vibration_scenario.hpp"
#include "pliant/host/fem/fem_recording.hpp"
#include "pliant/host/fem/material_map.hpp"
#include "pliant/host/fem/material_map_selection.hpp"

namespace {

using namespace pliant::host::fem;

BarVibrationOptions small_bar(std::vector<double> moduli) {
  BarVibrationOptions options;
  options.cells = {10, 3, 3};
  options.generator_substeps = 16;
  options.frame_count = 60;
  options.control_youngs_modulus_pa = std::move(moduli);
  options.slabs = true;
  options.noise_m = 2e-5;
  return options;
}

TrajectoryEstimateOptions fit_options() {
  TrajectoryEstimateOptions o;
  o.simulation.substeps = 4;
  o.position_noise_m = 2e-5;
  return o;
}

/// Volume-weighted geometric mean of the fitted modulus over the tetrahedra whose centroid lies
/// in [from_x, to_x).
double slab_modulus(const BarVibrationScenario& s, const Eigen::VectorXd& element_pa, double from_x, double to_x) {
  const std::vector<Eigen::Vector3d> centroids = element_centroids(*s.recording.mesh);
  double log_sum = 0, weight = 0;
  for (std::size_t e = 0; e < centroids.size(); ++e) {
    if (centroids[e].x() < from_x || centroids[e].x() >= to_x) continue;
    log_sum += std::log(element_pa[static_cast<Eigen::Index>(e)]);
    weight += 1;
  }
  return std::exp(log_sum / weight);
}

void print(const MaterialMapSelection& s) {
  for (const MaterialMapCandidate& c : s.candidates) {
    std::cout << "  " << c.control_points << " points: rms " << c.residual_rms_m << " m, lag-1 " << c.lag1_correlation
              << ", BIC " << c.bic << ", " << c.cpu_time_s << " s CPU\n";
  }
  std::cout << "  chosen " << s.candidates[static_cast<std::size_t>(s.chosen)].control_points
            << " points, design effect " << s.design_effect << ", undetermined " << s.undetermined.size() << "\n";
}

TEST(MaterialMapSelection, TwoSlabsGetAMapAndEachSlabItsModulus) {
  const BarVibrationScenario bar = make_bar_vibration_scenario(small_bar({2e5, 8e5}));
  const FemRecordingProblem problem = fem_problem_from_recording(bar.recording);
  MaterialMapSelectionOptions options;
  // 4 points overshoot past the step (the tip slab read 1.35e6 Pa); 8 represent it. The default
  // counts go on to 16 and 32, which this test leaves out for time.
  options.counts = {1, 2, 4, 8};
  const MaterialMapSelection s = select_material_map(problem, fit_options(), options);
  print(s);
  ASSERT_GE(s.candidates.size(), 2u);
  EXPECT_GE(s.candidates[static_cast<std::size_t>(s.chosen)].control_points, 2);
  const double length = 0.8;
  const Eigen::VectorXd& fitted = s.estimate.element_youngs_modulus_pa;
  // The slab's middle half: a smooth map cannot jump at the glued face.
  const double near_clamp = slab_modulus(bar, fitted, 0.1 * length, 0.4 * length);
  const double near_tip = slab_modulus(bar, fitted, 0.6 * length, 0.9 * length);
  std::cout << "  slabs: " << near_clamp << " Pa (truth 2e5), " << near_tip << " Pa (truth 8e5)\n";
  EXPECT_NEAR(near_clamp, 2e5, 0.15 * 2e5);
  EXPECT_NEAR(near_tip, 8e5, 0.15 * 8e5);
}

TEST(MaterialMapSelection, UniformBarKeepsOneModulus) {
  const BarVibrationScenario bar = make_bar_vibration_scenario(small_bar({5e5}));
  const FemRecordingProblem problem = fem_problem_from_recording(bar.recording);
  MaterialMapSelectionOptions options;
  options.counts = {1, 2, 4};
  const MaterialMapSelection s = select_material_map(problem, fit_options(), options);
  print(s);
  for (std::size_t i = 0; i < s.estimate.control_youngs_modulus_pa.size(); ++i) {
    std::cout << "  point " << i << ": " << s.estimate.control_youngs_modulus_pa[i] << " +- "
              << s.estimate.control_youngs_modulus_sd_pa[i] << " Pa\n";
  }
  EXPECT_EQ(s.candidates[static_cast<std::size_t>(s.chosen)].control_points, 1);
  EXPECT_NEAR(s.estimate.control_youngs_modulus_pa.at(0), 5e5, 0.02 * 5e5);
  EXPECT_TRUE(s.undetermined.empty());
}

TEST(MaterialMapSelection, BadOptionsAreRefused) {
  const BarVibrationScenario bar = make_bar_vibration_scenario(small_bar({5e5}));
  const FemRecordingProblem problem = fem_problem_from_recording(bar.recording);
  MaterialMapSelectionOptions options;
  options.counts = {};
  EXPECT_THROW(select_material_map(problem, fit_options(), options), std::invalid_argument);
  options.counts = {2, 1};
  EXPECT_THROW(select_material_map(problem, fit_options(), options), std::invalid_argument);
  options.counts = {0, 1};
  EXPECT_THROW(select_material_map(problem, fit_options(), options), std::invalid_argument);
  options.counts = {100000};  // more control points than tetrahedra
  EXPECT_THROW(select_material_map(problem, fit_options(), options), std::invalid_argument);
  options.counts = {1, 2};
  options.patience = 0;
  EXPECT_THROW(select_material_map(problem, fit_options(), options), std::invalid_argument);
  options.patience = 1;
  options.undetermined_relative_sd = 0;
  EXPECT_THROW(select_material_map(problem, fit_options(), options), std::invalid_argument);
}

}  // namespace
