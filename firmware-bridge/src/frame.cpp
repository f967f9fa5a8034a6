// The frame group's tracker half: push observations and tool contact, step, read the track.
#include "bridge_internal.hpp"

using namespace pliant::bridge;

namespace {

// After an accepted step: the masked copies the guard's strain and the estimator read, and
// the frame's strain (the deformation sample).
template <int Dim>
void publish_frame(Common& c, Engine<Dim>& engine) noexcept {
  using Vec = typename Engine<Dim>::Vec;
  const Vec unobserved = Vec::Constant(std::numeric_limits<Scalar>::quiet_NaN());
  const int n = to_int(c.particle_count);
  const pliant::Tracker<Dim, Scalar>& tracker = engine.tracker;
  if (engine.strain_positions != nullptr) {
    for (int i = 0; i < n; ++i) {
      engine.strain_positions[i] =
          tracker.status[i] == pliant::TrackStatus::lost ? unobserved : tracker.state.position[i];
    }
  }
  if (engine.estimate_positions != nullptr) {
    for (int i = 0; i < n; ++i) {
      engine.estimate_positions[i] =
          tracker.status[i] == pliant::TrackStatus::observed ? tracker.state.position[i] : unobserved;
    }
  }
  if (!c.guard_enabled) return;
  pliant::GraspStrainMeasurement measured;
  const pliant::Status status =
      pliant::grasp_guard_measure_strain(engine.guard_model, engine.guard, engine.strain_positions, measured);
  pliant_deformation_t& d = c.deformation;
  d.stamp_s = c.frame_stamp_s;
  d.strain = measured.strain;
  d.cluster = measured.cluster;
  d.clusters_measured = measured.clusters_measured;
  d.clusters_skipped = measured.clusters_skipped;
  d.valid = status == pliant::Status::ok;
  if (!d.valid) ++c.strain_unmeasured;
}

}  // namespace

