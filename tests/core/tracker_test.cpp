// MSM-regularised tracker: checked against the simulated truth it never sees (the observations
// are the truth plus noise, outliers and occlusion).
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "press_observations.hpp"
#include "pliant/core/tracker.hpp"

namespace pliant {
namespace {

template <int D, typename S>
struct Space {
  static constexpr int kDim = D;
  using Scalar = S;
};
using Spaces = ::testing::Types<Space<2, float>, Space<2, double>, Space<3, float>, Space<3, double>>;

constexpr double kSpacing = 100.0;
constexpr double kRate = 30.0;

// A tracker on the press experiment's model (rest = the first, noise-free frame).
template <typename SpaceT>
struct TrackerRig {
  static constexpr int Dim = SpaceT::kDim;
  using Scalar = typename SpaceT::Scalar;
  using Vec = Eigen::Matrix<Scalar, Dim, 1>;

  test::PressExperiment<Dim, Scalar> truth;
  test::MsmFixture<Dim, Scalar> fixture;
  std::vector<unsigned char> block;
  Tracker<Dim, Scalar> tracker;
  int n = 0;

  TrackerRig(double beta_truth, double beta_model, const TrackerConfig& config = {})
      : truth(beta_truth, 1.0, 0.0, 1u, 8, 4, 3, kSpacing, 60.0, 4.0, kRate), fixture(truth.builder.config()) {
    n = fixture.model.particle_count;
    MsmParams<Dim, Scalar> params;
    params.msm_beta = static_cast<Scalar>(beta_model);
    block.resize(tracker_workspace_size(fixture.model, config));
    Arena arena(block.data(), block.size());
    EXPECT_EQ(tracker_init(arena, fixture.model, params, config, tracker), Status::ok);
  }
  int frames() const { return static_cast<int>(truth.times.size()); }
  Vec true_position(int frame, int i) const {
    Vec v;
    for (int d = 0; d < Dim; ++d) v(d) = truth.positions[static_cast<std::size_t>((frame * n + i) * Dim + d)];
    return v;
  }
  bool free_particle(int i) const { return fixture.model.fixed[i] == 0 && i != truth.tool; }
  // One frame with the tool target taken from the truth.
  Status step(int frame, const Vec* observed, const Scalar* confidence = nullptr) {
    const Vec target = true_position(frame, truth.tool);
    TrackerFrame<Dim, Scalar> in;
    in.dt = static_cast<Scalar>(1.0 / kRate);
    in.driven = {&truth.tool, &target, 1};
    in.observed = observed;
    in.confidence = confidence;
    return tracker_update(fixture.model, tracker, in);
  }
  double error(int frame, int i) const {
    return static_cast<double>((tracker.state.position[i] - true_position(frame, i)).norm());
  }
};

template <typename SpaceT>
class TrackerTest : public ::testing::Test {};
TYPED_TEST_SUITE(TrackerTest, Spaces);

TYPED_TEST(TrackerTest, ExactObservationsOfTheSameModelAreReproduced) {
  TrackerRig<TypeParam> rig(0.5, 0.5);
  std::vector<typename TrackerRig<TypeParam>::Vec> observed(static_cast<std::size_t>(rig.n));
  double worst = 0;
  for (int f = 1; f < rig.frames(); ++f) {
    for (int i = 0; i < rig.n; ++i) observed[static_cast<std::size_t>(i)] = rig.true_position(f, i);
    ASSERT_EQ(rig.step(f, observed.data()), Status::ok);
    for (int i = 0; i < rig.n; ++i) worst = std::max(worst, rig.error(f, i));
  }
  EXPECT_LT(worst, 1e-3 * kSpacing);
  EXPECT_EQ(rig.tracker.counters.outliers, 0u);
}

TYPED_TEST(TrackerTest, NoisyObservationsAreSmoothedBelowTheNoise) {
  using Rig = TrackerRig<TypeParam>;
  TrackerConfig config;
  config.min_residual_scale = 2.0;
  config.observation_gain = 0.5;  // equal trust in prior and observation
  Rig rig(0.5, 0.5, config);
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0.0, 2.0);
  std::vector<typename Rig::Vec> observed(static_cast<std::size_t>(rig.n));
  double tracked_sq = 0, raw_sq = 0;
  for (int f = 1; f < rig.frames(); ++f) {
    for (int i = 0; i < rig.n; ++i) {
      auto& o = observed[static_cast<std::size_t>(i)];
      o = rig.true_position(f, i);
      for (int d = 0; d < Rig::Dim; ++d) o(d) += static_cast<typename Rig::Scalar>(noise(rng));
    }
    ASSERT_EQ(rig.step(f, observed.data()), Status::ok);
    for (int i = 0; i < rig.n; ++i) {
      if (!rig.free_particle(i)) continue;
      tracked_sq += rig.error(f, i) * rig.error(f, i);
      const double raw = static_cast<double>((observed[static_cast<std::size_t>(i)] - rig.true_position(f, i)).norm());
      raw_sq += raw * raw;
    }
  }
  // The MSM prior averages each particle with its cluster: the tracked path is closer to the
  // truth than the observations are.
  EXPECT_LT(std::sqrt(tracked_sq), 0.8 * std::sqrt(raw_sq)) << std::sqrt(tracked_sq / raw_sq);
  // Gaussian noise is not mistaken for outliers (a few tail rejections at most).
  EXPECT_LT(rig.tracker.counters.outliers, rig.tracker.counters.observations / 100 + 1);
}

TYPED_TEST(TrackerTest, ModelMismatchStillFollowsTheObservations) {
  // The model is much stiffer than the object (beta 0.2 against 0.8): next to the tool its
  // prediction is off by up to 10 % of the spacing every frame. Exact observations, default
  // configuration: the tracker must follow them, not reject the steep ones as outliers.
  TrackerRig<TypeParam> rig(0.8, 0.2);
  std::vector<typename TrackerRig<TypeParam>::Vec> observed(static_cast<std::size_t>(rig.n));
  double worst = 0;
  for (int f = 1; f < rig.frames(); ++f) {
    for (int i = 0; i < rig.n; ++i) observed[static_cast<std::size_t>(i)] = rig.true_position(f, i);
    ASSERT_EQ(rig.step(f, observed.data()), Status::ok);
    for (int i = 0; i < rig.n; ++i) worst = std::max(worst, rig.error(f, i));
  }
  EXPECT_LT(worst, 0.02 * kSpacing);
}

TYPED_TEST(TrackerTest, OccludedParticlesFollowTheirNeighbours) {
  using Rig = TrackerRig<TypeParam>;
  TrackerConfig config;
  config.max_unobserved_frames = 100;  // the occlusion lasts 56 frames
  Rig rig(0.5, 0.5, config);
  std::vector<typename Rig::Vec> observed(static_cast<std::size_t>(rig.n));
  const auto nan = std::numeric_limits<typename Rig::Scalar>::quiet_NaN();
  // An occluder covers the three columns nearest the tool (x in [3, 5] spacings) for frames
  // 5 to 60, while the press moves them most.
  auto occluded = [&](int f, int i) {
    const double x = static_cast<double>(rig.fixture.model.rest[i](0)) / kSpacing;
    return f >= 5 && f <= 60 && x > 2.5 && x < 5.5;
  };
  std::vector<typename Rig::Vec> held(static_cast<std::size_t>(rig.n));
  double tracker_sq = 0, hold_sq = 0, worst = 0, moved = 0;
  int hidden = 0;
  for (int f = 1; f < rig.frames(); ++f) {
    for (int i = 0; i < rig.n; ++i) {
      const auto k = static_cast<std::size_t>(i);
      if (occluded(f, i)) {
        observed[k].setConstant(nan);
      } else {
        observed[k] = rig.true_position(f, i);
        held[k] = observed[k];
      }
    }
    ASSERT_EQ(rig.step(f, observed.data()), Status::ok);
    for (int i = 0; i < rig.n; ++i) {
      if (!occluded(f, i) || !rig.free_particle(i)) continue;
      ++hidden;
      EXPECT_EQ(rig.tracker.status[i], TrackStatus::predicted);
      const double e = rig.error(f, i);
      tracker_sq += e * e;
      worst = std::max(worst, e);
      const double h = static_cast<double>((held[static_cast<std::size_t>(i)] - rig.true_position(f, i)).norm());
      hold_sq += h * h;
      moved = std::max(moved, static_cast<double>((rig.true_position(f, i) - rig.true_position(0, i)).norm()));
    }
  }
  ASSERT_GT(hidden, 0);
  ASSERT_GT(moved, 10.0);  // the hidden particles really moved
  EXPECT_LT(std::sqrt(tracker_sq), 0.25 * std::sqrt(hold_sq));
  EXPECT_LT(worst, 0.1 * moved);
  EXPECT_EQ(rig.tracker.counters.lost_events, 0u);
}

TYPED_TEST(TrackerTest, GrossOutliersGetNoWeight) {
  using Rig = TrackerRig<TypeParam>;
  TrackerConfig config;
  config.min_residual_scale = 1.0;
  Rig rig(0.5, 0.5, config);
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::vector<typename Rig::Vec> observed(static_cast<std::size_t>(rig.n));
  std::uint32_t injected = 0;
  double worst = 0;
  for (int f = 1; f < rig.frames(); ++f) {
    for (int i = 0; i < rig.n; ++i) {
      auto& o = observed[static_cast<std::size_t>(i)];
      o = rig.true_position(f, i);
      for (int d = 0; d < Rig::Dim; ++d) o(d) += static_cast<typename Rig::Scalar>(noise(rng));
      if (rig.free_particle(i) && uniform(rng) < 0.1) {  // a wrong match, half a lattice away or more
        o(0) += static_cast<typename Rig::Scalar>(kSpacing * (0.5 + uniform(rng)));
        ++injected;
      }
    }
    ASSERT_EQ(rig.step(f, observed.data()), Status::ok);
    for (int i = 0; i < rig.n; ++i) worst = std::max(worst, rig.error(f, i));
  }
  EXPECT_GE(rig.tracker.counters.outliers, injected);
  EXPECT_LT(rig.tracker.counters.outliers, injected + injected / 10 + 5);
  EXPECT_LT(worst, 0.06 * kSpacing);
}

TYPED_TEST(TrackerTest, LongOcclusionIsReportedLostAndRecovers) {
  using Rig = TrackerRig<TypeParam>;
  TrackerConfig config;
  config.max_unobserved_frames = 5;
  Rig rig(0.5, 0.5, config);
  for (int f = 1; f <= 6; ++f) EXPECT_EQ(rig.step(f, nullptr), Status::no_observations);
  int free_count = 0;
  for (int i = 0; i < rig.n; ++i) {
    if (!rig.free_particle(i)) continue;
    ++free_count;
    EXPECT_EQ(rig.tracker.status[i], TrackStatus::lost) << i;
  }
  EXPECT_EQ(rig.tracker.counters.lost_events, static_cast<std::uint32_t>(free_count));
  EXPECT_EQ(rig.tracker.counters.empty_frames, 6u);
  // Still on a plausible path without any observation: the tool drives the model.
  for (int i = 0; i < rig.n; ++i) EXPECT_LT(rig.error(6, i), 0.02 * kSpacing);
  std::vector<typename Rig::Vec> observed(static_cast<std::size_t>(rig.n));
  for (int i = 0; i < rig.n; ++i) observed[static_cast<std::size_t>(i)] = rig.true_position(7, i);
  EXPECT_EQ(rig.step(7, observed.data()), Status::ok);
  for (int i = 0; i < rig.n; ++i) EXPECT_EQ(rig.tracker.status[i], TrackStatus::observed);
  EXPECT_EQ(rig.tracker.counters.lost_events, static_cast<std::uint32_t>(free_count));
}

TYPED_TEST(TrackerTest, ZeroConfidenceMeansUnobserved) {
  using Rig = TrackerRig<TypeParam>;
  Rig rig(0.5, 0.5);
  std::vector<typename Rig::Vec> observed(static_cast<std::size_t>(rig.n));
  std::vector<typename Rig::Scalar> confidence(static_cast<std::size_t>(rig.n), 1);
  for (int i = 0; i < rig.n; ++i) {
    observed[static_cast<std::size_t>(i)] = rig.true_position(1, i);
    observed[static_cast<std::size_t>(i)](0) += 30;  // all wrong by the same amount
  }
  confidence.assign(confidence.size(), 0);
  EXPECT_EQ(rig.step(1, observed.data(), confidence.data()), Status::no_observations);
  for (int i = 0; i < rig.n; ++i) EXPECT_LT(rig.error(1, i), 1.0);
}

TYPED_TEST(TrackerTest, BadFramesAreRefusedAndCounted) {
  using Rig = TrackerRig<TypeParam>;
  using Scalar = typename Rig::Scalar;
  Rig rig(0.5, 0.5);
  std::vector<typename Rig::Vec> before(rig.tracker.state.position, rig.tracker.state.position + rig.n);
  const typename Rig::Vec target = rig.true_position(1, rig.truth.tool);
  TrackerFrame<Rig::Dim, Scalar> in;
  in.driven = {&rig.truth.tool, &target, 1};
  for (Scalar dt :
       {Scalar(0), Scalar(-0.1), std::numeric_limits<Scalar>::quiet_NaN(), std::numeric_limits<Scalar>::infinity()}) {
    in.dt = dt;
    EXPECT_EQ(tracker_update(rig.fixture.model, rig.tracker, in), Status::invalid_argument);
  }
  in.dt = Scalar(0.1);
  const int bad_ids[] = {-1, rig.n, 0};  // 0 is fixed (bottom layer) and not drivable
  for (int id : bad_ids) {
    in.driven = {&id, &target, 1};
    EXPECT_EQ(tracker_update(rig.fixture.model, rig.tracker, in), Status::invalid_argument);
  }
  in.driven = {nullptr, nullptr, 1};
  EXPECT_EQ(tracker_update(rig.fixture.model, rig.tracker, in), Status::invalid_argument);
  rig.tracker.params.msm_beta = Scalar(2);
  in.driven = {&rig.truth.tool, &target, 1};
  EXPECT_EQ(tracker_update(rig.fixture.model, rig.tracker, in), Status::invalid_argument);
  rig.tracker.params.msm_beta = Scalar(0.5);
  EXPECT_EQ(rig.tracker.counters.rejected_frames, 9u);
  EXPECT_EQ(rig.tracker.counters.frames, 0u);
  for (int i = 0; i < rig.n; ++i) EXPECT_EQ(rig.tracker.state.position[i], before[static_cast<std::size_t>(i)]);
  // A NaN tool target is dropped; the contact particle holds and the frame is used.
  const typename Rig::Vec nan_target = Rig::Vec::Constant(std::numeric_limits<Scalar>::quiet_NaN());
  in.driven = {&rig.truth.tool, &nan_target, 1};
  EXPECT_EQ(tracker_update(rig.fixture.model, rig.tracker, in), Status::no_observations);
  EXPECT_EQ(rig.tracker.state.dropped_targets, 1u);
  EXPECT_EQ(rig.tracker.counters.frames, 1u);
  for (int i = 0; i < rig.n; ++i) EXPECT_TRUE(rig.tracker.state.position[i].allFinite());
}

TEST(TrackerInit, RejectsBadConfigurationsAndSmallBlocks) {
  test::PressExperiment<3, double> truth(0.5, 1.0, 0.0, 1u);
  test::MsmFixture<3, double> fixture(truth.builder.config());
  MsmParams<3, double> params;
  std::vector<unsigned char> block(tracker_workspace_size(fixture.model, TrackerConfig{}));
  Tracker<3, double> tracker;
  auto init = [&](const TrackerConfig& config, std::size_t bytes) {
    Arena arena(block.data(), bytes);
    return tracker_init(arena, fixture.model, params, config, tracker);
  };
  TrackerConfig bad;
  bad.tukey_c = 0;
  EXPECT_EQ(init(bad, block.size()), Status::invalid_argument);
  bad = {};
  bad.observation_gain = 1.5;
  EXPECT_EQ(init(bad, block.size()), Status::invalid_argument);
  bad = {};
  bad.max_unobserved_frames = 0;
  EXPECT_EQ(init(bad, block.size()), Status::invalid_argument);
  bad = {};
  bad.min_residual_scale = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(init(bad, block.size()), Status::invalid_argument);
  EXPECT_EQ(init(TrackerConfig{}, block.size() / 2), Status::capacity_exceeded);
  EXPECT_FALSE(tracker.initialized());
  params.msm_beta = -0.1;
  EXPECT_EQ(init(TrackerConfig{}, block.size()), Status::invalid_argument);
  params.msm_beta = 0.5;
  EXPECT_EQ(init(TrackerConfig{}, block.size()), Status::ok);
  EXPECT_NEAR(tracker.config.min_residual_scale, 0.02 * fixture.model.spacing, 1e-12);

  MsmModel<3, double> empty;
  EXPECT_EQ(tracker_workspace_size(empty, TrackerConfig{}), 0u);
  Arena arena(block.data(), block.size());
  EXPECT_EQ(tracker_init(arena, empty, params, TrackerConfig{}, tracker), Status::not_initialized);
  TrackerFrame<3, double> in;
  in.dt = 0.1;
  EXPECT_EQ(tracker_update(fixture.model, tracker, in), Status::not_initialized);
}

}  // namespace
}  // namespace pliant
