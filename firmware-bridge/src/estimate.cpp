// The frame group's estimator half: online msm_beta from the tracked frames.
#include "bridge_internal.hpp"

using namespace pliant::bridge;

extern "C" {

pliant_status_t pliant_update_estimate(pliant_t* instance) {
  const pliant_status_t usable = check_instance(instance);
  if (usable != PLIANT_OK) return usable;
  Common& c = instance->common;
  constexpr std::uint8_t kCall = PLIANT_CALL_UPDATE_ESTIMATE;
  if (!c.estimator_enabled) return reject(instance, kCall, PLIANT_ERROR_DISABLED);
  if (!c.estimate_due) return reject(instance, kCall, PLIANT_ERROR_BAD_STATE);
  const double dt = c.frame_dt_s + c.skipped_dt_s;
  c.estimate_due = false;
  c.skipped_dt_s = 0;
  const pliant::Status status = dispatch(instance, [&](auto& engine) {
    constexpr int kDim = std::decay_t<decltype(engine)>::Vec::RowsAtCompileTime;
    pliant::MsmDrivenTargets<kDim, Scalar> driven;
    driven.ids = engine.last_contact_ids;
    driven.positions = engine.last_contact_targets;
    driven.count = c.last_contact_count;
    const pliant::Status updated = pliant::online_deformability_update(
        engine.model, engine.estimator, static_cast<Scalar>(dt), driven, engine.estimate_positions);
    if (updated == pliant::Status::ok || updated == pliant::Status::no_observations) {
      c.estimate = pliant::online_deformability_estimate(engine.estimator);
      const double sd = c.estimate.msm_beta_std;
      c.estimate_fed_back = c.feed_back_beta && is_finite(sd) && sd <= c.feed_back_max_std;
      if (c.estimate_fed_back) engine.tracker.params.msm_beta = static_cast<Scalar>(c.estimate.msm_beta);
    }
    return updated;
  });
  if (status != pliant::Status::ok && status != pliant::Status::no_observations) {
    return reject(instance, kCall, to_status(status));
  }
  ++c.estimator_frames;
  c.estimate_stamp_s = c.frame_stamp_s;
  return to_status(status);
}

pliant_status_t pliant_get_estimate(pliant_t* instance, pliant_estimate_t* out) {
  const pliant_status_t usable = check_instance(instance);
  if (usable != PLIANT_OK) return usable;
  const Common& c = instance->common;
  constexpr std::uint8_t kCall = PLIANT_CALL_GET_ESTIMATE;
  if (out == nullptr) return reject(instance, kCall, PLIANT_ERROR_NULL_ARGUMENT);
  if (!c.estimator_enabled) return reject(instance, kCall, PLIANT_ERROR_DISABLED);
  pliant_estimate_t e{};
  e.stamp_s = c.estimate_stamp_s;
  e.msm_beta = c.estimate.msm_beta;
  e.msm_beta_std = c.estimate.msm_beta_std;
  e.rms = c.estimate.rms;
  e.msm_alpha = c.estimate.msm_alpha;
  e.steps_per_frame = static_cast<std::uint32_t>(c.estimate.steps_per_frame);
  e.form_fitted = c.estimate.alpha_fitted;
  e.frames = c.estimate.frames;
  e.unique_minimum = c.estimate.unique_minimum;
  e.valid = c.estimate.frames > 0 && is_finite(c.estimate.msm_beta_std);
  e.fed_back = c.estimate_fed_back;
  e.tracker_msm_beta =
      dispatch(instance, [](auto& engine) { return static_cast<double>(engine.tracker.params.msm_beta); });
  *out = e;
  return PLIANT_OK;
}

}  // extern "C"
