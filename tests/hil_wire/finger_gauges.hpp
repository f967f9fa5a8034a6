// The emulated ATI sensor's strain gauges for a wrench: the inverse of the calibration that the
// driver reads from the emulator and applies (wrench = M (sg - bias) / counts), plus gauge noise,
// so that the driver's calibrated wrench is the plant's wrench to within the noise and one count.
//
// The calibration (wire_calibration()) is a full 6 x 6 matrix with cross-coupling, as a real
// sensor's is, in N and N m: 400 counts per N (2.5 mN per count; +-32767 counts span about
// +-80 N) and 20000 counts per N m. Gauge noise: Gaussian, noise_counts sd on every gauge. A
// live ATI sensor always has a few counts of noise, and the guard relies on it: a wrench repeated
// bit for bit means a frozen sensor (wrench_frozen_samples). With 3 counts the chance that all
// six gauges repeat is about 1e-7 per sample.
// Allocation-free after construction; not thread-safe.
#pragma once

#include <cstdint>
#include <random>

#include <Eigen/Core>

#include "pliant/drivers/socketcan/ati_netcanoem_protocol.hpp"

namespace pliant::hil {

/// The wire rig's sensor calibration (what the emulator reports, what the driver applies).
drivers::socketcan::ati::Calibration wire_calibration();

class FingerGauges {
 public:
  FingerGauges(const drivers::socketcan::ati::Calibration& calibration, double noise_counts, std::uint64_t seed);

  /// SG0..SG5 for `wrench` (Fx Fy Fz N, Tx Ty Tz N m), noisy, rounded and clamped to int16.
  void gauges(const double wrench[6], std::int16_t out[6]) noexcept;

 private:
  Eigen::Matrix<double, 6, 6> inverse_;  ///< wrench in counts -> gauges
  double counts_[6] = {0, 0, 0, 0, 0, 0};
  double noise_counts_ = 0;
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_{0.0, 1.0};
};

}  // namespace pliant::hil
