#include "pliant/core/grasp_guard.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include <Eigen/Eigenvalues>

namespace pliant {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kPi = 3.14159265358979323846;

// Fault kinds, the first index of GraspGuardState::fault.
enum FaultKind : int { kNan = 0, kInvalid, kSensor, kBusOff, kTimeout, kStale, kFaultKindCount };
static_assert(kFaultKindCount == GraspGuardState::kFaultKinds, "fault kinds");

constexpr int source_index(GuardSource source) noexcept { return static_cast<int>(source); }
constexpr int reason_index(GuardReason reason) noexcept { return static_cast<int>(reason); }
constexpr std::uint32_t reason_bit(GuardReason reason) noexcept { return 1u << static_cast<unsigned>(reason); }
static_assert(kGuardReasonCount <= 32, "reasons must fit the bit set");

bool finite(double value) noexcept { return std::isfinite(value); }

GuardReason fault_reason(int kind, int source) noexcept {
  switch (kind) {
    case kNan: return GuardReason::nan_input;
    case kInvalid: return GuardReason::invalid_input;
    case kSensor: return GuardReason::sensor_fault;
    case kBusOff: return GuardReason::bus_off;
    case kTimeout: return GuardReason::timeout;
    default: break;
  }
  switch (static_cast<GuardSource>(source)) {
    case GuardSource::gripper: return GuardReason::stale_gripper;
    case GuardSource::wrench: return GuardReason::stale_wrench;
    case GuardSource::camera: return GuardReason::stale_camera;
    case GuardSource::estimate: return GuardReason::stale_estimate;
    default: return GuardReason::timeout;  // the clock is never stale; its gaps are timeouts
  }
}

// Set at once; cleared after `needed` consecutive samples of the reason's source that are clear
// of the hysteresis band. Cycles without a new sample of that source leave the latch as it is.
void step_latch(GuardLatch& latch, bool set, bool clear, bool new_sample, int needed) noexcept {
  if (set) {
    latch.active = true;
    latch.clear_count = 0;
    return;
  }
  if (!latch.active || !new_sample) return;
  if (!clear) {
    latch.clear_count = 0;
    return;
  }
  if (++latch.clear_count >= needed) {
    latch.active = false;
    latch.clear_count = 0;
  }
}

// A measure against a threshold: set at or above it, clear below threshold x (1 - margin).
// A non-finite threshold (a disabled limit) never sets; a measure <= 0 never sets.
void step_measured(GuardLatch& latch, double measure, double threshold, double margin, bool new_sample,
                   int needed) noexcept {
  const bool enabled = finite(threshold);
  const bool set = enabled && measure > 0 && measure >= threshold;
  const bool clear = !enabled || measure <= 0 || measure < threshold * (1 - margin);
  step_latch(latch, set, clear, new_sample, needed);
}

// --- strain gauge -----------------------------------------------------------------------------

// Smallest and largest eigenvalue of a symmetric matrix.
void extreme_eigenvalues(const Eigen::Matrix<double, 2, 2>& m, double& low, double& high) noexcept {
  const double mean = 0.5 * (m(0, 0) + m(1, 1));
  const double half_difference = 0.5 * (m(0, 0) - m(1, 1));
  const double off = 0.5 * (m(0, 1) + m(1, 0));
  const double radius = std::sqrt(half_difference * half_difference + off * off);
  low = mean - radius;
  high = mean + radius;
}
// 3D: the trigonometric solution of the characteristic cubic (Smith 1961), shifted by the mean
// eigenvalue and scaled, for the two extreme roots only: one acos, one cos, two sqrt (about
// half the cost of a full closed-form eigensolver; this runs once per cluster and frame).
// Near a double root acos loses half the digits of its argument: ~1e-8 of the spread, far below
// any strain limit.
void extreme_eigenvalues(const Eigen::Matrix<double, 3, 3>& m, double& low, double& high) noexcept {
  const double a00 = m(0, 0), a11 = m(1, 1), a22 = m(2, 2);
  const double a01 = 0.5 * (m(0, 1) + m(1, 0));
  const double a02 = 0.5 * (m(0, 2) + m(2, 0));
  const double a12 = 0.5 * (m(1, 2) + m(2, 1));
  const double mean = (a00 + a11 + a22) / 3;
  const double b00 = a00 - mean, b11 = a11 - mean, b22 = a22 - mean;
  const double off = a01 * a01 + a02 * a02 + a12 * a12;
  const double spread2 = (b00 * b00 + b11 * b11 + b22 * b22 + 2 * off) / 6;
  if (!(spread2 > 0)) {  // a multiple of the identity (or NaN, which the caller rejects)
    low = high = mean;
    return;
  }
  const double spread = std::sqrt(spread2);
  // det(B) / 2 with B = (A - mean I) / spread.
  const double det = b00 * (b11 * b22 - a12 * a12) - a01 * (a01 * b22 - a12 * a02) + a02 * (a01 * a12 - b11 * a02);
  const double r = std::clamp(det / (2 * spread2 * spread), -1.0, 1.0);
  const double c = std::cos(std::acos(r) / 3);  // cos(phi), phi in [0, pi/3]
  const double s = std::sqrt(std::max(0.0, 1 - c * c));
  high = mean + 2 * spread * c;                                   // cos(phi)
  low = mean + 2 * spread * (-0.5 * c - 0.8660254037844386 * s);  // cos(phi + 2 pi / 3)
}

// Largest |principal stretch - 1| of cluster c at positions x. The affine fit A = A_pq A_qq^+;
// A^T A - I has the squared stretches minus one on the cluster's span and -1 on directions a
// flat cluster does not span, which `null` (their projector) lifts to 0. Computed in double
// from the cluster's own offsets (A_pq is translation invariant because sum m q0 = 0).
template <int Dim, typename Scalar>
bool cluster_strain(const MsmModel<Dim, Scalar>& model, const Eigen::Matrix<double, Dim, Dim>& null, int c,
                    const Eigen::Matrix<Scalar, Dim, 1>* x, double& strain) noexcept {
  using VecD = Eigen::Matrix<double, Dim, 1>;
  using MatD = Eigen::Matrix<double, Dim, Dim>;
  const int begin = model.cluster_begin[c];
  const int end = model.cluster_begin[c + 1];
  const VecD reference = x[model.members[begin]].template cast<double>();
  MatD apq = MatD::Zero();
  for (int k = begin; k < end; ++k) {
    const int j = model.members[k];
    const VecD p = x[j].template cast<double>() - reference;
    apq.noalias() +=
        static_cast<double>(model.mass[j]) * p * model.member_rest_offset[k].template cast<double>().transpose();
  }
  const MatD a = apq * model.cluster_aqq_inverse[c].template cast<double>();
  // A non-finite member (an unobserved particle) makes the fit non-finite: checked once here.
  if (!a.allFinite()) return false;
  const MatD green2 = a.transpose() * a - MatD::Identity() + null;
  double low = 0;
  double high = 0;
  extreme_eigenvalues(green2, low, high);
  const double stretch_low = std::sqrt(std::max(0.0, 1.0 + low));
  const double stretch_high = std::sqrt(std::max(0.0, 1.0 + high));
  strain = std::max(1.0 - stretch_low, stretch_high - 1.0);
  return true;
}

template <int Dim, typename Scalar>
GraspStrainMeasurement measure(const MsmModel<Dim, Scalar>& model, const Eigen::Matrix<double, Dim, Dim>* null,
                               const Eigen::Matrix<Scalar, Dim, 1>* x) noexcept {
  GraspStrainMeasurement out;
  double worst = -1;
  for (int c = 0; c < model.cluster_count; ++c) {
    double strain = 0;
    if (!cluster_strain(model, null[c], c, x, strain) || !finite(strain)) {
      ++out.clusters_skipped;
      continue;
    }
    ++out.clusters_measured;
    if (strain > worst) {
      worst = strain;
      out.cluster = c;
    }
  }
  out.strain = out.clusters_measured > 0 ? worst : kNaN;
  return out;
}

// --- config -----------------------------------------------------------------------------------

bool positive(double value) noexcept { return finite(value) && value > 0; }
bool positive_or_inf(double value) noexcept { return value > 0 && !std::isnan(value); }

Status validate(const GraspGuardConfig& c) noexcept {
  const bool limits =
      positive_or_inf(c.max_strain) && positive_or_inf(c.max_indentation_m) && positive(c.max_force_n) &&
      (std::isnan(c.nominal_force_n) || (positive(c.nominal_force_n) && c.nominal_force_n <= c.max_force_n));
  const bool contact = (std::isnan(c.contact_width_m) || positive(c.contact_width_m)) && finite(c.contact_force_n) &&
                       c.contact_force_n >= 0 && positive_or_inf(c.contact_width_tolerance) && positive(c.max_width_m);
  const bool force =
      c.force_source == ForceSource::force_sensor ||
      (c.force_source == ForceSource::motor_current && positive(c.current_gain_n_per_a) && finite(c.current_offset_a));
  const bool timing = positive(c.gripper_timeout_s) && positive(c.wrench_timeout_s) && positive(c.camera_timeout_s) &&
                      positive(c.estimate_timeout_s) && positive(c.cycle_timeout_s) && finite(c.clock_tolerance_s) &&
                      c.clock_tolerance_s >= 0 && c.wrench_frozen_samples >= 0;
  bool verdicts = c.uncertain_estimate_verdict <= GraspVerdict::stop && c.exceeded_stop_action <= StopAction::open &&
                  c.fault_stop_action <= StopAction::open;
  for (GraspVerdict v : c.fault_verdict) verdicts = verdicts && (v == GraspVerdict::limit || v == GraspVerdict::stop);
  const bool hysteresis = finite(c.hysteresis_margin) && c.hysteresis_margin >= 0 && c.hysteresis_margin < 1 &&
                          c.clear_samples >= 1 && finite(c.stop_overshoot) && c.stop_overshoot >= 0;
  const bool estimate = finite(c.confidence_k) && c.confidence_k >= 0 && positive_or_inf(c.max_beta_std);
  const bool slip = positive(c.slip_cutoff_hz) && finite(c.slip_ratio) && c.slip_ratio >= 0 && finite(c.slip_floor_n) &&
                    c.slip_floor_n >= 0 && finite(c.slip_ceiling_n) && c.slip_ceiling_n >= c.slip_floor_n &&
                    finite(c.slip_force_rate_per_s) && c.slip_force_rate_per_s >= 0;
  const bool fit = positive(c.force_fit_spacing_m) && finite(c.force_fit_forgetting) && c.force_fit_forgetting > 0 &&
                   c.force_fit_forgetting <= 1 && finite(c.force_model_min_closure_m) &&
                   c.force_model_min_closure_m >= 0;
  const bool table = c.prediction_beta_points >= 2 && c.prediction_beta_points <= 1001 &&
                     c.prediction_closure_points >= 2 && c.prediction_closure_points <= 100000 &&
                     c.prediction_refine_steps >= 1 && c.prediction_refine_steps <= 1000 &&
                     (std::isnan(c.prediction_max_closure_m) || positive(c.prediction_max_closure_m)) &&
                     c.relax_max_iterations >= 1 && positive(c.relax_tolerance);
  return limits && contact && force && timing && verdicts && hysteresis && estimate && slip && fit && table
             ? Status::ok
             : Status::invalid_argument;
}

// --- init-time squeeze --------------------------------------------------------------------------

// The init-time simulation: the model, its state and the jaw contact bookkeeping, with a
// checkpoint so a crossing of the strain limit can be located on a refined closure path.
template <int Dim, typename Scalar>
struct Squeeze {
  using Vec = Eigen::Matrix<Scalar, Dim, 1>;
  MsmState<Dim, Scalar> state;
  std::int8_t* initial_side = nullptr;                     // [n] -1 jaw A, +1 jaw B, 0 free
  std::int8_t* side = nullptr;                             // [n]
  Vec* anchor = nullptr;                                   // [n] position on the jaw when the particle joined
  double* anchor_closure = nullptr;                        // [n] closure when it joined
  int* ids = nullptr;                                      // [n]
  Vec* targets = nullptr;                                  // [n]
  Vec* previous = nullptr;                                 // [n]
  Vec* saved_position = nullptr;                           // [n]
  ClusterRotation<Dim, Scalar>* saved_rotation = nullptr;  // [clusters]
  std::int8_t* saved_side = nullptr;                       // [n]
  Vec* saved_anchor = nullptr;                             // [n]
  double* saved_anchor_closure = nullptr;                  // [n]
};

template <int Dim, typename Scalar>
Status carve(Arena& arena, const MsmModel<Dim, Scalar>& model, const GraspGuardConfig& config,
             GraspGuard<Dim, Scalar>& guard, Squeeze<Dim, Scalar>& squeeze) noexcept {
  using Vec = Eigen::Matrix<Scalar, Dim, 1>;
  const auto n = static_cast<std::size_t>(model.particle_count);
  const auto clusters = static_cast<std::size_t>(model.cluster_count);
  const auto betas = static_cast<std::size_t>(config.prediction_beta_points);
  const auto columns = static_cast<std::size_t>(config.prediction_closure_points) + 1;
  guard.strain_table = arena.carve<double>(betas * columns);
  guard.crossing_closure_m = arena.carve<double>(betas);
  guard.refined_segment = arena.carve<int>(betas);
  guard.refined_strain = arena.carve<double>(betas * (static_cast<std::size_t>(config.prediction_refine_steps) + 1));
  guard.cluster_null = arena.carve<Eigen::Matrix<double, Dim, Dim>>(clusters);
  squeeze.initial_side = arena.carve<std::int8_t>(n);
  squeeze.side = arena.carve<std::int8_t>(n);
  squeeze.anchor = arena.carve<Vec>(n);
  squeeze.anchor_closure = arena.carve<double>(n);
  squeeze.ids = arena.carve<int>(n);
  squeeze.targets = arena.carve<Vec>(n);
  squeeze.previous = arena.carve<Vec>(n);
  squeeze.saved_position = arena.carve<Vec>(n);
  squeeze.saved_rotation = arena.carve<ClusterRotation<Dim, Scalar>>(clusters);
  squeeze.saved_side = arena.carve<std::int8_t>(n);
  squeeze.saved_anchor = arena.carve<Vec>(n);
  squeeze.saved_anchor_closure = arena.carve<double>(n);
  const Status state = msm_state_init(arena, model, squeeze.state);
  if (arena.exhausted()) return Status::capacity_exceeded;
  return state;
}

// Convergence threshold on a step's largest move: relax_tolerance x spacing, but no finer than
// 8 rounding units of the coordinates (float cannot settle below its own rounding noise, a few
// units; stopping at 8 leaves ~1e-5 of strain in float).
template <int Dim, typename Scalar>
double relax_tolerance(const MsmModel<Dim, Scalar>& model, const GraspGuardConfig& config) noexcept {
  double coordinate = 0;
  for (int i = 0; i < model.particle_count; ++i) {
    coordinate = std::max(coordinate, static_cast<double>(model.rest[i].cwiseAbs().maxCoeff()));
  }
  const double rounding = 8.0 * static_cast<double>(std::numeric_limits<Scalar>::epsilon()) * coordinate;
  return std::max(config.relax_tolerance * static_cast<double>(model.spacing), rounding);
}

template <int Dim, typename Scalar>
class SqueezeRun {
 public:
  using Vec = Eigen::Matrix<Scalar, Dim, 1>;
  SqueezeRun(const MsmModel<Dim, Scalar>& model, Squeeze<Dim, Scalar>& squeeze, const Vec& axis, double low,
             double high, const GraspGuardConfig& config, const Eigen::Matrix<double, Dim, Dim>* null) noexcept
      : model_(model),
        s_(squeeze),
        axis_(axis),
        low_(low),
        high_(high),
        null_(null),
        tolerance_(relax_tolerance(model, config)),
        max_iterations_(config.relax_max_iterations) {}

