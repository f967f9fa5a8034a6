// Online estimation frame by frame: converges to the offline answer on the same press.
#include "pliant/core/online_deformability.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "press_observations.hpp"

namespace {

using pliant::Status;

template <int Dim, typename Scalar>
pliant::OnlineDeformabilityEstimate run_online(const pliant::test::PressExperiment<Dim, Scalar>& experiment,
                                               const pliant::OnlineDeformabilityConfig& config) {
  pliant::test::MsmFixture<Dim, Scalar> f(experiment.builder.config());
  EXPECT_EQ(f.status, Status::ok);
  std::vector<unsigned char> block(pliant::online_deformability_workspace_size(f.model, config));
  pliant::Arena arena(block.data(), block.size());
  pliant::OnlineDeformability<Dim, Scalar> online;
  EXPECT_EQ(pliant::online_deformability_init(arena, f.model, pliant::MsmParams<Dim, Scalar>{}, config, online),
            Status::ok);
  const auto obs = experiment.observations();
  using Vec = Eigen::Matrix<Scalar, Dim, 1>;
  std::vector<Vec> frame(static_cast<std::size_t>(obs.particle_count));
  for (int k = 1; k < obs.frame_count; ++k) {
    for (int i = 0; i < obs.particle_count; ++i) frame[static_cast<std::size_t>(i)] = obs.point(k, i);
    const Vec target = obs.point(k, experiment.tool);
    const pliant::MsmDrivenTargets<Dim, Scalar> driven{&experiment.tool, &target, 1};
    EXPECT_EQ(pliant::online_deformability_update(
                  f.model, online, static_cast<Scalar>(obs.times_s[k] - obs.times_s[k - 1]), driven, frame.data()),
              Status::ok);
  }
  return pliant::online_deformability_estimate(online);
}

TEST(OnlineDeformability, ConvergesToTheTruthDuringThePress) {
  for (double beta : {0.2, 0.55, 0.85}) {
    pliant::test::PressExperiment<2, double> experiment(beta, 1.0, 0.5, 3);
    const auto estimate = run_online(experiment, pliant::OnlineDeformabilityConfig{});
    EXPECT_NEAR(estimate.msm_beta, beta, 0.03) << beta;
    EXPECT_TRUE(estimate.unique_minimum);
    EXPECT_LT(estimate.msm_beta_std, 0.05);
    EXPECT_EQ(estimate.frames, experiment.times.size() - 1);
  }
}

pliant::OnlineDeformabilityConfig held_form() {
  pliant::OnlineDeformabilityConfig config;
  config.alpha_candidates = 1;
  config.step_candidates = 1;
  return config;
}

pliant::OnlineDeformabilityConfig alpha_and_step_rows() {
  pliant::OnlineDeformabilityConfig config;
  config.step_candidates = 3;
  return config;
}

TEST(OnlineDeformability, ChoosesMsmAlphaWhenThePressDeterminesIt) {
  for (double beta : {0.25, 0.6}) {
    pliant::test::PressExperiment<2, double> experiment(beta, 0.5, 0.5, 5);
    const auto fitted = run_online(experiment, pliant::OnlineDeformabilityConfig{});
    const auto held = run_online(experiment, held_form());
    EXPECT_TRUE(fitted.alpha_fitted) << beta;
    // alpha is a nuisance here, read off a grid 0.35 apart: under-relaxed is what matters.
    EXPECT_LT(fitted.msm_alpha, 0.85) << beta;
    EXPECT_EQ(fitted.steps_per_frame, 1);
    EXPECT_NEAR(fitted.msm_beta, beta, 0.03) << beta;
    EXPECT_LT(fitted.rms, held.rms) << beta;
    // The interval of a fitted form spans the held form's answer.
    EXPECT_GE(fitted.msm_beta_std, std::abs(fitted.msm_beta - held.msm_beta)) << beta;
    EXPECT_FALSE(held.alpha_fitted);
    EXPECT_EQ(held.msm_alpha, 1.0);
  }
}

TEST(OnlineDeformability, HoldsAlphaOneWhenItFits) {
  pliant::test::PressExperiment<2, double> experiment(0.45, 1.0, 0.5, 9);
  const auto estimate = run_online(experiment, alpha_and_step_rows());
  EXPECT_FALSE(estimate.alpha_fitted);
  EXPECT_EQ(estimate.msm_alpha, 1.0);
  EXPECT_EQ(estimate.steps_per_frame, 1);
  EXPECT_NEAR(estimate.msm_beta, 0.45, 0.03);
}

TEST(OnlineDeformability, FindsSeveralStepsPerFrame) {
  pliant::test::PressExperiment<2, double> experiment(0.35, 0.65, 0.5, 11, 8, 4, 3, 100.0, 60.0, 4.0, 30.0, HUGE_VAL,
                                                      2);
  const auto held = run_online(experiment, held_form());
  const auto fitted = run_online(experiment, alpha_and_step_rows());
  EXPECT_TRUE(fitted.alpha_fitted);
  EXPECT_EQ(fitted.steps_per_frame, 2);
  EXPECT_LT(fitted.msm_alpha, 0.9);
  EXPECT_NEAR(fitted.msm_beta, 0.35, 0.03);
  EXPECT_GT(std::abs(held.msm_beta - 0.35), std::abs(fitted.msm_beta - 0.35));
}

TEST(OnlineDeformability, ThreeDimensionalFloat) {
  pliant::test::PressExperiment<3, float> experiment(0.35, 1.0, 0.0, 1, 5, 4, 3, 0.01, 0.004, 3.0);
  const auto estimate = run_online(experiment, pliant::OnlineDeformabilityConfig{});
  EXPECT_NEAR(estimate.msm_beta, 0.35, 0.03);
}

TEST(OnlineDeformability, NoEvidenceMeansNoConfidence) {
  pliant::test::PressExperiment<2, double> experiment(0.5, 1.0, 0.0, 1);
  pliant::test::MsmFixture<2, double> f(experiment.builder.config());
  ASSERT_EQ(f.status, Status::ok);
  pliant::OnlineDeformabilityConfig config;
  std::vector<unsigned char> block(pliant::online_deformability_workspace_size(f.model, config));
  pliant::Arena arena(block.data(), block.size());
  pliant::OnlineDeformability<2, double> online;
  ASSERT_EQ(pliant::online_deformability_init(arena, f.model, pliant::MsmParams<2, double>{}, config, online),
            Status::ok);
  EXPECT_FALSE(std::isfinite(pliant::online_deformability_estimate(online).msm_beta_std));

  std::vector<Eigen::Vector2d> hidden(32, Eigen::Vector2d::Constant(std::nan("")));
  const pliant::MsmDrivenTargets<2, double> none{};
  EXPECT_EQ(pliant::online_deformability_update(f.model, online, 1.0 / 30, none, hidden.data()),
            Status::no_observations);
  EXPECT_EQ(online.empty_frames, 1u);
  EXPECT_EQ(pliant::online_deformability_update(f.model, online, std::nan(""), none, hidden.data()),
            Status::invalid_argument);
  EXPECT_EQ(online.rejected_frames, 1u);
  auto refused = [&](void (*spoil)(pliant::OnlineDeformabilityConfig&)) {
    pliant::OnlineDeformabilityConfig bad;
    spoil(bad);
    return pliant::online_deformability_init(arena, f.model, pliant::MsmParams<2, double>{}, bad, online) ==
           Status::invalid_argument;
  };
  EXPECT_TRUE(refused([](pliant::OnlineDeformabilityConfig& c) { c.candidates = 2; }));
  EXPECT_TRUE(refused([](pliant::OnlineDeformabilityConfig& c) { c.alpha_candidates = 0; }));
  EXPECT_TRUE(
      refused([](pliant::OnlineDeformabilityConfig& c) { c.alpha_candidates = pliant::kMaxOnlineAlphaRows + 1; }));
  EXPECT_TRUE(refused([](pliant::OnlineDeformabilityConfig& c) { c.alpha_min = 0; }));
  EXPECT_TRUE(refused([](pliant::OnlineDeformabilityConfig& c) { c.alpha_min = 1; }));
  EXPECT_TRUE(refused([](pliant::OnlineDeformabilityConfig& c) { c.step_candidates = 0; }));
  EXPECT_TRUE(
      refused([](pliant::OnlineDeformabilityConfig& c) { c.step_candidates = pliant::kMaxOnlineStepRows + 1; }));
  EXPECT_TRUE(refused([](pliant::OnlineDeformabilityConfig& c) { c.forgetting = 0; }));
  EXPECT_TRUE(refused([](pliant::OnlineDeformabilityConfig& c) { c.equilibrium_iterations = -1; }));
  EXPECT_TRUE(refused(
      [](pliant::OnlineDeformabilityConfig& c) { c.equilibrium_iterations = pliant::kMaxEquilibriumIterations + 1; }));
  EXPECT_TRUE(refused([](pliant::OnlineDeformabilityConfig& c) {
    c.equilibrium_iterations = 8;
    c.equilibrium_tolerance = 0;
  }));
  EXPECT_TRUE(refused([](pliant::OnlineDeformabilityConfig& c) {
    c.equilibrium_iterations = 8;
    c.equilibrium_tolerance = std::nan("");
  }));
}

// The press of PressExperiment made by an object that settles between frames: every frame the
// truth is relaxed to equilibrium under the tool's target (velocities zeroed every iteration,
// no momentum: another iteration than the estimator's, with the same fixed point), then noised.
struct SettledPress {
  pliant::test::PressExperiment<2, double> experiment;

