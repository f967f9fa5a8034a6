// Internal to pliant_bridge: the instance layout and helpers shared by the bridge's sources.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>

#include "pliant.h"
#include "pliant_telemetry.h"
#include "pliant/core/grasp_guard.hpp"
#include "pliant/core/msm_model.hpp"
#include "pliant/core/online_deformability.hpp"
#include "pliant/core/tracker.hpp"

namespace pliant::bridge {

#if defined(PLIANT_BRIDGE_SCALAR_DOUBLE) && PLIANT_BRIDGE_SCALAR_DOUBLE
using Scalar = double;
#else
using Scalar = float;
#endif

inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
inline constexpr double kInf = std::numeric_limits<double>::infinity();
inline constexpr std::uint32_t kMagic = 0x504c4e54u;  // "PLNT"
/// Upper bound of particles, so that every count * dim * sizeof fits an int32 byte offset.
inline constexpr std::uint32_t kMaxParticles = 1u << 20;
inline constexpr std::int32_t kMaxCandidates = 1001;

/// The per-frame arrays of an Engine (carved from the block at init).
template <int Dim>
struct FrameBuffers {
  using Vec = Eigen::Matrix<Scalar, Dim, 1>;
  Vec* observed = nullptr;          ///< [N] the pending frame
  Scalar* confidence = nullptr;     ///< [N] the pending frame's confidences
  int* contact_ids = nullptr;       ///< [drivable_count] the pending frame's tool contact
  Vec* contact_targets = nullptr;   ///< [drivable_count]
  int* last_contact_ids = nullptr;  ///< [drivable_count] the last stepped frame's contact
  Vec* last_contact_targets = nullptr;
  Vec* strain_positions = nullptr;           ///< [N] last tracked frame, lost particles NaN (guard on)
  Vec* estimate_positions = nullptr;         ///< [N] last tracked frame, observed particles only (estimator on)
  std::uint8_t* contact_mark = nullptr;      ///< [N] all 0 between calls: repeated-id check scratch
  float* telemetry_positions = nullptr;      ///< [N * Dim] the tracked frame as the codec reads it
  std::uint8_t* telemetry_status = nullptr;  ///< [N]
};

/// Everything whose type depends on the dimension.
template <int Dim>
struct Engine : FrameBuffers<Dim> {
  MsmModel<Dim, Scalar> model;        ///< the object: fixed and drivable as configured
  MsmModel<Dim, Scalar> guard_model;  ///< same rest shape and clusters, all drivable, none fixed
  Tracker<Dim, Scalar> tracker;
  OnlineDeformability<Dim, Scalar> estimator;
  GraspGuard<Dim, Scalar> guard;
};

/// Bridge state that does not depend on the dimension.
struct Common {
  std::uint32_t particle_count = 0;
  std::uint32_t drivable_count = 0;
  std::size_t workspace_bytes = 0;
  bool estimator_enabled = false;
  bool guard_enabled = false;
  bool feed_back_beta = false;
  double feed_back_max_std = 0;
  double initial_msm_beta = 0;

  // The pending frame (pushed, not yet stepped).
  bool pending = false;
  bool pending_observed = false;    ///< positions were given
  bool pending_confidence = false;  ///< confidences were given
  double pending_stamp_s = kNaN;
  int pending_contact_count = 0;

  // The last stepped frame.
  bool has_frame = false;
  double last_stamp_s = -kInf;  ///< stamp order reference (kept across reset_grasp)
  double frame_stamp_s = kNaN;  ///< stamp of the last frame stepped since init / reset
  double frame_dt_s = 0;
  int last_contact_count = 0;
  bool estimate_due = false;  ///< the last stepped frame has not been given to the estimator
  double skipped_dt_s = 0;    ///< time of stepped frames the estimator missed

  // Published samples.
  pliant_deformation_t deformation{};
  double estimate_stamp_s = kNaN;        ///< frame of the last estimator update; NaN before any
  OnlineDeformabilityEstimate estimate;  ///< cached after each estimator update
  bool estimate_fed_back = false;
  pliant_verdict_t last_verdict{};  ///< the last guard cycle's verdict (telemetry)
  bool has_verdict = false;
  pliant_tm_encoder_t telemetry{};  ///< sequence numbers of emitted packets

  // The bridge's own counters.
  std::uint32_t estimator_frames = 0;  ///< the core's count restarts at reset; this one does not
  std::uint32_t calls_rejected = 0;
  std::uint32_t frames_replaced = 0;
  std::uint32_t estimator_frames_skipped = 0;
  std::uint32_t strain_unmeasured = 0;
  std::uint32_t telemetry_not_sent = 0;
  std::uint8_t last_rejected_status = PLIANT_OK;
  std::uint8_t last_rejected_call = PLIANT_CALL_NONE;
};

}  // namespace pliant::bridge

