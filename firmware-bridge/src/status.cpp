// Version, ABI, status codes and names.
#include "bridge_internal.hpp"

#define PLIANT_BRIDGE_STRINGIFY_(x) #x
#define PLIANT_BRIDGE_STRINGIFY(x) PLIANT_BRIDGE_STRINGIFY_(x)

// The header's version must be the project's (CMake passes project(VERSION) in).
#if defined(PLIANT_PROJECT_VERSION_MAJOR)
static_assert(PLIANT_VERSION_MAJOR == PLIANT_PROJECT_VERSION_MAJOR &&
                  PLIANT_VERSION_MINOR == PLIANT_PROJECT_VERSION_MINOR &&
                  PLIANT_VERSION_PATCH == PLIANT_PROJECT_VERSION_PATCH,
              "pliant.h PLIANT_VERSION_* differs from the CMake project version");
#endif

// The ABI's numbers are the core's.
static_assert(PLIANT_VERDICT_OK == static_cast<unsigned>(pliant::GraspVerdict::ok) &&
              PLIANT_VERDICT_LIMIT == static_cast<unsigned>(pliant::GraspVerdict::limit) &&
              PLIANT_VERDICT_STOP == static_cast<unsigned>(pliant::GraspVerdict::stop));
static_assert(PLIANT_STOP_FREEZE == static_cast<unsigned>(pliant::StopAction::freeze) &&
              PLIANT_STOP_OPEN == static_cast<unsigned>(pliant::StopAction::open));
static_assert(PLIANT_SOURCE_GRIPPER == static_cast<unsigned>(pliant::GuardSource::gripper) &&
              PLIANT_SOURCE_WRENCH == static_cast<unsigned>(pliant::GuardSource::wrench) &&
              PLIANT_SOURCE_CAMERA == static_cast<unsigned>(pliant::GuardSource::camera) &&
              PLIANT_SOURCE_ESTIMATE == static_cast<unsigned>(pliant::GuardSource::estimate) &&
              PLIANT_SOURCE_CLOCK == static_cast<unsigned>(pliant::GuardSource::clock) &&
              PLIANT_GUARD_SOURCE_COUNT == static_cast<unsigned>(pliant::kGuardSourceCount));
static_assert(PLIANT_FORCE_SENSOR == static_cast<unsigned>(pliant::ForceSource::force_sensor) &&
              PLIANT_FORCE_MOTOR_CURRENT == static_cast<unsigned>(pliant::ForceSource::motor_current));
static_assert(PLIANT_CLUSTERS_RADIUS == static_cast<unsigned>(pliant::ClusterLayout::radius) &&
              PLIANT_CLUSTERS_K_NEAREST == static_cast<unsigned>(pliant::ClusterLayout::k_nearest) &&
              PLIANT_CLUSTERS_GRID_BLOCKS == static_cast<unsigned>(pliant::ClusterLayout::grid_blocks));
static_assert(PLIANT_TRACK_OBSERVED == static_cast<unsigned>(pliant::TrackStatus::observed) &&
              PLIANT_TRACK_PREDICTED == static_cast<unsigned>(pliant::TrackStatus::predicted) &&
              PLIANT_TRACK_LOST == static_cast<unsigned>(pliant::TrackStatus::lost));
static_assert(PLIANT_REASON_NONE == static_cast<unsigned>(pliant::GuardReason::none) &&
              PLIANT_REASON_FORCE_EXCEEDED == static_cast<unsigned>(pliant::GuardReason::force_exceeded) &&
              PLIANT_REASON_STRAIN_EXCEEDED == static_cast<unsigned>(pliant::GuardReason::strain_exceeded) &&
              PLIANT_REASON_INDENTATION_EXCEEDED == static_cast<unsigned>(pliant::GuardReason::indentation_exceeded) &&
              PLIANT_REASON_NOT_CONFIGURED == static_cast<unsigned>(pliant::GuardReason::not_configured) &&
              PLIANT_REASON_NAN_INPUT == static_cast<unsigned>(pliant::GuardReason::nan_input) &&
              PLIANT_REASON_INVALID_INPUT == static_cast<unsigned>(pliant::GuardReason::invalid_input) &&
              PLIANT_REASON_SENSOR_FAULT == static_cast<unsigned>(pliant::GuardReason::sensor_fault) &&
              PLIANT_REASON_BUS_OFF == static_cast<unsigned>(pliant::GuardReason::bus_off) &&
              PLIANT_REASON_TIMEOUT == static_cast<unsigned>(pliant::GuardReason::timeout) &&
              PLIANT_REASON_STALE_GRIPPER == static_cast<unsigned>(pliant::GuardReason::stale_gripper) &&
              PLIANT_REASON_STALE_WRENCH == static_cast<unsigned>(pliant::GuardReason::stale_wrench) &&
              PLIANT_REASON_STALE_CAMERA == static_cast<unsigned>(pliant::GuardReason::stale_camera) &&
              PLIANT_REASON_STALE_ESTIMATE == static_cast<unsigned>(pliant::GuardReason::stale_estimate) &&
              PLIANT_REASON_FORCE_LIMIT == static_cast<unsigned>(pliant::GuardReason::force_limit) &&
              PLIANT_REASON_STRAIN_LIMIT == static_cast<unsigned>(pliant::GuardReason::strain_limit) &&
              PLIANT_REASON_INDENTATION_LIMIT == static_cast<unsigned>(pliant::GuardReason::indentation_limit) &&
              PLIANT_REASON_PREDICTED_STRAIN == static_cast<unsigned>(pliant::GuardReason::predicted_strain) &&
              PLIANT_REASON_ESTIMATE_UNCERTAIN == static_cast<unsigned>(pliant::GuardReason::estimate_uncertain) &&
              PLIANT_REASON_COUNT == static_cast<unsigned>(pliant::kGuardReasonCount));