  SettledPress(double beta, double rate_hz, double noise_std, unsigned seed)
      : experiment(beta, 1.0, 0.0, seed, 8, 4, 3, 100.0, 60.0, 2.0, rate_hz) {
    pliant::test::MsmFixture<2, double> truth(experiment.builder.config());
    EXPECT_EQ(truth.status, Status::ok);
    pliant::MsmParams<2, double> params;
    params.msm_beta = beta;
    std::mt19937 noise(seed);
    std::normal_distribution<double> normal(0.0, noise_std);
    const int n = truth.model.particle_count;
    for (std::size_t k = 1; k < experiment.times.size(); ++k) {
      const Eigen::Vector2d target(experiment.positions[coordinate(k, experiment.tool, 0, n)],
                                   experiment.positions[coordinate(k, experiment.tool, 1, n)]);
      relax(truth, params, target);
      for (int i = 0; i < n; ++i) {
        const double sd = i == experiment.tool ? 0.0 : 1.0;
        for (int d = 0; d < 2; ++d) {
          experiment.positions[coordinate(k, i, d, n)] = truth.state.position[i](d) + sd * normal(noise);
        }
      }
    }
  }

  static std::size_t coordinate(std::size_t frame, int particle, int axis, int particle_count) {
    return (frame * static_cast<std::size_t>(particle_count) + static_cast<std::size_t>(particle)) * 2 +
           static_cast<std::size_t>(axis);
  }

