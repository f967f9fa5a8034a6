// Configuration: defaults (taken from the core's own defaults), validation and mapping to the
// core's config structs.
#include <cstring>

#include "bridge_internal.hpp"

namespace pliant::bridge {
namespace {

bool in_unit_interval(double value) noexcept { return value >= 0 && value <= 1; }
bool positive_finite(double value) noexcept { return is_finite(value) && value > 0; }
bool non_negative_finite(double value) noexcept { return is_finite(value) && value >= 0; }

void default_clusters(pliant_cluster_config_t& out) noexcept {
  const ClusterConfig core;
  out.layout = static_cast<std::uint8_t>(core.layout);
  out.radius_factor = core.radius_factor;
  out.k = core.k;
  out.grid_cols = core.grid_cols;
  out.grid_rows = core.grid_rows;
  out.grid_layers = core.grid_layers;
  out.block_cols = core.block_cols;
  out.block_rows = core.block_rows;
  out.block_layers = core.block_layers;
}

void default_tracker(pliant_tracker_config_t& out) noexcept {
  const TrackerConfig core;
  out.tukey_c = core.tukey_c;
  out.min_residual_scale = core.min_residual_scale;
  out.observation_gain = core.observation_gain;
  out.projection_iterations = core.projection_iterations;
  out.max_unobserved_frames = core.max_unobserved_frames;
}

void default_estimator(pliant_estimator_config_t& out) noexcept {
  const OnlineDeformabilityConfig core;
  out.enabled = true;
  out.candidates = core.candidates;
  out.alpha_candidates = core.alpha_candidates;
  out.alpha_min = core.alpha_min;
  out.step_candidates = core.step_candidates;
  out.forgetting = core.forgetting;
  out.feed_back_beta = true;
  out.feed_back_max_std = 0.1;
  out.equilibrium_iterations = core.equilibrium_iterations;
  out.equilibrium_tolerance = core.equilibrium_tolerance;
}

void default_guard(pliant_guard_config_t& out) noexcept {
  const GraspGuardConfig c;
  const GraspObject<3, Scalar> object;
  out.enabled = true;
  out.max_strain = c.max_strain;
  out.max_indentation_m = c.max_indentation_m;
  out.max_force_n = c.max_force_n;
  out.nominal_force_n = c.nominal_force_n;
  for (double& axis : out.squeeze_axis) axis = 0;
  out.jaw_a_ids = nullptr;
  out.jaw_a_count = 0;
  out.jaw_b_ids = nullptr;
  out.jaw_b_count = 0;
  out.contact_band = object.contact_band;
  out.contact_width_m = c.contact_width_m;
  out.contact_force_n = c.contact_force_n;
  out.contact_width_tolerance = c.contact_width_tolerance;
  out.max_width_m = c.max_width_m;
  out.force_source = static_cast<std::uint8_t>(c.force_source);
  out.current_gain_n_per_a = c.current_gain_n_per_a;
  out.current_offset_a = c.current_offset_a;
  out.gripper_timeout_s = c.gripper_timeout_s;
  out.wrench_timeout_s = c.wrench_timeout_s;
  out.camera_timeout_s = c.camera_timeout_s;
  out.estimate_timeout_s = c.estimate_timeout_s;
  out.cycle_timeout_s = c.cycle_timeout_s;
  out.clock_tolerance_s = c.clock_tolerance_s;
  out.wrench_frozen_samples = c.wrench_frozen_samples;
  out.gripper_fault_mask = c.gripper_fault_mask;
  out.wrench_fault_mask = c.wrench_fault_mask;
  out.camera_fault_mask = c.camera_fault_mask;
  for (int s = 0; s < kGuardSourceCount; ++s) out.fault_verdict[s] = static_cast<std::uint8_t>(c.fault_verdict[s]);
  out.uncertain_estimate_verdict = static_cast<std::uint8_t>(c.uncertain_estimate_verdict);
  out.exceeded_stop_action = static_cast<std::uint8_t>(c.exceeded_stop_action);
  out.fault_stop_action = static_cast<std::uint8_t>(c.fault_stop_action);
  out.latch_stop = c.latch_stop;
  out.hysteresis_margin = c.hysteresis_margin;
  out.clear_samples = c.clear_samples;
  out.stop_overshoot = c.stop_overshoot;
  out.confidence_k = c.confidence_k;
  out.max_beta_std = c.max_beta_std;
  out.slip_cutoff_hz = c.slip_cutoff_hz;
  out.slip_ratio = c.slip_ratio;
  out.slip_floor_n = c.slip_floor_n;
  out.slip_ceiling_n = c.slip_ceiling_n;
  out.slip_force_rate_per_s = c.slip_force_rate_per_s;
  out.force_fit_spacing_m = c.force_fit_spacing_m;
  out.force_fit_forgetting = c.force_fit_forgetting;
  out.force_model_min_closure_m = c.force_model_min_closure_m;
  out.prediction_beta_points = c.prediction_beta_points;
  out.prediction_closure_points = c.prediction_closure_points;
  out.prediction_refine_steps = c.prediction_refine_steps;
  out.prediction_max_closure_m = c.prediction_max_closure_m;
  out.relax_max_iterations = c.relax_max_iterations;
  out.relax_tolerance = c.relax_tolerance;
}

// count ids in [0, n) (ids may be NULL only when count is 0).
bool ids_valid(const int32_t* ids, std::uint32_t count, std::uint32_t n) noexcept {
  if (count == 0) return true;
  if (ids == nullptr || count > n) return false;
  for (std::uint32_t k = 0; k < count; ++k) {
    if (ids[k] < 0 || static_cast<std::uint32_t>(ids[k]) >= n) return false;
  }
  return true;
}

pliant_status_t validate_clusters(const pliant_cluster_config_t& c, std::uint32_t dim) noexcept {
  switch (c.layout) {
    case PLIANT_CLUSTERS_RADIUS: return positive_finite(c.radius_factor) ? PLIANT_OK : PLIANT_ERROR_INVALID_ARGUMENT;
    case PLIANT_CLUSTERS_K_NEAREST: return c.k >= 1 && c.k <= 64 ? PLIANT_OK : PLIANT_ERROR_INVALID_ARGUMENT;
    case PLIANT_CLUSTERS_GRID_BLOCKS: {
      const bool sizes = c.grid_cols > 0 && c.grid_rows > 0 && c.grid_layers > 0 && c.block_cols > 0 &&
                         c.block_rows > 0 && c.block_layers > 0 && c.block_cols <= c.grid_cols &&
                         c.block_rows <= c.grid_rows && c.block_layers <= c.grid_layers;
      return sizes && (dim == 3 || c.grid_layers == 1) ? PLIANT_OK : PLIANT_ERROR_INVALID_ARGUMENT;
    }
    default: return PLIANT_ERROR_INVALID_ARGUMENT;
  }
}

pliant_status_t validate_msm(const pliant_msm_config_t& m) noexcept {
  if (!is_finite(m.msm_alpha) || !is_finite(m.msm_beta) || !is_finite(m.velocity_damping) ||
      !is_finite(m.driven_mass_factor)) {
    return PLIANT_ERROR_NON_FINITE;
  }
  for (double g : m.gravity) {
    if (!is_finite(g)) return PLIANT_ERROR_NON_FINITE;
  }
  if (!(m.msm_alpha > 0) || m.msm_alpha > 1 || !in_unit_interval(m.msm_beta) || m.velocity_damping < 0) {
    return PLIANT_ERROR_INVALID_ARGUMENT;
  }
  return m.driven_mass_factor > 0 ? PLIANT_OK : PLIANT_ERROR_INVALID_MASS;
}

pliant_status_t validate_tracker(const pliant_tracker_config_t& t) noexcept {
  const bool ok = positive_finite(t.tukey_c) && non_negative_finite(t.min_residual_scale) &&
                  positive_finite(t.observation_gain) && t.observation_gain <= 1 && t.projection_iterations >= 0 &&
                  t.projection_iterations <= 64 && t.max_unobserved_frames >= 1;
  return ok ? PLIANT_OK : PLIANT_ERROR_INVALID_ARGUMENT;
}

pliant_status_t validate_estimator(const pliant_estimator_config_t& e) noexcept {
  if (!e.enabled) return PLIANT_OK;
  const bool rows_ok = e.alpha_candidates >= 1 && e.alpha_candidates <= kMaxOnlineAlphaRows && e.step_candidates >= 1 &&
                       e.step_candidates <= kMaxOnlineStepRows &&
                       (e.alpha_candidates == 1 || (e.alpha_min > 0 && e.alpha_min < 1));
  const bool quasi_static_ok =
      e.equilibrium_iterations == 0 ||
      (e.equilibrium_iterations >= 1 && e.equilibrium_iterations <= kMaxEquilibriumIterations &&
       std::isfinite(e.equilibrium_tolerance) && e.equilibrium_tolerance > 0);
  const bool ok = rows_ok && quasi_static_ok && e.candidates >= 3 && e.candidates <= kMaxCandidates &&
                  e.forgetting > 0 && e.forgetting <= 1 && !std::isnan(e.feed_back_max_std) && e.feed_back_max_std >= 0;
  return ok ? PLIANT_OK : PLIANT_ERROR_INVALID_ARGUMENT;
}

// The guard's numeric ranges are checked by the core (grasp_guard_workspace_size answers 0 for
// an invalid config); here only what the core cannot see: the ABI's enumerations, the jaws.
pliant_status_t validate_guard(const pliant_guard_config_t& g, std::uint32_t dim, std::uint32_t n) noexcept {
  if (!g.enabled) return PLIANT_OK;
  for (std::uint32_t s = 0; s < PLIANT_GUARD_SOURCE_COUNT; ++s) {
    if (g.fault_verdict[s] != PLIANT_VERDICT_LIMIT && g.fault_verdict[s] != PLIANT_VERDICT_STOP) {
      return PLIANT_ERROR_INVALID_ARGUMENT;
    }
  }
  if (g.uncertain_estimate_verdict > PLIANT_VERDICT_STOP || g.exceeded_stop_action > PLIANT_STOP_OPEN ||
      g.fault_stop_action > PLIANT_STOP_OPEN || g.force_source > PLIANT_FORCE_MOTOR_CURRENT) {
    return PLIANT_ERROR_INVALID_ARGUMENT;
  }
  double norm = 0;
  for (std::uint32_t d = 0; d < dim; ++d) {
    if (!is_finite(g.squeeze_axis[d])) return PLIANT_ERROR_NON_FINITE;
    norm += g.squeeze_axis[d] * g.squeeze_axis[d];
  }
  if (!(norm > 0)) return PLIANT_ERROR_INVALID_ARGUMENT;
  if ((g.jaw_a_count > 0 && g.jaw_a_ids == nullptr) || (g.jaw_b_count > 0 && g.jaw_b_ids == nullptr)) {
    return PLIANT_ERROR_NULL_ARGUMENT;
  }
  if (!ids_valid(g.jaw_a_ids, g.jaw_a_count, n) || !ids_valid(g.jaw_b_ids, g.jaw_b_count, n)) {
    return PLIANT_ERROR_INVALID_ARGUMENT;
  }
  return PLIANT_OK;
}

}  // namespace

pliant_abi_t library_abi() noexcept {
  pliant_abi_t abi;
  abi.version = PLIANT_ABI_VERSION;
  abi.config_size = static_cast<std::uint32_t>(sizeof(pliant_config_t));
  abi.guard_input_size = static_cast<std::uint32_t>(sizeof(pliant_guard_input_t));
  abi.verdict_size = static_cast<std::uint32_t>(sizeof(pliant_verdict_t));
  abi.estimate_size = static_cast<std::uint32_t>(sizeof(pliant_estimate_t));
  abi.deformation_size = static_cast<std::uint32_t>(sizeof(pliant_deformation_t));
  abi.counters_size = static_cast<std::uint32_t>(sizeof(pliant_counters_t));
  abi.info_size = static_cast<std::uint32_t>(sizeof(pliant_info_t));
  return abi;
}

bool abi_matches(const pliant_abi_t& abi) noexcept {
  const pliant_abi_t mine = library_abi();
  return abi.version == mine.version && abi.config_size == mine.config_size &&
         abi.guard_input_size == mine.guard_input_size && abi.verdict_size == mine.verdict_size &&
         abi.estimate_size == mine.estimate_size && abi.deformation_size == mine.deformation_size &&
         abi.counters_size == mine.counters_size && abi.info_size == mine.info_size;
}

pliant_status_t validate_config(const pliant_config_t& config) noexcept {
  if (!abi_matches(config.abi)) return PLIANT_ERROR_ABI_MISMATCH;
  if (config.dim != 2 && config.dim != 3) return PLIANT_ERROR_INVALID_ARGUMENT;
  const std::uint32_t n = config.particle_count;
  if (n < 2 || n > kMaxParticles) return PLIANT_ERROR_INVALID_ARGUMENT;
  if (config.rest_positions == nullptr) return PLIANT_ERROR_NULL_ARGUMENT;
  for (std::uint32_t i = 0; i < n * config.dim; ++i) {
    if (!std::isfinite(config.rest_positions[i])) return PLIANT_ERROR_NON_FINITE;
  }
  if (config.masses != nullptr) {
    for (std::uint32_t i = 0; i < n; ++i) {
      if (!std::isfinite(config.masses[i]) || !(config.masses[i] > 0.0f)) return PLIANT_ERROR_INVALID_MASS;
    }
  }
  if (config.drivable_count > 0 && config.drivable_ids == nullptr) return PLIANT_ERROR_NULL_ARGUMENT;
  if (!ids_valid(config.drivable_ids, config.drivable_count, n)) return PLIANT_ERROR_INVALID_ARGUMENT;
  pliant_status_t status = validate_clusters(config.clusters, config.dim);
  if (status == PLIANT_OK) status = validate_msm(config.msm);
  if (status == PLIANT_OK) status = validate_tracker(config.tracker);
  if (status == PLIANT_OK) status = validate_estimator(config.estimator);
  if (status == PLIANT_OK) status = validate_guard(config.guard, config.dim, n);
  return status;
}

ClusterConfig to_core(const pliant_cluster_config_t& clusters) noexcept {
  ClusterConfig out;
  out.layout = static_cast<ClusterLayout>(clusters.layout);
  out.radius_factor = clusters.radius_factor;
  out.k = clusters.k;
  out.grid_cols = clusters.grid_cols;
  out.grid_rows = clusters.grid_rows;
  out.grid_layers = clusters.grid_layers;
  out.block_cols = clusters.block_cols;
  out.block_rows = clusters.block_rows;
  out.block_layers = clusters.block_layers;
  return out;
}

TrackerConfig to_core(const pliant_tracker_config_t& tracker) noexcept {
  TrackerConfig out;
  out.tukey_c = tracker.tukey_c;
  out.min_residual_scale = tracker.min_residual_scale;
  out.observation_gain = tracker.observation_gain;
  out.projection_iterations = tracker.projection_iterations;
  out.max_unobserved_frames = tracker.max_unobserved_frames;
  return out;
}

OnlineDeformabilityConfig to_core(const pliant_estimator_config_t& estimator) noexcept {
  OnlineDeformabilityConfig out;
  out.candidates = estimator.candidates;
  out.alpha_candidates = estimator.alpha_candidates;
  out.alpha_min = estimator.alpha_min;
  out.step_candidates = estimator.step_candidates;
  out.forgetting = estimator.forgetting;
  out.equilibrium_iterations = estimator.equilibrium_iterations;
  out.equilibrium_tolerance = estimator.equilibrium_tolerance;
  return out;
}

GraspGuardConfig to_core(const pliant_guard_config_t& g) noexcept {
  GraspGuardConfig c;
  c.max_strain = g.max_strain;
  c.max_indentation_m = g.max_indentation_m;
  c.max_force_n = g.max_force_n;
  c.nominal_force_n = g.nominal_force_n;
  c.contact_width_m = g.contact_width_m;
  c.contact_force_n = g.contact_force_n;
  c.contact_width_tolerance = g.contact_width_tolerance;
  c.max_width_m = g.max_width_m;
  c.force_source = static_cast<ForceSource>(g.force_source);
  c.current_gain_n_per_a = g.current_gain_n_per_a;
  c.current_offset_a = g.current_offset_a;
  c.gripper_timeout_s = g.gripper_timeout_s;
  c.wrench_timeout_s = g.wrench_timeout_s;
  c.camera_timeout_s = g.camera_timeout_s;
  c.estimate_timeout_s = g.estimate_timeout_s;
  c.cycle_timeout_s = g.cycle_timeout_s;
  c.clock_tolerance_s = g.clock_tolerance_s;
  c.wrench_frozen_samples = g.wrench_frozen_samples;
  c.gripper_fault_mask = g.gripper_fault_mask;
  c.wrench_fault_mask = g.wrench_fault_mask;
  c.camera_fault_mask = g.camera_fault_mask;
  for (int s = 0; s < kGuardSourceCount; ++s) c.fault_verdict[s] = static_cast<GraspVerdict>(g.fault_verdict[s]);
  c.uncertain_estimate_verdict = static_cast<GraspVerdict>(g.uncertain_estimate_verdict);
  c.exceeded_stop_action = static_cast<StopAction>(g.exceeded_stop_action);
  c.fault_stop_action = static_cast<StopAction>(g.fault_stop_action);
  c.latch_stop = g.latch_stop;
  c.hysteresis_margin = g.hysteresis_margin;
  c.clear_samples = g.clear_samples;
  c.stop_overshoot = g.stop_overshoot;
  c.confidence_k = g.confidence_k;
  c.max_beta_std = g.max_beta_std;
  c.slip_cutoff_hz = g.slip_cutoff_hz;
  c.slip_ratio = g.slip_ratio;
  c.slip_floor_n = g.slip_floor_n;
  c.slip_ceiling_n = g.slip_ceiling_n;
  c.slip_force_rate_per_s = g.slip_force_rate_per_s;
  c.force_fit_spacing_m = g.force_fit_spacing_m;
  c.force_fit_forgetting = g.force_fit_forgetting;
  c.force_model_min_closure_m = g.force_model_min_closure_m;
  c.prediction_beta_points = g.prediction_beta_points;
  c.prediction_closure_points = g.prediction_closure_points;
  c.prediction_refine_steps = g.prediction_refine_steps;
  c.prediction_max_closure_m = g.prediction_max_closure_m;
  c.relax_max_iterations = g.relax_max_iterations;
  c.relax_tolerance = g.relax_tolerance;
  return c;
}

}  // namespace pliant::bridge

