// Analysis of a sampled 1-D error curve E(beta): minimum, its uniqueness and its uncertainty.
// Shared by the offline and the online deformability estimators. Real-time safe, O(n).
#pragma once

namespace pliant {

/// Vertex of the parabola through three equally spaced samples (x0 - h, x0, x0 + h).
struct ParabolaFit {
  double x = 0;          ///< abscissa of the vertex (x0 when the parabola is not convex)
  double value = 0;      ///< fitted value at x
  double curvature = 0;  ///< second derivative (<= 0: not a minimum)
};
ParabolaFit fit_parabola(double x0, double h, double left, double centre, double right) noexcept;

/// Second derivative of the parabola through three samples at x0 < x1 < x2 (any spacing):
/// twice the second divided difference.
double second_difference(double x0, double f0, double x1, double f1, double x2, double f2) noexcept;

/// True when the sampled curve has a single basin: every other local minimum is separated from
/// the global one by a barrier lower than `prominence` x (max - min). A flat curve (range below
/// 1e-12 relative) has no unique minimum. `values` has `count` >= 1 entries on ascending x.
bool single_basin(const double* values, int count, double prominence = 0.02) noexcept;

/// One standard deviation of a least-squares parameter from the curvature of the sum of
/// squared residuals S at its minimum: var = 2 sigma^2 / S'', sigma^2 = S_min / (n - 1), with
/// n scalar residuals assumed independent. Returns +infinity when S'' <= 0 or n < 2.
double least_squares_std(double sum_squares_min, double curvature, long residual_count) noexcept;

}  // namespace pliant