/// The opaque instance of pliant.h, placed at the start of the caller's block.
struct pliant_s {
  std::uint32_t magic = 0;
  std::uint32_t dim = 0;
  pliant::bridge::Engine<2>* engine2 = nullptr;
  pliant::bridge::Engine<3>* engine3 = nullptr;
  pliant::bridge::Common common;
};

namespace pliant::bridge {

/// Maps a core status to the ABI's.
pliant_status_t to_status(Status status) noexcept;

/// Counts a refused call on a usable instance and returns `status`.
inline pliant_status_t reject(pliant_t* instance, std::uint8_t call, pliant_status_t status) noexcept {
  Common& c = instance->common;
  ++c.calls_rejected;
  c.last_rejected_status = static_cast<std::uint8_t>(status);
  c.last_rejected_call = call;
  return status;
}

/// PLIANT_OK when `instance` is usable; otherwise the status to return (not counted: there is
/// no instance to count in).
inline pliant_status_t check_instance(const pliant_t* instance) noexcept {
  if (instance == nullptr) return PLIANT_ERROR_NULL_ARGUMENT;
  if (instance->magic != kMagic) return PLIANT_ERROR_NOT_INITIALIZED;
  return PLIANT_OK;
}

/// Calls f(engine) with the instance's Engine<2> or Engine<3>.
template <typename F>
decltype(auto) dispatch(pliant_t* instance, F&& f) noexcept {
  if (instance->dim == 2) return f(*instance->engine2);
  return f(*instance->engine3);
}

inline bool is_finite(double value) noexcept { return std::isfinite(value); }

/// Reads an ABI uint32 count as an int (callers have bounded it by kMaxParticles).
inline int to_int(std::uint32_t value) noexcept { return static_cast<int>(value); }

// --- configuration mapping (config.cpp) -------------------------------------------------------

/// The abi stamp this library was built with.
pliant_abi_t library_abi() noexcept;
bool abi_matches(const pliant_abi_t& abi) noexcept;

/// Validates everything that can be checked without building a model. PLIANT_OK or the error.
pliant_status_t validate_config(const pliant_config_t& config) noexcept;

ClusterConfig to_core(const pliant_cluster_config_t& clusters) noexcept;
TrackerConfig to_core(const pliant_tracker_config_t& tracker) noexcept;
OnlineDeformabilityConfig to_core(const pliant_estimator_config_t& estimator) noexcept;
GraspGuardConfig to_core(const pliant_guard_config_t& guard) noexcept;

template <int Dim>
MsmParams<Dim, Scalar> to_core_params(const pliant_msm_config_t& msm) noexcept {
  MsmParams<Dim, Scalar> params;
  params.msm_alpha = static_cast<Scalar>(msm.msm_alpha);
  params.msm_beta = static_cast<Scalar>(msm.msm_beta);
  for (int d = 0; d < Dim; ++d) params.gravity(d) = static_cast<Scalar>(msm.gravity[d]);
  params.velocity_damping = static_cast<Scalar>(msm.velocity_damping);
  return params;
}

template <int Dim>
GraspObject<Dim, Scalar> to_core_object(const pliant_guard_config_t& guard, const int* jaw_a,
                                        const int* jaw_b) noexcept {
  GraspObject<Dim, Scalar> object;
  for (int d = 0; d < Dim; ++d) object.squeeze_axis(d) = static_cast<Scalar>(guard.squeeze_axis[d]);
  object.jaw_a_ids = jaw_a;
  object.jaw_a_count = jaw_a != nullptr ? to_int(guard.jaw_a_count) : 0;
  object.jaw_b_ids = jaw_b;
  object.jaw_b_count = jaw_b != nullptr ? to_int(guard.jaw_b_count) : 0;
  object.contact_band = guard.contact_band;
  return object;
}

// --- layout (layout.cpp) ----------------------------------------------------------------------

/// Bytes pliant_init needs for a validated config.
pliant_status_t required_bytes(const pliant_config_t& config, std::size_t& bytes) noexcept;

/// Why the core refuses the config's rest shape (duplicates, degenerate clusters...): builds it
/// in the caller's block to learn the status. Call only after required_bytes failed.
pliant_status_t model_refusal(void* memory, std::size_t size, const pliant_config_t& config) noexcept;

/// Builds the instance in the block for a validated config that fits (init.cpp's work).
pliant_status_t build_instance(void* memory, std::size_t size, const pliant_config_t& config, std::size_t bytes,
                               pliant_t*& out) noexcept;

}  // namespace pliant::bridge
