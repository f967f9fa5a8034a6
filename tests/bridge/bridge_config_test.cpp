// Configurations through pliant.h: defaults equal the core's, the size query suffices for every
// layout at every block alignment, and 2D and 3D objects run the whole loop.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "bridge_fixture.hpp"
#include "pliant/core/grasp_guard.hpp"
#include "pliant/core/msm_model.hpp"
#include "pliant/core/online_deformability.hpp"
#include "pliant/core/tracker.hpp"

namespace pliant::bridge_test {
namespace {

bool same(double a, double b) { return (std::isnan(a) && std::isnan(b)) || a == b; }

TEST(BridgeDefaults, AreTheCoresDefaults) {
  pliant_config_t c;
  ASSERT_EQ(pliant_config_init_default(&c), PLIANT_OK);
  EXPECT_EQ(c.dim, 3u);
  EXPECT_EQ(c.particle_count, 0u);
  EXPECT_EQ(c.rest_positions, nullptr);
  EXPECT_EQ(c.masses, nullptr);
  EXPECT_EQ(c.fixed, nullptr);

  const ClusterConfig clusters;
  EXPECT_EQ(c.clusters.layout, static_cast<std::uint8_t>(clusters.layout));
  EXPECT_EQ(c.clusters.radius_factor, clusters.radius_factor);
  EXPECT_EQ(c.clusters.k, clusters.k);
  EXPECT_EQ(c.clusters.block_cols, clusters.block_cols);
  EXPECT_EQ(c.clusters.block_rows, clusters.block_rows);

  const MsmParams<3, double> msm;
  EXPECT_EQ(c.msm.msm_alpha, msm.msm_alpha);
  EXPECT_EQ(c.msm.msm_beta, 0.5);
  EXPECT_EQ(c.msm.gravity[2], 0.0);
  EXPECT_EQ(c.msm.velocity_damping, msm.velocity_damping);
  EXPECT_EQ(c.msm.driven_mass_factor, 1.0);

  const TrackerConfig tracker;
  EXPECT_EQ(c.tracker.tukey_c, tracker.tukey_c);
  EXPECT_EQ(c.tracker.min_residual_scale, tracker.min_residual_scale);
  EXPECT_EQ(c.tracker.observation_gain, tracker.observation_gain);
  EXPECT_EQ(c.tracker.projection_iterations, tracker.projection_iterations);
  EXPECT_EQ(c.tracker.max_unobserved_frames, tracker.max_unobserved_frames);

  const OnlineDeformabilityConfig estimator;
  EXPECT_TRUE(c.estimator.enabled);
  EXPECT_EQ(c.estimator.candidates, estimator.candidates);
  EXPECT_EQ(c.estimator.forgetting, estimator.forgetting);
  EXPECT_EQ(c.estimator.alpha_candidates, estimator.alpha_candidates);
  EXPECT_EQ(c.estimator.alpha_min, estimator.alpha_min);
  EXPECT_EQ(c.estimator.step_candidates, estimator.step_candidates);
  EXPECT_EQ(c.estimator.equilibrium_iterations, estimator.equilibrium_iterations);
  EXPECT_EQ(c.estimator.equilibrium_tolerance, estimator.equilibrium_tolerance);
  EXPECT_TRUE(c.estimator.feed_back_beta);

  const GraspGuardConfig g;
  const pliant_guard_config_t& b = c.guard;
  EXPECT_TRUE(b.enabled);
  EXPECT_TRUE(same(b.max_strain, g.max_strain));
  EXPECT_TRUE(same(b.max_indentation_m, g.max_indentation_m));
  EXPECT_TRUE(same(b.max_force_n, g.max_force_n));
  EXPECT_TRUE(same(b.nominal_force_n, g.nominal_force_n));
  EXPECT_TRUE(same(b.contact_width_m, g.contact_width_m));
  EXPECT_TRUE(same(b.contact_force_n, g.contact_force_n));
  EXPECT_TRUE(same(b.contact_width_tolerance, g.contact_width_tolerance));
  EXPECT_TRUE(same(b.max_width_m, g.max_width_m));
  EXPECT_EQ(b.force_source, static_cast<std::uint8_t>(g.force_source));
  EXPECT_TRUE(same(b.gripper_timeout_s, g.gripper_timeout_s));
  EXPECT_TRUE(same(b.wrench_timeout_s, g.wrench_timeout_s));
  EXPECT_TRUE(same(b.camera_timeout_s, g.camera_timeout_s));
  EXPECT_TRUE(same(b.estimate_timeout_s, g.estimate_timeout_s));
  EXPECT_TRUE(same(b.cycle_timeout_s, g.cycle_timeout_s));
  EXPECT_TRUE(same(b.clock_tolerance_s, g.clock_tolerance_s));
  EXPECT_EQ(b.wrench_frozen_samples, g.wrench_frozen_samples);
  EXPECT_EQ(b.gripper_fault_mask, g.gripper_fault_mask);
  EXPECT_EQ(b.wrench_fault_mask, g.wrench_fault_mask);
  EXPECT_EQ(b.camera_fault_mask, g.camera_fault_mask);
  for (int s = 0; s < kGuardSourceCount; ++s)
    EXPECT_EQ(b.fault_verdict[s], static_cast<std::uint8_t>(g.fault_verdict[s]));
  EXPECT_EQ(b.uncertain_estimate_verdict, static_cast<std::uint8_t>(g.uncertain_estimate_verdict));
  EXPECT_EQ(b.exceeded_stop_action, static_cast<std::uint8_t>(g.exceeded_stop_action));
  EXPECT_EQ(b.fault_stop_action, static_cast<std::uint8_t>(g.fault_stop_action));
  EXPECT_EQ(b.latch_stop, g.latch_stop);
  EXPECT_TRUE(same(b.hysteresis_margin, g.hysteresis_margin));
  EXPECT_EQ(b.clear_samples, g.clear_samples);
  EXPECT_TRUE(same(b.stop_overshoot, g.stop_overshoot));
  EXPECT_TRUE(same(b.confidence_k, g.confidence_k));
  EXPECT_TRUE(same(b.max_beta_std, g.max_beta_std));
  EXPECT_TRUE(same(b.slip_cutoff_hz, g.slip_cutoff_hz));
  EXPECT_TRUE(same(b.slip_ratio, g.slip_ratio));
  EXPECT_TRUE(same(b.slip_floor_n, g.slip_floor_n));
  EXPECT_TRUE(same(b.slip_ceiling_n, g.slip_ceiling_n));
  EXPECT_TRUE(same(b.slip_force_rate_per_s, g.slip_force_rate_per_s));
  EXPECT_TRUE(same(b.force_fit_spacing_m, g.force_fit_spacing_m));
  EXPECT_TRUE(same(b.force_fit_forgetting, g.force_fit_forgetting));
  EXPECT_TRUE(same(b.force_model_min_closure_m, g.force_model_min_closure_m));
  EXPECT_EQ(b.prediction_beta_points, g.prediction_beta_points);
  EXPECT_EQ(b.prediction_closure_points, g.prediction_closure_points);
  EXPECT_EQ(b.prediction_refine_steps, g.prediction_refine_steps);
  EXPECT_TRUE(same(b.prediction_max_closure_m, g.prediction_max_closure_m));
  EXPECT_EQ(b.relax_max_iterations, g.relax_max_iterations);
  EXPECT_TRUE(same(b.relax_tolerance, g.relax_tolerance));
  EXPECT_EQ(b.squeeze_axis[0], 0.0);
  EXPECT_EQ(b.jaw_a_count, 0u);
  EXPECT_EQ(b.contact_band, (GraspObject<3, double>{}.contact_band));
}

struct LayoutCase {
  std::string name;
  std::uint32_t dim;
  std::uint8_t layout;
  bool estimator;
  bool guard;
};

std::string layout_name(const ::testing::TestParamInfo<LayoutCase>& info) { return info.param.name; }

class BridgeLayout : public ::testing::TestWithParam<LayoutCase> {};

// The queried size is enough at any block alignment, and init uses the configured pieces.
TEST_P(BridgeLayout, QueriedSizeSufficesAtAnyAlignment) {
  const LayoutCase& param = GetParam();
  LatticeObject object(param.dim, param.dim == 2 ? 8 : 4, 4, 3);
  object.drive_jaws();
  pliant_config_t config = object.config();
  config.clusters.layout = param.layout;
  config.clusters.k = 6;
  config.clusters.grid_cols = object.nx;
  config.clusters.grid_rows = object.ny;
  config.clusters.grid_layers = object.nz;
  config.clusters.block_layers = param.dim == 3 ? 2 : 1;
  config.estimator.enabled = param.estimator;
  config.guard.enabled = param.guard;
  std::size_t bytes = 0;
  ASSERT_EQ(pliant_workspace_size(&config, &bytes), PLIANT_OK);
  for (std::size_t offset : {0u, 1u, 3u, 8u, 17u, 63u}) {
    Instance instance(config, offset);
    ASSERT_EQ(instance.status, PLIANT_OK) << "offset " << offset << ": " << pliant_status_name(instance.status);
    ASSERT_EQ(instance.bytes, bytes);
    pliant_info_t info;
    ASSERT_EQ(pliant_get_info(instance.pliant, &info), PLIANT_OK);
    EXPECT_EQ(info.dim, param.dim);
    EXPECT_EQ(info.particle_count, object.count());
    EXPECT_EQ(info.workspace_bytes, bytes);
    EXPECT_EQ(info.scalar_bytes, sizeof(Scalar));
    EXPECT_EQ(info.estimator_enabled, param.estimator);
    EXPECT_EQ(info.guard_enabled, param.guard);
    EXPECT_NEAR(info.spacing_m, object.h, 1e-6);
    if (param.layout == PLIANT_CLUSTERS_GRID_BLOCKS) {
      const std::uint32_t expected = param.dim == 3 ? 2u * 3u * 2u : 6u * 3u;
      EXPECT_EQ(info.cluster_count, expected);
    } else {
      EXPECT_EQ(info.cluster_count, object.count());
    }
    if (param.guard) {
      EXPECT_NEAR(info.guard_extent_m, object.h * (object.nx - 1), 1e-6);
      EXPECT_GT(info.guard_relaxation_steps, 0);
    }
    // One frame through, to touch every buffer.
    ASSERT_EQ(pliant_push_observations(instance.pliant, 0.0, object.rest.data(), nullptr), PLIANT_OK);
    ASSERT_EQ(pliant_step_tracker(instance.pliant, 1.0 / 30), PLIANT_OK);
    if (param.estimator) {
      EXPECT_EQ(pliant_update_estimate(instance.pliant), PLIANT_OK);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(All, BridgeLayout,
                         ::testing::Values(LayoutCase{"radius_3d", 3, PLIANT_CLUSTERS_RADIUS, true, true},
                                           LayoutCase{"radius_2d", 2, PLIANT_CLUSTERS_RADIUS, true, true},
                                           LayoutCase{"k_nearest_3d", 3, PLIANT_CLUSTERS_K_NEAREST, true, true},
                                           LayoutCase{"k_nearest_2d", 2, PLIANT_CLUSTERS_K_NEAREST, true, true},
                                           LayoutCase{"grid_3d", 3, PLIANT_CLUSTERS_GRID_BLOCKS, true, true},
                                           LayoutCase{"grid_2d", 2, PLIANT_CLUSTERS_GRID_BLOCKS, true, true},
                                           LayoutCase{"tracker_only_3d", 3, PLIANT_CLUSTERS_RADIUS, false, false},
                                           LayoutCase{"no_guard_2d", 2, PLIANT_CLUSTERS_RADIUS, true, false},
                                           LayoutCase{"no_estimator_3d", 3, PLIANT_CLUSTERS_GRID_BLOCKS, false, true}),
                         layout_name);

// Sizes for the docs: printed, and checked to grow with what is switched on.
TEST(BridgeLayout, FootprintOfTheExamples) {
  for (std::uint32_t dim : {2u, 3u}) {
    LatticeObject object(dim, dim == 2 ? 8 : 4, 4, 3);
    object.drive_jaws();
    pliant_config_t config = object.config();
    config.guard.prediction_beta_points = 11;
    config.guard.prediction_closure_points = 32;
    std::size_t full = 0, tracker_only = 0, no_estimator = 0;
    ASSERT_EQ(pliant_workspace_size(&config, &full), PLIANT_OK);
    config.estimator.enabled = false;
    ASSERT_EQ(pliant_workspace_size(&config, &no_estimator), PLIANT_OK);
    config.guard.enabled = false;
    ASSERT_EQ(pliant_workspace_size(&config, &tracker_only), PLIANT_OK);
    EXPECT_LT(tracker_only, no_estimator);
    EXPECT_LT(no_estimator, full);
    std::printf(
        "[footprint] %uD, %u particles, %zu-byte scalar: all %zu B, without estimator %zu B, tracker only %zu B\n", dim,
        object.count(), sizeof(Scalar), full, no_estimator, tracker_only);
  }
}

// The whole loop in 2D and 3D: frames, contact, estimate, guard; results plausible.
class BridgeLoop : public ::testing::TestWithParam<std::uint32_t> {};

TEST_P(BridgeLoop, SqueezeRunsThroughEveryCall) {
  const std::uint32_t dim = GetParam();
  LatticeObject object(dim, 4, 4, 3);
  object.drive_jaws();
  pliant_config_t config = object.config();
  config.guard.max_strain = 0.1;
  Instance instance(config);
  ASSERT_EQ(instance.status, PLIANT_OK);
  pliant_t* p = instance.pliant;
  const int n = static_cast<int>(object.count());
  const double extent = object.h * (object.nx - 1);
  std::vector<float> frame(object.rest.size());
  std::vector<float> targets(object.drivable.size() * dim);
  double now = 0;
  pliant_verdict_t verdict{};
  bool saw_ok = false, saw_limit = false;
  int frames = 0;
  double last_frame_s = kNaN;
  for (int cycle = 0; cycle < 1500 && verdict.verdict != PLIANT_VERDICT_STOP; ++cycle, now += 0.001) {
    const double width = extent + 0.001 - 0.004 * now;
    const double closure = std::max(0.0, extent - width);
    if (cycle % 33 == 0) {
      const double strain = closure / extent;
      for (int i = 0; i < n; ++i) {
        const double x = object.rest[static_cast<std::size_t>(i) * dim];
        frame[static_cast<std::size_t>(i) * dim] = static_cast<float>(0.5 * extent + (x - 0.5 * extent) * (1 - strain));
        for (std::uint32_t d = 1; d < dim; ++d) {
          frame[static_cast<std::size_t>(i) * dim + d] = object.rest[static_cast<std::size_t>(i) * dim + d];
        }
      }
      for (std::size_t k = 0; k < object.drivable.size(); ++k) {
        for (std::uint32_t d = 0; d < dim; ++d)
          targets[k * dim + d] = frame[static_cast<std::size_t>(object.drivable[k]) * dim + d];
      }
      ASSERT_EQ(pliant_push_observations(p, now, frame.data(), nullptr), PLIANT_OK);
      ASSERT_EQ(pliant_push_tool_contact(p, object.drivable.data(), targets.data(),
                                         closure > 0 ? static_cast<std::uint32_t>(object.drivable.size()) : 0u),
                PLIANT_OK);
      ASSERT_EQ(pliant_step_tracker(p, 0.033), PLIANT_OK);
      ASSERT_EQ(pliant_update_estimate(p), PLIANT_OK);
      ++frames;
      last_frame_s = now;
    }
    const pliant_guard_input_t in = fresh_input(now, width, 2000 * closure);
    ASSERT_EQ(pliant_guard_update(p, &in, &verdict), PLIANT_OK);
    saw_ok = saw_ok || verdict.verdict == PLIANT_VERDICT_OK;
    saw_limit = saw_limit || verdict.verdict == PLIANT_VERDICT_LIMIT;
  }
  EXPECT_TRUE(saw_ok);
  EXPECT_TRUE(saw_limit);
  EXPECT_EQ(verdict.verdict, PLIANT_VERDICT_STOP);
  std::vector<float> tracked(object.rest.size());
  std::vector<std::uint8_t> status(object.count());
  std::uint32_t index = 0;
  ASSERT_EQ(pliant_get_tracked(p, tracked.data(), status.data(), object.count(), &index), PLIANT_OK);
  EXPECT_EQ(index, static_cast<std::uint32_t>(frames));
  for (std::size_t i = 0; i < tracked.size(); ++i) EXPECT_NEAR(tracked[i], frame[i], 2e-4) << i;
  pliant_deformation_t deformation;
  ASSERT_EQ(pliant_get_deformation(p, &deformation), PLIANT_OK);
  EXPECT_TRUE(deformation.valid);
  EXPECT_EQ(deformation.stamp_s, last_frame_s);
  pliant_estimate_t estimate;
  ASSERT_EQ(pliant_get_estimate(p, &estimate), PLIANT_OK);
  EXPECT_EQ(estimate.frames, static_cast<std::uint32_t>(frames));
  const pliant_counters_t counters = instance.counters();
  EXPECT_EQ(counters.calls_rejected, 0u);
  EXPECT_EQ(counters.tracker_frames, static_cast<std::uint32_t>(frames));

  // A new grasp: rest shape, no contact, a fresh frame gives an OK verdict again.
  ASSERT_EQ(pliant_reset_grasp(p), PLIANT_OK);
  ASSERT_EQ(pliant_get_tracked(p, tracked.data(), nullptr, object.count(), &index), PLIANT_OK);
  EXPECT_EQ(index, 0u);
  for (std::size_t i = 0; i < tracked.size(); ++i) EXPECT_FLOAT_EQ(tracked[i], object.rest[i]);
  ASSERT_EQ(pliant_get_deformation(p, &deformation), PLIANT_OK);
  EXPECT_FALSE(deformation.valid) << "the old grasp's strain must not reach the new grasp";
  {
    const pliant_guard_input_t in = fresh_input(now, extent + 0.01, 0);
    ASSERT_EQ(pliant_guard_update(p, &in, &verdict), PLIANT_OK);
    EXPECT_NE(verdict.fault_sources & (1u << PLIANT_SOURCE_CAMERA), 0u);
    EXPECT_NE(verdict.verdict, PLIANT_VERDICT_OK);
  }
  EXPECT_EQ(pliant_push_observations(p, now - 1.0, object.rest.data(), nullptr), PLIANT_ERROR_STAMP_ORDER);
  for (int k = 0; k < 10; ++k, now += 0.033) {
    ASSERT_EQ(pliant_push_observations(p, now, object.rest.data(), nullptr), PLIANT_OK);
    ASSERT_EQ(pliant_step_tracker(p, 0.033), PLIANT_OK);
    ASSERT_EQ(pliant_update_estimate(p), PLIANT_OK);
    for (int c = 0; c < 33; ++c) {
      const pliant_guard_input_t in = fresh_input(now + 0.001 * c, extent + 0.01, 0);
      ASSERT_EQ(pliant_guard_update(p, &in, &verdict), PLIANT_OK);
    }
  }
  EXPECT_EQ(verdict.verdict, PLIANT_VERDICT_OK) << pliant_reason_name(verdict.reason);
  EXPECT_FALSE(verdict.in_contact);
}

INSTANTIATE_TEST_SUITE_P(Dims, BridgeLoop, ::testing::Values(2u, 3u),
                         [](const ::testing::TestParamInfo<std::uint32_t>& dims) {
                           return std::to_string(dims.param) + "d";
                         });

// Frames the estimator misses are counted and their time goes into the next update.
TEST(BridgeEstimate, SkippedFramesAreCounted) {
  LatticeObject object(3, 4, 4, 3);
  object.drive_jaws();
  Instance instance(object.config());
  ASSERT_EQ(instance.status, PLIANT_OK);
  for (int k = 0; k < 5; ++k) {
    ASSERT_EQ(pliant_push_observations(instance.pliant, 0.033 * k, object.rest.data(), nullptr), PLIANT_OK);
    ASSERT_EQ(pliant_step_tracker(instance.pliant, 0.033), PLIANT_OK);
    if (k == 4) {
      ASSERT_EQ(pliant_update_estimate(instance.pliant), PLIANT_OK);
    }
  }
  const pliant_counters_t counters = instance.counters();
  EXPECT_EQ(counters.estimator_frames_skipped, 4u);
  EXPECT_EQ(counters.estimator_frames, 1u);
  EXPECT_EQ(counters.tracker_frames, 5u);
}

}  // namespace
}  // namespace pliant::bridge_test