  void start(double beta) noexcept {
    params_ = MsmParams<Dim, Scalar>{};
    params_.msm_beta = static_cast<Scalar>(beta);
    // Momentum: little helps at low beta, the affine modes of high beta want much.
    params_.velocity_damping = static_cast<Scalar>(1.0 - (0.5 + 0.4 * beta));
    msm_state_reset(model_, s_.state);
    for (int i = 0; i < model_.particle_count; ++i) {
      s_.side[i] = s_.initial_side[i];
      s_.anchor[i] = model_.rest[i];
      s_.anchor_closure[i] = 0;
    }
  }

  void save() noexcept {
    for (int i = 0; i < model_.particle_count; ++i) {
      s_.saved_position[i] = s_.state.position[i];
      s_.saved_side[i] = s_.side[i];
      s_.saved_anchor[i] = s_.anchor[i];
      s_.saved_anchor_closure[i] = s_.anchor_closure[i];
    }
    for (int c = 0; c < model_.cluster_count; ++c) s_.saved_rotation[c] = s_.state.rotation[c];
  }

  void restore() noexcept {
    for (int i = 0; i < model_.particle_count; ++i) {
      s_.state.position[i] = s_.saved_position[i];
      s_.state.velocity[i].setZero();
      s_.side[i] = s_.saved_side[i];
      s_.anchor[i] = s_.saved_anchor[i];
      s_.anchor_closure[i] = s_.saved_anchor_closure[i];
    }
    for (int c = 0; c < model_.cluster_count; ++c) s_.state.rotation[c] = s_.saved_rotation[c];
  }

