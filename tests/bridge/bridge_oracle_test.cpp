// Oracle: pliant.h against the core called directly. A simulated press (a known msm_beta, noisy
// observations, an occluded particle, an outlier) runs through the bridge and through the same
// core calls made by hand; tracked positions, strain, estimate and every guard verdict field
// must agree exactly, and the estimate must find the true msm_beta.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "bridge_fixture.hpp"
#include "pliant/core/grasp_guard.hpp"
#include "pliant/core/msm.hpp"
#include "pliant/core/online_deformability.hpp"
#include "pliant/core/tracker.hpp"

namespace pliant::bridge_test {
namespace {

constexpr double kRateHz = 30.0;
constexpr double kNoiseM = 1e-4;  // 1 % of the spacing

bool same(double a, double b) { return (std::isnan(a) && std::isnan(b)) || a == b; }

/// The bridge's pipeline, written out with core calls and this test's own config mapping.
template <int Dim>
struct CorePipeline {
  using Vec = Eigen::Matrix<Scalar, Dim, 1>;
  std::vector<Scalar> rest;
  std::vector<int> drivable, all;
  std::vector<unsigned char> model_block, guard_model_block, tracker_block, estimator_block, guard_block;
  MsmModel<Dim, Scalar> model, guard_model;
  Tracker<Dim, Scalar> tracker;
  OnlineDeformability<Dim, Scalar> estimator;
  GraspGuard<Dim, Scalar> guard;
  std::vector<Vec> observed, strain_positions, estimate_positions, targets;
  GraspStrainMeasurement strain;
  Status strain_status = Status::not_initialized;
  double frame_stamp = kNaN;
  double estimate_stamp = kNaN;
  OnlineDeformabilityEstimate estimate;
  double feed_back_max_std = 0.1;

  Status build(const pliant_config_t& c) {
    const int n = static_cast<int>(c.particle_count);
    rest.assign(c.rest_positions, c.rest_positions + n * Dim);
    drivable.assign(c.drivable_ids, c.drivable_ids + c.drivable_count);
    MsmModelConfig<Dim, Scalar> object;
    object.particle_count = n;
    object.rest_positions = rest.data();
    object.fixed = c.fixed;
    object.drivable_ids = drivable.data();
    object.drivable_count = static_cast<int>(drivable.size());
    model_block.resize(msm_model_workspace_size(object));
    Arena model_arena(model_block.data(), model_block.size());
    Status s = msm_model_init(model_arena, object, model);
    if (s != Status::ok) return s;

    MsmParams<Dim, Scalar> params;
    params.msm_alpha = Scalar(1);
    params.msm_beta = static_cast<Scalar>(c.msm.msm_beta);
    TrackerConfig tracker_config;
    tracker_config.min_residual_scale = c.tracker.min_residual_scale;
    tracker_block.resize(tracker_workspace_size(model, tracker_config));
    Arena tracker_arena(tracker_block.data(), tracker_block.size());
    s = tracker_init(tracker_arena, model, params, tracker_config, tracker);
    if (s != Status::ok) return s;

    const OnlineDeformabilityConfig estimator_config;
    estimator_block.resize(online_deformability_workspace_size(model, estimator_config));
    Arena estimator_arena(estimator_block.data(), estimator_block.size());
    s = online_deformability_init(estimator_arena, model, params, estimator_config, estimator);
    if (s != Status::ok) return s;
    estimate.msm_beta = c.msm.msm_beta;
    estimate.msm_beta_std = kInf;

    for (int i = 0; i < n; ++i) all.push_back(i);
    MsmModelConfig<Dim, Scalar> squeezed = object;
    squeezed.fixed = nullptr;
    squeezed.drivable_ids = all.data();
    squeezed.drivable_count = n;
    guard_model_block.resize(msm_model_workspace_size(squeezed));
    Arena guard_model_arena(guard_model_block.data(), guard_model_block.size());
    s = msm_model_init(guard_model_arena, squeezed, guard_model);
    if (s != Status::ok) return s;
    GraspGuardConfig guard_config;
    guard_config.max_strain = c.guard.max_strain;
    guard_config.max_force_n = c.guard.max_force_n;
    guard_config.prediction_beta_points = c.guard.prediction_beta_points;
    guard_config.prediction_closure_points = c.guard.prediction_closure_points;
    guard_config.contact_width_m = c.guard.contact_width_m;
    GraspObject<Dim, Scalar> jaws;
    for (int d = 0; d < Dim; ++d) jaws.squeeze_axis(d) = static_cast<Scalar>(c.guard.squeeze_axis[d]);
    guard_block.resize(grasp_guard_workspace_size(guard_model, guard_config));
    Arena guard_arena(guard_block.data(), guard_block.size());
    s = grasp_guard_init(guard_arena, guard_model, jaws, guard_config, guard);
    observed.resize(static_cast<std::size_t>(n));
    strain_positions.resize(static_cast<std::size_t>(n));
    estimate_positions.resize(static_cast<std::size_t>(n));
    return s;
  }