static_assert(PLIANT_REASON_COUNT <= 32, "reasons is a 32-bit mask");

namespace pliant::bridge {

pliant_status_t to_status(Status status) noexcept {
  switch (status) {
    case Status::ok: return PLIANT_OK;
    case Status::no_observations: return PLIANT_NO_OBSERVATIONS;
    case Status::invalid_argument: return PLIANT_ERROR_INVALID_ARGUMENT;
    case Status::capacity_exceeded: return PLIANT_ERROR_MEMORY_TOO_SMALL;
    case Status::invalid_mass: return PLIANT_ERROR_INVALID_MASS;
    case Status::non_finite_input: return PLIANT_ERROR_NON_FINITE;
    case Status::duplicate_rest_positions: return PLIANT_ERROR_DUPLICATE_REST;
    case Status::degenerate_cluster: return PLIANT_ERROR_DEGENERATE_CLUSTER;
    case Status::no_free_particles: return PLIANT_ERROR_NO_FREE_PARTICLES;
    // The bridge never hands the core an uninitialised object or asks for an iteration.
    case Status::not_converged:
    case Status::not_initialized: return PLIANT_ERROR_INTERNAL;
  }
  return PLIANT_ERROR_INTERNAL;
}

}  // namespace pliant::bridge

extern "C" {

uint32_t pliant_version(void) { return PLIANT_VERSION_NUMBER; }

const char* pliant_version_string(void) {
  return PLIANT_BRIDGE_STRINGIFY(PLIANT_VERSION_MAJOR) "." PLIANT_BRIDGE_STRINGIFY(
      PLIANT_VERSION_MINOR) "." PLIANT_BRIDGE_STRINGIFY(PLIANT_VERSION_PATCH);
}

uint32_t pliant_abi_version(void) { return PLIANT_ABI_VERSION; }

const char* pliant_status_name(pliant_status_t status) {
  switch (status) {
    case PLIANT_OK: return "ok";
    case PLIANT_NO_OBSERVATIONS: return "no_observations";
    case PLIANT_ERROR_NULL_ARGUMENT: return "error_null_argument";
    case PLIANT_ERROR_INVALID_ARGUMENT: return "error_invalid_argument";
    case PLIANT_ERROR_NON_FINITE: return "error_non_finite";
    case PLIANT_ERROR_STAMP_ORDER: return "error_stamp_order";
    case PLIANT_ERROR_ABI_MISMATCH: return "error_abi_mismatch";
    case PLIANT_ERROR_MEMORY_TOO_SMALL: return "error_memory_too_small";
    case PLIANT_ERROR_NOT_INITIALIZED: return "error_not_initialized";
    case PLIANT_ERROR_BAD_STATE: return "error_bad_state";
    case PLIANT_ERROR_DISABLED: return "error_disabled";
    case PLIANT_ERROR_INVALID_MASS: return "error_invalid_mass";
    case PLIANT_ERROR_DUPLICATE_REST: return "error_duplicate_rest";
    case PLIANT_ERROR_DEGENERATE_CLUSTER: return "error_degenerate_cluster";
    case PLIANT_ERROR_NO_FREE_PARTICLES: return "error_no_free_particles";
    case PLIANT_ERROR_INTERNAL: return "error_internal";
    case PLIANT_STATUS_COUNT: break;
  }
  return "unknown";
}

const char* pliant_verdict_name(uint8_t verdict) {
  if (verdict > PLIANT_VERDICT_STOP) return "unknown";
  return pliant::grasp_verdict_name(static_cast<pliant::GraspVerdict>(verdict));
}

const char* pliant_reason_name(uint8_t reason) {
  if (reason >= PLIANT_REASON_COUNT) return "unknown";
  return pliant::guard_reason_name(static_cast<pliant::GuardReason>(reason));
}

const char* pliant_source_name(uint8_t source) {
  if (source >= PLIANT_GUARD_SOURCE_COUNT) return "unknown";
  return pliant::guard_source_name(static_cast<pliant::GuardSource>(source));
}

void pliant_set_assert_handler(pliant_assert_handler_t handler) { pliant::set_assert_handler(handler); }

}  // extern "C"