  // Quasi-static equilibrium with the jaws closed by `closure`: msm_step with the contact
  // particles driven, until no particle moves more than the tolerance in two successive steps.
  // Then particles past a jaw plane join that jaw (projected onto it, stuck from then on) and
  // the relaxation repeats, until no particle joins (an active set decided at equilibrium, so
  // a transient overshoot cannot make a contact). The steps carry momentum mu (MSM's velocity
  // damping, 1 - mu per unit step): the fixed point is the same, velocities being zero there,
  // and the slow affine modes of high beta converge several times faster. At most
  // relax_max_iterations steps per call.
  Status relax(double closure) noexcept {
    const double plane_a = low_ + 0.5 * closure;
    const double plane_b = high_ - 0.5 * closure;
    const int n = model_.particle_count;
    MsmStepInput<Dim, Scalar> input;
    input.dt = Scalar(1);
    input.driven.ids = s_.ids;
    input.driven.positions = s_.targets;
    int budget = max_iterations_;
    while (true) {
      int count = 0;
      for (int i = 0; i < n; ++i) {
        s_.state.velocity[i].setZero();
        if (s_.side[i] == 0) continue;
        const double travel = -static_cast<double>(s_.side[i]) * 0.5 * (closure - s_.anchor_closure[i]);
        s_.ids[count] = i;
        s_.targets[count] = s_.anchor[i] + static_cast<Scalar>(travel) * axis_;
        ++count;
      }
      input.driven.count = count;
      int quiet = 0;
      while (quiet < 2 && budget > 0) {
        for (int i = 0; i < n; ++i) s_.previous[i] = s_.state.position[i];
        const Status stepped = msm_step(model_, params_, input, s_.state);
        if (stepped != Status::ok) return stepped;
        ++steps_;
        --budget;
        double move = 0;
        for (int i = 0; i < n; ++i)
          move = std::max(move, static_cast<double>((s_.state.position[i] - s_.previous[i]).norm()));
        quiet = move <= tolerance_ ? quiet + 1 : 0;
      }
      int joined = 0;
      for (int i = 0; i < n; ++i) {
        if (s_.side[i] != 0) continue;
        Vec& x = s_.state.position[i];
        const double along = static_cast<double>(axis_.dot(x));
        if (!(along < plane_a) && !(along > plane_b)) continue;
        const bool jaw_a = along < plane_a;
        x += static_cast<Scalar>((jaw_a ? plane_a : plane_b) - along) * axis_;
        s_.side[i] = jaw_a ? std::int8_t{-1} : std::int8_t{1};
        s_.anchor[i] = x;
        s_.anchor_closure[i] = closure;
        ++joined;
      }
      if (quiet < 2) {
        ++unconverged_;
        return Status::ok;
      }
      if (joined == 0) return Status::ok;
    }
  }

  double strain() const noexcept { return measure(model_, null_, s_.state.position).strain; }
  long steps() const noexcept { return steps_; }
  int unconverged() const noexcept { return unconverged_; }

 private:
  const MsmModel<Dim, Scalar>& model_;
  Squeeze<Dim, Scalar>& s_;
  Vec axis_;
  double low_;
  double high_;
  const Eigen::Matrix<double, Dim, Dim>* null_;
  double tolerance_;
  int max_iterations_;
  MsmParams<Dim, Scalar> params_;
  long steps_ = 0;
  int unconverged_ = 0;
};

template <int Dim, typename Scalar>
void fill_null_projectors(const MsmModel<Dim, Scalar>& model, Eigen::Matrix<double, Dim, Dim>* null) noexcept {
  using MatD = Eigen::Matrix<double, Dim, Dim>;
  for (int c = 0; c < model.cluster_count; ++c) {
    Eigen::SelfAdjointEigenSolver<MatD> solver;
    solver.computeDirect(model.cluster_aqq_inverse[c].template cast<double>());
    const double largest = solver.eigenvalues().cwiseAbs().maxCoeff();
    MatD projector = MatD::Zero();
    // msm_model drops directions under 1e-3 of the cluster's largest variance; its pseudo-
    // inverse is exactly zero there up to rounding, so 1e-5 separates the two cleanly.
    for (int d = 0; d < Dim; ++d) {
      if (solver.eigenvalues()(d) <= 1e-5 * largest) {
        projector.noalias() += solver.eigenvectors().col(d) * solver.eigenvectors().col(d).transpose();
      }
    }
    null[c] = projector;
  }
}

// Strain of row j at closure x (in closure steps): linear between nodes (between the refined
// sub-steps inside the segment that holds the crossing), linear extrapolation through the last
// two nodes past the table.
double row_strain(const double* row, int columns, double steps, int segment, const double* refined,
                  int refine) noexcept {
  if (!(steps > 0)) return 0;
  const int last = columns - 1;
  if (steps >= last) return row[last] + (row[last] - row[last - 1]) * (steps - last);
  const int k = static_cast<int>(steps);
  if (k == segment) {
    const double sub = (steps - k) * refine;
    const int r = std::min(static_cast<int>(sub), refine - 1);
    return refined[r] + (sub - r) * (refined[r + 1] - refined[r]);
  }
  const double t = steps - k;
  return row[k] + t * (row[k + 1] - row[k]);
}

void bracket(int beta_points, double beta_low, double beta_high, int& first, int& last) noexcept {
  const double scale = beta_points - 1;
  const double low = std::clamp(std::isnan(beta_low) ? 0.0 : beta_low, 0.0, 1.0);
  const double high = std::clamp(std::isnan(beta_high) ? 1.0 : beta_high, low, 1.0);
  first = std::clamp(static_cast<int>(std::floor(low * scale + 1e-9)), 0, beta_points - 1);
  last = std::clamp(static_cast<int>(std::ceil(high * scale - 1e-9)), first, beta_points - 1);
}

// Per-source check of one sample: the raw fault conditions, whether it is new (a stamp not seen
// before), and whether it is usable (no fault). Records the stamp unless it is out of order.
struct SampleCheck {
  bool raw[kFaultKindCount] = {};
  bool new_sample = false;
  bool usable = false;
};

struct SampleFields {
  double stamp = kNaN;
  bool values_finite = false;
  bool valid = false;
  bool range_ok = false;
  std::uint32_t status_bits = 0;
  std::uint32_t mask = 0;
  bool bus_off = false;
  bool timeout = false;
  double max_age = 0;
};

SampleCheck check_sample(GraspGuardState& state, int source, bool clock_known, double now, double tolerance,
                         const SampleFields& f) noexcept {
  SampleCheck check;
  const bool stamp_finite = finite(f.stamp);
  check.raw[kNan] = !stamp_finite || !f.values_finite;
  bool ordered = true;
  if (stamp_finite) {
    const bool backwards = state.seen[source] && f.stamp < state.last_stamp_s[source];
    const bool future = clock_known && f.stamp > now + tolerance;
    ordered = !backwards && !future;
    if (ordered) {
      check.new_sample = !state.seen[source] || f.stamp != state.last_stamp_s[source];
      state.last_stamp_s[source] = f.stamp;
      state.seen[source] = true;
    }
    check.raw[kStale] = clock_known && now - f.stamp > f.max_age;
  }
  check.raw[kInvalid] = !f.valid || !f.range_ok || !ordered;
  check.raw[kSensor] = (f.status_bits & f.mask) != 0;
  check.raw[kBusOff] = f.bus_off;
  check.raw[kTimeout] = f.timeout;
  return check;
}

// Steps the source's fault latches and counters with a checked sample; sets `usable`.
void apply_sample(GraspGuardState& state, GraspGuardCounters& counters, int source, int needed,
                  SampleCheck& check) noexcept {
  bool refused = false;
  check.usable = true;
  for (int kind = 0; kind < kFaultKindCount; ++kind) {
    step_latch(state.fault[kind][source], check.raw[kind], !check.raw[kind], check.new_sample, needed);
    check.usable = check.usable && !check.raw[kind];
    if (kind != kStale) refused = refused || check.raw[kind];
  }
  if (refused) ++counters.refused[source];
  if (check.raw[kStale]) ++counters.stale_cycles[source];
}

}  // namespace

