// fit_least_squares against problems with known answers: closed-form linear regression (value
// and standard error), convergence from starts 10x off on a log scale, robustness to outliers,
// bounds, and undetermined parameters.
#include "pliant/host/least_squares_fit.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

namespace {

using pliant::host::fit_least_squares;
using pliant::host::FitOptions;
using pliant::host::FitParameter;
using pliant::host::RobustLoss;

struct Line {
  std::vector<double> x, y;
};

Line noisy_line(double slope, double intercept, double sigma, int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, sigma);
  Line line;
  for (int i = 0; i < n; ++i) {
    const double x = static_cast<double>(i) / (n - 1);
    line.x.push_back(x);
    line.y.push_back(slope * x + intercept + noise(rng));
  }
  return line;
}

TEST(LeastSquaresFit, LinearRegressionMatchesClosedForm) {
  const Line line = noisy_line(2.0, 0.5, 0.1, 50, 3);
  const size_t n = line.x.size();
  std::vector<FitParameter> parameters = {{"slope", 1.0, -10.0, 10.0, false}, {"intercept", 0.0, -10.0, 10.0, false}};
  FitOptions options;
  options.loss = RobustLoss::none;
  const auto result = fit_least_squares(
      parameters, static_cast<int>(n),
      [&](const std::vector<double>& v, std::vector<double>& r) {
        for (size_t i = 0; i < n; ++i) r[i] = v[0] * line.x[i] + v[1] - line.y[i];
        return true;
      },
      options);

  // Closed form: normal equations and the textbook standard error of the slope.
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (size_t i = 0; i < n; ++i) {
    sx += line.x[i];
    sy += line.y[i];
    sxx += line.x[i] * line.x[i];
    sxy += line.x[i] * line.y[i];
  }
  const double count = static_cast<double>(n);
  const double slope = (count * sxy - sx * sy) / (count * sxx - sx * sx);
  const double intercept = (sy - slope * sx) / count;
  double ss = 0;
  for (size_t i = 0; i < n; ++i) {
    const double e = line.y[i] - slope * line.x[i] - intercept;
    ss += e * e;
  }
  const double s2 = ss / (count - 2.0);
  const double slope_se = std::sqrt(s2 * count / (count * sxx - sx * sx));

  EXPECT_NEAR(result.values[0], slope, 1e-7);
  EXPECT_NEAR(result.values[1], intercept, 1e-7);
  EXPECT_NEAR(result.standard_deviations[0], slope_se, 1e-6 * slope_se + 1e-9);
  EXPECT_TRUE(result.converged);
  EXPECT_EQ(result.names[0], "slope");
  EXPECT_FALSE(result.at_bound[0]);
}

// Exponential decay y = a exp(-t / tau): a log-scale time constant from 10x low and 10x high.
class DecayFromFarStart : public ::testing::TestWithParam<double> {};

TEST_P(DecayFromFarStart, ConvergesToTruth) {
  const double a = 3.0, tau = 0.7;
  std::vector<double> t, y;
  for (int i = 0; i < 80; ++i) {
    t.push_back(0.05 * static_cast<double>(i));
    y.push_back(a * std::exp(-t.back() / tau));
  }
  const size_t n = t.size();
  const double factor = GetParam();
  std::vector<FitParameter> parameters = {{"amplitude", a * factor, 1e-3, 1e3, true},
                                          {"time_constant", tau * factor, 1e-3, 1e3, true}};
  const auto result =
      fit_least_squares(parameters, static_cast<int>(n), [&](const std::vector<double>& v, std::vector<double>& r) {
        for (size_t i = 0; i < n; ++i) r[i] = v[0] * std::exp(-t[i] / v[1]) - y[i];
        return true;
      });
  EXPECT_NEAR(result.values[0], a, 1e-5 * a);
  EXPECT_NEAR(result.values[1], tau, 1e-5 * tau);
}

