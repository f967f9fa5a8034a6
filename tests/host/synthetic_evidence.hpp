// Fits as diagnosis's selection sees them (selection.hpp), made up with known scatter, for the
// selection and engine tests: the right decision follows from the numbers alone.
#pragma once

#include <algorithm>
#include <random>
#include <vector>

#include "pliant/host/diagnose/selection.hpp"

namespace pliant::host::testing {

inline constexpr int kSyntheticResiduals = 2000;
inline constexpr int kSyntheticBlocks = 20;
inline constexpr long kSyntheticPerBlock = 50;

/// A fit whose residuals scatter with std `sigma` (fitting and held-out alike); `offset` is
/// added to the held-out residuals of the blocks listed in `biased_blocks`.
inline FitEvidence fit_with(double sigma, int fitted, unsigned seed, const std::vector<int>& biased_blocks = {},
                            double offset = 0.0) {
  std::mt19937 random(seed);
  std::normal_distribution<double> noise(0.0, sigma);
  FitEvidence f;
  f.fit_residuals.resize(kSyntheticResiduals);
  for (int i = 0; i < kSyntheticResiduals; ++i) f.fit_residuals(i) = noise(random);
  f.fitted = fitted;
  for (int b = 0; b < kSyntheticBlocks; ++b) {
    HeldBlock block;
    const bool biased = std::find(biased_blocks.begin(), biased_blocks.end(), b) != biased_blocks.end();
    for (long i = 0; i < kSyntheticPerBlock; ++i) {
      const double r = noise(random) + (biased ? offset : 0.0);
      block.rss += r * r;
    }
    block.count = kSyntheticPerBlock;
    f.held_blocks.push_back(block);
  }
  return f;
}

/// An effect's fit: scatter `sigma`, one parameter at `value` +- `std` with null 0.
inline FitEvidence effect_with(double sigma, double value, double std, unsigned seed) {
  FitEvidence f = fit_with(sigma, 2, seed);
  f.values = {value};
  f.std = {std};
  f.nulls = {0.0};
  return f;
}

}  // namespace pliant::host::testing