// --- names -------------------------------------------------------------------------------------

const char* guard_reason_name(GuardReason reason) noexcept {
  switch (reason) {
    case GuardReason::none: return "none";
    case GuardReason::force_exceeded: return "force_exceeded";
    case GuardReason::strain_exceeded: return "strain_exceeded";
    case GuardReason::indentation_exceeded: return "indentation_exceeded";
    case GuardReason::not_configured: return "not_configured";
    case GuardReason::nan_input: return "nan_input";
    case GuardReason::invalid_input: return "invalid_input";
    case GuardReason::sensor_fault: return "sensor_fault";
    case GuardReason::bus_off: return "bus_off";
    case GuardReason::timeout: return "timeout";
    case GuardReason::stale_gripper: return "stale_gripper";
    case GuardReason::stale_wrench: return "stale_wrench";
    case GuardReason::stale_camera: return "stale_camera";
    case GuardReason::stale_estimate: return "stale_estimate";
    case GuardReason::force_limit: return "force_limit";
    case GuardReason::strain_limit: return "strain_limit";
    case GuardReason::indentation_limit: return "indentation_limit";
    case GuardReason::predicted_strain: return "predicted_strain";
    case GuardReason::estimate_uncertain: return "estimate_uncertain";
    case GuardReason::count: break;
  }
  return "unknown";
}

const char* grasp_verdict_name(GraspVerdict verdict) noexcept {
  switch (verdict) {
    case GraspVerdict::ok: return "ok";
    case GraspVerdict::limit: return "limit";
    case GraspVerdict::stop: return "stop";
  }
  return "unknown";
}

const char* guard_source_name(GuardSource source) noexcept {
  switch (source) {
    case GuardSource::gripper: return "gripper";
    case GuardSource::wrench: return "wrench";
    case GuardSource::camera: return "camera";
    case GuardSource::estimate: return "estimate";
    case GuardSource::clock: return "clock";
    case GuardSource::count: break;
  }
  return "unknown";
}

// --- init --------------------------------------------------------------------------------------

template <int Dim, typename Scalar>
std::size_t grasp_guard_workspace_size(const MsmModel<Dim, Scalar>& model, const GraspGuardConfig& config) noexcept {
  if (!model.initialized() || validate(config) != Status::ok) return 0;
  Arena measuring;
  GraspGuard<Dim, Scalar> scratch;
  Squeeze<Dim, Scalar> squeeze;
  (void)carve(measuring, model, config, scratch, squeeze);
  return measuring.required_bytes();
}

template <int Dim, typename Scalar>
Status grasp_guard_init(Arena& arena, const MsmModel<Dim, Scalar>& model, const GraspObject<Dim, Scalar>& object,
                        const GraspGuardConfig& config, GraspGuard<Dim, Scalar>& guard) noexcept {
  using Vec = Eigen::Matrix<Scalar, Dim, 1>;
  guard = GraspGuard<Dim, Scalar>{};
  if (!model.initialized()) return Status::not_initialized;
  const Status valid = validate(config);
  if (valid != Status::ok) return valid;
  if (arena.measuring()) return Status::capacity_exceeded;
  const int n = model.particle_count;
  if (n < 2 || !(model.spacing > Scalar(0))) return Status::invalid_argument;
  for (int i = 0; i < n; ++i) {
    if (model.drivable[i] == 0 || model.fixed[i] != 0) return Status::invalid_argument;
  }
  const Scalar axis_norm = object.squeeze_axis.norm();
  if (!object.squeeze_axis.allFinite() || !(axis_norm > Scalar(0))) return Status::invalid_argument;
  const Vec axis = object.squeeze_axis / axis_norm;
  double low = kInf;
  double high = -kInf;
  for (int i = 0; i < n; ++i) {
    const double along = static_cast<double>(axis.dot(model.rest[i]));
    low = std::min(low, along);
    high = std::max(high, along);
  }
  const double extent = high - low;
  if (!(extent > 0.5 * static_cast<double>(model.spacing))) return Status::invalid_argument;
  // Default: twice the closure that would reach the stop threshold under uniform compression
  // (strain = closure / extent), at most half the extent. Strain concentrates at the jaws, so
  // crossings come earlier, and past twice the threshold the rows are extrapolated anyway.
  const double uniform = 2 * config.max_strain * (1 + config.stop_overshoot) * extent;
  const double max_closure =
      std::isnan(config.prediction_max_closure_m) ? std::min(0.5 * extent, uniform) : config.prediction_max_closure_m;
  if (!(max_closure < extent)) return Status::invalid_argument;
  if (finite(config.contact_width_m) && finite(config.contact_width_tolerance) &&
      std::abs(config.contact_width_m - extent) > config.contact_width_tolerance * extent) {
    return Status::invalid_argument;
  }
  const bool explicit_a = object.jaw_a_count > 0;
  const bool explicit_b = object.jaw_b_count > 0;
  if (explicit_a != explicit_b || object.jaw_a_count < 0 || object.jaw_b_count < 0 ||
      (explicit_a && (object.jaw_a_ids == nullptr || object.jaw_b_ids == nullptr)) ||
      (!explicit_a && !(finite(object.contact_band) && object.contact_band >= 0))) {
    return Status::invalid_argument;
  }

  GraspGuard<Dim, Scalar> g;
  g.config = config;
  if (std::isnan(g.config.nominal_force_n)) g.config.nominal_force_n = config.max_force_n;
  Squeeze<Dim, Scalar> squeeze;
  const Status carved = carve(arena, model, config, g, squeeze);
  if (carved != Status::ok) return carved;

  // Initial contacts.
  for (int i = 0; i < n; ++i) squeeze.initial_side[i] = 0;
  int count_a = 0;
  int count_b = 0;
  if (explicit_a) {
    for (int k = 0; k < object.jaw_a_count + object.jaw_b_count; ++k) {
      const bool jaw_a = k < object.jaw_a_count;
      const int id = jaw_a ? object.jaw_a_ids[k] : object.jaw_b_ids[k - object.jaw_a_count];
      if (id < 0 || id >= n) return Status::invalid_argument;
      const std::int8_t side = jaw_a ? std::int8_t{-1} : std::int8_t{1};
      if (squeeze.initial_side[id] == -side) return Status::invalid_argument;
      squeeze.initial_side[id] = side;
    }
  } else {
    const double band = object.contact_band * static_cast<double>(model.spacing);
    for (int i = 0; i < n; ++i) {
      const double along = static_cast<double>(axis.dot(model.rest[i]));
      const bool a = along <= low + band;
      const bool b = along >= high - band;
      if (a && b) return Status::invalid_argument;
      squeeze.initial_side[i] = a ? std::int8_t{-1} : (b ? std::int8_t{1} : std::int8_t{0});
    }
  }
  for (int i = 0; i < n; ++i) {
    count_a += squeeze.initial_side[i] < 0 ? 1 : 0;
    count_b += squeeze.initial_side[i] > 0 ? 1 : 0;
  }
  if (count_a == 0 || count_b == 0 || count_a + count_b == n) return Status::invalid_argument;

  fill_null_projectors(model, g.cluster_null);
  g.particle_count = n;
  g.cluster_count = model.cluster_count;
  g.squeeze_axis = axis;
  g.extent_m = extent;
  g.beta_points = config.prediction_beta_points;
  g.closure_points = config.prediction_closure_points;
  g.closure_step_m = max_closure / config.prediction_closure_points;

  // The table: for each beta, a quasi-static loading path in closure_points steps. Where the
  // strain first exceeds the limit, the last step is redone in refine_steps sub-steps from a
  // checkpoint; the crossing is the last sub-step still at or below the limit, and the refined
  // path (not the coarse step) continues.
  SqueezeRun<Dim, Scalar> run(model, squeeze, axis, low, high, config, g.cluster_null);
  const int columns = g.closure_points + 1;
  const double limit = config.max_strain;
  const int refine = config.prediction_refine_steps;
  // Past twice the stop threshold nothing the guard decides depends on the exact strain: a
  // row ends there and continues by linear extrapolation (never decreasing).
  const double enough = 2 * limit * (1 + config.stop_overshoot);
  for (int j = 0; j < g.beta_points; ++j) {
    double* row = g.strain_table + static_cast<std::ptrdiff_t>(j) * columns;
    run.start(static_cast<double>(j) / (g.beta_points - 1));
    row[0] = run.strain();
    double crossing = kNaN;
    int computed = columns;
    double* refined = g.refined_strain + static_cast<std::ptrdiff_t>(j) * (refine + 1);
    g.refined_segment[j] = -1;
    for (int k = 1; k < columns; ++k) {
      if (!std::isnan(crossing) && row[k - 1] > enough && k >= 2) {
        computed = k;
        break;
      }
      const bool searching = std::isnan(crossing);
      if (searching) run.save();
      Status relaxed = run.relax(k * g.closure_step_m);
      if (relaxed != Status::ok) return relaxed;
      double strain = run.strain();
      if (searching && strain > limit) {
        run.restore();
        g.refined_segment[j] = k - 1;
        refined[0] = row[k - 1];
        for (int r = 1; r <= refine; ++r) {
          const double closure = ((k - 1) + static_cast<double>(r) / refine) * g.closure_step_m;
          relaxed = run.relax(closure);
          if (relaxed != Status::ok) return relaxed;
          strain = run.strain();
          refined[r] = strain;
          if (std::isnan(crossing) && strain > limit)
            crossing = ((k - 1) + static_cast<double>(r - 1) / refine) * g.closure_step_m;
        }
      }
      row[k] = strain;
    }
    for (int k = computed; k < columns; ++k) row[k] = std::max(row[k - 1], 2 * row[k - 1] - row[k - 2]);
    g.crossing_closure_m[j] = std::isnan(crossing) ? max_closure : crossing;
  }
  g.unconverged_relaxations = run.unconverged();
  g.relaxation_steps = run.steps();
  guard = g;
  grasp_guard_reset(guard);
  return Status::ok;
}