INSTANTIATE_TEST_SUITE_P(Starts, DecayFromFarStart, ::testing::Values(0.1, 10.0));

// Forward differences (n + 1 evaluations per Jacobian instead of 2n + 1) end at the same solution
// from the same start; a parameter starting next to its upper bound falls back to the backward side.
TEST(LeastSquaresFit, ForwardDifferencesReachTheSameSolutionWithFewerEvaluations) {
  const double a = 3.0, tau = 0.7;
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0.0, 1e-3);
  std::vector<double> t, y;
  for (int i = 0; i < 80; ++i) {
    t.push_back(0.05 * static_cast<double>(i));
    y.push_back(a * std::exp(-t.back() / tau) + noise(rng));
  }
  const size_t n = t.size();
  const auto residuals = [&](const std::vector<double>& v, std::vector<double>& r) {
    for (size_t i = 0; i < n; ++i) r[i] = v[0] * std::exp(-t[i] / v[1]) - y[i];
    return true;
  };
  const std::vector<FitParameter> parameters = {{"amplitude", 2.0, 1e-3, 1e3, true},
                                                {"time_constant", 1.4, 1e-3, 1e3, true}};
  FitOptions central;
  central.loss = RobustLoss::none;
  FitOptions forward = central;
  forward.central_differences = false;
  const auto c = fit_least_squares(parameters, static_cast<int>(n), residuals, central);
  const auto f = fit_least_squares(parameters, static_cast<int>(n), residuals, forward);
  // The same minimum (to the fit's tolerances), within a few standard deviations of the truth.
  EXPECT_NEAR(f.values[0], c.values[0], 1e-6 * a);
  EXPECT_NEAR(f.values[1], c.values[1], 1e-6 * tau);
  EXPECT_NEAR(f.values[1], tau, 4 * c.standard_deviations[1]);
  EXPECT_TRUE(f.converged);
  // Per Jacobian 3 evaluations instead of 5. (Near the solution the O(step) error of forward
  // differences slows Gauss-Newton's final convergence to very tight tolerances, so the totals
  // are compared per iteration.)
  EXPECT_LT(static_cast<double>(f.evaluations) / f.iterations, 0.8 * c.evaluations / c.iterations);
  EXPECT_NEAR(f.standard_deviations[1], c.standard_deviations[1], 1e-2 * c.standard_deviations[1] + 1e-12);

  // The time constant's upper bound just below the solution: the fit ends on the bound, where
  // there is no room for a plus step, and its Jacobian there (for the covariance too) takes the
  // minus side.
  std::vector<FitParameter> tight = parameters;
  tight[1] = {"time_constant", 0.9 * c.values[1], 1e-3, (1.0 - 1e-3) * c.values[1], true};
  const auto b = fit_least_squares(tight, static_cast<int>(n), residuals, forward);
  EXPECT_TRUE(b.at_bound[1]);
  EXPECT_FALSE(b.at_bound[0]);
  EXPECT_NEAR(b.values[1], tight[1].upper, 1e-6 * tau);
  EXPECT_NEAR(b.values[0], c.values[0], 4 * c.standard_deviations[0]);
  EXPECT_TRUE(std::isfinite(b.standard_deviations[0]));
}

