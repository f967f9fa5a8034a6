// Layout of the caller's block: the workspace size and the build of an instance in it.
//
// The block holds the instance, the Engine, init-only scratch (the rest shape and masses in the
// internal Scalar, int copies of the id lists), the object model, the guard's model, the
// tracker, the estimator, the guard and the per-frame buffers. Every carve is aligned to
// kArenaAlignment and measuring Arenas count the worst-case padding, so a block of the queried
// size works at any address, and the sum of the parts' sizes bounds the whole in any order.
//
// The query cannot build the models (that needs the block), so it sizes them with the core's
// own query on a float copy of the config, which reads the caller's float rest positions
// directly: exact when the bridge computes in float; in double every Scalar array doubles and
// no other array grows, so twice the float size bounds it. The tracker's, estimator's and
// guard's states are arrays per particle and per cluster, so their sizes come from the core's
// queries on a model carrying only those counts (see bytes_for_counts); init then carves the
// real thing, and a query that fell short would fail there as MEMORY_TOO_SMALL, never overrun.
#include <type_traits>

#include "bridge_internal.hpp"

namespace pliant::bridge {
namespace {

constexpr bool kScalarIsFloat = std::is_same_v<Scalar, float>;
// The core's size query refused the rest shape without saying why (internal only).
constexpr auto kModelRefused = static_cast<pliant_status_t>(PLIANT_STATUS_COUNT + 1);

struct InitScratch {
  Scalar* rest = nullptr;    ///< [N * dim], only when Scalar is not float
  Scalar* masses = nullptr;  ///< [N], when masses are given and Scalar is not float
  int* drivable = nullptr;   ///< [drivable_count]
  int* all_ids = nullptr;    ///< [N] the guard model's drivable list
  int* jaw_a = nullptr;
  int* jaw_b = nullptr;
};

void carve_scratch(Arena& arena, const pliant_config_t& config, InitScratch& scratch) noexcept {
  const std::size_t n = config.particle_count;
  if (!kScalarIsFloat) {
    scratch.rest = arena.carve<Scalar>(n * config.dim);
    if (config.masses != nullptr) scratch.masses = arena.carve<Scalar>(n);
  }
  scratch.drivable = arena.carve<int>(config.drivable_count);
  if (config.guard.enabled) {
    scratch.all_ids = arena.carve<int>(n);
    scratch.jaw_a = arena.carve<int>(config.guard.jaw_a_count);
    scratch.jaw_b = arena.carve<int>(config.guard.jaw_b_count);
  }
}

template <int Dim>
void carve_buffers(Arena& arena, const pliant_config_t& config, FrameBuffers<Dim>& buffers) noexcept {
  using Vec = typename FrameBuffers<Dim>::Vec;
  const std::size_t n = config.particle_count;
  const std::size_t drivable = config.drivable_count;
  buffers.observed = arena.carve<Vec>(n);
  buffers.confidence = arena.carve<Scalar>(n);
  buffers.contact_ids = arena.carve<int>(drivable);
  buffers.contact_targets = arena.carve<Vec>(drivable);
  buffers.last_contact_ids = arena.carve<int>(drivable);
  buffers.last_contact_targets = arena.carve<Vec>(drivable);
  if (config.guard.enabled) buffers.strain_positions = arena.carve<Vec>(n);
  if (config.estimator.enabled) buffers.estimate_positions = arena.carve<Vec>(n);
  buffers.contact_mark = arena.carve<std::uint8_t>(n);
  buffers.telemetry_positions = arena.carve<float>(n * Dim);
  buffers.telemetry_status = arena.carve<std::uint8_t>(n);
}

// The caller's float array when the bridge computes in float, else its converted copy.
[[maybe_unused]] const float* in_scalar(const float* caller, float* /*converted*/) noexcept { return caller; }
[[maybe_unused]] const double* in_scalar(const float* /*caller*/, double* converted) noexcept { return converted; }

int cluster_count(const pliant_config_t& config) noexcept {
  const pliant_cluster_config_t& c = config.clusters;
  if (c.layout != PLIANT_CLUSTERS_GRID_BLOCKS) return to_int(config.particle_count);
  return (c.grid_cols - c.block_cols + 1) * (c.grid_rows - c.block_rows + 1) * (c.grid_layers - c.block_layers + 1);
}

// Bytes of one MSM model of the config's rest shape and clusters (0: the core refused it).
template <int Dim>
std::size_t model_bytes(const pliant_config_t& config) noexcept {
  MsmModelConfig<Dim, float> shape;
  shape.particle_count = to_int(config.particle_count);
  shape.rest_positions = config.rest_positions;
  shape.clusters = to_core(config.clusters);
  const std::size_t bytes = msm_model_workspace_size(shape);
  return kScalarIsFloat ? bytes : 2 * bytes;
}

// A component's workspace for the config's particle and cluster counts, from the core's own
// query on a model that carries just the counts: the rest origin, and cluster offsets of one
// cluster holding every particle (so a per-cluster scratch sized by the largest cluster gets
// its bound, N). Sizes are affine in the cluster count (arrays per particle and per cluster,
// padding per array), so measuring 1 and 2 clusters gives the size for C. 0: refused.
template <int Dim, typename Query>
std::size_t bytes_for_counts(const pliant_config_t& config, Query&& query) noexcept {
  typename MsmModel<Dim, Scalar>::Vec origin = MsmModel<Dim, Scalar>::Vec::Zero();
  const auto n = static_cast<std::int32_t>(config.particle_count);
  std::int32_t cluster_begin[3] = {0, n, n};
  MsmModel<Dim, Scalar> counts;
  counts.particle_count = n;
  counts.spacing = Scalar(1);
  counts.rest = &origin;
  counts.cluster_begin = cluster_begin;
  counts.cluster_count = 1;
  const std::size_t one = query(counts);
  counts.cluster_count = 2;
  const std::size_t two = query(counts);
  if (one == 0 || two < one) return 0;
  return one + static_cast<std::size_t>(cluster_count(config) - 1) * (two - one);
}

template <int Dim>
pliant_status_t required_bytes_dim(const pliant_config_t& config, std::size_t& bytes) noexcept {
  const std::size_t one_model = model_bytes<Dim>(config);
  if (one_model == 0) return kModelRefused;
  Arena measure;
  (void)measure.carve<pliant_s>(1);
  (void)measure.carve<Engine<Dim>>(1);
  InitScratch scratch;
  carve_scratch(measure, config, scratch);
  FrameBuffers<Dim> buffers;
  carve_buffers(measure, config, buffers);
  std::size_t total = measure.required_bytes();
  total += config.guard.enabled ? 2 * one_model : one_model;

  const std::size_t tracker = bytes_for_counts<Dim>(config, [&](const MsmModel<Dim, Scalar>& counts) {
    return tracker_workspace_size(counts, to_core(config.tracker));
  });
  if (tracker == 0) return PLIANT_ERROR_INVALID_ARGUMENT;
  total += tracker;
  if (config.estimator.enabled) {
    const std::size_t estimator = bytes_for_counts<Dim>(config, [&](const MsmModel<Dim, Scalar>& counts) {
      return online_deformability_workspace_size(counts, to_core(config.estimator));
    });
    if (estimator == 0) return PLIANT_ERROR_INVALID_ARGUMENT;
    total += estimator;
  }
  if (config.guard.enabled) {
    const std::size_t guard = bytes_for_counts<Dim>(config, [&](const MsmModel<Dim, Scalar>& counts) {
      return grasp_guard_workspace_size(counts, to_core(config.guard));
    });
    if (guard == 0) return PLIANT_ERROR_INVALID_ARGUMENT;
    total += guard;
  }
  bytes = total;
  return PLIANT_OK;
}

template <int Dim>
pliant_status_t build(Arena& arena, const pliant_config_t& config, pliant_t& instance) noexcept {
  const int n = to_int(config.particle_count);
  Engine<Dim>* engine = arena.carve<Engine<Dim>>(1);
  InitScratch scratch;
  carve_scratch(arena, config, scratch);
  if (engine == nullptr || arena.exhausted()) return PLIANT_ERROR_MEMORY_TOO_SMALL;

  // The object model.
  if (scratch.rest != nullptr) {
    for (int i = 0; i < n * Dim; ++i) scratch.rest[i] = static_cast<Scalar>(config.rest_positions[i]);
  }
  if (scratch.masses != nullptr) {
    for (int i = 0; i < n; ++i) scratch.masses[i] = static_cast<Scalar>(config.masses[i]);
  }
  const Scalar* rest = in_scalar(config.rest_positions, scratch.rest);
  const Scalar* masses = config.masses != nullptr ? in_scalar(config.masses, scratch.masses) : nullptr;
  for (std::uint32_t k = 0; k < config.drivable_count; ++k) scratch.drivable[k] = config.drivable_ids[k];
  MsmModelConfig<Dim, Scalar> object;
  object.particle_count = n;
  object.rest_positions = rest;
  object.masses = masses;
  object.fixed = config.fixed;
  object.drivable_ids = scratch.drivable;
  object.drivable_count = to_int(config.drivable_count);
  object.driven_mass_factor = config.msm.driven_mass_factor;
  object.clusters = to_core(config.clusters);
  Status status = msm_model_init(arena, object, engine->model);
  if (status != Status::ok) return to_status(status);

  const MsmParams<Dim, Scalar> params = to_core_params<Dim>(config.msm);
  status = tracker_init(arena, engine->model, params, to_core(config.tracker), engine->tracker);
  if (status != Status::ok) return to_status(status);

  if (config.estimator.enabled) {
    bool any_free = false;
    for (int i = 0; i < n; ++i) any_free = any_free || (engine->model.fixed[i] == 0 && engine->model.drivable[i] == 0);
    if (!any_free) return PLIANT_ERROR_NO_FREE_PARTICLES;
    status = online_deformability_init(arena, engine->model, params, to_core(config.estimator), engine->estimator);
    if (status != Status::ok) return to_status(status);
  }

  if (config.guard.enabled) {
    // The guard squeezes the object between jaws that may touch any particle, unpinned.
    for (int i = 0; i < n; ++i) scratch.all_ids[i] = i;
    MsmModelConfig<Dim, Scalar> squeezed = object;
    squeezed.fixed = nullptr;
    squeezed.drivable_ids = scratch.all_ids;
    squeezed.drivable_count = n;
    squeezed.driven_mass_factor = 1.0;
    status = msm_model_init(arena, squeezed, engine->guard_model);
    if (status != Status::ok) return to_status(status);
    const pliant_guard_config_t& g = config.guard;
    for (std::uint32_t k = 0; k < g.jaw_a_count; ++k) scratch.jaw_a[k] = g.jaw_a_ids[k];
    for (std::uint32_t k = 0; k < g.jaw_b_count; ++k) scratch.jaw_b[k] = g.jaw_b_ids[k];
    const GraspObject<Dim, Scalar> jaws = to_core_object<Dim>(g, g.jaw_a_count > 0 ? scratch.jaw_a : nullptr,
                                                              g.jaw_b_count > 0 ? scratch.jaw_b : nullptr);
    status = grasp_guard_init(arena, engine->guard_model, jaws, to_core(g), engine->guard);
    if (status != Status::ok) return to_status(status);
  }

  carve_buffers(arena, config, static_cast<FrameBuffers<Dim>&>(*engine));
  if (arena.exhausted()) return PLIANT_ERROR_MEMORY_TOO_SMALL;
  for (int i = 0; i < n; ++i) {
    engine->observed[i].setConstant(std::numeric_limits<Scalar>::quiet_NaN());
    engine->confidence[i] = Scalar(0);
  }
  if constexpr (Dim == 2) {
    instance.engine2 = engine;
  } else {
    instance.engine3 = engine;
  }
  return PLIANT_OK;
}

}  // namespace

pliant_status_t required_bytes(const pliant_config_t& config, std::size_t& bytes) noexcept {
  const pliant_status_t status =
      config.dim == 2 ? required_bytes_dim<2>(config, bytes) : required_bytes_dim<3>(config, bytes);
  return status == kModelRefused ? PLIANT_ERROR_INVALID_ARGUMENT : status;
}

pliant_status_t model_refusal(void* memory, std::size_t size, const pliant_config_t& config) noexcept {
  std::size_t bytes = 0;
  const pliant_status_t sized =
      config.dim == 2 ? required_bytes_dim<2>(config, bytes) : required_bytes_dim<3>(config, bytes);
  if (sized != kModelRefused) return sized == PLIANT_OK ? PLIANT_ERROR_INTERNAL : sized;
  // Build the object model alone in the caller's block, for the core's own reason.
  Arena arena(memory, size);
  pliant_t* instance = arena.carve<pliant_s>(1);
  if (instance == nullptr) return PLIANT_ERROR_INVALID_ARGUMENT;
  const pliant_status_t built =
      config.dim == 2 ? build<2>(arena, config, *instance) : build<3>(arena, config, *instance);
  return built == PLIANT_OK || built == PLIANT_ERROR_MEMORY_TOO_SMALL ? PLIANT_ERROR_INVALID_ARGUMENT : built;
}

pliant_status_t build_instance(void* memory, std::size_t size, const pliant_config_t& config, std::size_t bytes,
                               pliant_t*& out) noexcept {
  out = nullptr;
  Arena arena(memory, size);
  pliant_t* instance = arena.carve<pliant_s>(1);
  if (instance == nullptr) return PLIANT_ERROR_MEMORY_TOO_SMALL;
  instance->dim = config.dim;
  const pliant_status_t status =
      config.dim == 2 ? build<2>(arena, config, *instance) : build<3>(arena, config, *instance);
  if (status != PLIANT_OK) return status;

  Common& c = instance->common;
  c.particle_count = config.particle_count;
  c.drivable_count = config.drivable_count;
  c.workspace_bytes = bytes;
  c.estimator_enabled = config.estimator.enabled;
  c.guard_enabled = config.guard.enabled;
  c.feed_back_beta = config.estimator.feed_back_beta;
  c.feed_back_max_std = config.estimator.feed_back_max_std;
  c.initial_msm_beta = config.msm.msm_beta;
  c.deformation.stamp_s = kNaN;
  c.deformation.strain = kNaN;
  c.deformation.cluster = -1;
  c.estimate.msm_beta = config.msm.msm_beta;
  c.estimate.msm_beta_std = kInf;
  pliant_tm_encoder_init(&c.telemetry, 0);
  instance->magic = kMagic;
  out = instance;
  return PLIANT_OK;
}

}  // namespace pliant::bridge
