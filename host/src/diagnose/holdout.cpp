#include "pliant/host/diagnose/holdout.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <stdexcept>

namespace pliant::host {

std::vector<unsigned char> interleaved_holdout(int frame_count, int block_frames) {
  if (block_frames < 1) throw std::invalid_argument("interleaved_holdout: block_frames must be >= 1");
  std::vector<unsigned char> mask(static_cast<std::size_t>(std::max(frame_count, 0)), 0);
  for (int k = 0; k < frame_count; ++k) {
    mask[static_cast<std::size_t>(k)] = static_cast<unsigned char>((k / block_frames) % 2);
  }
  return mask;
}

double residual_rms(const std::vector<double>& observed, const std::vector<double>& simulated, int particle_count,
                    int dimension, const std::vector<unsigned char>& frame_mask, unsigned char wanted,
                    const std::vector<unsigned char>* particle_mask) {
  if (dimension < 1 || particle_count < 0) throw std::invalid_argument("residual_rms: bad dimension or particle count");
  if (observed.size() != simulated.size())
    throw std::invalid_argument("residual_rms: observed and simulated differ in size");
  if (particle_count == 0) {
    if (!observed.empty()) throw std::invalid_argument("residual_rms: positions given for zero particles");
    return 0.0;
  }
  const auto n = static_cast<std::size_t>(particle_count);
  const auto dim = static_cast<std::size_t>(dimension);
  if (observed.size() % (n * dim) != 0) {
    throw std::invalid_argument("residual_rms: size is not a multiple of particle_count * dimension");
  }
  const std::size_t frames = observed.size() / (n * dim);
  if (frame_mask.size() != frames) throw std::invalid_argument("residual_rms: frame_mask needs one entry per frame");
  if (particle_mask != nullptr && particle_mask->size() != n) {
    throw std::invalid_argument("residual_rms: particle_mask needs one entry per particle");
  }
  double sum = 0;
  std::size_t pairs = 0;
  for (std::size_t k = 0; k < frames; ++k) {
    if (frame_mask[k] != wanted) continue;
    for (std::size_t i = 0; i < n; ++i) {
      if (particle_mask != nullptr && (*particle_mask)[i] == 0) continue;
      double squared = 0;
      bool finite = true;
      for (std::size_t d = 0; d < dim && finite; ++d) {
        const std::size_t at = (k * n + i) * dim + d;
        const double error = observed[at] - simulated[at];
        finite = std::isfinite(error);
        squared += error * error;
      }
      if (!finite || !std::isfinite(squared)) continue;
      sum += squared;
      ++pairs;
    }
  }
  if (pairs == 0) return 0.0;
  return std::sqrt(sum / static_cast<double>(pairs));
}

double explained_share(double baseline_rms, double fit_rms, double noise_rms) {
  const double excess = baseline_rms * baseline_rms - noise_rms * noise_rms;
  if (!(excess > 0)) return 0.0;
  return 1.0 - std::max(0.0, fit_rms * fit_rms - noise_rms * noise_rms) / excess;
}

}  // namespace pliant::host