  void frame(double stamp, double dt, const std::vector<float>& positions, const std::vector<int>& ids,
             const std::vector<float>& target_xyz) {
    const int n = model.particle_count;
    for (int i = 0; i < n; ++i) {
      for (int d = 0; d < Dim; ++d)
        observed[static_cast<std::size_t>(i)](d) =
            static_cast<Scalar>(positions[static_cast<std::size_t>(i * Dim + d)]);
    }
    targets.resize(ids.size());
    for (std::size_t k = 0; k < ids.size(); ++k) {
      for (int d = 0; d < Dim; ++d)
        targets[k](d) = static_cast<Scalar>(target_xyz[k * Dim + static_cast<std::size_t>(d)]);
    }
    TrackerFrame<Dim, Scalar> f;
    f.dt = static_cast<Scalar>(dt);
    f.driven = {ids.data(), targets.data(), static_cast<int>(ids.size())};
    f.observed = observed.data();
    const Status tracked = tracker_update(model, tracker, f);
    ASSERT_TRUE(tracked == Status::ok || tracked == Status::no_observations);
    const Vec nan = Vec::Constant(std::numeric_limits<Scalar>::quiet_NaN());
    for (int i = 0; i < n; ++i) {
      const auto u = static_cast<std::size_t>(i);
      strain_positions[u] = tracker.status[i] == TrackStatus::lost ? nan : tracker.state.position[i];
      estimate_positions[u] = tracker.status[i] == TrackStatus::observed ? tracker.state.position[i] : nan;
    }
    frame_stamp = stamp;
    strain_status = grasp_guard_measure_strain(guard_model, guard, strain_positions.data(), strain);
    const Status estimated =
        online_deformability_update(model, estimator, static_cast<Scalar>(dt), f.driven, estimate_positions.data());
    ASSERT_TRUE(estimated == Status::ok || estimated == Status::no_observations);
    estimate = online_deformability_estimate(estimator);
    estimate_stamp = stamp;
    if (std::isfinite(estimate.msm_beta_std) && estimate.msm_beta_std <= feed_back_max_std) {
      tracker.params.msm_beta = static_cast<Scalar>(estimate.msm_beta);
    }
  }

