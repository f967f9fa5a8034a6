// The cycle group: the grasp guard through the C structs.
#include "bridge_internal.hpp"

using namespace pliant::bridge;

namespace {

// What the guard answers when it cannot run: stop, freeze, not configured.
void fail_safe(pliant_verdict_t& out) noexcept {
  out = pliant_verdict_t{};
  out.verdict = PLIANT_VERDICT_STOP;
  out.reason = PLIANT_REASON_NOT_CONFIGURED;
  out.stop_action = PLIANT_STOP_FREEZE;
  out.reasons = 1u << PLIANT_REASON_NOT_CONFIGURED;
  out.contact_width_m = out.force_n = out.strain = out.allowed_force_n = kNaN;
  out.predicted_strain = out.safe_width_m = out.predicted_force_n = out.stiffness_n_per_m = kNaN;
  out.beta_low = 0;
  out.beta_high = 1;
  out.force_safe_closure_m = kInf;
}

pliant::GraspGuardInput to_core(const pliant_guard_input_t& in, const Common& c) noexcept {
  pliant::GraspGuardInput out;
  out.now_s = in.now_s;
  out.gripper.stamp_s = in.gripper.stamp_s;
  out.gripper.width_m = in.gripper.width_m;
  out.gripper.force_n = in.gripper.force_n;
  out.gripper.current_a = in.gripper.current_a;
  out.gripper.status_bits = in.gripper.status_bits;
  out.gripper.valid = in.gripper.valid;
  out.gripper.bus_off = in.gripper.bus_off;
  out.gripper.timeout = in.gripper.timeout;

  out.wrench.stamp_s = in.wrench.stamp_s;
  for (int k = 0; k < 6; ++k) out.wrench.wrench[k] = in.wrench.wrench[k];
  out.wrench.status_bits = in.wrench.status_bits;
  out.wrench.valid = in.wrench.valid;
  out.wrench.bus_off = in.wrench.bus_off;
  out.wrench.timeout = in.wrench.timeout;

  const pliant_deformation_sample_t& d = in.deformation;
  if (d.source == PLIANT_SOURCE_BRIDGE) {
    out.deformation.stamp_s = c.deformation.stamp_s;
    out.deformation.strain = c.deformation.strain;
    out.deformation.valid = c.deformation.valid;
  } else {
    out.deformation.stamp_s = d.stamp_s;
    out.deformation.strain = d.strain;
    out.deformation.valid = d.valid;
  }
  out.deformation.status_bits = d.status_bits;
  out.deformation.bus_off = d.bus_off;
  out.deformation.timeout = d.timeout;

  const pliant_estimate_sample_t& e = in.estimate;
  if (e.source == PLIANT_SOURCE_BRIDGE) {
    // Valid from the first estimator frame on; an sd of +inf is "not identifiable yet".
    out.estimate.stamp_s = c.estimate_stamp_s;
    out.estimate.msm_beta = c.estimate.msm_beta;
    out.estimate.msm_beta_std = c.estimate.msm_beta_std;
    out.estimate.valid = c.estimator_enabled && is_finite(c.estimate_stamp_s);
  } else {
    out.estimate.stamp_s = e.stamp_s;
    out.estimate.msm_beta = e.msm_beta;
    out.estimate.msm_beta_std = e.msm_beta_std;
    out.estimate.valid = e.valid;
  }
  return out;
}

void to_abi(const pliant::GraspGuardOutput& in, pliant_verdict_t& out) noexcept {
  out.verdict = static_cast<std::uint8_t>(in.verdict);
  out.reason = static_cast<std::uint8_t>(in.reason);
  out.stop_action = static_cast<std::uint8_t>(in.stop_action);
  out.fault_sources = in.fault_sources;
  out.reasons = in.reasons;
  out.in_contact = in.in_contact;
  out.slip = in.slip;
  out.contact_width_m = in.contact_width_m;
  out.closure_m = in.closure_m;
  out.force_n = in.force_n;
  out.strain = in.strain;
  out.allowed_force_n = in.allowed_force_n;
  out.beta_low = in.beta_low;
  out.beta_high = in.beta_high;
  out.predicted_strain = in.predicted_strain;
  out.strain_safe_closure_m = in.strain_safe_closure_m;
  out.force_safe_closure_m = in.force_safe_closure_m;
  out.safe_closure_m = in.safe_closure_m;
  out.safe_width_m = in.safe_width_m;
  out.predicted_force_n = in.predicted_force_n;
  out.stiffness_n_per_m = in.stiffness_n_per_m;
  out.slip_force_n = in.slip_force_n;
}

}  // namespace

extern "C" {

pliant_status_t pliant_guard_update(pliant_t* instance, const pliant_guard_input_t* input, pliant_verdict_t* out) {
  if (out != nullptr) fail_safe(*out);
  const pliant_status_t usable = check_instance(instance);
  if (usable != PLIANT_OK) return usable;
  const Common& c = instance->common;
  constexpr std::uint8_t kCall = PLIANT_CALL_GUARD_UPDATE;
  if (input == nullptr || out == nullptr) return reject(instance, kCall, PLIANT_ERROR_NULL_ARGUMENT);
  if (!c.guard_enabled) return reject(instance, kCall, PLIANT_ERROR_DISABLED);
  if (input->deformation.source > PLIANT_SOURCE_CALLER || input->estimate.source > PLIANT_SOURCE_CALLER) {
    return reject(instance, kCall, PLIANT_ERROR_INVALID_ARGUMENT);
  }
  const pliant::GraspGuardInput core_input = to_core(*input, c);
  pliant::GraspGuardOutput core_output;
  const pliant::Status status = dispatch(
      instance, [&](auto& engine) { return pliant::grasp_guard_update(engine.guard, core_input, core_output); });
  if (status != pliant::Status::ok) return reject(instance, kCall, to_status(status));
  to_abi(core_output, *out);
  instance->common.last_verdict = *out;
  instance->common.has_verdict = true;
  return PLIANT_OK;
}

pliant_status_t pliant_reset_grasp_guard(pliant_t* instance) {
  const pliant_status_t usable = check_instance(instance);
  if (usable != PLIANT_OK) return usable;
  if (!instance->common.guard_enabled) return reject(instance, PLIANT_CALL_RESET_GRASP_GUARD, PLIANT_ERROR_DISABLED);
  dispatch(instance, [](auto& engine) { pliant::grasp_guard_reset(engine.guard); });
  return PLIANT_OK;
}

pliant_status_t pliant_acknowledge_stop(pliant_t* instance) {
  const pliant_status_t usable = check_instance(instance);
  if (usable != PLIANT_OK) return usable;
  if (!instance->common.guard_enabled) return reject(instance, PLIANT_CALL_ACKNOWLEDGE_STOP, PLIANT_ERROR_DISABLED);
  dispatch(instance, [](auto& engine) { pliant::grasp_guard_acknowledge_stop(engine.guard); });
  return PLIANT_OK;
}

pliant_status_t pliant_get_deformation(pliant_t* instance, pliant_deformation_t* out) {
  const pliant_status_t usable = check_instance(instance);
  if (usable != PLIANT_OK) return usable;
  constexpr std::uint8_t kCall = PLIANT_CALL_GET_DEFORMATION;
  if (out == nullptr) return reject(instance, kCall, PLIANT_ERROR_NULL_ARGUMENT);
  if (!instance->common.guard_enabled) return reject(instance, kCall, PLIANT_ERROR_DISABLED);
  *out = instance->common.deformation;
  return PLIANT_OK;
}

}  // extern "C"