  void relax(pliant::test::MsmFixture<2, double>& truth, const pliant::MsmParams<2, double>& params,
             const Eigen::Vector2d& target) const {
    pliant::MsmStepInput<2, double> input;
    input.dt = 1.0;
    input.driven = {&experiment.tool, &target, 1};
    for (int iteration = 0; iteration < 20000; ++iteration) {
      double largest = 0;
      for (int i = 0; i < truth.model.particle_count; ++i) truth.state.velocity[i].setZero();
      std::vector<Eigen::Vector2d> before(truth.state.position, truth.state.position + truth.model.particle_count);
      EXPECT_EQ(pliant::msm_step(truth.model, params, input, truth.state), Status::ok);
      for (int i = 0; i < truth.model.particle_count; ++i) {
        largest = std::max(largest, (truth.state.position[i] - before[static_cast<std::size_t>(i)]).norm());
      }
      if (largest < 1e-9) return;
    }
    ADD_FAILURE() << "the truth did not settle";
  }
};

pliant::OnlineDeformabilityConfig with_quasi_static_row() {
  pliant::OnlineDeformabilityConfig config;
  config.equilibrium_iterations = 64;
  return config;
}

// The press at 10 Hz (6 % of the spacing per frame): the rows that step through the frame
// interval misread it; the quasi-static row answers and reads msm_beta.
TEST(OnlineDeformability, QuasiStaticRowReadsAnObjectThatSettlesBetweenFrames) {
  for (double beta : {0.2, 0.5, 0.8}) {
    const SettledPress press(beta, 10.0, 0.5, 21);
    const auto stepped = run_online(press.experiment, pliant::OnlineDeformabilityConfig{});
    const auto settled = run_online(press.experiment, with_quasi_static_row());
    // One step per frame lags an object that settles: 0.08, 0.36, 0.66 when this was written.
    EXPECT_GT(std::abs(stepped.msm_beta - beta), 0.1) << beta;
    EXPECT_EQ(settled.steps_per_frame, 0) << beta;
    EXPECT_TRUE(settled.alpha_fitted) << beta;
    EXPECT_NEAR(settled.msm_beta, beta, 0.03) << beta;
  }
}

}  // namespace