template <int Dim, typename Scalar>
void grasp_guard_reset(GraspGuard<Dim, Scalar>& guard) noexcept {
  GraspGuardState& s = guard.state;
  for (GuardLatch& latch : s.measured) latch = GuardLatch{};
  s.geometry_mismatch = false;
  s.stop_latched = false;
  s.latched_reason = GuardReason::none;
  s.in_contact = false;
  s.contact_width_m = kNaN;
  s.has_wrench = false;
  for (double& v : s.high_pass) v = 0;
  s.frozen_count = 0;
  s.slip_force_n = 0;
  s.slip = false;
  s.allowed_force_n = guard.config.nominal_force_n;
  s.fit_w = s.fit_x = s.fit_y = s.fit_xx = s.fit_xy = 0;
  s.fit_samples = 0;
  s.fit_last_closure_m = -kInf;
  s.fit_last_force_n = 0;
  s.fit_segment_slope = kNaN;
}

template <int Dim, typename Scalar>
void grasp_guard_acknowledge_stop(GraspGuard<Dim, Scalar>& guard) noexcept {
  guard.state.stop_latched = false;
  guard.state.latched_reason = GuardReason::none;
}

template <int Dim, typename Scalar>
double grasp_guard_predicted_strain(const GraspGuard<Dim, Scalar>& guard, double closure_m, double beta_low,
                                    double beta_high) noexcept {
  if (!guard.initialized()) return kNaN;
  int first = 0;
  int last = 0;
  bracket(guard.beta_points, beta_low, beta_high, first, last);
  const int columns = guard.closure_points + 1;
  const int refine = guard.config.prediction_refine_steps;
  const double steps = closure_m / guard.closure_step_m;
  double worst = 0;
  for (int j = first; j <= last; ++j) {
    worst = std::max(worst, row_strain(guard.strain_table + static_cast<std::ptrdiff_t>(j) * columns, columns, steps,
                                       guard.refined_segment[j],
                                       guard.refined_strain + static_cast<std::ptrdiff_t>(j) * (refine + 1), refine));
  }
  return worst;
}

template <int Dim, typename Scalar>
double grasp_guard_strain_safe_closure(const GraspGuard<Dim, Scalar>& guard, double beta_low,
                                       double beta_high) noexcept {
  if (!guard.initialized()) return 0;
  int first = 0;
  int last = 0;
  bracket(guard.beta_points, beta_low, beta_high, first, last);
  double safe = kInf;
  for (int j = first; j <= last; ++j) safe = std::min(safe, guard.crossing_closure_m[j]);
  return safe;
}

template <int Dim, typename Scalar>
Status grasp_guard_measure_strain(const MsmModel<Dim, Scalar>& model, const GraspGuard<Dim, Scalar>& guard,
                                  const Eigen::Matrix<Scalar, Dim, 1>* positions,
                                  GraspStrainMeasurement& measurement) noexcept {
  measurement = GraspStrainMeasurement{};
  if (!guard.initialized() || !model.initialized()) return Status::not_initialized;
  if (positions == nullptr || model.particle_count != guard.particle_count ||
      model.cluster_count != guard.cluster_count) {
    return Status::invalid_argument;
  }
  measurement = measure(model, guard.cluster_null, positions);
  return measurement.clusters_measured > 0 ? Status::ok : Status::no_observations;
}

// --- the cycle's stages ---------------------------------------------------------------------------