using namespace pliant::bridge;

extern "C" pliant_status_t pliant_config_init_default_checked(pliant_config_t* config, const pliant_abi_t* caller_abi) {
  if (config == nullptr || caller_abi == nullptr) return PLIANT_ERROR_NULL_ARGUMENT;
  if (!abi_matches(*caller_abi)) return PLIANT_ERROR_ABI_MISMATCH;
  std::memset(config, 0, sizeof *config);
  config->abi = library_abi();
  config->dim = 3;
  config->particle_count = 0;
  config->rest_positions = nullptr;
  config->masses = nullptr;
  config->fixed = nullptr;
  config->drivable_ids = nullptr;
  config->drivable_count = 0;
  default_clusters(config->clusters);
  const pliant::MsmParams<3, double> msm;
  const pliant::MsmModelConfig<3, double> model;
  config->msm.msm_alpha = msm.msm_alpha;
  config->msm.msm_beta = 0.5;
  for (double& g : config->msm.gravity) g = 0;
  config->msm.velocity_damping = msm.velocity_damping;
  config->msm.driven_mass_factor = model.driven_mass_factor;
  default_tracker(config->tracker);
  default_estimator(config->estimator);
  default_guard(config->guard);
  return PLIANT_OK;
}

extern "C" pliant_status_t pliant_guard_input_init_checked(pliant_guard_input_t* input, size_t input_size) {
  if (input == nullptr) return PLIANT_ERROR_NULL_ARGUMENT;
  if (input_size != sizeof(pliant_guard_input_t)) return PLIANT_ERROR_ABI_MISMATCH;
  std::memset(input, 0, sizeof *input);
  input->now_s = kNaN;
  pliant_gripper_sample_t& g = input->gripper;
  g.stamp_s = g.width_m = g.force_n = g.current_a = kNaN;
  input->wrench.stamp_s = kNaN;
  for (double& w : input->wrench.wrench) w = kNaN;
  input->deformation.source = PLIANT_SOURCE_BRIDGE;
  input->deformation.stamp_s = input->deformation.strain = kNaN;
  input->estimate.source = PLIANT_SOURCE_BRIDGE;
  input->estimate.stamp_s = input->estimate.msm_beta = input->estimate.msm_beta_std = kNaN;
  return PLIANT_OK;
}
