#include "pliant/core/msm.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/LU>

#include "pliant/core/polar.hpp"

namespace pliant {
namespace {

// Newton iterations on the 3D rotation (polar.hpp) allowed per cluster and step.
constexpr int kRotationIterations = 24;

template <typename Scalar>
bool finite(Scalar value) noexcept {
  return std::isfinite(value);
}

template <int Dim, typename Scalar>
void identity_rotation(ClusterRotation<Dim, Scalar>& rotation) noexcept {
  rotation.setIdentity();
}

// Rotation of `apq` into a matrix, updating the per-cluster warm start.
template <typename Scalar>
Eigen::Matrix<Scalar, 2, 2> rotation_of(const Eigen::Matrix<Scalar, 2, 2>& apq,
                                        Eigen::Matrix<Scalar, 2, 2>& warm) noexcept {
  (void)extract_rotation(apq, warm);
  return warm;
}
template <typename Scalar>
Eigen::Matrix<Scalar, 3, 3> rotation_of(const Eigen::Matrix<Scalar, 3, 3>& apq,
                                        Eigen::Quaternion<Scalar>& warm) noexcept {
  Eigen::Matrix<Scalar, 3, 3> rotation;
  (void)extract_rotation(apq, warm, rotation, kRotationIterations, simulation_rotation_tolerance<Scalar>());
  return rotation;
}

// out = sum of the items at byte offsets offset[k] from `items`, k in [begin, end) (the model's
// precomputed membership offsets). Two interleaved accumulators: these gathers are the bulk of
// a step and a single running sum is latency-bound.
template <typename Item>
inline void gather_sum(const Item* items, const std::int32_t* offset, int begin, int end, Item& out) noexcept {
  const char* base = reinterpret_cast<const char*>(items);
  Item even = Item::Zero();
  Item odd = Item::Zero();
  int k = begin;
  for (; k + 1 < end; k += 2) {
    even += *reinterpret_cast<const Item*>(base + offset[k]);
    odd += *reinterpret_cast<const Item*>(base + offset[k + 1]);
  }
  if (k < end) even += *reinterpret_cast<const Item*>(base + offset[k]);
  out = even + odd;
}

// Goal map [G | b] (column-major out[Dim * (Dim + 1)]) of an elastic cluster:
// G = (1 - beta) R + beta A_pq A_qq^-1 and b = t - G r_c, with t = (sum m x) / M. Column-major
// inputs: apq and aqq_inverse [Dim * Dim], rotation [Dim * Dim], mx_sum and rest_centroid [Dim].
template <int Dim, typename Scalar>
PLIANT_INLINE void elastic_goal_map(const Scalar* apq, const Scalar* aqq_inverse, const Scalar* rotation, Scalar beta,
                                    const Scalar* mx_sum, Scalar inverse_mass, const Scalar* rest_centroid,
                                    Scalar* out) noexcept {
  const Scalar keep = Scalar(1) - beta;
  for (int col = 0; col < Dim; ++col) {
    for (int row = 0; row < Dim; ++row) {
      Scalar affine = apq[row] * aqq_inverse[col * Dim];
      for (int k = 1; k < Dim; ++k) affine += apq[k * Dim + row] * aqq_inverse[col * Dim + k];
      out[col * Dim + row] = keep * rotation[col * Dim + row] + beta * affine;
    }
  }
  for (int row = 0; row < Dim; ++row) {
    Scalar mapped = out[row] * rest_centroid[0];
    for (int k = 1; k < Dim; ++k) mapped += out[k * Dim + row] * rest_centroid[k];
    out[Dim * Dim + row] = mx_sum[row] * inverse_mass - mapped;
  }
}

// A_pq relative to the cluster's rest centroid from the moment sum [sum m x r^T | sum m x]
// (column-major sum[Dim * (Dim + 1)]): A_pq = sum m x r^T - (sum m x) r_c^T.
template <int Dim, typename Scalar>
PLIANT_INLINE void cluster_apq(const Scalar* sum, const Scalar* rest_centroid, Scalar* apq) noexcept {
  for (int col = 0; col < Dim; ++col) {
    for (int row = 0; row < Dim; ++row)
      apq[col * Dim + row] = sum[col * Dim + row] - sum[Dim * Dim + row] * rest_centroid[col];
  }
}

// Scratch of one batch of the elastic cluster pass, laid out [field][lane] so that the lane loops
// vectorise. Lanes past `count` are padding: a copy of lane 0, computed and discarded.
template <int Dim, typename Scalar>
struct ClusterBatch {
  static constexpr int kBatch = kMsmClusterBatch;
  static constexpr int kMoment = Dim * (Dim + 1);
  static constexpr int kMat = Dim * Dim;
  static constexpr int kWarm = 4;  // 3D quaternion (w, x, y, z); unused in 2D
  static constexpr int kFields = kMsmClusterLaneFields<Dim>;
  // Array extents (unsigned, as -Wsign-conversion wants them).
  static constexpr auto kBatchN = static_cast<std::size_t>(kBatch);
  static constexpr auto kMomentN = static_cast<std::size_t>(kMoment);
  static constexpr auto kMatN = static_cast<std::size_t>(kMat);
  static constexpr auto kWarmN = static_cast<std::size_t>(kWarm);
  static constexpr auto kDimN = static_cast<std::size_t>(Dim);