  GraspGuardOutput cycle(const pliant_guard_input_t& in) {
    GraspGuardInput g;
    g.now_s = in.now_s;
    g.gripper = {in.gripper.stamp_s,     in.gripper.width_m, in.gripper.force_n, in.gripper.current_a,
                 in.gripper.status_bits, in.gripper.valid,   in.gripper.bus_off, in.gripper.timeout};
    g.wrench.stamp_s = in.wrench.stamp_s;
    for (int k = 0; k < 6; ++k) g.wrench.wrench[k] = in.wrench.wrench[k];
    g.wrench.status_bits = in.wrench.status_bits;
    g.wrench.valid = in.wrench.valid;
    g.wrench.bus_off = in.wrench.bus_off;
    g.wrench.timeout = in.wrench.timeout;
    if (in.deformation.source == PLIANT_SOURCE_BRIDGE) {
      g.deformation.stamp_s = frame_stamp;
      g.deformation.strain = strain.strain;
      g.deformation.valid = strain_status == Status::ok;
    } else {
      g.deformation.stamp_s = in.deformation.stamp_s;
      g.deformation.strain = in.deformation.strain;
      g.deformation.valid = in.deformation.valid;
    }
    g.deformation.status_bits = in.deformation.status_bits;
    g.deformation.bus_off = in.deformation.bus_off;
    g.deformation.timeout = in.deformation.timeout;
    if (in.estimate.source == PLIANT_SOURCE_BRIDGE) {
      g.estimate = {estimate_stamp, estimate.msm_beta, estimate.msm_beta_std, std::isfinite(estimate_stamp)};
    } else {
      g.estimate = {in.estimate.stamp_s, in.estimate.msm_beta, in.estimate.msm_beta_std, in.estimate.valid};
    }
    GraspGuardOutput out;
    EXPECT_EQ(grasp_guard_update(guard, g, out), Status::ok);
    return out;
  }
};

void expect_same_verdict(const pliant_verdict_t& b, const GraspGuardOutput& c, int cycle) {
  EXPECT_EQ(b.verdict, static_cast<std::uint8_t>(c.verdict)) << cycle;
  EXPECT_EQ(b.reason, static_cast<std::uint8_t>(c.reason)) << cycle;
  EXPECT_EQ(b.stop_action, static_cast<std::uint8_t>(c.stop_action)) << cycle;
  EXPECT_EQ(b.fault_sources, c.fault_sources) << cycle;
  EXPECT_EQ(b.reasons, c.reasons) << cycle;
  EXPECT_EQ(b.in_contact, c.in_contact) << cycle;
  EXPECT_EQ(b.slip, c.slip) << cycle;
  const double pairs[][2] = {{b.contact_width_m, c.contact_width_m},
                             {b.closure_m, c.closure_m},
                             {b.force_n, c.force_n},
                             {b.strain, c.strain},
                             {b.allowed_force_n, c.allowed_force_n},
                             {b.beta_low, c.beta_low},
                             {b.beta_high, c.beta_high},
                             {b.predicted_strain, c.predicted_strain},
                             {b.strain_safe_closure_m, c.strain_safe_closure_m},
                             {b.force_safe_closure_m, c.force_safe_closure_m},
                             {b.safe_closure_m, c.safe_closure_m},
                             {b.safe_width_m, c.safe_width_m},
                             {b.predicted_force_n, c.predicted_force_n},
                             {b.stiffness_n_per_m, c.stiffness_n_per_m},
                             {b.slip_force_n, c.slip_force_n}};
  for (std::size_t k = 0; k < sizeof pairs / sizeof pairs[0]; ++k) {
    EXPECT_TRUE(same(pairs[k][0], pairs[k][1]))
        << "cycle " << cycle << " field " << k << ": " << pairs[k][0] << " vs " << pairs[k][1];
  }
}

/// A press: bottom layer fixed, the top-centre particle pushed down (the last axis) by a third
/// of the spacing over 1 s and held; truth from the core's msm_step at `beta`.
template <int Dim>
struct Press {
  using Vec = Eigen::Matrix<Scalar, Dim, 1>;
  LatticeObject object;
  int tool = 0;
  std::vector<std::vector<float>> frames;  // observed, with noise, occlusion and an outlier
  std::vector<float> tool_targets;         // [frame][Dim] the tool's observed position

