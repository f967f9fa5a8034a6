#include "finger_gauges.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>

namespace pliant::hil {

namespace ati = drivers::socketcan::ati;

ati::Calibration wire_calibration() {
  ati::Calibration c;
  // Diagonal 1 with cross-talk of up to 8 % between axes (a fixed pattern, well conditioned).
  for (int r = 0; r < 6; ++r) {
    for (int k = 0; k < 6; ++k) {
      c.matrix[6 * r + k] = r == k ? 1.0f : 0.04f * static_cast<float>((7 * r + 3 * k) % 5 - 2);
    }
  }
  c.counts_per_force = 400;
  c.counts_per_torque = 20000;
  c.force_unit = 2;   // N
  c.torque_unit = 3;  // N m
  return c;
}

FingerGauges::FingerGauges(const ati::Calibration& calibration, double noise_counts, std::uint64_t seed)
    : noise_counts_(noise_counts), rng_(seed) {
  Eigen::Matrix<double, 6, 6> m;
  for (int r = 0; r < 6; ++r) {
    for (int k = 0; k < 6; ++k) m(r, k) = static_cast<double>(calibration.matrix[6 * r + k]);
  }
  inverse_ = m.inverse();
  for (int k = 0; k < 3; ++k) {
    counts_[k] = static_cast<double>(calibration.counts_per_force) / ati::force_unit_to_newton(calibration.force_unit);
    counts_[k + 3] =
        static_cast<double>(calibration.counts_per_torque) / ati::torque_unit_to_newton_metre(calibration.torque_unit);
  }
}

void FingerGauges::gauges(const double wrench[6], std::int16_t out[6]) noexcept {
  Eigen::Matrix<double, 6, 1> w;
  for (int k = 0; k < 6; ++k) w(k) = wrench[k] * counts_[k];
  const Eigen::Matrix<double, 6, 1> g = inverse_ * w;
  for (int k = 0; k < 6; ++k) {
    const double v = std::round(g(k) + noise_counts_ * normal_(rng_));
    out[k] = static_cast<std::int16_t>(std::clamp(v, -32768.0, 32767.0));
  }
}

}  // namespace pliant::hil