  int first = 0;  // the batch's first cluster
  int count = 0;  // its clusters (at most kBatch)
  // Model constants of this batch: [field][lane].
  const Scalar* centre = nullptr;
  const Scalar* aqq = nullptr;
  const Scalar* inverse_mass = nullptr;
  alignas(64) Scalar beta[kBatchN];  // kept across batches: params.msm_beta unless cluster_beta
  alignas(64) Scalar sum[kMomentN][kBatchN];
  alignas(64) Scalar apq[kMatN][kBatchN];
  alignas(64) Scalar guard[kBatchN];
  alignas(64) Scalar warm[kWarmN][kBatchN];     // 3D: warm start, then the result
  alignas(64) Scalar rotation[kMatN][kBatchN];  // its matrix, then the result's
  alignas(64) Scalar turned[kWarmN][kBatchN];   // 3D: after the first Newton iteration
  alignas(64) Scalar turned_rotation[kMatN][kBatchN];
  alignas(64) Scalar plain_step[kBatchN];
  alignas(64) Scalar converged[kBatchN];
  alignas(64) Scalar status[kBatchN];  // 0 special case, 1 first step plain, 2 also converged
  alignas(64) Scalar goal[kMomentN][kBatchN];
};

// The batch's model constants, and per lane the cluster's moment sum, warm start and beta.
template <int Dim, typename Scalar>
PLIANT_INLINE void load_cluster_batch(const MsmModel<Dim, Scalar>& model, const MsmParams<Dim, Scalar>& params,
                                      const MsmState<Dim, Scalar>& state, int first,
                                      ClusterBatch<Dim, Scalar>& b) noexcept {
  using Batch = ClusterBatch<Dim, Scalar>;
  constexpr int kBatch = Batch::kBatch;
  b.first = first;
  b.count = std::min(kBatch, model.cluster_count - first);
  const Scalar* constants = model.cluster_lanes + static_cast<std::ptrdiff_t>(first) * Batch::kFields;
  b.centre = constants;
  b.aqq = constants + Dim * kBatch;
  b.inverse_mass = constants + (Dim + Batch::kMat) * kBatch;
  for (int lane = 0; lane < b.count; ++lane) {
    const int c = first + lane;
    Eigen::Matrix<Scalar, Dim, Dim + 1> moment;
    gather_sum(state.moment, model.member_byte_offset, model.cluster_begin[c], model.cluster_begin[c + 1], moment);
    for (int e = 0; e < Batch::kMoment; ++e) b.sum[e][lane] = moment.data()[e];
    if constexpr (Dim == 3) {
      const Eigen::Quaternion<Scalar>& q = state.rotation[c];
      b.warm[0][lane] = q.w();
      b.warm[1][lane] = q.x();
      b.warm[2][lane] = q.y();
      b.warm[3][lane] = q.z();
    }  // 2D needs no warm start: its rotation is closed form
    if (params.cluster_beta != nullptr) b.beta[lane] = params.cluster_beta[c];
  }
  for (int lane = b.count; lane < kBatch; ++lane) {  // padding: a copy of lane 0, computed and discarded
    for (int e = 0; e < Batch::kMoment; ++e) b.sum[e][lane] = b.sum[e][0];
    if constexpr (Dim == 3) {
      for (int e = 0; e < Batch::kWarm; ++e) b.warm[e][lane] = b.warm[e][0];
    }
    if (params.cluster_beta != nullptr) b.beta[lane] = b.beta[0];
  }
}

// 3D: the rotation's starting point is the warm start's matrix `r`; true when extract_rotation
// has no preliminaries to do (a finite, nonzero A_pq and a unit warm start). Sets the lane's
// Newton guard.
template <typename Scalar>
PLIANT_INLINE bool start_rotation_3d(const Scalar* a, ClusterBatch<3, Scalar>& b, int lane, Scalar* r) noexcept {
  constexpr Scalar kEpsilon = std::numeric_limits<Scalar>::epsilon();
  const Scalar w = b.warm[0][lane];
  const Scalar x = b.warm[1][lane];
  const Scalar y = b.warm[2][lane];
  const Scalar z = b.warm[3][lane];
  const Scalar scale2 = detail::squared_sum9(a);
  const Scalar length2 = w * w + x * x + y * y + z * z;
  // Branch-free on purpose (integer &, not &&).
  const bool ok =
      (static_cast<int>(scale2 > Scalar(0)) & static_cast<int>(scale2 <= std::numeric_limits<Scalar>::max()) &
       static_cast<int>(std::abs(length2 - Scalar(1)) <= Scalar(64) * kEpsilon)) != 0;
  b.guard[lane] = std::sqrt(kEpsilon * scale2);
  detail::quaternion_to_matrix(w, x, y, z, r);
  return ok;
}

// 2D: extract_rotation's closed form into `r`; true when it applies, with a margin on its
// acceptance test so that a lane taken here is certainly taken there.
template <typename Scalar>
PLIANT_INLINE bool start_rotation_2d(const Scalar* a, Scalar* r) noexcept {
  constexpr Scalar kEpsilon = std::numeric_limits<Scalar>::epsilon();
  const Scalar cos_part = a[0] + a[3];
  const Scalar sin_part = a[1] - a[2];
  const Scalar length2 = cos_part * cos_part + sin_part * sin_part;
  const Scalar scale2 = a[0] * a[0] + a[1] * a[1] + a[2] * a[2] + a[3] * a[3];
  const bool ok = (length2 > Scalar(4) * kEpsilon * kEpsilon * scale2) &
                  (length2 <= Scalar(0.5) * std::numeric_limits<Scalar>::max());
  const Scalar inverse_length = Scalar(1) / std::sqrt(length2);
  const Scalar co = cos_part * inverse_length;
  const Scalar si = sin_part * inverse_length;
  r[0] = co;
  r[1] = si;
  r[2] = -si;
  r[3] = co;
  return ok;
}

// A_pq and the rotation's starting point, lane-wise; status 2 where the lane-wise path applies.
template <int Dim, typename Scalar>
PLIANT_INLINE void start_rotations(ClusterBatch<Dim, Scalar>& b) noexcept {
  using Batch = ClusterBatch<Dim, Scalar>;
  for (int lane = 0; lane < Batch::kBatch; ++lane) {
    Scalar s[Batch::kMomentN];
    for (int e = 0; e < Batch::kMoment; ++e) s[e] = b.sum[e][lane];
    Scalar rc[Batch::kDimN];
    for (int e = 0; e < Dim; ++e) rc[e] = b.centre[e * Batch::kBatch + lane];
    Scalar a[Batch::kMatN];
    cluster_apq<Dim>(s, rc, a);
    for (int e = 0; e < Batch::kMat; ++e) b.apq[e][lane] = a[e];
    Scalar r[Batch::kMatN];
    bool ok;
    if constexpr (Dim == 3) {
      ok = start_rotation_3d(a, b, lane, r);
    } else {
      ok = start_rotation_2d(a, r);
    }
    for (int e = 0; e < Batch::kMat; ++e) b.rotation[e][lane] = r[e];
    b.status[lane] = ok ? Scalar(2) : Scalar(0);
  }
}

// 3D: the first Newton iteration, lane-wise (extract_rotation's loop body), into `turned`; the
// status becomes 2 for a plain step already converged, 1 for a plain step, else 0.
template <typename Scalar>
PLIANT_INLINE void first_newton_iteration(ClusterBatch<3, Scalar>& b) noexcept {
  using Batch = ClusterBatch<3, Scalar>;
  const Scalar tolerance = simulation_rotation_tolerance<Scalar>();
  const Scalar stop2 = tolerance * tolerance;
  for (int lane = 0; lane < Batch::kBatch; ++lane) {
    Scalar a[Batch::kMatN];
    Scalar r[Batch::kMatN];
    for (int e = 0; e < Batch::kMat; ++e) {
      a[e] = b.apq[e][lane];
      r[e] = b.rotation[e][lane];
    }
    const detail::RotationTerms<Scalar> t = detail::rotation_terms(r, a);
    const Scalar g = b.guard[lane];
    const Scalar g2 = g * g;
    const Scalar g3 = g2 * g;
    const Scalar angle2 = t.n0 * t.n0 + t.n1 * t.n1 + t.n2 * t.n2;
    // A plain Newton step: positive definite H, a nonzero step of at most 1 rad.
    const bool plain = (t.h00 > g) & (t.c22 > g2) & (t.det > g3) & (angle2 > Scalar(0)) & (angle2 <= Scalar(1)) &
                       (b.status[lane] != Scalar(0));
    b.plain_step[lane] = plain ? Scalar(1) : Scalar(0);
    b.converged[lane] = angle2 < stop2 ? Scalar(1) : Scalar(0);
    Scalar w = b.warm[0][lane];
    Scalar x = b.warm[1][lane];
    Scalar y = b.warm[2][lane];
    Scalar z = b.warm[3][lane];
    const Scalar half = Scalar(0.5);
    detail::quaternion_advance(w, x, y, z, half * t.n0, half * t.n1, half * t.n2);
    detail::quaternion_to_matrix(w, x, y, z, r);
    b.turned[0][lane] = w;
    b.turned[1][lane] = x;
    b.turned[2][lane] = y;
    b.turned[3][lane] = z;
    for (int e = 0; e < Batch::kMat; ++e) b.turned_rotation[e][lane] = r[e];
  }
  // status (exact on these small integers): 2 plain and converged, 1 plain, else 0.
  for (int lane = 0; lane < Batch::kBatch; ++lane)
    b.status[lane] = b.plain_step[lane] * (Scalar(1) + b.converged[lane]);
}

// 3D: extract_rotation finishes the lane, resumed after the lane-wise first iteration (status 1)
// or redone from the warm start (status 0); the warm start becomes its result.
template <typename Scalar>
PLIANT_INLINE void scalar_rotation_3d(ClusterBatch<3, Scalar>& b, int lane, const Eigen::Matrix<Scalar, 3, 3>& a,
                                      Eigen::Matrix<Scalar, 3, 3>& r) noexcept {
  const bool resume = b.status[lane] == Scalar(1);
  Eigen::Quaternion<Scalar> q;
  q.w() = resume ? b.turned[0][lane] : b.warm[0][lane];
  q.x() = resume ? b.turned[1][lane] : b.warm[1][lane];
  q.y() = resume ? b.turned[2][lane] : b.warm[2][lane];
  q.z() = resume ? b.turned[3][lane] : b.warm[3][lane];
  (void)extract_rotation(a, q, r, resume ? kRotationIterations - 1 : kRotationIterations,
                         simulation_rotation_tolerance<Scalar>());
  b.warm[0][lane] = q.w();
  b.warm[1][lane] = q.x();
  b.warm[2][lane] = q.y();
  b.warm[3][lane] = q.z();
}

// Lanes done lane-wise take the result of the first iteration; the scalar extract_rotation
// finishes the others from where they are. (2D: only lanes that met a special case, usually
// none, and those keep the previous rotation where A_pq has no rotational information.)
template <int Dim, typename Scalar>
PLIANT_INLINE void finish_rotations(const MsmState<Dim, Scalar>& state, ClusterBatch<Dim, Scalar>& b) noexcept {
  using Batch = ClusterBatch<Dim, Scalar>;
  using Mat = Eigen::Matrix<Scalar, Dim, Dim>;
  bool scalar_lanes = true;
  if constexpr (Dim == 2) {
    Scalar lowest = b.status[0];
    for (int lane = 1; lane < Batch::kBatch; ++lane) lowest = std::min(lowest, b.status[lane]);
    scalar_lanes = lowest == Scalar(0);
  }
  for (int lane = 0; scalar_lanes && lane < b.count; ++lane) {
    const Scalar lane_status = b.status[lane];
    if constexpr (Dim == 3) {
      if (lane_status == Scalar(2)) {
        for (int e = 0; e < Batch::kWarm; ++e) b.warm[e][lane] = b.turned[e][lane];
        for (int e = 0; e < Batch::kMat; ++e) b.rotation[e][lane] = b.turned_rotation[e][lane];
        continue;
      }
    } else {
      if (lane_status != Scalar(0)) continue;
    }
    Mat a;
    for (int e = 0; e < Batch::kMat; ++e) a.data()[e] = b.apq[e][lane];
    Mat r;
    if constexpr (Dim == 3) {
      scalar_rotation_3d(b, lane, a, r);
    } else {
      Mat previous = state.rotation[b.first + lane];
      (void)extract_rotation(a, previous);
      r = previous;
    }
    for (int e = 0; e < Batch::kMat; ++e) b.rotation[e][lane] = r.data()[e];
  }
}

// Goal maps [G | b], lane-wise.
template <int Dim, typename Scalar>
PLIANT_INLINE void batch_goal_maps(ClusterBatch<Dim, Scalar>& b) noexcept {
  using Batch = ClusterBatch<Dim, Scalar>;
  for (int lane = 0; lane < Batch::kBatch; ++lane) {
    Scalar a[Batch::kMatN];
    Scalar r[Batch::kMatN];
    Scalar q[Batch::kMatN];
    for (int e = 0; e < Batch::kMat; ++e) {
      a[e] = b.apq[e][lane];
      r[e] = b.rotation[e][lane];
      q[e] = b.aqq[e * Batch::kBatch + lane];
    }
    Scalar mx[Batch::kDimN];
    Scalar rc[Batch::kDimN];
    for (int e = 0; e < Dim; ++e) {
      mx[e] = b.sum[Batch::kMat + e][lane];
      rc[e] = b.centre[e * Batch::kBatch + lane];
    }
    Scalar out[Batch::kMomentN];
    elastic_goal_map<Dim>(a, q, r, b.beta[lane], mx, b.inverse_mass[lane], rc, out);
    for (int e = 0; e < Batch::kMoment; ++e) b.goal[e][lane] = out[e];
  }
}

// The batch's goal maps and rotations (3D: the warm starts) back into the state.
template <int Dim, typename Scalar>
PLIANT_INLINE void store_cluster_batch(const ClusterBatch<Dim, Scalar>& b, MsmState<Dim, Scalar>& state) noexcept {
  using Batch = ClusterBatch<Dim, Scalar>;
  for (int lane = 0; lane < b.count; ++lane) {
    const int c = b.first + lane;
    Scalar* map = state.cluster_goal_map[c].data();
    for (int e = 0; e < Batch::kMoment; ++e) map[e] = b.goal[e][lane];
    if constexpr (Dim == 3) {
      Eigen::Quaternion<Scalar>& q = state.rotation[c];
      q.w() = b.warm[0][lane];
      q.x() = b.warm[1][lane];
      q.y() = b.warm[2][lane];
      q.z() = b.warm[3][lane];
    } else {
      for (int e = 0; e < Batch::kMat; ++e)
        state.rotation[c].data()[e] = b.rotation[e][lane];  // 2D: the rotation itself
    }
  }
}

// The elastic model's cluster pass (no plasticity, relaxation or stiffening): per cluster the
// goal map [G | b] and the updated rotation. Clusters are taken kMsmClusterBatch at a time and
// laid out lane-wise (structure of arrays) so that the arithmetic, identical for every cluster,
// runs as branch-free loops over lanes that the compiler vectorises. In 3D the first Newton
// iteration of extract_rotation runs lane-wise too; a lane whose first iteration is a plain
// Newton step (no special case) but not yet below the tolerance is continued by the scalar
// extract_rotation from there, and a lane that meets a special case (zero or non-finite A_pq,
// a warm start off the unit sphere, an ascent or clamped step) is redone by it from its warm
// start. In 2D the rotation is closed form and needs no warm start; only a lane whose A_pq
// carries no rotational information (or is not finite) goes to the scalar extract_rotation,
// which keeps the previous rotation. Each lane therefore does the same arithmetic as the scalar
// code: results do not depend on the batching. The steps are force-inlined so that the batch
// stays a local the vectoriser sees whole.
template <int Dim, typename Scalar>
void elastic_cluster_pass(const MsmModel<Dim, Scalar>& model, const MsmParams<Dim, Scalar>& params,
                          MsmState<Dim, Scalar>& state) noexcept {
  ClusterBatch<Dim, Scalar> batch;
  for (int lane = 0; lane < kMsmClusterBatch; ++lane) batch.beta[lane] = params.msm_beta;
  for (int first = 0; first < model.cluster_count; first += kMsmClusterBatch) {
    load_cluster_batch(model, params, state, first, batch);
    start_rotations(batch);
    if constexpr (Dim == 3) first_newton_iteration(batch);
    finish_rotations(state, batch);
    batch_goal_maps(batch);
    store_cluster_batch(batch, state);
  }
}

// Mueller 2005 plasticity: the plastic state creeps toward the cluster's strain while the
// strain exceeds the yield, is capped at `plastic_max` and kept volume-preserving.
template <int Dim, typename Scalar>
void update_plastic(const MsmParams<Dim, Scalar>& params, Scalar dt, const Eigen::Matrix<Scalar, Dim, Dim>& rotation,
                    const Eigen::Matrix<Scalar, Dim, Dim>& affine_rest,
                    Eigen::Matrix<Scalar, Dim, Dim>& plastic) noexcept {
  using Mat = Eigen::Matrix<Scalar, Dim, Dim>;
  const Scalar plastic_det = plastic.determinant();
  if (!(plastic_det > Scalar(0))) {
    plastic.setIdentity();
    return;
  }
  // A (for the plastically deformed rest shape) = A0 S_p^-1; strain S = R^T A, symmetrised.
  const Mat affine = affine_rest * plastic.inverse();
  const Mat strain_full = rotation.transpose() * affine;
  const Mat strain = Scalar(0.5) * (strain_full + strain_full.transpose());
  const Mat identity = Mat::Identity();
  if ((strain - identity).norm() <= params.plastic_yield) return;
  Mat next = (identity + dt * params.plastic_creep * (strain - identity)) * plastic;
  next = Scalar(0.5) * (next + next.transpose());
  const Scalar excess = (next - identity).norm();
  if (excess > params.plastic_max && excess > Scalar(0)) {
    next = identity + (params.plastic_max / excess) * (next - identity);
  }
  const Scalar det = next.determinant();
  if (!(det > Scalar(0)) || !next.allFinite()) return;
  next /= std::pow(det, Scalar(1) / Scalar(Dim));
  plastic = next;
}

// A support particle in its plane (through its rest position, normal n into the object): the
// normal offset is undone (the support holds it in the plane, as a pin does); the tangential
// move since the last step is cancelled while it is within mu x that normal correction (stick)
// and shortened by that much otherwise (slip). mu -> infinity is the pin exactly.
template <int Dim, typename Scalar>
Eigen::Matrix<Scalar, Dim, 1> support_contact(const MsmParams<Dim, Scalar>& params,
                                              const Eigen::Matrix<Scalar, Dim, 1>& rest,
                                              const Eigen::Matrix<Scalar, Dim, 1>& previous,
                                              Eigen::Matrix<Scalar, Dim, 1> next) noexcept {
  const Eigen::Matrix<Scalar, Dim, 1>& normal = params.support_normal;
  const Scalar correction = normal.dot(rest - next);
  next += correction * normal;
  Eigen::Matrix<Scalar, Dim, 1> slide = next - previous;
  slide -= normal.dot(slide) * normal;
  const Scalar length = slide.norm();
  const Scalar limit = params.support_friction * std::abs(correction);
  if (length <= limit) return next - slide;
  return next - slide * (limit / length);
}

// --- msm_step's stages ---------------------------------------------------------------------------
// Force-inlined: msm_step compiles as the single function it was written as (the same loops,
// hoisting and vectorisation). The stages copy the arrays they loop over into locals: the
// compiler cannot tell that the state's arrays do not alias the model and the parameters, so
// members read inside the loops would be reloaded.

// The parameters msm_step accepts (their ranges are documented in msm.hpp).
template <int Dim, typename Scalar>
PLIANT_INLINE bool step_params_valid(const MsmParams<Dim, Scalar>& params) noexcept {
  return finite(params.msm_alpha) && params.msm_alpha > Scalar(0) && params.msm_alpha <= Scalar(1) &&
         finite(params.msm_beta) && params.msm_beta >= Scalar(0) && params.msm_beta <= Scalar(1) &&
         params.gravity.allFinite() && finite(params.velocity_damping) && params.velocity_damping >= Scalar(0) &&
         finite(params.relaxation_fraction) && params.relaxation_fraction >= Scalar(0) &&
         params.relaxation_fraction < Scalar(1) && finite(params.relaxation_time_s) &&
         params.relaxation_time_s > Scalar(0) && finite(params.stiffening) && params.stiffening >= Scalar(0) &&
         params.support_friction >= Scalar(0) &&
         (!finite(params.support_friction) || std::abs(params.support_normal.squaredNorm() - Scalar(1)) < Scalar(1e-3));
}

// ok, or the refusal of a step that cannot run (a bad dt, parameter or driven list, or a
// non-finite external force), counted in rejected_steps; the state is left as it was.
template <int Dim, typename Scalar>
PLIANT_INLINE Status validate_step(const MsmModel<Dim, Scalar>& model, const MsmParams<Dim, Scalar>& params,
                                   const MsmStepInput<Dim, Scalar>& input, MsmState<Dim, Scalar>& state) noexcept {
  const Scalar dt = input.dt;
  const bool params_ok = step_params_valid(params);
  if (!finite(dt) || !(dt > Scalar(0)) || !params_ok || input.driven.count < 0 ||
      (input.driven.count > 0 && (input.driven.ids == nullptr || input.driven.positions == nullptr))) {
    ++state.rejected_steps;
    return Status::invalid_argument;
  }
  if (input.external_force != nullptr) {
    for (int i = 0; i < model.particle_count; ++i) {
      if (!input.external_force[i].allFinite()) {
        ++state.rejected_steps;
        return Status::non_finite_input;
      }
    }
  }
  return Status::ok;
}

// Driven targets become their particles' predictions and mark them driven_now. A target on a
// particle that may not be driven is dropped; a non-finite one holds its particle where it was
// (fail safe: the contact particle holds rather than falling free). Either is non_finite_input.
template <int Dim, typename Scalar>
PLIANT_INLINE Status place_driven_targets(const MsmModel<Dim, Scalar>& model, const MsmStepInput<Dim, Scalar>& input,
                                          MsmState<Dim, Scalar>& state) noexcept {
  using Vec = typename MsmState<Dim, Scalar>::Vec;
  const int n = model.particle_count;
  const Vec* const position = state.position;
  Vec* const predicted = state.predicted;
  std::uint8_t* const driven_now = state.driven_now;
  const std::uint8_t* const fixed = model.fixed;
  for (int i = 0; i < n; ++i) driven_now[i] = 0;
  Status result = Status::ok;
  for (int k = 0; k < input.driven.count; ++k) {
    const int id = input.driven.ids[k];
    const Vec& target = input.driven.positions[k];
    if (id < 0 || id >= n || model.drivable[id] == 0 || fixed[id] != 0) {
      ++state.dropped_targets;
      result = Status::non_finite_input;
      continue;
    }
    if (!target.allFinite()) {
      ++state.dropped_targets;
      result = Status::non_finite_input;
      predicted[id] = position[id];
      driven_now[id] = 1;
      continue;
    }
    predicted[id] = target;
    driven_now[id] = 1;
  }
  return result;
}

// Predictions of the particles not driven (eqs. 1-2): a pinned support at its rest position,
// the others moved by their damped velocity under gravity and the external forces. Returns the
// step's mean predicted position, summed in particle order.
template <int Dim, typename Scalar>
PLIANT_INLINE typename MsmState<Dim, Scalar>::Vec predict_free_particles(const MsmModel<Dim, Scalar>& model,
                                                                         const MsmParams<Dim, Scalar>& params,
                                                                         const MsmStepInput<Dim, Scalar>& input,
                                                                         MsmState<Dim, Scalar>& state) noexcept {
  using Vec = typename MsmState<Dim, Scalar>::Vec;
  const int n = model.particle_count;
  const Scalar dt = input.dt;
  const bool pinned = !finite(params.support_friction);
  const Vec* const position = state.position;
  Vec* const predicted = state.predicted;
  const Vec* const velocity = state.velocity;
  const std::uint8_t* const driven_now = state.driven_now;
  const std::uint8_t* const fixed = model.fixed;
  const Vec* const rest = model.rest;
  const Scalar* const mass = model.mass;
  const Scalar keep = std::max(Scalar(0), Scalar(1) - params.velocity_damping * dt);
  const Vec gravity = params.gravity;
  const Vec* const external_force = input.external_force;
  Vec origin = Vec::Zero();
  for (int i = 0; i < n; ++i) {
    if (driven_now[i] == 0) {
      if (fixed[i] != 0 && pinned) {
        predicted[i] = rest[i];
      } else {
        Vec acceleration = gravity;
        if (external_force != nullptr) acceleration += external_force[i] / mass[i];
        const Vec v = (velocity[i] + dt * acceleration) * keep;
        predicted[i] = position[i] + dt * v;
      }
    }
    origin += predicted[i];
  }
  origin /= static_cast<Scalar>(n);
  return origin;
}

// The step's coordinate origins: the mean predicted position and the model's mean rest position.
// Coordinates are taken relative to them so that the cancellation in A_pq's difference stays
// small in float. (Passed by value: the loops then read them from locals.)
template <int Dim, typename Scalar>
struct StepOrigins {
  Scalar predicted[static_cast<std::size_t>(Dim)];
  Scalar rest[static_cast<std::size_t>(Dim)];
};

template <int Dim, typename Scalar>
PLIANT_INLINE StepOrigins<Dim, Scalar> step_origins(const MsmModel<Dim, Scalar>& model,
                                                    const typename MsmState<Dim, Scalar>::Vec& origin) noexcept {
  StepOrigins<Dim, Scalar> origins;
  for (int d = 0; d < Dim; ++d) {
    origins.predicted[d] = origin(d);
    origins.rest[d] = model.rest_origin(d);
  }
  return origins;
}

// Per-particle moments [m x r^T | m x], relative to the origins. With q0 = r - r_c and
// sum m q0 = 0, A_pq = sum m x q0^T = sum m x r^T - (sum m x) r_c^T: the moments are formed once
// and each cluster sums them, instead of an outer product per membership.
template <int Dim, typename Scalar>
PLIANT_INLINE void form_particle_moments(const MsmModel<Dim, Scalar>& model, const StepOrigins<Dim, Scalar> origins,
                                         MsmState<Dim, Scalar>& state) noexcept {
  using Vec = typename MsmState<Dim, Scalar>::Vec;
  const Vec* const predicted = state.predicted;
  const Vec* const rest = model.rest;
  const Scalar* const mass = model.mass;
  Eigen::Matrix<Scalar, Dim, Dim + 1>* const moments = state.moment;
  for (int i = 0; i < model.particle_count; ++i) {
    const Scalar m = mass[i];
    Scalar mx[static_cast<std::size_t>(Dim)];
    Scalar r[static_cast<std::size_t>(Dim)];
    for (int d = 0; d < Dim; ++d) {
      mx[d] = m * (predicted[i](d) - origins.predicted[d]);
      r[d] = rest[i](d) - origins.rest[d];
    }
    Scalar* moment = moments[i].data();
    for (int col = 0; col < Dim; ++col) {
      for (int row = 0; row < Dim; ++row) moment[col * Dim + row] = mx[row] * r[col];
    }
    for (int row = 0; row < Dim; ++row) moment[Dim * Dim + row] = mx[row];
  }
}

// The effects beyond the elastic model that this step's cluster pass runs.
template <typename Scalar>
struct ClusterEffects {
  bool plastic = false;       // plastic_creep > 0
  bool relax = false;         // relaxation_fraction > 0
  bool stiffen = false;       // stiffening > 0
  bool rest_changes = false;  // plastic or relax: the rest shape is deformed by E
  Scalar relax_rate = 0;      // the share of V's way to the strain covered this step
  bool elastic() const noexcept { return !rest_changes && !stiffen; }
};

template <int Dim, typename Scalar>
PLIANT_INLINE ClusterEffects<Scalar> cluster_effects(const MsmParams<Dim, Scalar>& params, Scalar dt) noexcept {
  ClusterEffects<Scalar> effects;
  effects.plastic = params.plastic_creep > Scalar(0);
  effects.relax = params.relaxation_fraction > Scalar(0);
  effects.stiffen = params.stiffening > Scalar(0);
  effects.rest_changes = effects.plastic || effects.relax;
  // Exact decay of V toward the strain over one step, stable for any dt / tau.
  effects.relax_rate = effects.relax ? Scalar(1) - std::exp(-dt / params.relaxation_time_s) : Scalar(0);
  return effects;
}

// Rest deformation E of cluster c: plastic set S_p and relaxed share (1 - g1) I + g1 V
// (identity when off).
template <int Dim, typename Scalar>
PLIANT_INLINE Eigen::Matrix<Scalar, Dim, Dim> rest_deformation_of(const MsmParams<Dim, Scalar>& params,
                                                                  const ClusterEffects<Scalar>& effects,
                                                                  const MsmState<Dim, Scalar>& state, int c) noexcept {
  using Mat = Eigen::Matrix<Scalar, Dim, Dim>;
  Mat rest_deformation = Mat::Identity();
  if (effects.rest_changes) {
    rest_deformation = effects.plastic ? state.plastic[c] : Mat::Identity();
    if (effects.relax) {
      rest_deformation = rest_deformation * ((Scalar(1) - params.relaxation_fraction) * Mat::Identity() +
                                             params.relaxation_fraction * state.relaxed[c]);
    }
  }
  return rest_deformation;
}

// One cluster of the general pass (eqs. 3-13 with plasticity, relaxation or stiffening): its
// goal map, rotation, plastic set and relaxed strain.
template <int Dim, typename Scalar>
PLIANT_INLINE void effects_cluster_update(const MsmModel<Dim, Scalar>& model, const MsmParams<Dim, Scalar>& params,
                                          const ClusterEffects<Scalar>& effects, Scalar dt, int c,
                                          MsmState<Dim, Scalar>& state) noexcept {
  using Vec = Eigen::Matrix<Scalar, Dim, 1>;
  using Mat = Eigen::Matrix<Scalar, Dim, Dim>;
  using Moment = Eigen::Matrix<Scalar, Dim, Dim + 1>;
  Moment sum;
  gather_sum(state.moment, model.member_byte_offset, model.cluster_begin[c], model.cluster_begin[c + 1], sum);
  const Vec rest_centroid = model.cluster_rest_centroid[c] - model.rest_origin;
  const Mat apq_rest = sum.template leftCols<Dim>() - sum.col(Dim) * rest_centroid.transpose();
  const Vec centroid = sum.col(Dim) * model.cluster_inverse_mass[c];
  const Mat affine_rest = apq_rest * model.cluster_aqq_inverse[c];
  const Mat rest_deformation = rest_deformation_of(params, effects, state, c);
  const Mat rotation = effects.rest_changes
                           ? rotation_of(Mat(apq_rest * rest_deformation.transpose()), state.rotation[c])
                           : rotation_of(apq_rest, state.rotation[c]);
  Scalar beta = params.cluster_beta != nullptr ? params.cluster_beta[c] : params.msm_beta;
  Mat strain = Mat::Zero();  // sym(R^T A) - I, formed only when an effect needs it
  if (effects.stiffen || effects.relax) {
    const Mat stretch = rotation.transpose() * affine_rest;
    strain = Scalar(0.5) * (stretch + stretch.transpose()) - Mat::Identity();
  }
  if (effects.stiffen) beta /= Scalar(1) + params.stiffening * strain.norm();
  // Goal map applied to q0: ((1 - beta) R + beta A) E q0 = (1 - beta) R E q0 + beta A0 q0.
  const Mat goal_map = effects.rest_changes ? Mat((Scalar(1) - beta) * rotation * rest_deformation + beta * affine_rest)
                                            : Mat((Scalar(1) - beta) * rotation + beta * affine_rest);
  // goal(r) = G (r - r_c) + t = G r + (t - G r_c), all relative to the origins.
  Moment& map = state.cluster_goal_map[c];
  map.template leftCols<Dim>() = goal_map;
  map.col(Dim).noalias() = centroid - goal_map * rest_centroid;
  if (effects.plastic) update_plastic<Dim, Scalar>(params, dt, rotation, affine_rest, state.plastic[c]);
  if (effects.relax) {
    Mat& relaxed = state.relaxed[c];
    const Mat target = strain + Mat::Identity();
    if (target.allFinite()) relaxed += effects.relax_rate * (target - relaxed);
  }
}

// The general cluster pass, for any of plasticity, relaxation and stiffening. The effects come
// by value so that the loop sees the flags as its own constants (the compiler can then take the
// tests on them out of the loop).
template <int Dim, typename Scalar>
PLIANT_INLINE void effects_cluster_pass(const MsmModel<Dim, Scalar>& model, const MsmParams<Dim, Scalar>& params,
                                        const ClusterEffects<Scalar> effects, Scalar dt,
                                        MsmState<Dim, Scalar>& state) noexcept {
  for (int c = 0; c < model.cluster_count; ++c) effects_cluster_update(model, params, effects, dt, c, state);
}

// Integration (eqs. 10-11): a free particle moves msm_alpha of the way from its prediction to
// its goal averaged over its clusters (its prediction when it has none); a pinned support stays
// at rest, a driven particle takes its target, a support with friction slides in its plane.
// Velocities are the step's moves over dt.
template <int Dim, typename Scalar>
PLIANT_INLINE void integrate_particles(const MsmModel<Dim, Scalar>& model, const MsmParams<Dim, Scalar>& params,
                                       Scalar dt, const StepOrigins<Dim, Scalar> origins,
                                       MsmState<Dim, Scalar>& state) noexcept {
  using Vec = typename MsmState<Dim, Scalar>::Vec;
  using Moment = Eigen::Matrix<Scalar, Dim, Dim + 1>;
  const bool pinned = !finite(params.support_friction);
  const Scalar inverse_dt = Scalar(1) / dt;
  const Scalar alpha = params.msm_alpha;
  const std::uint8_t* const fixed = model.fixed;
  const Vec* const rest = model.rest;
  const Scalar* const inverse_cluster_count = model.inverse_cluster_count;
  const std::int32_t* const particle_cluster_begin = model.particle_cluster_begin;
  const std::int32_t* const particle_cluster_offset = model.particle_cluster_byte_offset;
  const Moment* const goal_maps = state.cluster_goal_map;
  const std::uint8_t* const driven_now = state.driven_now;
  const Vec* const predicted = state.predicted;
  Vec* const position = state.position;
  Vec* const velocity_out = state.velocity;
  for (int i = 0; i < model.particle_count; ++i) {
    const Vec previous = position[i];
    Vec next;
    if (fixed[i] != 0 && pinned) {
      next = rest[i];
    } else if (driven_now[i] != 0) {  // NOLINT(bugprone-branch-clone): as the last branch, for another reason
      next = predicted[i];            // the goal of a driven particle is its target
    } else if (inverse_cluster_count[i] > Scalar(0)) {
      Moment map_sum;
      gather_sum(goal_maps, particle_cluster_offset, particle_cluster_begin[i], particle_cluster_begin[i + 1], map_sum);
      // Mean goal: (sum of G) r + (sum of b), over the clusters holding i.
      const Scalar* g = map_sum.data();
      Scalar r[static_cast<std::size_t>(Dim)];
      for (int d = 0; d < Dim; ++d) r[d] = rest[i](d) - origins.rest[d];
      const Scalar inverse_count = inverse_cluster_count[i];
      for (int row = 0; row < Dim; ++row) {
        Scalar goal = g[row] * r[0];
        for (int k = 1; k < Dim; ++k) goal += g[k * Dim + row] * r[k];
        goal = (goal + g[Dim * Dim + row]) * inverse_count;
        const Scalar x = predicted[i](row);
        next(row) = x + alpha * (origins.predicted[row] + goal - x);
      }
    } else {
      next = predicted[i];
    }
    if (fixed[i] != 0 && !pinned) next = support_contact(params, rest[i], previous, next);
    position[i] = next;
    velocity_out[i] = (next - previous) * inverse_dt;
  }
}

}  // namespace

template <int Dim, typename Scalar>
std::size_t msm_state_workspace_size(const MsmModel<Dim, Scalar>& model) noexcept {
  Arena measure;
  MsmState<Dim, Scalar> scratch;
  (void)msm_state_init(measure, model, scratch);
  return measure.required_bytes();
}

template <int Dim, typename Scalar>
Status msm_state_init(Arena& arena, const MsmModel<Dim, Scalar>& model, MsmState<Dim, Scalar>& state) noexcept {
  using Vec = typename MsmState<Dim, Scalar>::Vec;
  using Mat = typename MsmState<Dim, Scalar>::Mat;
  state = MsmState<Dim, Scalar>{};
  if (!model.initialized()) return Status::not_initialized;
  const auto n = static_cast<std::size_t>(model.particle_count);
  const auto c = static_cast<std::size_t>(model.cluster_count);
  MsmState<Dim, Scalar> s;
  s.position = arena.carve<Vec>(n);
  s.velocity = arena.carve<Vec>(n);
  s.predicted = arena.carve<Vec>(n);
  s.moment = arena.carve<Eigen::Matrix<Scalar, Dim, Dim + 1>>(n);
  s.cluster_goal_map = arena.carve<Eigen::Matrix<Scalar, Dim, Dim + 1>>(c);
  s.driven_now = arena.carve<std::uint8_t>(n);
  s.rotation = arena.carve<ClusterRotation<Dim, Scalar>>(c);
  s.plastic = arena.carve<Mat>(c);
  s.relaxed = arena.carve<Mat>(c);
  if (arena.exhausted()) return Status::capacity_exceeded;
  state = s;
  msm_state_reset(model, state);
  return Status::ok;
}

template <int Dim, typename Scalar>
void msm_state_reset(const MsmModel<Dim, Scalar>& model, MsmState<Dim, Scalar>& state) noexcept {
  PLIANT_ASSERT(state.initialized() && model.initialized());
  for (int i = 0; i < model.particle_count; ++i) {
    state.position[i] = model.rest[i];
    state.velocity[i].setZero();
    state.driven_now[i] = 0;
  }
  for (int c = 0; c < model.cluster_count; ++c) {
    identity_rotation<Dim, Scalar>(state.rotation[c]);
    state.plastic[c].setIdentity();
    state.relaxed[c].setIdentity();
  }
  state.time_s = 0;
  state.steps = 0;
}

template <int Dim, typename Scalar>
Status msm_step(const MsmModel<Dim, Scalar>& model, const MsmParams<Dim, Scalar>& params,
                const MsmStepInput<Dim, Scalar>& input, MsmState<Dim, Scalar>& state) noexcept {
  if (!model.initialized() || !state.initialized()) return Status::not_initialized;
  const Status valid = validate_step(model, params, input, state);
  if (valid != Status::ok) return valid;
  const Scalar dt = input.dt;
  // 1. Prediction (eqs. 1-2). Driven targets first (they replace the prediction), so that one
  // pass predicts the others and sums the step's mean position in particle order.
  const Status result = place_driven_targets(model, input, state);
  const StepOrigins<Dim, Scalar> origins = step_origins(model, predict_free_particles(model, params, input, state));
  // 2. Cluster shape matching (eqs. 3-13): per-particle moments, then per cluster its goal map.
  form_particle_moments(model, origins, state);
  const ClusterEffects<Scalar> effects = cluster_effects(params, dt);
  if (effects.elastic()) {
    elastic_cluster_pass(model, params, state);
  } else {
    effects_cluster_pass(model, params, effects, dt, state);
  }
  // 3. Integration (eqs. 10-11) with goals averaged over each particle's clusters.
  integrate_particles(model, params, dt, origins, state);
  state.time_s += static_cast<double>(dt);
  ++state.steps;
  return result;
}

#define PLIANT_INSTANTIATE_MSM(DIM, SCALAR)                                                                           \
  template std::size_t msm_state_workspace_size<DIM, SCALAR>(const MsmModel<DIM, SCALAR>&) noexcept;                  \
  template Status msm_state_init<DIM, SCALAR>(Arena&, const MsmModel<DIM, SCALAR>&, MsmState<DIM, SCALAR>&) noexcept; \
  template void msm_state_reset<DIM, SCALAR>(const MsmModel<DIM, SCALAR>&, MsmState<DIM, SCALAR>&) noexcept;          \
  template Status msm_step<DIM, SCALAR>(const MsmModel<DIM, SCALAR>&, const MsmParams<DIM, SCALAR>&,                  \
                                        const MsmStepInput<DIM, SCALAR>&, MsmState<DIM, SCALAR>&) noexcept;
PLIANT_INSTANTIATE_MSM(2, float)
PLIANT_INSTANTIATE_MSM(2, double)
PLIANT_INSTANTIATE_MSM(3, float)
PLIANT_INSTANTIATE_MSM(3, double)
#undef PLIANT_INSTANTIATE_MSM

}  // namespace pliant
