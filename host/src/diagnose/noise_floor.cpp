#include "pliant/host/diagnose/noise_floor.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <vector>

namespace pliant::host {
namespace {

constexpr int kHalfWindow = 3;  // 7-frame window
constexpr int kMaxDegree = 3;   // cubic: exact for constant velocity and acceleration
constexpr double kMadToStd = 1.4826;

using Matrix4 = Eigen::Matrix<double, kMaxDegree + 1, kMaxDegree + 1>;
using Vector4 = Eigen::Matrix<double, kMaxDegree + 1, 1>;

// Residual of sample `center` against the local polynomial through (t, y), divided by its
// exact noise gain sqrt(1 - H_cc). Returns false when the window cannot give one.
bool normalised_residual(const std::vector<double>& t, const std::vector<double>& y, std::size_t center, double& out) {
  const int samples = static_cast<int>(t.size());
  const int degree = std::min(kMaxDegree, samples - 2);
  if (degree < 1) return false;
  const int terms = degree + 1;
  // Times relative to the centre sample and scaled to [-1, 1] for conditioning.
  double scale = 0;
  for (double ti : t) scale = std::max(scale, std::abs(ti - t[center]));
  if (!(scale > 0)) return false;
  Matrix4 normal = Matrix4::Zero();
  Vector4 rhs = Vector4::Zero();
  for (std::size_t s = 0; s < t.size(); ++s) {
    Vector4 row = Vector4::Zero();
    const double tau = (t[s] - t[center]) / scale;
    double power = 1;
    for (int j = 0; j < terms; ++j) {
      row(j) = power;
      power *= tau;
    }
    normal += row * row.transpose();
    rhs += row * (y[s] - y[center]);
  }
  for (int j = terms; j <= kMaxDegree; ++j) normal(j, j) = 1;  // unused terms: identity block
  Eigen::LDLT<Matrix4> solver(normal);
  if (solver.info() != Eigen::Success) return false;
  const Vector4 beta = solver.solve(rhs);
  Vector4 unit = Vector4::Zero();
  unit(0) = 1;  // the design row of the centre sample (tau = 0)
  const double leverage = unit.dot(solver.solve(unit));
  const double gain2 = 1 - leverage;
  if (!(gain2 > 1e-6) || !std::isfinite(beta(0))) return false;
  out = -beta(0) / std::sqrt(gain2);  // y_c - fit(t_c), with y_c subtracted beforehand
  return std::isfinite(out);
}

}  // namespace

double estimate_noise_std(const Recording& recording) {
  const int frames = recording.frame_count();
  const int n = recording.particle_count;
  const int dim = recording.dimension;
  if (dim < 1 || n < 0) throw std::invalid_argument("estimate_noise_std: bad dimension or particle count");
  if (recording.positions.size() !=
      static_cast<std::size_t>(frames) * static_cast<std::size_t>(n) * static_cast<std::size_t>(dim)) {
    throw std::invalid_argument("estimate_noise_std: positions size does not match frames * particles * dimension");
  }
  std::vector<double> magnitudes;
  std::vector<double> t;
  std::vector<double> y;
  const int width = 2 * kHalfWindow + 1;
  for (int i = 0; i < n; ++i) {
    for (int d = 0; d < dim; ++d) {
      for (int k = 0; k < frames; ++k) {
        if (!std::isfinite(recording.position(k, i, d))) continue;
        int first = std::max(0, k - kHalfWindow);
        const int last = std::min(frames - 1, first + width - 1);
        first = std::max(0, last - width + 1);
        t.clear();
        y.clear();
        std::size_t center = 0;
        for (int j = first; j <= last; ++j) {
          const double value = recording.position(j, i, d);
          if (!std::isfinite(value)) continue;
          if (j == k) center = t.size();
          t.push_back(recording.frame_times_s[static_cast<std::size_t>(j)]);
          y.push_back(value);
        }
        double residual = 0;
        if (normalised_residual(t, y, center, residual)) magnitudes.push_back(std::abs(residual));
      }
    }
  }
  if (magnitudes.empty()) return 0.0;
  auto middle = magnitudes.begin() + static_cast<std::ptrdiff_t>(magnitudes.size() / 2);
  std::nth_element(magnitudes.begin(), middle, magnitudes.end());
  const double estimate = kMadToStd * *middle;
  return std::isfinite(estimate) ? estimate : 0.0;
}

}  // namespace pliant::host
