#include "pliant/core/curve_analysis.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace pliant {

ParabolaFit fit_parabola(double x0, double h, double left, double centre, double right) noexcept {
  ParabolaFit fit;
  fit.x = x0;
  fit.value = centre;
  if (!(h > 0)) return fit;
  const double second = left - 2.0 * centre + right;
  fit.curvature = second / (h * h);
  if (!(second > 0)) return fit;
  const double offset = 0.5 * h * (left - right) / second;
  fit.x = x0 + std::clamp(offset, -h, h);
  const double u = fit.x - x0;
  fit.value = centre + u * (right - left) / (2.0 * h) + 0.5 * fit.curvature * u * u;
  return fit;
}

double second_difference(double x0, double f0, double x1, double f1, double x2, double f2) noexcept {
  return 2.0 * ((f2 - f1) / (x2 - x1) - (f1 - f0) / (x1 - x0)) / (x2 - x0);
}

bool single_basin(const double* values, int count, double prominence) noexcept {
  if (count < 1) return false;
  int best = 0;
  double lowest = values[0];
  double highest = values[0];
  for (int i = 1; i < count; ++i) {
    if (values[i] < lowest) {
      lowest = values[i];
      best = i;
    }
    highest = std::max(highest, values[i]);
  }
  const double range = highest - lowest;
  if (!(range > 1e-12 * (1.0 + std::abs(lowest)))) return false;
  for (int j = 0; j < count; ++j) {
    if (j == best) continue;
    const bool left_ok = j == 0 || values[j] < values[j - 1];
    const bool right_ok = j == count - 1 || values[j] <= values[j + 1];
    if (!left_ok || !right_ok) continue;
    double barrier = values[j];
    const int from = std::min(j, best);
    const int to = std::max(j, best);
    for (int k = from; k <= to; ++k) barrier = std::max(barrier, values[k]);
    if (barrier - values[j] > prominence * range) return false;
  }
  return true;
}

double least_squares_std(double sum_squares_min, double curvature, long residual_count) noexcept {
  if (!(curvature > 0) || residual_count < 2) return std::numeric_limits<double>::infinity();
  const double sigma_squared = sum_squares_min / static_cast<double>(residual_count - 1);
  return std::sqrt(2.0 * sigma_squared / curvature);
}

}  // namespace pliant