TEST(LeastSquaresFit, HuberIgnoresOutliersThatBiasPlainLeastSquares) {
  Line line = noisy_line(2.0, 0.5, 0.02, 60, 11);
  for (size_t i = 40; i < 60; i += 4) line.y[i] += 3.0;  // five gross outliers at the high end
  const size_t n = line.x.size();
  std::vector<FitParameter> parameters = {{"slope", 1.0, -10.0, 10.0, false}, {"intercept", 0.0, -10.0, 10.0, false}};
  auto residuals = [&](const std::vector<double>& v, std::vector<double>& r) {
    for (size_t i = 0; i < n; ++i) r[i] = v[0] * line.x[i] + v[1] - line.y[i];
    return true;
  };
  FitOptions plain;
  plain.loss = RobustLoss::none;
  const auto biased = fit_least_squares(parameters, static_cast<int>(n), residuals, plain);
  const auto robust = fit_least_squares(parameters, static_cast<int>(n), residuals);  // Huber, automatic scale
  FitOptions heavy;
  heavy.loss = RobustLoss::cauchy;
  const auto cauchy = fit_least_squares(parameters, static_cast<int>(n), residuals, heavy);
  EXPECT_GT(std::abs(biased.values[0] - 2.0), 0.3);
  EXPECT_LT(std::abs(robust.values[0] - 2.0), 0.1);
  EXPECT_LT(std::abs(cauchy.values[0] - 2.0), 0.03);
}

TEST(LeastSquaresFit, StopsAtBoundAndSaysSo) {
  std::vector<FitParameter> parameters = {{"x", 1.0, 0.5, 2.0, true}};
  const auto result = fit_least_squares(parameters, 1, [](const std::vector<double>& v, std::vector<double>& r) {
    r[0] = v[0] - 5.0;  // optimum outside the bounds
    return true;
  });
  EXPECT_NEAR(result.values[0], 2.0, 1e-9);
  EXPECT_TRUE(result.at_bound[0]);
}

TEST(LeastSquaresFit, UndeterminedParameterHasNoStandardDeviation) {
  // Only the sum a + b is observed: neither is determined on its own.
  std::vector<FitParameter> parameters = {{"a", 1.0, -5.0, 5.0, false}, {"b", 1.0, -5.0, 5.0, false}};
  FitOptions options;
  options.loss = RobustLoss::none;
  const auto result = fit_least_squares(
      parameters, 3,
      [](const std::vector<double>& v, std::vector<double>& r) {
        r[0] = v[0] + v[1] - 1.0;
        r[1] = 0.5 * (v[0] + v[1]) - 0.5;
        r[2] = 2.0 * (v[0] + v[1]) - 2.1;
        return true;
      },
      options);
  EXPECT_TRUE(std::isnan(result.standard_deviations[0]));
  EXPECT_TRUE(std::isnan(result.standard_deviations[1]));
}

TEST(LeastSquaresFit, FailedEvaluationsAreRejectedSteps) {
  // The model refuses values above 3 (as a solver that inverts elements would); the optimum
  // at 2.5 is still found.
  std::vector<FitParameter> parameters = {{"x", 0.5, 0.1, 100.0, true}};
  FitOptions options;
  options.loss = RobustLoss::none;
  const auto result = fit_least_squares(
      parameters, 1,
      [](const std::vector<double>& v, std::vector<double>& r) {
        if (v[0] > 3.0) return false;
        r[0] = v[0] - 2.5;
        return true;
      },
      options);
  EXPECT_NEAR(result.values[0], 2.5, 1e-6);
}

TEST(LeastSquaresFit, RejectsInconsistentProblems) {
  auto zero = [](const std::vector<double>&, std::vector<double>& r) {
    r[0] = 0.0;
    return true;
  };
  EXPECT_THROW(fit_least_squares({}, 1, zero), std::invalid_argument);
  EXPECT_THROW(fit_least_squares({{"x", 1.0, 0.0, 2.0, true}}, 1, zero), std::invalid_argument);
  EXPECT_THROW(fit_least_squares({{"x", 3.0, 0.5, 2.0, true}}, 1, zero), std::invalid_argument);
  EXPECT_THROW(fit_least_squares({{"x", 1.0, 0.5, 2.0, true}}, 0, zero), std::invalid_argument);
  EXPECT_THROW(fit_least_squares({{"x", 1.0, 0.5, 2.0, true}}, 1,
                                 [](const std::vector<double>&, std::vector<double>&) { return false; }),
               std::invalid_argument);
  EXPECT_THROW(fit_least_squares({{"x", 1.0, 1.0, 1.0, false}}, 1, zero), std::invalid_argument);
  FitOptions no_damping;
  no_damping.initial_damping = 0.0;
  EXPECT_THROW(fit_least_squares({{"x", 1.0, 0.5, 2.0, true}}, 1, zero, no_damping), std::invalid_argument);
}