namespace {

// What the cycle has established so far, handed from stage to stage.
struct Cycle {
  int needed = 1;            // consecutive clear samples that clear a latch (clear_samples)
  double dt = 0;             // since the last good cycle, at most cycle_timeout_s
  bool clock_known = false;  // a good now was seen: stamps can be aged and caught in the future
  double reference = 0;      // this cycle's now, or the last good one
  SampleCheck gripper;
  SampleCheck wrench;
  SampleCheck camera;
  SampleCheck estimate;
  bool gripper_new = false;  // a usable gripper sample not seen before
  double closure = 0;        // contact width - width, >= 0 (0 before contact)
};

// The prediction and the closures it allows.
struct Limits {
  double beta_low = 0;
  double beta_high = 1;
  double strain_safe = 0;
  double predicted_strain = kNaN;
  double stiffness = kNaN;
  double force_safe = kInf;
  double safe = 0;
};

// The verdict and the reasons behind it.
struct Decision {
  GraspVerdict severity[kGuardReasonCount] = {};  // per active reason
  std::uint32_t reasons = 0;
  std::uint8_t fault_sources = 0;
  GraspVerdict verdict = GraspVerdict::ok;
  GuardReason dominant = GuardReason::none;
  StopAction action = StopAction::freeze;
};

// The clock: a non-finite now, a now going backwards, or a gap longer than cycle_timeout_s. A
// refused now leaves the last good one as the reference the samples are checked against.
void read_clock(const GraspGuardConfig& config, double now, GraspGuardState& s, GraspGuardCounters& counters,
                Cycle& cycle) noexcept {
  bool clock_raw[kFaultKindCount] = {};
  double dt = 0;
  if (!finite(now)) {
    clock_raw[kNan] = true;
  } else if (s.has_now && now < s.last_now_s) {
    clock_raw[kInvalid] = true;
  } else {
    if (s.has_now) {
      dt = now - s.last_now_s;
      clock_raw[kTimeout] = dt > config.cycle_timeout_s;
      dt = std::min(dt, config.cycle_timeout_s);
    }
    s.last_now_s = now;
    s.has_now = true;
  }
  cycle.dt = dt;
  cycle.clock_known = s.has_now;
  cycle.reference = s.last_now_s;
  const int clock = source_index(GuardSource::clock);
  for (int kind = 0; kind < kFaultKindCount; ++kind) {
    step_latch(s.fault[kind][clock], clock_raw[kind], !clock_raw[kind], true, cycle.needed);
  }
  if (clock_raw[kNan] || clock_raw[kInvalid]) ++counters.refused[clock];
  if (clock_raw[kTimeout]) ++counters.stale_cycles[clock];
}

// check_sample against this cycle's clock.
SampleCheck check_source(const GraspGuardConfig& config, GuardSource which, const SampleFields& fields,
                         GraspGuardState& s, const Cycle& cycle) noexcept {
  return check_sample(s, source_index(which), cycle.clock_known, cycle.reference, config.clock_tolerance_s, fields);
}

// Grip force from the configured source: the force sensor, or the motor current.
double grip_force(const GraspGuardConfig& config, const GripperSample& gripper) noexcept {
  const bool by_current = config.force_source == ForceSource::motor_current;
  return by_current ? config.current_gain_n_per_a * (gripper.current_a - config.current_offset_a) : gripper.force_n;
}

SampleFields gripper_fields(const GraspGuardConfig& config, const GripperSample& gripper, double raw_force) noexcept {
  const bool gripper_finite = finite(gripper.width_m) && finite(raw_force);
  SampleFields fields;
  fields.stamp = gripper.stamp_s;
  fields.values_finite = gripper_finite;
  fields.valid = gripper.valid;
  // A non-finite width is a nan_input, not also out of range.
  fields.range_ok = !gripper_finite || (gripper.width_m >= 0 && gripper.width_m <= config.max_width_m);
  fields.status_bits = gripper.status_bits;
  fields.mask = config.gripper_fault_mask;
  fields.bus_off = gripper.bus_off;
  fields.timeout = gripper.timeout;
  fields.max_age = config.gripper_timeout_s;
  return fields;
}

// First contact: at the configured contact width, or else at the first usable sample with at
// least contact_force_n, whose width must then agree with the model's extent (wrong object or
// unit otherwise).
void detect_contact(const GraspGuardConfig& config, double extent, GraspGuardState& s) noexcept {
  if (s.in_contact) return;
  if (finite(config.contact_width_m)) {
    if (s.width_m <= config.contact_width_m) {
      s.in_contact = true;
      s.contact_width_m = config.contact_width_m;
    }
  } else if (s.force_n >= config.contact_force_n) {
    s.in_contact = true;
    s.contact_width_m = s.width_m;
    s.geometry_mismatch = finite(config.contact_width_tolerance) &&
                          std::abs(s.contact_width_m - extent) > config.contact_width_tolerance * extent;
  }
}

// The gripper: a usable sample updates width, force and contact; the closure follows from the
// last usable width (a refused sample keeps the previous one).
void read_gripper(const GraspGuardConfig& config, double extent, const GripperSample& gripper, GraspGuardState& s,
                  GraspGuardCounters& counters, Cycle& cycle) noexcept {
  const double raw_force = grip_force(config, gripper);
  SampleCheck& g = cycle.gripper;
  g = check_source(config, GuardSource::gripper, gripper_fields(config, gripper, raw_force), s, cycle);
  apply_sample(s, counters, source_index(GuardSource::gripper), cycle.needed, g);
  cycle.gripper_new = g.usable && g.new_sample;
  if (g.usable) {
    s.width_m = gripper.width_m;
    s.force_n = raw_force;
    s.has_gripper = true;
    detect_contact(config, extent, s);
  }
  cycle.closure = s.in_contact && s.has_gripper ? std::max(0.0, s.contact_width_m - s.width_m) : 0.0;
}

// Force fit: samples admitted every force_fit_spacing_m of closure, so a hold adds nothing.
void admit_force_fit_sample(const GraspGuardConfig& config, const Cycle& cycle, GraspGuardState& s) noexcept {
  const double closure = cycle.closure;
  if (!(cycle.gripper_new && s.in_contact && std::abs(closure - s.fit_last_closure_m) >= config.force_fit_spacing_m)) {
    return;
  }
  const double keep = config.force_fit_forgetting;
  if (s.fit_samples > 0) s.fit_segment_slope = (s.force_n - s.fit_last_force_n) / (closure - s.fit_last_closure_m);
  s.fit_last_force_n = s.force_n;
  s.fit_w = keep * s.fit_w + 1;
  s.fit_x = keep * s.fit_x + closure;
  s.fit_y = keep * s.fit_y + s.force_n;
  s.fit_xx = keep * s.fit_xx + closure * closure;
  s.fit_xy = keep * s.fit_xy + closure * s.force_n;
  ++s.fit_samples;
  s.fit_last_closure_m = closure;
}

SampleFields wrench_fields(const GraspGuardConfig& config, const WrenchSample& wrench) noexcept {
  bool wrench_finite = true;
  for (double v : wrench.wrench) wrench_finite = wrench_finite && finite(v);
  SampleFields fields;
  fields.stamp = wrench.stamp_s;
  fields.values_finite = wrench_finite;
  fields.valid = wrench.valid;
  fields.range_ok = true;
  fields.status_bits = wrench.status_bits;
  fields.mask = config.wrench_fault_mask;
  fields.bus_off = wrench.bus_off;
  fields.timeout = wrench.timeout;
  fields.max_age = config.wrench_timeout_s;
  return fields;
}

// A frozen sensor repeats its last reading bit for bit (a live one always has noise in the low
// bits): counts the consecutive repeats.
void track_frozen_wrench(const WrenchSample& wrench, GraspGuardState& s) noexcept {
  // Bitwise on purpose: the values are finite (checked before), and "the same bits" is the test.
  // NOLINTNEXTLINE(bugprone-suspicious-memory-comparison)
  const bool repeated = s.frozen_seen && std::memcmp(wrench.wrench, s.previous_wrench, sizeof wrench.wrench) == 0;
  s.frozen_count = repeated ? s.frozen_count + 1 : 0;
  std::memcpy(s.previous_wrench, wrench.wrench, sizeof wrench.wrench);
  s.frozen_seen = true;
}

// The slip cue: a first-order high-pass (slip_cutoff_hz) of the wrist force over the samples'
// own stamps, started at zero by the first sample; slip_force_n is its magnitude.
void high_pass_wrench(const GraspGuardConfig& config, const WrenchSample& wrench, GraspGuardState& s) noexcept {
  if (!s.has_wrench) {
    for (int d = 0; d < 3; ++d) {
      s.previous_force[d] = wrench.wrench[d];
      s.high_pass[d] = 0;
    }
    s.has_wrench = true;
  } else {
    const double tau = 1.0 / (2.0 * kPi * config.slip_cutoff_hz);
    const double dt_w = std::max(0.0, wrench.stamp_s - s.wrench_stamp_s);
    const double a = tau / (tau + dt_w);
    for (int d = 0; d < 3; ++d) {
      s.high_pass[d] = a * (s.high_pass[d] + wrench.wrench[d] - s.previous_force[d]);
      s.previous_force[d] = wrench.wrench[d];
    }
  }
  s.wrench_stamp_s = wrench.stamp_s;
  s.slip_force_n =
      std::sqrt(s.high_pass[0] * s.high_pass[0] + s.high_pass[1] * s.high_pass[1] + s.high_pass[2] * s.high_pass[2]);
}

// Wrench: the frozen-sensor check (a frozen sensor counts as stale), then the slip cue's
// high-pass on a new usable sample.
void read_wrench(const GraspGuardConfig& config, const WrenchSample& wrench, GraspGuardState& s,
                 GraspGuardCounters& counters, Cycle& cycle) noexcept {
  const SampleFields fields = wrench_fields(config, wrench);
  SampleCheck& w = cycle.wrench;
  w = check_source(config, GuardSource::wrench, fields, s, cycle);
  if (w.new_sample && fields.values_finite) track_frozen_wrench(wrench, s);
  if (config.wrench_frozen_samples > 0 && s.frozen_count >= config.wrench_frozen_samples) w.raw[kStale] = true;
  apply_sample(s, counters, source_index(GuardSource::wrench), cycle.needed, w);
  if (w.usable && w.new_sample) high_pass_wrench(config, wrench, s);
}

// Slip in contact (the high-passed force over slip_ratio x the grip force, clamped to the floor
// and ceiling) raises the allowed force at slip_force_rate_per_s, up to max_force_n.
void update_slip(const GraspGuardConfig& config, const Cycle& cycle, GraspGuardState& s,
                 GraspGuardCounters& counters) noexcept {
  const double grip = s.has_gripper ? std::abs(s.force_n) : 0.0;
  const double slip_threshold = std::clamp(config.slip_ratio * grip, config.slip_floor_n, config.slip_ceiling_n);
  s.slip = s.in_contact && cycle.wrench.usable && s.has_wrench && s.slip_force_n > slip_threshold;
  if (s.slip) {
    s.allowed_force_n =
        std::min(config.max_force_n, s.allowed_force_n * (1.0 + config.slip_force_rate_per_s * cycle.dt));
    ++counters.slip_cycles;
  }
}

SampleFields camera_fields(const GraspGuardConfig& config, const DeformationSample& deformation) noexcept {
  SampleFields fields;
  fields.stamp = deformation.stamp_s;
  fields.values_finite = finite(deformation.strain);
  fields.valid = deformation.valid;
  fields.range_ok = !(deformation.strain < 0);
  fields.status_bits = deformation.status_bits;
  fields.mask = config.camera_fault_mask;
  fields.bus_off = deformation.bus_off;
  fields.timeout = deformation.timeout;
  fields.max_age = config.camera_timeout_s;
  return fields;
}

// Camera: a usable sample updates the measured strain.
void read_camera(const GraspGuardConfig& config, const DeformationSample& deformation, GraspGuardState& s,
                 GraspGuardCounters& counters, Cycle& cycle) noexcept {
  SampleCheck& cam = cycle.camera;
  cam = check_source(config, GuardSource::camera, camera_fields(config, deformation), s, cycle);
  apply_sample(s, counters, source_index(GuardSource::camera), cycle.needed, cam);
  if (cam.usable) {
    s.strain = deformation.strain;
    s.has_strain = true;
  }
}

// An sd of +inf is a legitimate "not yet identifiable", not a fault.
SampleFields estimate_fields(const GraspGuardConfig& config, const EstimateSample& estimate) noexcept {
  const bool estimate_finite = finite(estimate.msm_beta) && !std::isnan(estimate.msm_beta_std);
  SampleFields fields;
  fields.stamp = estimate.stamp_s;
  fields.values_finite = estimate_finite;
  fields.valid = estimate.valid;
  fields.range_ok =
      !estimate_finite || (estimate.msm_beta >= 0 && estimate.msm_beta <= 1 && estimate.msm_beta_std >= 0);
  fields.max_age = config.estimate_timeout_s;
  return fields;
}

// Estimate: a usable sample updates msm_beta and its sd.
void read_estimate(const GraspGuardConfig& config, const EstimateSample& estimate, GraspGuardState& s,
                   GraspGuardCounters& counters, Cycle& cycle) noexcept {
  SampleCheck& est = cycle.estimate;
  est = check_source(config, GuardSource::estimate, estimate_fields(config, estimate), s, cycle);
  apply_sample(s, counters, source_index(GuardSource::estimate), cycle.needed, est);
  if (est.usable) {
    s.msm_beta = estimate.msm_beta;
    s.msm_beta_std = estimate.msm_beta_std;
    s.has_estimate = true;
  }
}

// The prediction's msm_beta interval: the estimate +- confidence_k sd; without a usable,
// finite-sd estimate this cycle, the whole range.
void beta_interval(const GraspGuardConfig& config, const GraspGuardState& s, const Cycle& cycle,
                   Limits& limits) noexcept {
  limits.beta_low = 0;
  limits.beta_high = 1;
  if (cycle.estimate.usable && finite(s.msm_beta_std)) {
    limits.beta_low = std::clamp(s.msm_beta - config.confidence_k * s.msm_beta_std, 0.0, 1.0);
    limits.beta_high = std::clamp(s.msm_beta + config.confidence_k * s.msm_beta_std, 0.0, 1.0);
  }
}

// The force model's slope (NaN without one: before contact or below force_model_min_closure_m).
// The largest of the secant, the fit's slope (the mean tangent over its window) and the latest
// segment's slope (the current tangent): conservative for softening and stiffening.
double force_stiffness(const GraspGuardConfig& config, const GraspGuardState& s, double closure) noexcept {
  if (!(s.in_contact && s.has_gripper && closure >= config.force_model_min_closure_m && closure > 0)) return kNaN;
  double stiffness = std::max(0.0, s.force_n / closure);
  if (s.fit_samples >= 2 && finite(s.fit_segment_slope)) stiffness = std::max(stiffness, s.fit_segment_slope);
  if (s.fit_samples >= 3) {
    const double mean_x = s.fit_x / s.fit_w;
    const double variance = s.fit_xx / s.fit_w - mean_x * mean_x;
    // A slope only from a window whose closures spread (sd) over more than half the fit spacing.
    if (variance > 0.25 * config.force_fit_spacing_m * config.force_fit_spacing_m) {
      const double slope = (s.fit_xy / s.fit_w - mean_x * s.fit_y / s.fit_w) / variance;
      stiffness = std::max(stiffness, slope);
    }
  }
  return stiffness;
}

// The closure at which the force model reaches allowed_force_n: +inf without a model or with
// a flat one below the allowed force, the current closure with a flat one at or above it.
double force_safe_closure(const GraspGuardState& s, double stiffness, double closure) noexcept {
  double force_safe = kInf;
  if (finite(stiffness)) {
    if (stiffness > 0) {
      force_safe = std::max(0.0, closure + (s.allowed_force_n - s.force_n) / stiffness);
    } else if (s.force_n >= s.allowed_force_n) {
      force_safe = closure;
    }
  }
  return force_safe;
}

// Prediction: the safe closure is the least of the strain table's, the indentation limit and
// the force model's.
template <int Dim, typename Scalar>
Limits compute_limits(const GraspGuard<Dim, Scalar>& guard, const Cycle& cycle) noexcept {
  const GraspGuardConfig& config = guard.config;
  const GraspGuardState& s = guard.state;
  Limits limits;
  beta_interval(config, s, cycle, limits);
  limits.strain_safe = grasp_guard_strain_safe_closure(guard, limits.beta_low, limits.beta_high);
  limits.predicted_strain = grasp_guard_predicted_strain(guard, cycle.closure, limits.beta_low, limits.beta_high);
  limits.stiffness = force_stiffness(config, s, cycle.closure);
  limits.force_safe = force_safe_closure(s, limits.stiffness, cycle.closure);
  limits.safe = std::max(0.0, std::min({limits.strain_safe, config.max_indentation_m, limits.force_safe}));
  return limits;
}

// Measured limits, with hysteresis. Each latch steps only on a usable sample of its own source
// and counts clear samples of that source.
void step_measured_limits(const GraspGuardConfig& config, const Cycle& cycle, const Limits& limits,
                          GraspGuardState& s) noexcept {
  const int needed = cycle.needed;
  const double margin = config.hysteresis_margin;
  const double overshoot = 1 + config.stop_overshoot;
  const double closure = cycle.closure;
  const bool gripper_new = cycle.gripper_new;
  GuardLatch* m = s.measured;
  if (cycle.gripper.usable) {
    step_measured(m[reason_index(GuardReason::force_limit)], s.force_n, s.allowed_force_n, margin, gripper_new, needed);
    step_measured(m[reason_index(GuardReason::force_exceeded)], s.force_n, config.max_force_n * overshoot, margin,
                  gripper_new, needed);
    step_measured(m[reason_index(GuardReason::indentation_limit)], closure, config.max_indentation_m, margin,
                  gripper_new, needed);
    step_measured(m[reason_index(GuardReason::indentation_exceeded)], closure, config.max_indentation_m * overshoot,
                  margin, gripper_new, needed);
    step_measured(m[reason_index(GuardReason::predicted_strain)], closure, limits.strain_safe, margin, gripper_new,
                  needed);
  }
  const SampleCheck& cam = cycle.camera;
  if (cam.usable) {
    step_measured(m[reason_index(GuardReason::strain_limit)], s.strain, config.max_strain, margin, cam.new_sample,
                  needed);
    step_measured(m[reason_index(GuardReason::strain_exceeded)], s.strain, config.max_strain * overshoot, margin,
                  cam.new_sample, needed);
  }
  const SampleCheck& est = cycle.estimate;
  if (est.usable) {
    step_measured(m[reason_index(GuardReason::estimate_uncertain)], s.msm_beta_std, config.max_beta_std, margin,
                  est.new_sample, needed);
  }
}

// Every active fault latch, as its reason at its source's configured verdict.
void collect_faults(const GraspGuardConfig& config, const GraspGuardState& s, Decision& d) noexcept {
  for (int kind = 0; kind < kFaultKindCount; ++kind) {
    for (int source = 0; source < kGuardSourceCount; ++source) {
      if (!s.fault[kind][source].active) continue;
      const GuardReason reason = fault_reason(kind, source);
      const int r = reason_index(reason);
      d.reasons |= reason_bit(reason);
      d.fault_sources = static_cast<std::uint8_t>(d.fault_sources | (1u << static_cast<unsigned>(source)));
      d.severity[r] = std::max(d.severity[r], config.fault_verdict[source]);
    }
  }
}

// `reason` at `verdict` when its measured latch is active.
void raise_measured(const GuardLatch* m, GuardReason reason, GraspVerdict verdict, Decision& d) noexcept {
  if (!m[reason_index(reason)].active) return;
  d.reasons |= reason_bit(reason);
  d.severity[reason_index(reason)] = std::max(d.severity[reason_index(reason)], verdict);
}

// Every active measured latch, and a contact width that contradicts the model.
void collect_limits(const GraspGuardConfig& config, const GraspGuardState& s, Decision& d) noexcept {
  const GuardLatch* m = s.measured;
  raise_measured(m, GuardReason::force_exceeded, GraspVerdict::stop, d);
  raise_measured(m, GuardReason::strain_exceeded, GraspVerdict::stop, d);
  raise_measured(m, GuardReason::indentation_exceeded, GraspVerdict::stop, d);
  raise_measured(m, GuardReason::force_limit, GraspVerdict::limit, d);
  raise_measured(m, GuardReason::strain_limit, GraspVerdict::limit, d);
  raise_measured(m, GuardReason::indentation_limit, GraspVerdict::limit, d);
  raise_measured(m, GuardReason::predicted_strain, GraspVerdict::limit, d);
  raise_measured(m, GuardReason::estimate_uncertain, config.uncertain_estimate_verdict, d);
  if (s.geometry_mismatch) {
    d.reasons |= reason_bit(GuardReason::not_configured);
    d.severity[reason_index(GuardReason::not_configured)] = GraspVerdict::stop;
  }
}

// The verdict: the most severe active reason, ties to the lower (higher-priority) reason.
void pick_dominant(Decision& d) noexcept {
  d.verdict = GraspVerdict::ok;
  d.dominant = GuardReason::none;
  for (int r = 1; r < kGuardReasonCount; ++r) {
    if ((d.reasons & (1u << static_cast<unsigned>(r))) != 0 && d.severity[r] > d.verdict) {
      d.verdict = d.severity[r];
      d.dominant = static_cast<GuardReason>(r);
    }
  }
}

// What stop means: exceeded_stop_action for an exceeded limit, else fault_stop_action. With
// latch_stop a stop holds its reason and action until acknowledged, whatever the inputs do.
void apply_stop_latch(const GraspGuardConfig& config, GraspGuardState& s, Decision& d) noexcept {
  const bool exceeded = d.dominant == GuardReason::force_exceeded || d.dominant == GuardReason::strain_exceeded ||
                        d.dominant == GuardReason::indentation_exceeded;
  d.action = exceeded ? config.exceeded_stop_action : config.fault_stop_action;
  if (!config.latch_stop) return;
  if (s.stop_latched) {
    d.verdict = GraspVerdict::stop;
    d.dominant = s.latched_reason;
    d.action = s.latched_action;
    d.reasons |= reason_bit(d.dominant);
  } else if (d.verdict == GraspVerdict::stop) {
    s.stop_latched = true;
    s.latched_reason = d.dominant;
    s.latched_action = d.action;
  }
}

Decision decide_verdict(const GraspGuardConfig& config, GraspGuardState& s, GraspGuardCounters& counters) noexcept {
  Decision d;
  collect_faults(config, s, d);
  collect_limits(config, s, d);
  pick_dominant(d);
  apply_stop_latch(config, s, d);
  if (d.verdict == GraspVerdict::limit) ++counters.limit_cycles;
  if (d.verdict == GraspVerdict::stop) ++counters.stop_cycles;
  return d;
}

void fill_output(const GraspGuardState& s, const Cycle& cycle, const Limits& limits, const Decision& d,
                 GraspGuardOutput& output) noexcept {
  const double closure = cycle.closure;
  output.verdict = d.verdict;
  output.reason = d.dominant;
  output.stop_action = d.action;
  output.reasons = d.reasons;
  output.fault_sources = d.fault_sources;
  output.in_contact = s.in_contact;
  output.slip = s.slip;
  output.contact_width_m = s.contact_width_m;
  output.closure_m = closure;
  output.force_n = s.has_gripper ? s.force_n : kNaN;
  output.strain = s.has_strain ? s.strain : kNaN;
  output.allowed_force_n = s.allowed_force_n;
  output.beta_low = limits.beta_low;
  output.beta_high = limits.beta_high;
  output.predicted_strain = limits.predicted_strain;
  output.strain_safe_closure_m = limits.strain_safe;
  output.force_safe_closure_m = limits.force_safe;
  output.safe_closure_m = limits.safe;
  output.safe_width_m = s.in_contact ? s.contact_width_m - limits.safe : kNaN;
  output.stiffness_n_per_m = limits.stiffness;
  output.predicted_force_n = finite(limits.stiffness) ? s.force_n + limits.stiffness * (limits.safe - closure) : kNaN;
  output.slip_force_n = s.slip_force_n;
}

}  // namespace