extern "C" {

pliant_status_t pliant_push_observations(pliant_t* instance, double stamp_s, const float* positions,
                                         const float* confidence) {
  const pliant_status_t usable = check_instance(instance);
  if (usable != PLIANT_OK) return usable;
  Common& c = instance->common;
  if (!is_finite(stamp_s)) return reject(instance, PLIANT_CALL_PUSH_OBSERVATIONS, PLIANT_ERROR_NON_FINITE);
  if (!(stamp_s > c.last_stamp_s)) return reject(instance, PLIANT_CALL_PUSH_OBSERVATIONS, PLIANT_ERROR_STAMP_ORDER);
  if (c.pending) ++c.frames_replaced;
  const int n = to_int(c.particle_count);
  dispatch(instance, [&](auto& engine) {
    constexpr int kDim = std::decay_t<decltype(engine)>::Vec::RowsAtCompileTime;
    if (positions != nullptr) {
      for (int i = 0; i < n; ++i) {
        for (int d = 0; d < kDim; ++d) engine.observed[i](d) = static_cast<Scalar>(positions[i * kDim + d]);
      }
    }
    if (confidence != nullptr) {
      for (int i = 0; i < n; ++i) engine.confidence[i] = static_cast<Scalar>(confidence[i]);
    }
  });
  c.pending = true;
  c.pending_observed = positions != nullptr;
  c.pending_confidence = confidence != nullptr;
  c.pending_stamp_s = stamp_s;
  c.pending_contact_count = 0;
  return PLIANT_OK;
}

pliant_status_t pliant_push_tool_contact(pliant_t* instance, const int32_t* ids, const float* targets, uint32_t count) {
  const pliant_status_t usable = check_instance(instance);
  if (usable != PLIANT_OK) return usable;
  Common& c = instance->common;
  constexpr std::uint8_t kCall = PLIANT_CALL_PUSH_TOOL_CONTACT;
  if (!c.pending) return reject(instance, kCall, PLIANT_ERROR_BAD_STATE);
  if (count > 0 && (ids == nullptr || targets == nullptr)) return reject(instance, kCall, PLIANT_ERROR_NULL_ARGUMENT);
  if (count > c.drivable_count) return reject(instance, kCall, PLIANT_ERROR_INVALID_ARGUMENT);
  const pliant_status_t status = dispatch(instance, [&](auto& engine) -> pliant_status_t {
    constexpr int kDim = std::decay_t<decltype(engine)>::Vec::RowsAtCompileTime;
    // Validate everything before writing: a refused call leaves the frame's contact as it was.
    pliant_status_t verdict = PLIANT_OK;
    std::uint32_t marked = 0;
    for (; marked < count; ++marked) {
      const int32_t id = ids[marked];
      if (id < 0 || static_cast<std::uint32_t>(id) >= c.particle_count || engine.model.drivable[id] == 0 ||
          engine.contact_mark[id] != 0) {
        verdict = PLIANT_ERROR_INVALID_ARGUMENT;
        break;
      }
      engine.contact_mark[id] = 1;
      for (int d = 0; d < kDim; ++d) {
        if (!std::isfinite(targets[std::size_t{marked} * kDim + static_cast<std::size_t>(d)]))
          verdict = PLIANT_ERROR_NON_FINITE;
      }
      if (verdict != PLIANT_OK) {
        ++marked;
        break;
      }
    }
    for (std::uint32_t k = 0; k < marked; ++k) engine.contact_mark[ids[k]] = 0;
    if (verdict != PLIANT_OK) return verdict;
    for (std::uint32_t k = 0; k < count; ++k) {
      engine.contact_ids[k] = ids[k];
      for (int d = 0; d < kDim; ++d)
        engine.contact_targets[k](d) =
            static_cast<Scalar>(targets[std::size_t{k} * kDim + static_cast<std::size_t>(d)]);
    }
    return PLIANT_OK;
  });
  if (status != PLIANT_OK) return reject(instance, kCall, status);
  c.pending_contact_count = to_int(count);
  return PLIANT_OK;
}

pliant_status_t pliant_step_tracker(pliant_t* instance, double dt_s) {
  const pliant_status_t usable = check_instance(instance);
  if (usable != PLIANT_OK) return usable;
  Common& c = instance->common;
  constexpr std::uint8_t kCall = PLIANT_CALL_STEP_TRACKER;
  if (!is_finite(dt_s)) return reject(instance, kCall, PLIANT_ERROR_NON_FINITE);
  if (!(dt_s > 0) || !(static_cast<Scalar>(dt_s) > Scalar(0)))
    return reject(instance, kCall, PLIANT_ERROR_INVALID_ARGUMENT);
  if (!c.pending) return reject(instance, kCall, PLIANT_ERROR_BAD_STATE);
  c.pending = false;
  const pliant::Status stepped = dispatch(instance, [&](auto& engine) {
    using Engine = std::decay_t<decltype(engine)>;
    constexpr int kDim = Engine::Vec::RowsAtCompileTime;
    pliant::TrackerFrame<kDim, Scalar> frame;
    frame.dt = static_cast<Scalar>(dt_s);
    frame.driven.ids = engine.contact_ids;
    frame.driven.positions = engine.contact_targets;
    frame.driven.count = c.pending_contact_count;
    frame.observed = c.pending_observed ? engine.observed : nullptr;
    frame.confidence = c.pending_confidence ? engine.confidence : nullptr;
    const pliant::Status status = pliant::tracker_update(engine.model, engine.tracker, frame);
    if (status == pliant::Status::ok || status == pliant::Status::no_observations) {
      for (int k = 0; k < c.pending_contact_count; ++k) {
        engine.last_contact_ids[k] = engine.contact_ids[k];
        engine.last_contact_targets[k] = engine.contact_targets[k];
      }
    }
    return status;
  });
  if (stepped != pliant::Status::ok && stepped != pliant::Status::no_observations) {
    return reject(instance, kCall, to_status(stepped));
  }
  if (c.estimate_due) {
    // The previous frame never reached the estimator: its time goes into the next update.
    ++c.estimator_frames_skipped;
    c.skipped_dt_s += c.frame_dt_s;
  }
  c.last_contact_count = c.pending_contact_count;
  c.last_stamp_s = c.pending_stamp_s;
  c.frame_stamp_s = c.pending_stamp_s;
  c.frame_dt_s = dt_s;
  c.has_frame = true;
  c.estimate_due = c.estimator_enabled;
  dispatch(instance, [&](auto& engine) { publish_frame(c, engine); });
  return to_status(stepped);
}

pliant_status_t pliant_get_tracked(pliant_t* instance, float* positions, uint8_t* status, uint32_t particle_capacity,
                                   uint32_t* out_frame_index) {
  const pliant_status_t usable = check_instance(instance);
  if (usable != PLIANT_OK) return usable;
  const Common& c = instance->common;
  constexpr std::uint8_t kCall = PLIANT_CALL_GET_TRACKED;
  if (positions == nullptr && status == nullptr) return reject(instance, kCall, PLIANT_ERROR_NULL_ARGUMENT);
  if (particle_capacity < c.particle_count) return reject(instance, kCall, PLIANT_ERROR_INVALID_ARGUMENT);
  const int n = to_int(c.particle_count);
  dispatch(instance, [&](auto& engine) {
    constexpr int kDim = std::decay_t<decltype(engine)>::Vec::RowsAtCompileTime;
    const auto& tracker = engine.tracker;
    for (int i = 0; i < n; ++i) {
      if (positions != nullptr) {
        for (int d = 0; d < kDim; ++d) positions[i * kDim + d] = static_cast<float>(tracker.state.position[i](d));
      }
      if (status != nullptr) status[i] = static_cast<std::uint8_t>(tracker.status[i]);
    }
    if (out_frame_index != nullptr) *out_frame_index = tracker.frame_index;
  });
  return PLIANT_OK;
}

}  // extern "C"