  Press(double beta, int frame_count, unsigned seed) : object(Dim, Dim == 2 ? 8 : 4, 4, 3) {
    const int n = static_cast<int>(object.count());
    const int down = Dim - 1;
    object.fixed.assign(static_cast<std::size_t>(n), 0);
    for (int i = 0; i < n; ++i)
      object.fixed[static_cast<std::size_t>(i)] = object.rest[static_cast<std::size_t>(i * Dim + down)] == 0.0f;
    tool =
        Dim == 2 ? object.id(object.nx / 2, object.ny - 1, 0) : object.id(object.nx / 2, object.ny / 2, object.nz - 1);
    object.drivable = {tool};

    // The truth: the core model of the same object.
    std::vector<Scalar> rest(object.rest.begin(), object.rest.end());
    const int drivable = tool;
    MsmModelConfig<Dim, Scalar> config;
    config.particle_count = n;
    config.rest_positions = rest.data();
    config.fixed = object.fixed.data();
    config.drivable_ids = &drivable;
    config.drivable_count = 1;
    std::vector<unsigned char> model_block(msm_model_workspace_size(config));
    Arena model_arena(model_block.data(), model_block.size());
    MsmModel<Dim, Scalar> model;
    if (msm_model_init(model_arena, config, model) != Status::ok) return;
    std::vector<unsigned char> state_block(msm_state_workspace_size(model));
    Arena state_arena(state_block.data(), state_block.size());
    MsmState<Dim, Scalar> state;
    if (msm_state_init(state_arena, model, state) != Status::ok) return;
    MsmParams<Dim, Scalar> params;
    params.msm_beta = static_cast<Scalar>(beta);
    std::mt19937 rng(seed);
    std::normal_distribution<double> noise(0.0, kNoiseM);
    const int hidden = object.id(1, 1, Dim == 3 ? 1 : 0);
    const int outlier = object.id(object.nx - 1, object.ny - 1, Dim == 3 ? 1 : 0);
    for (int f = 0; f < frame_count; ++f) {
      const double t = f / kRateHz;
      if (f > 0) {
        Vec target = model.rest[tool];
        target(down) -= static_cast<Scalar>(object.h / 3 * std::min(1.0, t));
        MsmStepInput<Dim, Scalar> in;
        in.dt = static_cast<Scalar>(1 / kRateHz);
        in.driven = {&tool, &target, 1};
        if (msm_step(model, params, in, state) != Status::ok) return;
      }
      std::vector<float> frame(static_cast<std::size_t>(n * Dim));
      for (int i = 0; i < n; ++i) {
        for (int d = 0; d < Dim; ++d) {
          frame[static_cast<std::size_t>(i * Dim + d)] =
              static_cast<float>(static_cast<double>(state.position[i](d)) + noise(rng));
        }
      }
      if (f >= 10 && f < 50) {  // occluded long enough to be reported lost
        for (int d = 0; d < Dim; ++d)
          frame[static_cast<std::size_t>(hidden * Dim + d)] = std::numeric_limits<float>::quiet_NaN();
      }
      if (f == 20) frame[static_cast<std::size_t>(outlier * Dim)] += static_cast<float>(object.h);
      for (int d = 0; d < Dim; ++d) tool_targets.push_back(frame[static_cast<std::size_t>(tool * Dim + d)]);
      frames.push_back(std::move(frame));
    }
  }
};

template <typename DimTag>
class BridgeOracle : public ::testing::Test {};
using Dims = ::testing::Types<std::integral_constant<int, 2>, std::integral_constant<int, 3>>;
TYPED_TEST_SUITE(BridgeOracle, Dims);

TYPED_TEST(BridgeOracle, AgreesWithTheCoreAndFindsTheBeta) {
  constexpr int Dim = TypeParam::value;
  constexpr double kTruthBeta = 0.3;
  constexpr int kFrames = 75;
  Press<Dim> press(kTruthBeta, kFrames, 7);
  ASSERT_EQ(press.frames.size(), static_cast<std::size_t>(kFrames));
  pliant_config_t config = press.object.config();
  config.tracker.min_residual_scale = kNoiseM;
  config.guard.squeeze_axis[0] = 0;
  config.guard.squeeze_axis[Dim - 1] = 1;
  config.guard.jaw_a_count = config.guard.jaw_b_count = 0;  // the extreme particles along the axis
  config.guard.jaw_a_ids = config.guard.jaw_b_ids = nullptr;
  config.guard.contact_width_m = press.object.h * (Dim == 2 ? 3 : 2);
  Instance bridge(config);
  ASSERT_EQ(bridge.status, PLIANT_OK) << pliant_status_name(bridge.status);
  CorePipeline<Dim> core;
  ASSERT_EQ(core.build(config), Status::ok);

  const std::uint32_t n = press.object.count();
  const double dt = 1 / kRateHz;
  const double extent = config.guard.contact_width_m;
  std::vector<float> tracked(static_cast<std::size_t>(n) * Dim);
  std::vector<std::uint8_t> status(n);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> jitter(-1e-3, 1e-3);
  int cycle = 0;
  for (int f = 0; f < kFrames; ++f) {
    const double stamp = f * dt;
    const std::vector<float>& frame = press.frames[static_cast<std::size_t>(f)];
    const std::vector<int> ids = {press.tool};
    const std::vector<float> target(press.tool_targets.begin() + f * Dim, press.tool_targets.begin() + (f + 1) * Dim);
    const std::int32_t tool = press.tool;
    ASSERT_EQ(pliant_push_observations(bridge.pliant, stamp, frame.data(), nullptr), PLIANT_OK);
    ASSERT_EQ(pliant_push_tool_contact(bridge.pliant, &tool, target.data(), f > 0 ? 1u : 0u), PLIANT_OK);
    const pliant_status_t stepped = pliant_step_tracker(bridge.pliant, dt);
    ASSERT_TRUE(stepped == PLIANT_OK || stepped == PLIANT_NO_OBSERVATIONS);
    const pliant_status_t estimated = pliant_update_estimate(bridge.pliant);
    ASSERT_TRUE(estimated == PLIANT_OK || estimated == PLIANT_NO_OBSERVATIONS);
    core.frame(stamp, dt, frame, f > 0 ? ids : std::vector<int>{}, target);

    // Tracked state, strain and estimate: exactly the core's.
    ASSERT_EQ(pliant_get_tracked(bridge.pliant, tracked.data(), status.data(), n, nullptr), PLIANT_OK);
    for (std::uint32_t i = 0; i < n; ++i) {
      EXPECT_EQ(status[i], static_cast<std::uint8_t>(core.tracker.status[i])) << "frame " << f << " particle " << i;
      for (int d = 0; d < Dim; ++d) {
        ASSERT_EQ(tracked[std::size_t{i} * Dim + static_cast<std::size_t>(d)],
                  static_cast<float>(core.tracker.state.position[i](d)))
            << "frame " << f;
      }
    }
    pliant_deformation_t deformation;
    ASSERT_EQ(pliant_get_deformation(bridge.pliant, &deformation), PLIANT_OK);
    EXPECT_TRUE(same(deformation.strain, core.strain.strain)) << f;
    EXPECT_EQ(deformation.cluster, core.strain.cluster);
    EXPECT_EQ(deformation.clusters_skipped, core.strain.clusters_skipped);
    EXPECT_EQ(deformation.valid, core.strain_status == Status::ok);
    pliant_estimate_t estimate;
    ASSERT_EQ(pliant_get_estimate(bridge.pliant, &estimate), PLIANT_OK);
    EXPECT_TRUE(same(estimate.msm_beta, core.estimate.msm_beta)) << f;
    EXPECT_TRUE(same(estimate.msm_beta_std, core.estimate.msm_beta_std)) << f;
    EXPECT_TRUE(same(estimate.rms, core.estimate.rms)) << f;
    EXPECT_TRUE(same(estimate.msm_alpha, core.estimate.msm_alpha)) << f;
    EXPECT_EQ(estimate.steps_per_frame, static_cast<std::uint32_t>(core.estimate.steps_per_frame));
    EXPECT_EQ(estimate.form_fitted, core.estimate.alpha_fitted);
    EXPECT_EQ(estimate.frames, core.estimate.frames);
    EXPECT_EQ(estimate.tracker_msm_beta, static_cast<double>(core.tracker.params.msm_beta));

    // Guard cycles between frames, with scripted faults and both sample sources.
    for (int k = 0; k < 4; ++k, ++cycle) {
      const double now = stamp + 0.008 * k;
      const double closure = 0.3 * extent * std::min(1.0, stamp);
      pliant_guard_input_t in = fresh_input(now, extent - closure + 1e-4, 1500 * closure);
      in.wrench.wrench[0] = jitter(rng) + (f >= 40 && f < 44 ? 0.5 * k : 0.0);  // a slip burst
      switch (cycle % 37) {
        case 5: in.gripper.width_m = kNaN; break;
        case 9: in.wrench.bus_off = true; break;
        case 13:
          in.deformation.source = PLIANT_SOURCE_CALLER;
          in.deformation.stamp_s = now - 1.0;
          in.deformation.strain = 0.01;
          in.deformation.valid = true;
          break;
        case 17:
          in.estimate.source = PLIANT_SOURCE_CALLER;
          in.estimate.stamp_s = now;
          in.estimate.msm_beta = 0.6;
          in.estimate.msm_beta_std = 0.02;
          in.estimate.valid = true;
          break;
        case 21: in.gripper.status_bits = 4; break;
        case 25: in.now_s = now - 0.5; break;
        case 29: in.deformation.timeout = true; break;
        default: break;
      }
      pliant_verdict_t verdict;
      ASSERT_EQ(pliant_guard_update(bridge.pliant, &in, &verdict), PLIANT_OK);
      expect_same_verdict(verdict, core.cycle(in), cycle);
    }
  }
  const pliant_counters_t counters = bridge.counters();
  EXPECT_EQ(counters.guard_cycles, core.guard.counters.cycles);
  EXPECT_EQ(counters.guard_stop_cycles, core.guard.counters.stop_cycles);
  EXPECT_EQ(counters.guard_limit_cycles, core.guard.counters.limit_cycles);
  EXPECT_EQ(counters.outliers, core.tracker.counters.outliers);
  EXPECT_EQ(counters.particles_lost, core.tracker.counters.lost_events);
  EXPECT_GE(counters.particles_lost, 1u);
  EXPECT_GE(counters.guard_stop_cycles, 1u);
  EXPECT_EQ(counters.calls_rejected, 0u);

  pliant_estimate_t estimate;
  ASSERT_EQ(pliant_get_estimate(bridge.pliant, &estimate), PLIANT_OK);
  std::printf("[oracle %dD] msm_beta %.3f (truth %.2f) sd %.3f rms %.2e m, tracker prior %.3f\n", Dim,
              estimate.msm_beta, kTruthBeta, estimate.msm_beta_std, estimate.rms, estimate.tracker_msm_beta);
  EXPECT_NEAR(estimate.msm_beta, kTruthBeta, 0.1);
  EXPECT_TRUE(estimate.valid);
}

}  // namespace
}  // namespace pliant::bridge_test
