// pliant_workspace_size, pliant_init, pliant_get_info, pliant_reset_grasp.
#include "bridge_internal.hpp"

using namespace pliant::bridge;

extern "C" {

pliant_status_t pliant_workspace_size(const pliant_config_t* config, size_t* out_bytes) {
  if (out_bytes != nullptr) *out_bytes = 0;
  if (config == nullptr || out_bytes == nullptr) return PLIANT_ERROR_NULL_ARGUMENT;
  const pliant_status_t valid = validate_config(*config);
  if (valid != PLIANT_OK) return valid;
  return required_bytes(*config, *out_bytes);
}

pliant_status_t pliant_init(void* memory, size_t size, const pliant_config_t* config, pliant_t** out_instance) {
  if (out_instance != nullptr) *out_instance = nullptr;
  if (memory == nullptr || config == nullptr || out_instance == nullptr) return PLIANT_ERROR_NULL_ARGUMENT;
  const pliant_status_t valid = validate_config(*config);
  if (valid != PLIANT_OK) return valid;
  std::size_t bytes = 0;
  const pliant_status_t sized = required_bytes(*config, bytes);
  if (sized == PLIANT_ERROR_INVALID_ARGUMENT) return model_refusal(memory, size, *config);
  if (sized != PLIANT_OK) return sized;
  if (size < bytes) return PLIANT_ERROR_MEMORY_TOO_SMALL;
  return build_instance(memory, size, *config, bytes, *out_instance);
}

pliant_status_t pliant_get_info(pliant_t* instance, pliant_info_t* out) {
  const pliant_status_t usable = check_instance(instance);
  if (usable != PLIANT_OK) return usable;
  if (out == nullptr) return reject(instance, PLIANT_CALL_GET_INFO, PLIANT_ERROR_NULL_ARGUMENT);
  const Common& c = instance->common;
  pliant_info_t info{};
  info.dim = instance->dim;
  info.particle_count = c.particle_count;
  info.drivable_count = c.drivable_count;
  info.scalar_bytes = static_cast<std::uint32_t>(sizeof(Scalar));
  info.workspace_bytes = c.workspace_bytes;
  info.estimator_enabled = c.estimator_enabled;
  info.guard_enabled = c.guard_enabled;
  info.guard_extent_m = kNaN;
  dispatch(instance, [&](auto& engine) {
    info.cluster_count = static_cast<std::uint32_t>(engine.model.cluster_count);
    info.spacing_m = static_cast<double>(engine.model.spacing);
    if (c.guard_enabled) {
      info.guard_extent_m = engine.guard.extent_m;
      info.guard_unconverged_relaxations = engine.guard.unconverged_relaxations;
      info.guard_relaxation_steps = engine.guard.relaxation_steps;
    }
  });
  *out = info;
  return PLIANT_OK;
}

pliant_status_t pliant_reset_grasp(pliant_t* instance) {
  const pliant_status_t usable = check_instance(instance);
  if (usable != PLIANT_OK) return usable;
  Common& c = instance->common;
  dispatch(instance, [&](auto& engine) {
    pliant::tracker_reset(engine.model, engine.tracker);
    engine.tracker.params.msm_beta = static_cast<Scalar>(c.initial_msm_beta);
    if (c.estimator_enabled) pliant::online_deformability_reset(engine.model, engine.estimator);
    if (c.guard_enabled) pliant::grasp_guard_reset(engine.guard);
  });
  c.pending = false;
  c.pending_contact_count = 0;
  c.has_frame = false;
  c.frame_stamp_s = kNaN;
  c.frame_dt_s = 0;
  c.last_contact_count = 0;
  c.estimate_due = false;
  c.skipped_dt_s = 0;
  // The last frame's strain belongs to the old grasp: no deformation sample until a new frame
  // (the guard sees a camera fault meanwhile).
  c.deformation.valid = false;
  c.deformation.stamp_s = kNaN;
  c.deformation.strain = kNaN;
  // No evidence yet for the new grasp: the whole msm_beta range (its stamp stays the last
  // frame's, so it goes stale unless frames keep coming).
  c.estimate = pliant::OnlineDeformabilityEstimate{};
  c.estimate.msm_beta = c.initial_msm_beta;
  c.estimate.msm_beta_std = kInf;
  c.estimate_fed_back = false;
  return PLIANT_OK;
}

}  // extern "C"
