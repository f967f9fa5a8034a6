#include "pliant/core/online_deformability.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "pliant/core/curve_analysis.hpp"
#include "step_interval.hpp"

namespace pliant {

template <int Dim, typename Scalar>
std::size_t online_deformability_workspace_size(const MsmModel<Dim, Scalar>& model,
                                                const OnlineDeformabilityConfig& config) noexcept {
  Arena measure;
  OnlineDeformability<Dim, Scalar> scratch;
  (void)online_deformability_init(measure, model, MsmParams<Dim, Scalar>{}, config, scratch);
  return measure.required_bytes();
}

template <int Dim, typename Scalar>
Status online_deformability_init(Arena& arena, const MsmModel<Dim, Scalar>& model, const MsmParams<Dim, Scalar>& base,
                                 const OnlineDeformabilityConfig& config,
                                 OnlineDeformability<Dim, Scalar>& estimator) noexcept {
  estimator = OnlineDeformability<Dim, Scalar>{};
  if (!model.initialized()) return Status::not_initialized;
  if (config.candidates < 3 || !(config.forgetting > 0) || config.forgetting > 1) return Status::invalid_argument;
  if (config.alpha_candidates < 1 || config.alpha_candidates > kMaxOnlineAlphaRows) return Status::invalid_argument;
  if (config.alpha_candidates > 1 && !(config.alpha_min > 0 && config.alpha_min < 1)) return Status::invalid_argument;
  if (config.step_candidates < 1 || config.step_candidates > kMaxOnlineStepRows) return Status::invalid_argument;
  if (config.equilibrium_iterations < 0 || config.equilibrium_iterations > kMaxEquilibriumIterations ||
      (config.equilibrium_iterations > 0 &&
       !(std::isfinite(config.equilibrium_tolerance) && config.equilibrium_tolerance > 0))) {
    return Status::invalid_argument;
  }
  OnlineDeformability<Dim, Scalar> e;
  e.candidates = config.candidates;
  e.alpha_candidates = config.alpha_candidates;
  e.step_candidates = config.step_candidates;
  e.quasi_static = config.equilibrium_iterations > 0;
  e.equilibrium_iterations = config.equilibrium_iterations;
  e.equilibrium_tolerance = config.equilibrium_tolerance * static_cast<double>(model.spacing);
  e.alpha_min = config.alpha_candidates > 1 ? config.alpha_min : 1.0;
  e.params = base;
  e.forgetting = config.forgetting;
  const auto total = static_cast<std::size_t>(e.total_candidates());
  e.states = arena.carve<MsmState<Dim, Scalar>>(total);
  e.sum_squares = arena.carve<double>(total);
  const auto n = static_cast<std::size_t>(model.particle_count);
  e.step_start = arena.carve<Eigen::Matrix<Scalar, Dim, 1>>(n);
  e.step_targets = arena.carve<Eigen::Matrix<Scalar, Dim, 1>>(n);
  if (e.quasi_static) e.previous = arena.carve<Eigen::Matrix<Scalar, Dim, 1>>(n);
  bool ok = !arena.exhausted();
  for (int c = 0; c < e.total_candidates(); ++c) {
    MsmState<Dim, Scalar> dummy;
    ok = msm_state_init(arena, model, e.states != nullptr ? e.states[c] : dummy) == Status::ok && ok;
  }
  if (!ok || arena.exhausted()) return Status::capacity_exceeded;
  estimator = e;
  online_deformability_reset(model, estimator);
  return Status::ok;
}

template <int Dim, typename Scalar>
void online_deformability_reset(const MsmModel<Dim, Scalar>& model,
                                OnlineDeformability<Dim, Scalar>& estimator) noexcept {
  PLIANT_ASSERT(estimator.initialized());
  for (int c = 0; c < estimator.total_candidates(); ++c) {
    msm_state_reset(model, estimator.states[c]);
    estimator.sum_squares[c] = 0;
  }
  estimator.residual_count = 0;
  estimator.frames = 0;
}

namespace {

// Where each driven particle starts the frame interval: its previous target, or its simulated
// position when it was free (an unknown id: its own target, which msm_step then drops).
template <int Dim, typename Scalar>
void interval_start(const MsmModel<Dim, Scalar>& model, const MsmDrivenTargets<Dim, Scalar>& driven,
                    const MsmState<Dim, Scalar>& state, Eigen::Matrix<Scalar, Dim, 1>* start) noexcept {
  for (int c = 0; c < driven.count; ++c) {
    const int id = driven.ids[c];
    start[c] = id >= 0 && id < model.particle_count ? state.position[id] : driven.positions[c];
  }
}

// The largest distance any particle moved from `previous`.
template <int Dim, typename Scalar>
double largest_move(const MsmModel<Dim, Scalar>& model, const MsmState<Dim, Scalar>& state,
                    const Eigen::Matrix<Scalar, Dim, 1>* previous) noexcept {
  double largest = 0;
  for (int i = 0; i < model.particle_count; ++i) {
    largest = std::max(largest, static_cast<double>((state.position[i] - previous[i]).norm()));
  }
  return largest;
}

// The quasi-static row's frame: from where the candidate stood at the last frame, msm_steps
// with the frame's driven targets until no particle moves more than the tolerance in two
// successive iterations, or the iteration bound. The iterations carry momentum mu = 0.5 + 0.4
// msm_beta (as the grasp guard's relaxation: the fixed point has zero velocity, so it is the
// same, and the slow affine modes of high msm_beta settle several times faster); they run with
// msm_alpha 1 and the frame's dt, so that gravity weighs as in the other rows. Returns the first
// status that rejected a step, else ok; `relaxed` says whether the tolerance was reached.
template <int Dim, typename Scalar>
Status relax_towards_equilibrium(const MsmModel<Dim, Scalar>& model, OnlineDeformability<Dim, Scalar>& estimator,
                                 MsmParams<Dim, Scalar> params, Scalar dt, const MsmDrivenTargets<Dim, Scalar>& driven,
                                 MsmState<Dim, Scalar>& state, bool& relaxed) noexcept {
  const Scalar momentum = Scalar(0.5) + Scalar(0.4) * params.msm_beta;
  params.msm_alpha = Scalar(1);
  params.velocity_damping = (Scalar(1) - momentum) / dt;  // per second: 1 - damping dt = momentum
  MsmStepInput<Dim, Scalar> input;
  input.dt = dt;
  input.driven = driven;
  for (int i = 0; i < model.particle_count; ++i) state.velocity[i].setZero();
  int quiet = 0;
  for (int iteration = 0; iteration < estimator.equilibrium_iterations && quiet < 2; ++iteration) {
    for (int i = 0; i < model.particle_count; ++i) estimator.previous[i] = state.position[i];
    const Status stepped = msm_step(model, params, input, state);
    if (stepped == Status::invalid_argument || stepped == Status::not_initialized) return stepped;
    quiet = largest_move(model, state, estimator.previous) <= estimator.equilibrium_tolerance ? quiet + 1 : 0;
  }
  relaxed = quiet >= 2;
  return Status::ok;
}

// Advances candidate `c` over the frame interval in its row's form.
template <int Dim, typename Scalar>
Status advance_candidate(const MsmModel<Dim, Scalar>& model, OnlineDeformability<Dim, Scalar>& estimator, int c,
                         Scalar dt, const MsmDrivenTargets<Dim, Scalar>& driven) noexcept {
  const int k = estimator.candidates;
  const int row = c / k;
  MsmParams<Dim, Scalar> params = estimator.params;
  params.msm_beta = static_cast<Scalar>(static_cast<double>(c % k) / (k - 1));
  params.msm_alpha = static_cast<Scalar>(estimator.row_alpha(row));
  MsmState<Dim, Scalar>& state = estimator.states[c];
  if (estimator.is_quasi_static(row)) {
    bool relaxed = false;
    const Status status = relax_towards_equilibrium(model, estimator, params, dt, driven, state, relaxed);
    if (!relaxed) ++estimator.unrelaxed;
    return status;
  }
  const int steps = estimator.row_steps(row);
  if (steps > 1) interval_start(model, driven, state, estimator.step_start);
  return detail::step_frame_interval(model, params, dt, driven.ids, estimator.step_start, driven.positions,
                                     driven.count, steps, estimator.step_targets, state);
}

// Squared residuals of the free observed particles of one candidate; `count` gets their scalars.
template <int Dim, typename Scalar>
double frame_squares(const MsmModel<Dim, Scalar>& model, const MsmState<Dim, Scalar>& state,
                     const Eigen::Matrix<Scalar, Dim, 1>* observed, double& count) noexcept {
  double squares = 0;
  count = 0;
  for (int i = 0; i < model.particle_count; ++i) {
    if (model.fixed[i] != 0 || state.driven_now[i] != 0 || !observed[i].allFinite()) continue;
    squares += (state.position[i] - observed[i]).template cast<double>().squaredNorm();
    count += Dim;
  }
  return squares;
}

}  // namespace

template <int Dim, typename Scalar>
Status online_deformability_update(const MsmModel<Dim, Scalar>& model, OnlineDeformability<Dim, Scalar>& estimator,
                                   Scalar dt, const MsmDrivenTargets<Dim, Scalar>& driven,
                                   const Eigen::Matrix<Scalar, Dim, 1>* observed) noexcept {
  if (!estimator.initialized() || !model.initialized()) return Status::not_initialized;
  if (!std::isfinite(dt) || !(dt > Scalar(0)) || observed == nullptr) {
    ++estimator.rejected_frames;
    return Status::invalid_argument;
  }
  if (driven.count < 0 || (estimator.step_candidates > 1 && driven.count > model.particle_count)) {
    ++estimator.rejected_frames;
    return Status::invalid_argument;
  }
  double frame_count = 0;
  for (int c = 0; c < estimator.total_candidates(); ++c) {
    const Status stepped = advance_candidate(model, estimator, c, dt, driven);
    if (stepped == Status::invalid_argument || stepped == Status::not_initialized) {
      ++estimator.rejected_frames;
      return Status::invalid_argument;
    }
    const double squares = frame_squares(model, estimator.states[c], observed, frame_count);
    estimator.sum_squares[c] = estimator.forgetting * estimator.sum_squares[c] + squares;
  }
  estimator.residual_count = estimator.forgetting * estimator.residual_count + frame_count;
  ++estimator.frames;
  if (frame_count == 0) {
    ++estimator.empty_frames;
    return Status::no_observations;
  }
  return Status::ok;
}

namespace {

// The least residual of one row (model form) over msm_beta: the parabola through the best grid
// point and its neighbours (the best grid point itself when the parabola is not convex).
struct RowMinimum {
  double msm_beta = 0;
  double sum_squares = 0;
  double curvature = 0;
  int best = 0;
};

RowMinimum row_minimum(const double* sum_squares, int k) noexcept {
  RowMinimum row;
  for (int c = 1; c < k; ++c) {
    if (sum_squares[c] < sum_squares[row.best]) row.best = c;
  }
  const double h = 1.0 / (k - 1);
  const int centre = row.best == 0 ? 1 : (row.best == k - 1 ? k - 2 : row.best);
  const ParabolaFit fit =
      fit_parabola(centre * h, h, sum_squares[centre - 1], sum_squares[centre], sum_squares[centre + 1]);
  row.curvature = fit.curvature;
  const double vertex = fit.curvature > 0 ? fit.x : row.best * h;
  row.msm_beta = vertex < 0 ? 0 : (vertex > 1 ? 1 : vertex);
  row.sum_squares = fit.curvature > 0 ? std::max(fit.value, 0.0) : sum_squares[row.best];
  return row;
}

// The fitted form: the row (msm_alpha, steps per frame) with the least residual. With three or
// more alpha values, the parabola over alpha through that row and its neighbours of the same
// step count refines alpha (kept inside the grid) and msm_beta is interpolated quadratically
// between those rows. sum_squares stays the best row's own: the interpolated value is not a
// simulated one, and comparing it with the held row would favour the fitted form.
struct FittedForm {
  double msm_alpha = 1;
  double msm_beta = 0;
  double sum_squares = 0;
  int row = 0;
};

template <int Dim, typename Scalar>
FittedForm fitted_form(const RowMinimum* rows, const OnlineDeformability<Dim, Scalar>& estimator) noexcept {
  FittedForm form;
  for (int r = 1; r < estimator.rows(); ++r) {
    if (rows[r].sum_squares < rows[form.row].sum_squares) form.row = r;
  }
  form.msm_alpha = estimator.row_alpha(form.row);
  form.msm_beta = rows[form.row].msm_beta;
  form.sum_squares = rows[form.row].sum_squares;
  const int count = estimator.alpha_candidates;
  if (count < 3 || estimator.is_quasi_static(form.row)) return form;
  const int group = form.row - form.row % count;
  const int best = form.row % count;
  const int centre = best == 0 ? 1 : (best == count - 1 ? count - 2 : best);
  const RowMinimum& left = rows[group + centre - 1];
  const RowMinimum& mid = rows[group + centre];
  const RowMinimum& right = rows[group + centre + 1];
  const double alpha_centre = estimator.row_alpha(group + centre);
  const double h = estimator.row_alpha(group + 1) - estimator.row_alpha(group);
  const ParabolaFit fit = fit_parabola(alpha_centre, h, left.sum_squares, mid.sum_squares, right.sum_squares);
  if (!(fit.curvature > 0)) return form;
  const double alpha = std::min(std::max(fit.x, estimator.row_alpha(group)), 1.0);
  const double t = (alpha - alpha_centre) / h;
  const double beta = mid.msm_beta + 0.5 * t * (right.msm_beta - left.msm_beta) +
                      0.5 * t * t * (right.msm_beta - 2 * mid.msm_beta + left.msm_beta);
  form.msm_alpha = alpha;
  form.msm_beta = beta < 0 ? 0 : (beta > 1 ? 1 : beta);
  return form;
}

// BIC with `extra` more parameters: n ln(S_held / S_fitted) > extra ln n.
bool form_determined(double held, double fitted, double points, int extra) noexcept {
  if (!(points > 1) || !(held > fitted)) return false;
  if (!(fitted > 0)) return true;
  return points * std::log(held / fitted) > extra * std::log(points);
}

}  // namespace

template <int Dim, typename Scalar>
OnlineDeformabilityEstimate online_deformability_estimate(const OnlineDeformability<Dim, Scalar>& estimator) noexcept {
  OnlineDeformabilityEstimate out;
  out.frames = estimator.frames;
  out.msm_beta_std = std::numeric_limits<double>::infinity();
  if (!estimator.initialized() || estimator.residual_count < 2) return out;
  const int k = estimator.candidates;
  RowMinimum rows[kMaxOnlineAlphaRows * kMaxOnlineStepRows + 1];
  for (int r = 0; r < estimator.rows(); ++r) rows[r] = row_minimum(estimator.sum_squares + r * k, k);
  const int held = estimator.alpha_candidates - 1;  // alpha 1 (or the base alpha), one step per frame
  const FittedForm fitted = fitted_form(rows, estimator);
  const int extra = (estimator.alpha_candidates > 1 ? 1 : 0) + (estimator.step_candidates > 1 ? 1 : 0) +
                    (estimator.quasi_static ? 1 : 0);
  out.alpha_fitted =
      extra > 0 && form_determined(rows[held].sum_squares, fitted.sum_squares, estimator.residual_count / Dim, extra);
  const int answering = out.alpha_fitted ? fitted.row : held;
  const RowMinimum& row = rows[answering];
  out.msm_beta = out.alpha_fitted ? fitted.msm_beta : row.msm_beta;
  out.msm_alpha = out.alpha_fitted ? fitted.msm_alpha : estimator.row_alpha(held);
  out.steps_per_frame = estimator.row_steps(answering);
  out.msm_beta_std = least_squares_std(row.sum_squares, row.curvature, static_cast<long>(estimator.residual_count));
  if (out.alpha_fitted) {
    // The form was chosen by a criterion that counts every residual as independent; where the
    // forms disagree on msm_beta, the interval spans the held form's answer too.
    const double disagreement = out.msm_beta - rows[held].msm_beta;
    out.msm_beta_std = std::sqrt(out.msm_beta_std * out.msm_beta_std + disagreement * disagreement);
  }
  const double* row_squares = estimator.sum_squares + answering * k;
  out.unique_minimum = row.curvature > 0 && single_basin(row_squares, k);
  out.rms = std::sqrt(row_squares[row.best] / estimator.residual_count);
  return out;
}

#define PLIANT_INSTANTIATE_ONLINE(DIM, SCALAR)                                                                       \
  template std::size_t online_deformability_workspace_size<DIM, SCALAR>(const MsmModel<DIM, SCALAR>&,                \
                                                                        const OnlineDeformabilityConfig&) noexcept;  \
  template Status online_deformability_init<DIM, SCALAR>(                                                            \
      Arena&, const MsmModel<DIM, SCALAR>&, const MsmParams<DIM, SCALAR>&, const OnlineDeformabilityConfig&,         \
      OnlineDeformability<DIM, SCALAR>&) noexcept;                                                                   \
  template void online_deformability_reset<DIM, SCALAR>(const MsmModel<DIM, SCALAR>&,                                \
                                                        OnlineDeformability<DIM, SCALAR>&) noexcept;                 \
  template Status online_deformability_update<DIM, SCALAR>(                                                          \
      const MsmModel<DIM, SCALAR>&, OnlineDeformability<DIM, SCALAR>&, SCALAR, const MsmDrivenTargets<DIM, SCALAR>&, \
      const Eigen::Matrix<SCALAR, DIM, 1>*) noexcept;                                                                \
  template OnlineDeformabilityEstimate online_deformability_estimate<DIM, SCALAR>(                                   \
      const OnlineDeformability<DIM, SCALAR>&) noexcept;
PLIANT_INSTANTIATE_ONLINE(2, float)
PLIANT_INSTANTIATE_ONLINE(2, double)
PLIANT_INSTANTIATE_ONLINE(3, float)
PLIANT_INSTANTIATE_ONLINE(3, double)
#undef PLIANT_INSTANTIATE_ONLINE

}  // namespace pliant
