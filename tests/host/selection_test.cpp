// The selection stage of diagnosis (selection.hpp) on evidence built by hand, where the right
// decision is known without any model: what a fit's residuals and held-out blocks are decides.
#include "pliant/host/diagnose/selection.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "synthetic_evidence.hpp"

namespace {

using pliant::host::FitEvidence;
using pliant::host::held_block_of_frame;
using pliant::host::not_named_sentence;
using pliant::host::select_effect;
using pliant::host::Selection;
using pliant::host::unexplained_misfit_is_unknown;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr int kResiduals = pliant::host::testing::kSyntheticResiduals;
using pliant::host::testing::effect_with;
using pliant::host::testing::fit_with;

const std::vector<std::string> kNames{"first", "second", "third"};

TEST(Selection, NamesTheEffectThatBringsTheFitToTheNoise) {
  const FitEvidence baseline = fit_with(4.0, 1, 1);
  const std::vector<FitEvidence> effects{effect_with(1.05, 0.5, 0.01, 2), effect_with(3.8, 0.5, 0.01, 3)};
  const Selection s = select_effect(baseline, effects, 1.0, {});
  ASSERT_TRUE(s.named);
  EXPECT_EQ(s.ranked.front().effect, 0U);
  EXPECT_NEAR(s.misfit, 4.0, 0.3);
  EXPECT_GE(s.stability, 0.99);
  EXPECT_FALSE(s.has_runner_up);
  EXPECT_NEAR(s.design_effect, 1.0, 0.05);  // independent residuals
}

TEST(Selection, NothingIsNamedWhenTheBaselineIsWithinTheNoise) {
  const FitEvidence baseline = fit_with(1.2, 1, 1);
  const std::vector<FitEvidence> effects{effect_with(1.0, 0.5, 0.01, 2)};
  const Selection s = select_effect(baseline, effects, 1.0, {});
  EXPECT_FALSE(s.named);
  EXPECT_FALSE(unexplained_misfit_is_unknown(s, true));
}

TEST(Selection, AnEffectThatLeavesMostOfTheMisfitIsOnlyANearMiss) {
  // The effect halves the misfit beyond the noise: clear, but it explains too little.
  const FitEvidence baseline = fit_with(10.0, 1, 1);
  const std::vector<FitEvidence> effects{effect_with(6.0, 0.5, 0.01, 2)};
  const Selection s = select_effect(baseline, effects, 1.0, {});
  EXPECT_FALSE(s.named);
  ASSERT_TRUE(s.has_near_miss);
  EXPECT_FALSE(s.near_miss_unstable);
  const std::string why = not_named_sentence(s, kNames, "rms", "");
  EXPECT_NE(why.find("first improves the held-out rms"), std::string::npos) << why;
  EXPECT_NE(why.find("explains only"), std::string::npos) << why;
  EXPECT_TRUE(unexplained_misfit_is_unknown(s, true));
  EXPECT_FALSE(unexplained_misfit_is_unknown(s, false));  // not located: consistent
}

TEST(Selection, AParameterAtItsNullIsNotNamed) {
  const FitEvidence baseline = fit_with(4.0, 1, 1);
  const std::vector<FitEvidence> effects{effect_with(1.0, 0.02, 0.01, 2)};  // 2 std from its null
  EXPECT_FALSE(select_effect(baseline, effects, 1.0, {}).named);
  std::vector<FitEvidence> untested = effects;
  untested[0].nulls = {kNaN};  // nothing to test against: no significance at all
  EXPECT_FALSE(select_effect(baseline, untested, 1.0, {}).named);
}

TEST(Selection, TwoEffectsThatFitAlikeNameARunnerUp) {
  const FitEvidence baseline = fit_with(4.0, 1, 1);
  const std::vector<FitEvidence> effects{effect_with(1.0, 0.5, 0.01, 2), effect_with(1.0, 0.5, 0.01, 3)};
  const Selection s = select_effect(baseline, effects, 1.0, {});
  ASSERT_TRUE(s.named);
  ASSERT_TRUE(s.has_runner_up);
  EXPECT_NE(s.runner_up, s.ranked.front().effect);
}

TEST(Selection, AnImprovementOnOneHeldOutBlockDoesNotHoldUnderTheBootstrap) {
  // The baseline misses one of twenty held-out blocks badly and fits the rest to the noise; the
  // effect repairs that block. Over all blocks it passes every test, but about a third of the
  // resamples do not draw that block, and in those it improves nothing.
  FitEvidence baseline = fit_with(1.0, 1, 1, {9}, 8.0);
  baseline.fit_residuals *= 3.0;  // the fitting frames miss too (the BIC test passes)
  const std::vector<FitEvidence> effects{effect_with(1.0, 0.5, 0.01, 2)};
  const Selection s = select_effect(baseline, effects, 1.0, {});
  ASSERT_FALSE(s.ranked.empty());
  ASSERT_TRUE(s.ranked.front().passes);
  EXPECT_GT(s.stability, 0.5);
  EXPECT_LT(s.stability, 0.8);
  EXPECT_FALSE(s.named);
  EXPECT_TRUE(s.near_miss_unstable);
  EXPECT_NE(not_named_sentence(s, kNames, "rms", "").find("resamples"), std::string::npos);
}

TEST(Selection, ResidualsThatMoveTogetherCountAsFewerSamples) {
  // Residuals constant within clusters of 50: deff near 50, so a BIC gain that independent
  // residuals would show 50 times over is not enough.
  FitEvidence baseline = fit_with(1.0, 1, 1);
  FitEvidence effect = effect_with(1.0, 0.5, 0.01, 2);
  std::vector<int> clusters(kResiduals);
  std::mt19937 random(7);
  std::normal_distribution<double> noise(0.0, 1.0);
  for (int c = 0; c < kResiduals / 50; ++c) {
    const double shared_base = 1.5 * noise(random);
    const double shared_effect = 1.4 * noise(random);
    for (int i = 0; i < 50; ++i) {
      clusters[static_cast<std::size_t>(c * 50 + i)] = c;
      baseline.fit_residuals(c * 50 + i) = shared_base;
      effect.fit_residuals(c * 50 + i) = shared_effect;
    }
  }
  const Selection independent = select_effect(baseline, {effect}, 1.0, {});
  const Selection clustered = select_effect(baseline, {effect}, 1.0, clusters);
  EXPECT_NEAR(independent.design_effect, 1.0, 1e-12);
  EXPECT_GT(clustered.design_effect, 40.0);
  EXPECT_LT(std::abs(clustered.baseline_bic), std::abs(independent.baseline_bic) / 20.0);
}

TEST(Selection, HeldOutBlocksFollowTheFrames) {
  int blocks = 0;
  const std::vector<int> of = held_block_of_frame({0, 0, 1, 1, 0, 1, 0, 0, 1}, blocks);
  EXPECT_EQ(blocks, 3);
  EXPECT_EQ(of, (std::vector<int>{-1, -1, 0, 0, -1, 1, -1, -1, 2}));
}

TEST(Selection, RefusesEvidenceScoredOnOtherFrames) {
  const FitEvidence baseline = fit_with(4.0, 1, 1);
  FitEvidence fewer_blocks = effect_with(1.0, 0.5, 0.01, 2);
  fewer_blocks.held_blocks.pop_back();
  EXPECT_THROW(select_effect(baseline, {fewer_blocks}, 1.0, {}), std::invalid_argument);
  FitEvidence no_std = effect_with(1.0, 0.5, 0.01, 2);
  no_std.std.clear();
  EXPECT_THROW(select_effect(baseline, {no_std}, 1.0, {}), std::invalid_argument);
  EXPECT_THROW(select_effect(baseline, {}, 1.0, std::vector<int>(3, 0)), std::invalid_argument);
  FitEvidence failed;  // a fit that could not be simulated is left out, not refused
  failed.ok = false;
  EXPECT_TRUE(select_effect(baseline, {failed}, 1.0, {}).ranked.empty());
}

}  // namespace