// --- the cycle -----------------------------------------------------------------------------------

// The stages run in this order because each reads what the previous ones left in the state:
// the clock before the samples are aged, the gripper's closure before the force fit and the
// limits, the slip (which raises allowed_force_n) before the force limits.
template <int Dim, typename Scalar>
Status grasp_guard_update(GraspGuard<Dim, Scalar>& guard, const GraspGuardInput& input,
                          GraspGuardOutput& output) noexcept {
  output = GraspGuardOutput{};
  if (!guard.initialized()) {
    output.reasons = reason_bit(GuardReason::not_configured);
    return Status::not_initialized;
  }
  const GraspGuardConfig& config = guard.config;
  GraspGuardState& s = guard.state;
  GraspGuardCounters& counters = guard.counters;
  ++counters.cycles;
  Cycle cycle;
  cycle.needed = config.clear_samples;
  read_clock(config, input.now_s, s, counters, cycle);
  read_gripper(config, guard.extent_m, input.gripper, s, counters, cycle);
  admit_force_fit_sample(config, cycle, s);
  read_wrench(config, input.wrench, s, counters, cycle);
  update_slip(config, cycle, s, counters);
  read_camera(config, input.deformation, s, counters, cycle);
  read_estimate(config, input.estimate, s, counters, cycle);
  const Limits limits = compute_limits(guard, cycle);
  step_measured_limits(config, cycle, limits, s);
  const Decision decision = decide_verdict(config, s, counters);
  fill_output(s, cycle, limits, decision, output);
  return Status::ok;
}

