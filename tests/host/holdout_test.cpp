// interleaved_holdout and residual_rms: block layout, Euclidean per-pair rms, masks, NaN and
// degenerate input.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "pliant/host/diagnose/holdout.hpp"

namespace pliant::host::test {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
using Mask = std::vector<unsigned char>;

TEST(InterleavedHoldout, AlternatesBlocksStartingWithFitting) {
  EXPECT_EQ(interleaved_holdout(10, 3), (Mask{0, 0, 0, 1, 1, 1, 0, 0, 0, 1}));
  EXPECT_EQ(interleaved_holdout(4, 1), (Mask{0, 1, 0, 1}));
  EXPECT_EQ(interleaved_holdout(3, 5), (Mask{0, 0, 0}));
}

TEST(InterleavedHoldout, Degenerate) {
  EXPECT_TRUE(interleaved_holdout(0, 3).empty());
  EXPECT_TRUE(interleaved_holdout(-4, 3).empty());
  EXPECT_THROW(interleaved_holdout(10, 0), std::invalid_argument);
}

TEST(ResidualRms, EuclideanErrorPerPairAveragedOverPairs) {
  // 2 frames, 2 particles, 2D. Frame 0: errors (3, 4) and (0, 0); frame 1: (0, 0) and (6, 8).
  const std::vector<double> sim(8, 1.0);
  const std::vector<double> obs = {4, 5, 1, 1, 1, 1, 7, 9};
  const Mask frames = {0, 0};
  // Pairs: 25, 0, 0, 100 -> mean 31.25.
  EXPECT_DOUBLE_EQ(residual_rms(obs, sim, 2, 2, frames, 0), std::sqrt(31.25));
  EXPECT_DOUBLE_EQ(residual_rms(obs, sim, 2, 2, Mask{0, 1}, 0), std::sqrt(12.5));
  EXPECT_DOUBLE_EQ(residual_rms(obs, sim, 2, 2, Mask{0, 1}, 1), std::sqrt(50.0));
  const Mask second = {0, 1};
  EXPECT_DOUBLE_EQ(residual_rms(obs, sim, 2, 2, frames, 0, &second), std::sqrt(50.0));
}

TEST(ResidualRms, SkipsNonFinitePairs) {
  const std::vector<double> sim = {0, 0, 0, kNaN, 0, 0};
  const std::vector<double> obs = {2, 0, 5, 5, kNaN, 1};
  // 3 particles in 2D, one frame: only particle 0 has a finite pair.
  EXPECT_DOUBLE_EQ(residual_rms(obs, sim, 3, 2, Mask{0}, 0), 2.0);
}

TEST(ResidualRms, NoPairsGivesZero) {
  const std::vector<double> sim = {0, 0};
  const std::vector<double> obs = {kNaN, 1};
  EXPECT_EQ(residual_rms(obs, sim, 1, 2, Mask{0}, 0), 0.0);
  EXPECT_EQ(residual_rms({1, 1}, sim, 1, 2, Mask{0}, 1), 0.0);  // no frame wanted
  const Mask none = {0};
  EXPECT_EQ(residual_rms({1, 1}, sim, 1, 2, Mask{0}, 0, &none), 0.0);
  EXPECT_EQ(residual_rms({}, {}, 3, 2, Mask{}, 0), 0.0);  // zero frames
  EXPECT_EQ(residual_rms({}, {}, 0, 2, Mask{}, 0), 0.0);  // zero particles
}

TEST(ResidualRms, RejectsInconsistentSizes) {
  const std::vector<double> four(4, 0.0);
  EXPECT_THROW(residual_rms(four, std::vector<double>(3, 0.0), 1, 2, Mask{0, 0}, 0), std::invalid_argument);
  EXPECT_THROW(residual_rms(four, four, 3, 2, Mask{0}, 0), std::invalid_argument);
  EXPECT_THROW(residual_rms(four, four, 1, 2, Mask{0}, 0), std::invalid_argument);
  const Mask wrong = {1, 1};
  EXPECT_THROW(residual_rms(four, four, 1, 2, Mask{0, 0}, 0, &wrong), std::invalid_argument);
  EXPECT_THROW(residual_rms(four, four, 1, 0, Mask{0, 0}, 0), std::invalid_argument);
}

// Misfit 5 over noise 1: an excess of 24 in mean square. A fit at 3 leaves 8 of it (two
// thirds explained), one at the noise leaves none, one below the noise cannot do better than
// all, one worse than the baseline is negative; a baseline within the noise has nothing to
// explain.
TEST(ExplainedShare, IsTheShareOfTheMeanSquareBeyondTheNoise) {
  EXPECT_DOUBLE_EQ(explained_share(5.0, 3.0, 1.0), 1.0 - 8.0 / 24.0);
  EXPECT_DOUBLE_EQ(explained_share(5.0, 1.0, 1.0), 1.0);
  EXPECT_DOUBLE_EQ(explained_share(5.0, 0.5, 1.0), 1.0);
  EXPECT_DOUBLE_EQ(explained_share(5.0, 5.0, 1.0), 0.0);
  EXPECT_LT(explained_share(5.0, 6.0, 1.0), 0.0);
  EXPECT_DOUBLE_EQ(explained_share(0.8, 0.5, 1.0), 0.0);
  EXPECT_DOUBLE_EQ(explained_share(2.0, 1.0, 0.0), 0.75);  // no noise: the plain share of the mean square
}

}  // namespace
}  // namespace pliant::host::test
