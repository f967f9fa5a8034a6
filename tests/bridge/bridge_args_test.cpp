// Malformed arguments at every entry point of pliant.h: each is refused with its status,
// changes nothing, and (when there is an instance) is counted once in calls_rejected.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>

#include "bridge_fixture.hpp"

namespace pliant::bridge_test {
namespace {

// --- config and ABI --------------------------------------------------------------------------

TEST(BridgeAbi, DefaultsNeedTheCallersAbi) {
  pliant_config_t config;
  pliant_abi_t abi = pliant_abi_of_caller();
  EXPECT_EQ(pliant_config_init_default_checked(nullptr, &abi), PLIANT_ERROR_NULL_ARGUMENT);
  EXPECT_EQ(pliant_config_init_default_checked(&config, nullptr), PLIANT_ERROR_NULL_ARGUMENT);
  std::memset(&config, 0xab, sizeof config);
  for (int field = 0; field < 8; ++field) {
    pliant_abi_t wrong = abi;
    reinterpret_cast<std::uint32_t*>(&wrong)[field] += 1;  // pliant_abi_t is eight uint32_t
    EXPECT_EQ(pliant_config_init_default_checked(&config, &wrong), PLIANT_ERROR_ABI_MISMATCH) << field;
    EXPECT_EQ(reinterpret_cast<unsigned char*>(&config)[0], 0xab) << "written despite the mismatch";
  }
  EXPECT_EQ(pliant_config_init_default(&config), PLIANT_OK);
  EXPECT_EQ(config.abi.version, PLIANT_ABI_VERSION);
  EXPECT_EQ(pliant_abi_version(), PLIANT_ABI_VERSION);
  EXPECT_EQ(pliant_version(), PLIANT_VERSION_NUMBER);
}

TEST(BridgeAbi, ConfigFromAnotherHeaderIsRefused) {
  LatticeObject object(3, 4, 4, 3);
  std::size_t bytes = 1;
  for (int field = 0; field < 8; ++field) {
    pliant_config_t config = object.config();
    reinterpret_cast<std::uint32_t*>(&config.abi)[field] ^= 4u;
    EXPECT_EQ(pliant_workspace_size(&config, &bytes), PLIANT_ERROR_ABI_MISMATCH) << field;
    EXPECT_EQ(bytes, 0u);
    std::vector<unsigned char> block(1 << 20);
    pliant_t* instance = reinterpret_cast<pliant_t*>(1);
    EXPECT_EQ(pliant_init(block.data(), block.size(), &config, &instance), PLIANT_ERROR_ABI_MISMATCH);
    EXPECT_EQ(instance, nullptr);
  }
  pliant_config_t zeroed{};  // never passed through pliant_config_init_default
  EXPECT_EQ(pliant_workspace_size(&zeroed, &bytes), PLIANT_ERROR_ABI_MISMATCH);
}

TEST(BridgeAbi, GuardInputInitChecksTheSize) {
  pliant_guard_input_t in;
  EXPECT_EQ(pliant_guard_input_init_checked(nullptr, sizeof in), PLIANT_ERROR_NULL_ARGUMENT);
  EXPECT_EQ(pliant_guard_input_init_checked(&in, sizeof in - 8), PLIANT_ERROR_ABI_MISMATCH);
  ASSERT_EQ(pliant_guard_input_init(&in), PLIANT_OK);
  EXPECT_TRUE(std::isnan(in.now_s));
  EXPECT_TRUE(std::isnan(in.gripper.width_m));
  EXPECT_FALSE(in.gripper.valid);
  EXPECT_EQ(in.deformation.source, PLIANT_SOURCE_BRIDGE);
  EXPECT_EQ(in.estimate.source, PLIANT_SOURCE_BRIDGE);
}

struct ConfigCase {
  const char* name;
  std::function<void(pliant_config_t&)> mutate;
  pliant_status_t expected;
};

std::vector<ConfigCase> bad_configs() {
  return {
      {"dim 0", [](pliant_config_t& c) { c.dim = 0; }, PLIANT_ERROR_INVALID_ARGUMENT},
      {"dim 1", [](pliant_config_t& c) { c.dim = 1; }, PLIANT_ERROR_INVALID_ARGUMENT},
      {"dim 4", [](pliant_config_t& c) { c.dim = 4; }, PLIANT_ERROR_INVALID_ARGUMENT},
      {"particle count 0", [](pliant_config_t& c) { c.particle_count = 0; }, PLIANT_ERROR_INVALID_ARGUMENT},
      {"particle count 1", [](pliant_config_t& c) { c.particle_count = 1; }, PLIANT_ERROR_INVALID_ARGUMENT},
      {"particle count huge", [](pliant_config_t& c) { c.particle_count = 0xffffffffu; },
       PLIANT_ERROR_INVALID_ARGUMENT},
      {"rest NULL", [](pliant_config_t& c) { c.rest_positions = nullptr; }, PLIANT_ERROR_NULL_ARGUMENT},
      {"drivable ids NULL", [](pliant_config_t& c) { c.drivable_ids = nullptr; }, PLIANT_ERROR_NULL_ARGUMENT},
      {"drivable count > N", [](pliant_config_t& c) { c.drivable_count = c.particle_count + 1; },
       PLIANT_ERROR_INVALID_ARGUMENT},
      {"cluster layout 3", [](pliant_config_t& c) { c.clusters.layout = 3; }, PLIANT_ERROR_INVALID_ARGUMENT},
      {"radius factor 0", [](pliant_config_t& c) { c.clusters.radius_factor = 0; }, PLIANT_ERROR_INVALID_ARGUMENT},
      {"radius factor NaN", [](pliant_config_t& c) { c.clusters.radius_factor = kNaN; }, PLIANT_ERROR_INVALID_ARGUMENT},
      {"k 0",
       [](pliant_config_t& c) {
         c.clusters.layout = PLIANT_CLUSTERS_K_NEAREST;
         c.clusters.k = 0;
       },
       PLIANT_ERROR_INVALID_ARGUMENT},
      {"k 65",
       [](pliant_config_t& c) {
         c.clusters.layout = PLIANT_CLUSTERS_K_NEAREST;
         c.clusters.k = 65;
       },
       PLIANT_ERROR_INVALID_ARGUMENT},
      {"grid not N",
       [](pliant_config_t& c) {
         c.clusters.layout = PLIANT_CLUSTERS_GRID_BLOCKS;
         c.clusters.grid_cols = 4;
         c.clusters.grid_rows = 4;
         c.clusters.grid_layers = 2;
       },
       PLIANT_ERROR_INVALID_ARGUMENT},
      {"grid block larger than grid",
       [](pliant_config_t& c) {
         c.clusters.layout = PLIANT_CLUSTERS_GRID_BLOCKS;
         c.clusters.grid_cols = 4;
         c.clusters.grid_rows = 4;
         c.clusters.grid_layers = 3;
         c.clusters.block_cols = 5;
       },
       PLIANT_ERROR_INVALID_ARGUMENT},
      {"msm_alpha 0", [](pliant_config_t& c) { c.msm.msm_alpha = 0; }, PLIANT_ERROR_INVALID_ARGUMENT},
      {"msm_alpha 1.5", [](pliant_config_t& c) { c.msm.msm_alpha = 1.5; }, PLIANT_ERROR_INVALID_ARGUMENT},
      {"msm_alpha NaN", [](pliant_config_t& c) { c.msm.msm_alpha = kNaN; }, PLIANT_ERROR_NON_FINITE},
      {"msm_beta -0.1", [](pliant_config_t& c) { c.msm.msm_beta = -0.1; }, PLIANT_ERROR_INVALID_ARGUMENT},
      {"gravity inf", [](pliant_config_t& c) { c.msm.gravity[2] = kInf; }, PLIANT_ERROR_NON_FINITE},
      {"damping -1", [](pliant_config_t& c) { c.msm.velocity_damping = -1; }, PLIANT_ERROR_INVALID_ARGUMENT},
      {"driven mass factor 0", [](pliant_config_t& c) { c.msm.driven_mass_factor = 0; }, PLIANT_ERROR_INVALID_MASS},
      {"tukey_c 0", [](pliant_config_t& c) { c.tracker.tukey_c = 0; }, PLIANT_ERROR_INVALID_ARGUMENT},
      {"min residual scale -1", [](pliant_config_t& c) { c.tracker.min_residual_scale = -1; },
       PLIANT_ERROR_INVALID_ARGUMENT},
      {"observation gain 0", [](pliant_config_t& c) { c.tracker.observation_gain = 0; }, PLIANT_ERROR_INVALID_ARGUMENT},
      {"observation gain 1.5", [](pliant_config_t& c) { c.tracker.observation_gain = 1.5; },
       PLIANT_ERROR_INVALID_ARGUMENT},
      {"projection iterations -1", [](pliant_config_t& c) { c.tracker.projection_iterations = -1; },
       PLIANT_ERROR_INVALID_ARGUMENT},
      {"projection iterations 65", [](pliant_config_t& c) { c.tracker.projection_iterations = 65; },
       PLIANT_ERROR_INVALID_ARGUMENT},
      {"max unobserved 0", [](pliant_config_t& c) { c.tracker.max_unobserved_frames = 0; },
       PLIANT_ERROR_INVALID_ARGUMENT},
      {"candidates 2", [](pliant_config_t& c) { c.estimator.candidates = 2; }, PLIANT_ERROR_INVALID_ARGUMENT},
      {"candidates huge", [](pliant_config_t& c) { c.estimator.candidates = 1 << 30; }, PLIANT_ERROR_INVALID_ARGUMENT},
      {"forgetting 0", [](pliant_config_t& c) { c.estimator.forgetting = 0; }, PLIANT_ERROR_INVALID_ARGUMENT},
      {"alpha rows 0", [](pliant_config_t& c) { c.estimator.alpha_candidates = 0; }, PLIANT_ERROR_INVALID_ARGUMENT},
      {"alpha rows 9", [](pliant_config_t& c) { c.estimator.alpha_candidates = 9; }, PLIANT_ERROR_INVALID_ARGUMENT},
      {"alpha_min 1", [](pliant_config_t& c) { c.estimator.alpha_min = 1; }, PLIANT_ERROR_INVALID_ARGUMENT},
      {"alpha_min NaN", [](pliant_config_t& c) { c.estimator.alpha_min = std::nan(""); },
       PLIANT_ERROR_INVALID_ARGUMENT},
      {"step rows 0", [](pliant_config_t& c) { c.estimator.step_candidates = 0; }, PLIANT_ERROR_INVALID_ARGUMENT},
      {"step rows 5", [](pliant_config_t& c) { c.estimator.step_candidates = 5; }, PLIANT_ERROR_INVALID_ARGUMENT},
      {"equilibrium iterations -1", [](pliant_config_t& c) { c.estimator.equilibrium_iterations = -1; },
       PLIANT_ERROR_INVALID_ARGUMENT},
      {"equilibrium iterations 4097", [](pliant_config_t& c) { c.estimator.equilibrium_iterations = 4097; },
       PLIANT_ERROR_INVALID_ARGUMENT},
      {"equilibrium tolerance 0",
       [](pliant_config_t& c) {
         c.estimator.equilibrium_iterations = 8;
         c.estimator.equilibrium_tolerance = 0;
       },
       PLIANT_ERROR_INVALID_ARGUMENT},
      {"equilibrium tolerance NaN",
       [](pliant_config_t& c) {
         c.estimator.equilibrium_iterations = 8;
         c.estimator.equilibrium_tolerance = kNaN;
       },
       PLIANT_ERROR_INVALID_ARGUMENT},
      {"forgetting 1.5", [](pliant_config_t& c) { c.estimator.forgetting = 1.5; }, PLIANT_ERROR_INVALID_ARGUMENT},
      {"feed back sd NaN", [](pliant_config_t& c) { c.estimator.feed_back_max_std = kNaN; },
       PLIANT_ERROR_INVALID_ARGUMENT},
      {"fault verdict ok", [](pliant_config_t& c) { c.guard.fault_verdict[PLIANT_SOURCE_WRENCH] = PLIANT_VERDICT_OK; },
       PLIANT_ERROR_INVALID_ARGUMENT},
      {"fault verdict 3", [](pliant_config_t& c) { c.guard.fault_verdict[PLIANT_SOURCE_CLOCK] = 3; },
       PLIANT_ERROR_INVALID_ARGUMENT},
      {"uncertain verdict 3", [](pliant_config_t& c) { c.guard.uncertain_estimate_verdict = 3; },
       PLIANT_ERROR_INVALID_ARGUMENT},
      {"stop action 2", [](pliant_config_t& c) { c.guard.exceeded_stop_action = 2; }, PLIANT_ERROR_INVALID_ARGUMENT},
      {"fault stop action 7", [](pliant_config_t& c) { c.guard.fault_stop_action = 7; }, PLIANT_ERROR_INVALID_ARGUMENT},
      {"force source 2", [](pliant_config_t& c) { c.guard.force_source = 2; }, PLIANT_ERROR_INVALID_ARGUMENT},
      {"squeeze axis zero", [](pliant_config_t& c) { c.guard.squeeze_axis[0] = 0; }, PLIANT_ERROR_INVALID_ARGUMENT},
      {"squeeze axis NaN", [](pliant_config_t& c) { c.guard.squeeze_axis[1] = kNaN; }, PLIANT_ERROR_NON_FINITE},
      {"jaw a ids NULL", [](pliant_config_t& c) { c.guard.jaw_a_ids = nullptr; }, PLIANT_ERROR_NULL_ARGUMENT},
      {"jaw b count > N", [](pliant_config_t& c) { c.guard.jaw_b_count = c.particle_count + 1; },
       PLIANT_ERROR_INVALID_ARGUMENT},
      {"max strain 0", [](pliant_config_t& c) { c.guard.max_strain = 0; }, PLIANT_ERROR_INVALID_ARGUMENT},
      {"max force NaN", [](pliant_config_t& c) { c.guard.max_force_n = kNaN; }, PLIANT_ERROR_INVALID_ARGUMENT},
      {"clear samples 0", [](pliant_config_t& c) { c.guard.clear_samples = 0; }, PLIANT_ERROR_INVALID_ARGUMENT},
      {"beta points 1", [](pliant_config_t& c) { c.guard.prediction_beta_points = 1; }, PLIANT_ERROR_INVALID_ARGUMENT},
      {"motor current without gain", [](pliant_config_t& c) { c.guard.force_source = PLIANT_FORCE_MOTOR_CURRENT; },
       PLIANT_ERROR_INVALID_ARGUMENT},
  };
}

TEST(BridgeConfig, EveryMalformedFieldIsRefusedBySizeAndInit) {
  LatticeObject object(3, 4, 4, 3);
  object.drive_jaws();
  for (const ConfigCase& bad : bad_configs()) {
    pliant_config_t config = object.config();
    bad.mutate(config);
    std::size_t bytes = 7;
    EXPECT_EQ(pliant_workspace_size(&config, &bytes), bad.expected) << bad.name;
    EXPECT_EQ(bytes, 0u) << bad.name;
    std::vector<unsigned char> block(1 << 20);
    pliant_t* instance = reinterpret_cast<pliant_t*>(1);
    EXPECT_EQ(pliant_init(block.data(), block.size(), &config, &instance), bad.expected) << bad.name;
    EXPECT_EQ(instance, nullptr) << bad.name;
  }
}

TEST(BridgeConfig, BadDataFoundOnlyByBuildingIsRefusedByInit) {
  LatticeObject object(3, 4, 4, 3);
  object.drive_jaws();
  std::vector<unsigned char> block(1 << 21);
  pliant_t* instance = nullptr;
  {
    std::vector<float> rest = object.rest;
    rest[3] = rest[0];  // particle 1 on particle 0
    rest[4] = rest[1];
    rest[5] = rest[2];
    pliant_config_t config = object.config();
    config.rest_positions = rest.data();
    std::size_t bytes = 0;
    EXPECT_EQ(pliant_workspace_size(&config, &bytes), PLIANT_ERROR_INVALID_ARGUMENT);  // no reason without memory
    EXPECT_EQ(pliant_init(block.data(), block.size(), &config, &instance), PLIANT_ERROR_DUPLICATE_REST);
    EXPECT_EQ(instance, nullptr);
  }
  {
    std::vector<float> rest = object.rest;
    rest[7] = std::numeric_limits<float>::infinity();
    pliant_config_t config = object.config();
    config.rest_positions = rest.data();
    std::size_t bytes = 0;
    EXPECT_EQ(pliant_workspace_size(&config, &bytes), PLIANT_ERROR_NON_FINITE);
    EXPECT_EQ(pliant_init(block.data(), block.size(), &config, &instance), PLIANT_ERROR_NON_FINITE);
  }
  {
    std::vector<float> masses(object.count(), 1.0f);
    masses[5] = -1.0f;
    pliant_config_t config = object.config();
    config.masses = masses.data();
    std::size_t bytes = 0;
    EXPECT_EQ(pliant_workspace_size(&config, &bytes), PLIANT_ERROR_INVALID_MASS);
    masses[5] = std::numeric_limits<float>::quiet_NaN();
    EXPECT_EQ(pliant_init(block.data(), block.size(), &config, &instance), PLIANT_ERROR_INVALID_MASS);
  }
  {
    std::vector<std::int32_t> ids = object.drivable;
    ids[3] = -1;
    pliant_config_t config = object.config();
    config.drivable_ids = ids.data();
    EXPECT_EQ(pliant_init(block.data(), block.size(), &config, &instance), PLIANT_ERROR_INVALID_ARGUMENT);
    ids[3] = static_cast<std::int32_t>(object.count());
    EXPECT_EQ(pliant_init(block.data(), block.size(), &config, &instance), PLIANT_ERROR_INVALID_ARGUMENT);
  }
  {
    std::vector<std::int32_t> jaw = object.jaw_b;
    jaw[0] = object.jaw_a[0];  // one particle on both jaws
    pliant_config_t config = object.config();
    config.guard.jaw_b_ids = jaw.data();
    EXPECT_EQ(pliant_init(block.data(), block.size(), &config, &instance), PLIANT_ERROR_INVALID_ARGUMENT);
    jaw[0] = 1000;
    EXPECT_EQ(pliant_init(block.data(), block.size(), &config, &instance), PLIANT_ERROR_INVALID_ARGUMENT);
  }
  {
    // Every particle drivable: the estimator has nothing to score.
    std::vector<std::int32_t> all(object.count());
    for (std::size_t i = 0; i < all.size(); ++i) all[i] = static_cast<std::int32_t>(i);
    pliant_config_t config = object.config();
    config.drivable_ids = all.data();
    config.drivable_count = object.count();
    EXPECT_EQ(pliant_init(block.data(), block.size(), &config, &instance), PLIANT_ERROR_NO_FREE_PARTICLES);
    config.estimator.enabled = false;
    EXPECT_EQ(pliant_init(block.data(), block.size(), &config, &instance), PLIANT_OK);
  }
  EXPECT_EQ(instance != nullptr, true);
}

TEST(BridgeConfig, InitRefusesNullsAndShortBlocks) {
  LatticeObject object(2, 8, 4, 1);
  const pliant_config_t config = object.config();
  std::size_t bytes = 0;
  ASSERT_EQ(pliant_workspace_size(&config, &bytes), PLIANT_OK);
  std::size_t refused = 5;
  EXPECT_EQ(pliant_workspace_size(nullptr, &refused), PLIANT_ERROR_NULL_ARGUMENT);
  EXPECT_EQ(refused, 0u);
  EXPECT_EQ(pliant_workspace_size(&config, nullptr), PLIANT_ERROR_NULL_ARGUMENT);
  std::vector<unsigned char> block(bytes);
  pliant_t* instance = nullptr;
  EXPECT_EQ(pliant_init(nullptr, bytes, &config, &instance), PLIANT_ERROR_NULL_ARGUMENT);
  EXPECT_EQ(pliant_init(block.data(), bytes, nullptr, &instance), PLIANT_ERROR_NULL_ARGUMENT);
  EXPECT_EQ(pliant_init(block.data(), bytes, &config, nullptr), PLIANT_ERROR_NULL_ARGUMENT);
  for (std::size_t size : {std::size_t{0}, std::size_t{16}, bytes / 2, bytes - 1}) {
    EXPECT_EQ(pliant_init(block.data(), size, &config, &instance), PLIANT_ERROR_MEMORY_TOO_SMALL) << size;
    EXPECT_EQ(instance, nullptr);
  }
  EXPECT_EQ(pliant_init(block.data(), bytes, &config, &instance), PLIANT_OK);
}

// --- calls on no instance -----------------------------------------------------------------

// Every instance call: NULL instance -> NULL_ARGUMENT; a block never initialised (or whose init
// failed) -> NOT_INITIALIZED. Nothing can be counted (there is no instance).
TEST(BridgeCalls, NoInstance) {
  std::vector<unsigned char> zeroed(4096, 0);
  pliant_t* never = reinterpret_cast<pliant_t*>(zeroed.data());
  float positions[12] = {};
  std::uint8_t status[4] = {};
  pliant_info_t info;
  pliant_estimate_t estimate;
  pliant_deformation_t deformation;
  pliant_counters_t counters;
  pliant_guard_input_t in = fresh_input(0, 0.03, 0);
  pliant_verdict_t verdict;
  const std::int32_t id = 0;
  for (pliant_t* p : {static_cast<pliant_t*>(nullptr), never}) {
    const pliant_status_t expected = p == nullptr ? PLIANT_ERROR_NULL_ARGUMENT : PLIANT_ERROR_NOT_INITIALIZED;
    EXPECT_EQ(pliant_get_info(p, &info), expected);
    EXPECT_EQ(pliant_push_observations(p, 0.0, positions, nullptr), expected);
    EXPECT_EQ(pliant_push_tool_contact(p, &id, positions, 1), expected);
    EXPECT_EQ(pliant_step_tracker(p, 0.03), expected);
    EXPECT_EQ(pliant_get_tracked(p, positions, status, 4, nullptr), expected);
    EXPECT_EQ(pliant_update_estimate(p), expected);
    EXPECT_EQ(pliant_get_estimate(p, &estimate), expected);
    EXPECT_EQ(pliant_get_deformation(p, &deformation), expected);
    verdict.verdict = PLIANT_VERDICT_OK;
    EXPECT_EQ(pliant_guard_update(p, &in, &verdict), expected);
    EXPECT_EQ(verdict.verdict, PLIANT_VERDICT_STOP);
    EXPECT_EQ(verdict.reason, PLIANT_REASON_NOT_CONFIGURED);
    EXPECT_EQ(verdict.stop_action, PLIANT_STOP_FREEZE);
    EXPECT_EQ(pliant_reset_grasp_guard(p), expected);
    EXPECT_EQ(pliant_acknowledge_stop(p), expected);
    EXPECT_EQ(pliant_reset_grasp(p), expected);
    EXPECT_EQ(pliant_get_counters(p, &counters), expected);
  }
  EXPECT_EQ(pliant_counter_by_id(nullptr, 1, nullptr), PLIANT_ERROR_NULL_ARGUMENT);
  std::uint32_t value = 0;
  EXPECT_EQ(pliant_counter_by_id(nullptr, 1, &value), PLIANT_ERROR_NULL_ARGUMENT);
}

TEST(BridgeCalls, FailedInitLeavesNoUsableInstance) {
  LatticeObject object(3, 4, 4, 3);
  object.drive_jaws();
  pliant_config_t config = object.config();
  Instance good(config);
  ASSERT_EQ(good.status, PLIANT_OK);
  config.guard.max_strain = -1;  // refused by validation, before the block is touched
  pliant_t* again = nullptr;
  EXPECT_NE(pliant_init(good.block.data(), good.block.size(), &config, &again), PLIANT_OK);
  EXPECT_EQ(again, nullptr);
  EXPECT_EQ(pliant_step_tracker(good.pliant, 0.03), PLIANT_ERROR_BAD_STATE);  // still usable
  // A config that only the build refuses: the block is rebuilt from its start, so the old
  // instance is gone.
  std::vector<std::int32_t> jaw = object.jaw_b;
  jaw[0] = object.jaw_a[0];
  config = object.config();
  config.guard.jaw_b_ids = jaw.data();
  EXPECT_EQ(pliant_init(good.block.data(), good.block.size(), &config, &again), PLIANT_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(pliant_step_tracker(good.pliant, 0.03), PLIANT_ERROR_NOT_INITIALIZED);
}

// --- calls on an instance: each refusal counted once -------------------------------------

class BridgeRefusals : public ::testing::Test {
 protected:
  BridgeRefusals() : object_(3, 4, 4, 3) { object_.drive_jaws(); }
  void SetUp() override {
    instance_ = std::make_unique<Instance>(object_.config());
    ASSERT_EQ(instance_->status, PLIANT_OK);
    p_ = instance_->pliant;
  }

  // Runs `call`, expects `expected`, and that it was counted as the latest refusal of `call_id`.
  void expect_refused(const char* what, pliant_status_t got, pliant_status_t expected, std::uint8_t call_id) {
    const std::uint32_t before = rejected_;
    const pliant_counters_t counters = instance_->counters();
    EXPECT_EQ(got, expected) << what << ": " << pliant_status_name(got);
    EXPECT_EQ(counters.calls_rejected, before + 1) << what;
    EXPECT_EQ(counters.last_rejected_status, static_cast<std::uint8_t>(expected)) << what;
    EXPECT_EQ(counters.last_rejected_call, call_id) << what;
    rejected_ = counters.calls_rejected;
  }

  LatticeObject object_;
  std::unique_ptr<Instance> instance_;
  pliant_t* p_ = nullptr;
  std::uint32_t rejected_ = 0;
};

TEST_F(BridgeRefusals, PushObservations) {
  const float* rest = object_.rest.data();
  expect_refused("NaN stamp", pliant_push_observations(p_, kNaN, rest, nullptr), PLIANT_ERROR_NON_FINITE,
                 PLIANT_CALL_PUSH_OBSERVATIONS);
  expect_refused("inf stamp", pliant_push_observations(p_, kInf, rest, nullptr), PLIANT_ERROR_NON_FINITE,
                 PLIANT_CALL_PUSH_OBSERVATIONS);
  ASSERT_EQ(pliant_push_observations(p_, 1.0, rest, nullptr), PLIANT_OK);
  ASSERT_EQ(pliant_step_tracker(p_, 0.03), PLIANT_OK);
  expect_refused("same stamp", pliant_push_observations(p_, 1.0, rest, nullptr), PLIANT_ERROR_STAMP_ORDER,
                 PLIANT_CALL_PUSH_OBSERVATIONS);
  expect_refused("earlier stamp", pliant_push_observations(p_, 0.5, rest, nullptr), PLIANT_ERROR_STAMP_ORDER,
                 PLIANT_CALL_PUSH_OBSERVATIONS);
  // NULL positions and confidences are allowed (a frame without observation).
  EXPECT_EQ(pliant_push_observations(p_, 1.1, nullptr, nullptr), PLIANT_OK);
  EXPECT_EQ(pliant_step_tracker(p_, 0.03), PLIANT_NO_OBSERVATIONS);
  // A pushed frame replaced before its step is counted, not refused.
  EXPECT_EQ(pliant_push_observations(p_, 1.2, rest, nullptr), PLIANT_OK);
  EXPECT_EQ(pliant_push_observations(p_, 1.3, rest, nullptr), PLIANT_OK);
  EXPECT_EQ(instance_->counters().frames_replaced, 1u);
  EXPECT_EQ(instance_->counters().calls_rejected, rejected_);
}

TEST_F(BridgeRefusals, PushToolContact) {
  const std::int32_t jaw = object_.jaw_a[0];
  const std::int32_t free_particle = object_.id(1, 1, 1);
  const float target[6] = {0, 0, 0, 0.03f, 0, 0};
  expect_refused("no frame", pliant_push_tool_contact(p_, &jaw, target, 1), PLIANT_ERROR_BAD_STATE,
                 PLIANT_CALL_PUSH_TOOL_CONTACT);
  ASSERT_EQ(pliant_push_observations(p_, 0.0, object_.rest.data(), nullptr), PLIANT_OK);
  expect_refused("ids NULL", pliant_push_tool_contact(p_, nullptr, target, 1), PLIANT_ERROR_NULL_ARGUMENT,
                 PLIANT_CALL_PUSH_TOOL_CONTACT);
  expect_refused("targets NULL", pliant_push_tool_contact(p_, &jaw, nullptr, 1), PLIANT_ERROR_NULL_ARGUMENT,
                 PLIANT_CALL_PUSH_TOOL_CONTACT);
  expect_refused("count > drivable",
                 pliant_push_tool_contact(p_, object_.drivable.data(), target,
                                          static_cast<std::uint32_t>(object_.drivable.size()) + 1),
                 PLIANT_ERROR_INVALID_ARGUMENT, PLIANT_CALL_PUSH_TOOL_CONTACT);
  expect_refused("not drivable", pliant_push_tool_contact(p_, &free_particle, target, 1), PLIANT_ERROR_INVALID_ARGUMENT,
                 PLIANT_CALL_PUSH_TOOL_CONTACT);
  const std::int32_t out_of_range[2] = {-1, 1000};
  expect_refused("id -1", pliant_push_tool_contact(p_, &out_of_range[0], target, 1), PLIANT_ERROR_INVALID_ARGUMENT,
                 PLIANT_CALL_PUSH_TOOL_CONTACT);
  expect_refused("id 1000", pliant_push_tool_contact(p_, &out_of_range[1], target, 1), PLIANT_ERROR_INVALID_ARGUMENT,
                 PLIANT_CALL_PUSH_TOOL_CONTACT);
  const std::int32_t repeated[2] = {jaw, jaw};
  expect_refused("repeated id", pliant_push_tool_contact(p_, repeated, target, 2), PLIANT_ERROR_INVALID_ARGUMENT,
                 PLIANT_CALL_PUSH_TOOL_CONTACT);
  const float nan_target[3] = {0, std::numeric_limits<float>::quiet_NaN(), 0};
  expect_refused("NaN target", pliant_push_tool_contact(p_, &jaw, nan_target, 1), PLIANT_ERROR_NON_FINITE,
                 PLIANT_CALL_PUSH_TOOL_CONTACT);
  // The repeated-id marks were cleared after every refusal: a valid contact goes through.
  const std::int32_t two[2] = {jaw, object_.jaw_b[0]};
  EXPECT_EQ(pliant_push_tool_contact(p_, two, target, 2), PLIANT_OK);
  EXPECT_EQ(pliant_push_tool_contact(p_, nullptr, nullptr, 0), PLIANT_OK);
  EXPECT_EQ(instance_->counters().calls_rejected, rejected_);
}

TEST_F(BridgeRefusals, StepTracker) {
  expect_refused("no frame", pliant_step_tracker(p_, 0.03), PLIANT_ERROR_BAD_STATE, PLIANT_CALL_STEP_TRACKER);
  ASSERT_EQ(pliant_push_observations(p_, 0.0, object_.rest.data(), nullptr), PLIANT_OK);
  expect_refused("NaN dt", pliant_step_tracker(p_, kNaN), PLIANT_ERROR_NON_FINITE, PLIANT_CALL_STEP_TRACKER);
  expect_refused("inf dt", pliant_step_tracker(p_, kInf), PLIANT_ERROR_NON_FINITE, PLIANT_CALL_STEP_TRACKER);
  expect_refused("zero dt", pliant_step_tracker(p_, 0.0), PLIANT_ERROR_INVALID_ARGUMENT, PLIANT_CALL_STEP_TRACKER);
  expect_refused("negative dt", pliant_step_tracker(p_, -0.03), PLIANT_ERROR_INVALID_ARGUMENT,
                 PLIANT_CALL_STEP_TRACKER);
  // The frame survived the refusals.
  EXPECT_EQ(pliant_step_tracker(p_, 0.03), PLIANT_OK);
  expect_refused("frame consumed", pliant_step_tracker(p_, 0.03), PLIANT_ERROR_BAD_STATE, PLIANT_CALL_STEP_TRACKER);
  EXPECT_EQ(instance_->counters().tracker_frames, 1u);
}

TEST_F(BridgeRefusals, GetTracked) {
  std::vector<float> positions(object_.rest.size());
  std::vector<std::uint8_t> status(object_.count());
  expect_refused("both NULL", pliant_get_tracked(p_, nullptr, nullptr, object_.count(), nullptr),
                 PLIANT_ERROR_NULL_ARGUMENT, PLIANT_CALL_GET_TRACKED);
  expect_refused("capacity", pliant_get_tracked(p_, positions.data(), status.data(), object_.count() - 1, nullptr),
                 PLIANT_ERROR_INVALID_ARGUMENT, PLIANT_CALL_GET_TRACKED);
  EXPECT_EQ(pliant_get_tracked(p_, positions.data(), nullptr, object_.count(), nullptr), PLIANT_OK);
  EXPECT_EQ(pliant_get_tracked(p_, nullptr, status.data(), object_.count(), nullptr), PLIANT_OK);
  // Before any frame: the rest shape.
  for (std::size_t i = 0; i < positions.size(); ++i) EXPECT_FLOAT_EQ(positions[i], object_.rest[i]);
}

TEST_F(BridgeRefusals, Estimate) {
  pliant_estimate_t estimate;
  expect_refused("nothing stepped", pliant_update_estimate(p_), PLIANT_ERROR_BAD_STATE, PLIANT_CALL_UPDATE_ESTIMATE);
  ASSERT_EQ(pliant_push_observations(p_, 0.0, object_.rest.data(), nullptr), PLIANT_OK);
  ASSERT_EQ(pliant_step_tracker(p_, 0.03), PLIANT_OK);
  EXPECT_EQ(pliant_update_estimate(p_), PLIANT_OK);
  expect_refused("twice for one frame", pliant_update_estimate(p_), PLIANT_ERROR_BAD_STATE,
                 PLIANT_CALL_UPDATE_ESTIMATE);
  expect_refused("out NULL", pliant_get_estimate(p_, nullptr), PLIANT_ERROR_NULL_ARGUMENT, PLIANT_CALL_GET_ESTIMATE);
  EXPECT_EQ(pliant_get_estimate(p_, &estimate), PLIANT_OK);
  EXPECT_EQ(estimate.frames, 1u);
  expect_refused("deformation out NULL", pliant_get_deformation(p_, nullptr), PLIANT_ERROR_NULL_ARGUMENT,
                 PLIANT_CALL_GET_DEFORMATION);
}

TEST_F(BridgeRefusals, GuardUpdate) {
  pliant_guard_input_t in = fresh_input(0.0, 0.05, 0.0);
  pliant_verdict_t verdict;
  verdict.verdict = PLIANT_VERDICT_OK;
  expect_refused("input NULL", pliant_guard_update(p_, nullptr, &verdict), PLIANT_ERROR_NULL_ARGUMENT,
                 PLIANT_CALL_GUARD_UPDATE);
  EXPECT_EQ(verdict.verdict, PLIANT_VERDICT_STOP);
  EXPECT_EQ(verdict.reason, PLIANT_REASON_NOT_CONFIGURED);
  expect_refused("out NULL", pliant_guard_update(p_, &in, nullptr), PLIANT_ERROR_NULL_ARGUMENT,
                 PLIANT_CALL_GUARD_UPDATE);
  in.deformation.source = 2;
  verdict.verdict = PLIANT_VERDICT_OK;
  expect_refused("deformation source 2", pliant_guard_update(p_, &in, &verdict), PLIANT_ERROR_INVALID_ARGUMENT,
                 PLIANT_CALL_GUARD_UPDATE);
  EXPECT_EQ(verdict.verdict, PLIANT_VERDICT_STOP);
  in.deformation.source = PLIANT_SOURCE_BRIDGE;
  in.estimate.source = 9;
  expect_refused("estimate source 9", pliant_guard_update(p_, &in, &verdict), PLIANT_ERROR_INVALID_ARGUMENT,
                 PLIANT_CALL_GUARD_UPDATE);
  EXPECT_EQ(instance_->counters().guard_cycles, 0u) << "refused cycles must not reach the guard";
  // NaN sensor values are not call errors: they are faults in the verdict, counted by the guard.
  in = fresh_input(0.0, 0.05, 0.0);
  in.now_s = kNaN;
  EXPECT_EQ(pliant_guard_update(p_, &in, &verdict), PLIANT_OK);
  EXPECT_EQ(verdict.verdict, PLIANT_VERDICT_STOP);
  EXPECT_NE(verdict.fault_sources & (1u << PLIANT_SOURCE_CLOCK), 0u);
  in = fresh_input(0.001, kNaN, 0.0);
  EXPECT_EQ(pliant_guard_update(p_, &in, &verdict), PLIANT_OK);
  EXPECT_NE(verdict.reasons & (1u << PLIANT_REASON_NAN_INPUT), 0u);
  const pliant_counters_t counters = instance_->counters();
  EXPECT_EQ(counters.guard_cycles, 2u);
  EXPECT_GE(counters.guard_refused[PLIANT_SOURCE_CLOCK], 1u);
  EXPECT_GE(counters.guard_refused[PLIANT_SOURCE_GRIPPER], 1u);
  EXPECT_EQ(counters.calls_rejected, rejected_);
}

TEST_F(BridgeRefusals, CountersAndInfo) {
  expect_refused("counters NULL", pliant_get_counters(p_, nullptr), PLIANT_ERROR_NULL_ARGUMENT,
                 PLIANT_CALL_GET_COUNTERS);
  expect_refused("info NULL", pliant_get_info(p_, nullptr), PLIANT_ERROR_NULL_ARGUMENT, PLIANT_CALL_GET_INFO);
  pliant_counters_t counters = instance_->counters();
  std::uint32_t value = 0;
  EXPECT_EQ(pliant_counter_by_id(&counters, 0, &value), PLIANT_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(pliant_counter_by_id(&counters, 16, &value), PLIANT_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(pliant_counter_by_id(&counters, PLIANT_COUNTER_CALLS_REJECTED, nullptr), PLIANT_ERROR_NULL_ARGUMENT);
  EXPECT_EQ(pliant_counter_by_id(&counters, PLIANT_COUNTER_CALLS_REJECTED, &value), PLIANT_OK);
  EXPECT_EQ(value, 2u);
}

TEST(BridgeDisabled, ComponentsSwitchedOffRefuseTheirCalls) {
  LatticeObject object(3, 4, 4, 3);
  object.drive_jaws();
  pliant_config_t config = object.config();
  config.estimator.enabled = false;
  config.guard.enabled = false;
  config.guard.squeeze_axis[0] = 0;  // not validated while the guard is off
  Instance instance(config);
  ASSERT_EQ(instance.status, PLIANT_OK);
  pliant_t* p = instance.pliant;
  pliant_estimate_t estimate;
  pliant_deformation_t deformation;
  pliant_verdict_t verdict;
  const pliant_guard_input_t in = fresh_input(0, 0.05, 0);
  ASSERT_EQ(pliant_push_observations(p, 0.0, object.rest.data(), nullptr), PLIANT_OK);
  ASSERT_EQ(pliant_step_tracker(p, 0.03), PLIANT_OK);
  EXPECT_EQ(pliant_update_estimate(p), PLIANT_ERROR_DISABLED);
  EXPECT_EQ(pliant_get_estimate(p, &estimate), PLIANT_ERROR_DISABLED);
  EXPECT_EQ(pliant_get_deformation(p, &deformation), PLIANT_ERROR_DISABLED);
  EXPECT_EQ(pliant_guard_update(p, &in, &verdict), PLIANT_ERROR_DISABLED);
  EXPECT_EQ(verdict.verdict, PLIANT_VERDICT_STOP);
  EXPECT_EQ(pliant_reset_grasp_guard(p), PLIANT_ERROR_DISABLED);
  EXPECT_EQ(pliant_acknowledge_stop(p), PLIANT_ERROR_DISABLED);
  EXPECT_EQ(pliant_reset_grasp(p), PLIANT_OK);
  const pliant_counters_t counters = instance.counters();
  EXPECT_EQ(counters.calls_rejected, 6u);
  EXPECT_EQ(counters.last_rejected_call, PLIANT_CALL_ACKNOWLEDGE_STOP);
  EXPECT_EQ(counters.estimator_frames_skipped, 0u);
  // Smaller without the estimator and the guard.
  std::size_t full = 0;
  const pliant_config_t everything = object.config();
  ASSERT_EQ(pliant_workspace_size(&everything, &full), PLIANT_OK);
  EXPECT_LT(instance.bytes, full / 2);
}

}  // namespace
}  // namespace pliant::bridge_test