// Diagnosis starts fits from grid points on the edges of the unit search box: a start on a
// bound moves inwards to an interior minimum.
TEST(LeastSquaresFit, StartsOnABound) {
  FitOptions options;
  options.loss = RobustLoss::none;
  options.central_differences = false;
  for (const double start : {0.0, 1.0}) {
    const auto result = fit_least_squares(
        {{"u", start, 0.0, 1.0, false}}, 2,
        [](const std::vector<double>& v, std::vector<double>& r) {
          r[0] = v[0] - 0.3;
          r[1] = 2.0 * (v[0] - 0.3);
          return true;
        },
        options);
    EXPECT_NEAR(result.values[0], 0.3, 1e-6) << "start " << start;
    EXPECT_FALSE(result.at_bound[0]);
  }
}

// Every residual evaluation may be a long simulation: no point is run twice (Ceres asks for an
// accepted trial point again with its Jacobian; the fit evaluates its start and its solution),
// and `evaluations` counts the model runs made.
TEST(LeastSquaresFit, NeverRunsTheModelTwiceAtOnePoint) {
  std::vector<double> t, y;
  for (int i = 0; i < 40; ++i) {
    t.push_back(0.1 * i);
    y.push_back(2.0 * std::exp(-t.back() / 0.8) + 0.01 * std::sin(7.0 * i));
  }
  std::vector<std::vector<double>> asked;
  const auto residuals = [&](const std::vector<double>& v, std::vector<double>& r) {
    asked.push_back(v);
    for (size_t i = 0; i < t.size(); ++i) r[i] = v[0] * std::exp(-t[i] / v[1]) - y[i];
    return true;
  };
  for (const bool central : {true, false}) {
    asked.clear();
    FitOptions options;
    options.loss = RobustLoss::none;
    options.central_differences = central;
    const auto result =
        fit_least_squares({{"amplitude", 1.0, 1e-2, 1e2, true}, {"time_constant", 2.0, 1e-2, 1e2, true}},
                          static_cast<int>(t.size()), residuals, options);
    EXPECT_NEAR(result.values[1], 0.8, 0.02);
    EXPECT_EQ(result.evaluations, static_cast<int>(asked.size()));
    std::vector<std::vector<double>> unique = asked;
    std::sort(unique.begin(), unique.end());
    EXPECT_EQ(std::unique(unique.begin(), unique.end()), unique.end()) << "central " << central;
  }
}

// Without uncertainty the fit ends at the same point, takes no Jacobian for the covariance and
// reports none.
TEST(LeastSquaresFit, UncertaintyCanBeLeftToTheCaller) {
  const auto residuals = [](const std::vector<double>& v, std::vector<double>& r) {
    r[0] = v[0] - 0.4;
    r[1] = v[0] * v[0] - 0.16;
    r[2] = 0.1 * (v[0] - 0.4);
    return true;
  };
  FitOptions with;
  with.loss = RobustLoss::none;
  FitOptions without = with;
  without.uncertainty = false;
  const auto a = fit_least_squares({{"x", 0.9, 0.0, 1.0, false}}, 3, residuals, with);
  const auto b = fit_least_squares({{"x", 0.9, 0.0, 1.0, false}}, 3, residuals, without);
  EXPECT_EQ(a.values, b.values);
  EXPECT_TRUE(std::isfinite(a.standard_deviations[0]));
  EXPECT_TRUE(std::isnan(b.standard_deviations[0]));
  EXPECT_LE(b.evaluations, a.evaluations);
}

}  // namespace