#define PLIANT_INSTANTIATE_GRASP_GUARD(DIM, SCALAR)                                                                    \
  template std::size_t grasp_guard_workspace_size<DIM, SCALAR>(const MsmModel<DIM, SCALAR>&,                           \
                                                               const GraspGuardConfig&) noexcept;                      \
  template Status grasp_guard_init<DIM, SCALAR>(Arena&, const MsmModel<DIM, SCALAR>&, const GraspObject<DIM, SCALAR>&, \
                                                const GraspGuardConfig&, GraspGuard<DIM, SCALAR>&) noexcept;           \
  template void grasp_guard_reset<DIM, SCALAR>(GraspGuard<DIM, SCALAR>&) noexcept;                                     \
  template void grasp_guard_acknowledge_stop<DIM, SCALAR>(GraspGuard<DIM, SCALAR>&) noexcept;                          \
  template Status grasp_guard_update<DIM, SCALAR>(GraspGuard<DIM, SCALAR>&, const GraspGuardInput&,                    \
                                                  GraspGuardOutput&) noexcept;                                         \
  template Status grasp_guard_measure_strain<DIM, SCALAR>(                                                             \
      const MsmModel<DIM, SCALAR>&, const GraspGuard<DIM, SCALAR>&, const Eigen::Matrix<SCALAR, DIM, 1>*,              \
      GraspStrainMeasurement&) noexcept;                                                                               \
  template double grasp_guard_predicted_strain<DIM, SCALAR>(const GraspGuard<DIM, SCALAR>&, double, double,            \
                                                            double) noexcept;                                          \
  template double grasp_guard_strain_safe_closure<DIM, SCALAR>(const GraspGuard<DIM, SCALAR>&, double, double) noexcept;
PLIANT_INSTANTIATE_GRASP_GUARD(2, float)
PLIANT_INSTANTIATE_GRASP_GUARD(2, double)
PLIANT_INSTANTIATE_GRASP_GUARD(3, float)
PLIANT_INSTANTIATE_GRASP_GUARD(3, double)
#undef PLIANT_INSTANTIATE_GRASP_GUARD

}  // namespace pliant
