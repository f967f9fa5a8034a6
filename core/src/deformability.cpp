#include "pliant/core/deformability.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "pliant/core/curve_analysis.hpp"
#include "step_interval.hpp"

namespace pliant {
namespace {

template <int Dim, typename Scalar>
Status check_inputs(const MsmModel<Dim, Scalar>& model, const ObservationSequence<Dim, Scalar>& obs,
                    const DeformabilityConfig& config, const DeformabilityWorkspace<Dim, Scalar>& ws) noexcept {
  if (!model.initialized() || !ws.state.initialized()) return Status::not_initialized;
  if (config.grid_points < 3 || !(config.tolerance > 0) || config.max_refinements < 0 || !(config.alpha_min > 0) ||
      !(config.alpha_min <= 1) || config.equilibrium_max_iterations < 1 || !(config.equilibrium_tolerance > 0) ||
      config.steps_per_frame < 1 || config.steps_per_frame > max_steps_per_frame) {
    return Status::invalid_argument;
  }
  if (ws.curve_capacity < config.grid_points + config.max_refinements || ws.grid_capacity < config.grid_points) {
    return Status::capacity_exceeded;
  }
  if (obs.frame_count < 2 || obs.particle_count != model.particle_count || obs.times_s == nullptr ||
      obs.positions == nullptr || obs.driven_count < 0 || obs.driven_count > ws.driven_capacity ||
      (obs.driven_count > 0 && obs.driven == nullptr)) {
    return Status::invalid_argument;
  }
  for (int k = 0; k < obs.frame_count; ++k) {
    if (!std::isfinite(obs.times_s[k]) || (k > 0 && !(obs.times_s[k] > obs.times_s[k - 1]))) {
      return Status::invalid_argument;
    }
  }
  for (int w = 0; w < obs.driven_count; ++w) {
    const int id = obs.driven[w].id;
    if (id < 0 || id >= model.particle_count || model.drivable[id] == 0) return Status::invalid_argument;
  }
  int free_particles = 0;
  for (int i = 0; i < model.particle_count; ++i) {
    if (model.fixed[i] == 0) ++free_particles;
  }
  // Particles driven for the whole recording are not free either.
  for (int w = 0; w < obs.driven_count; ++w) {
    const DrivenWindow& window = obs.driven[w];
    if (window.active_at(obs.times_s[0]) && window.active_at(obs.times_s[obs.frame_count - 1]) &&
        model.fixed[window.id] == 0) {
      --free_particles;
    }
  }
  return free_particles > 0 ? Status::ok : Status::no_free_particles;
}

// Driven targets for frame `k`: the particle's observation there, else its last target. Also
// records where each target starts the interval from frame k - 1: its previous target, or where
// the particle is when its window has just opened.
template <int Dim, typename Scalar>
int gather_targets(const ObservationSequence<Dim, Scalar>& obs, int k, const MsmState<Dim, Scalar>& state,
                   DeformabilityWorkspace<Dim, Scalar>& ws) noexcept {
  int count = 0;
  const double t = obs.times_s[k];
  for (int w = 0; w < obs.driven_count; ++w) {
    const DrivenWindow& window = obs.driven[w];
    if (!window.active_at(t)) {
      ws.window_active[w] = 0;
      continue;
    }
    if (ws.window_active[w] == 0) ws.held[w] = state.position[window.id];
    ws.window_active[w] = 1;
    ws.interval_start[count] = ws.held[w];
    if (obs.observed(k, window.id)) ws.held[w] = obs.point(k, window.id);
    ws.target_ids[count] = window.id;
    ws.targets[count] = ws.held[w];
    ++count;
  }
  return count;
}

// True when every coordinate of every frame is finite: then no residual needs the observed()
// test (checked once per estimate rather than per particle, frame and evaluation).
template <int Dim, typename Scalar>
bool all_observed(const ObservationSequence<Dim, Scalar>& obs) noexcept {
  const long scalars = static_cast<long>(obs.frame_count) * obs.particle_count * Dim;
  bool finite = true;
  for (long j = 0; j < scalars; ++j) finite &= std::isfinite(obs.positions[j]);
  return finite;
}

// Adds frame k's residuals of free observed particles to `error` (kAllObserved: the caller has
// checked that every observation is finite).
// With `residual_sum` ([particle_count]) and `samples` it also sums each particle's residuals
// over frames, from which the estimator measures how much of the residual persists in time.
template <bool kAllObserved, int Dim, typename Scalar>
void accumulate_frame(const MsmModel<Dim, Scalar>& model, const ObservationSequence<Dim, Scalar>& obs, int k,
                      const MsmState<Dim, Scalar>& state, Eigen::Matrix<double, Dim, 1>* residual_sum, double* samples,
                      TrajectoryError& error) noexcept {
  // Hot loop of every evaluation (once per frame): plain arrays and local sums, so that nothing
  // is reloaded through the output pointers. Same arithmetic, in the same order, as
  // (position - observation).cast<double>() and its squaredNorm.
  long used = 0;
  double sum_squares = error.sum_squares;
  double distance = error.mean_distance;
  const std::uint8_t* fixed = model.fixed;
  const std::uint8_t* driven = state.driven_now;
  const Eigen::Matrix<Scalar, Dim, 1>* position = state.position;
  const Scalar* observed = obs.at(k, 0);
  const int n = model.particle_count;
  for (int i = 0; i < n; ++i, observed += Dim) {
    if ((fixed[i] | driven[i]) != 0) continue;
    bool finite = true;
    double residual[static_cast<std::size_t>(Dim)];
    for (int d = 0; d < Dim; ++d) {
      if constexpr (!kAllObserved) finite = finite && std::isfinite(observed[d]);
      residual[d] = static_cast<double>(position[i](d) - observed[d]);
    }
    if (!finite) continue;
    double squared = residual[0] * residual[0];
    for (int d = 1; d < Dim; ++d) squared += residual[d] * residual[d];
    sum_squares += squared;
    distance += std::sqrt(squared);
    ++used;
    if (residual_sum != nullptr) {
      for (int d = 0; d < Dim; ++d) residual_sum[i](d) += residual[d];
      samples[i] += 1.0;
    }
  }
  error.sum_squares = sum_squares;
  error.mean_distance = distance;
  if (used == 0) ++error.frames_without_observations;
  error.count += used;
}

template <int Dim, typename Scalar>
void run_trajectory(const MsmModel<Dim, Scalar>& model, const MsmParams<Dim, Scalar>& params,
                    const ObservationSequence<Dim, Scalar>& obs, int steps_per_frame, bool observed_everywhere,
                    DeformabilityWorkspace<Dim, Scalar>& ws, TrajectoryError& error) noexcept {
  MsmState<Dim, Scalar>& state = ws.state;
  msm_state_reset(model, state);
  for (int w = 0; w < obs.driven_count; ++w) ws.window_active[w] = 0;
  for (int i = 0; i < model.particle_count; ++i) {
    ws.residual_sum[i].setZero();
    ws.residual_samples[i] = 0;
  }
  (void)gather_targets(obs, 0, state, ws);
  for (int k = 1; k < obs.frame_count; ++k) {
    const auto dt = static_cast<Scalar>(obs.times_s[k] - obs.times_s[k - 1]);
    const int target_count = gather_targets(obs, k, state, ws);
    // The interval starts where each driven particle was held (step_interval.hpp).
    (void)detail::step_frame_interval(model, params, dt, ws.target_ids, ws.interval_start, ws.targets, target_count,
                                      steps_per_frame, ws.step_targets, state);
    if (observed_everywhere) {
      accumulate_frame<true>(model, obs, k, state, ws.residual_sum, ws.residual_samples, error);
    } else {
      accumulate_frame<false>(model, obs, k, state, ws.residual_sum, ws.residual_samples, error);
    }
  }
  for (int i = 0; i < model.particle_count; ++i) {
    if (ws.residual_samples[i] > 0) {
      error.between_squares += ws.residual_sum[i].squaredNorm() / ws.residual_samples[i];
      ++error.compared_particles;
    }
  }
}

// Final-frame targets: the last observation of each window active at the final time.
template <int Dim, typename Scalar>
int final_targets(const MsmModel<Dim, Scalar>& model, const ObservationSequence<Dim, Scalar>& obs,
                  DeformabilityWorkspace<Dim, Scalar>& ws) noexcept {
  int count = 0;
  const int last = obs.frame_count - 1;
  for (int w = 0; w < obs.driven_count; ++w) {
    const DrivenWindow& window = obs.driven[w];
    if (!window.active_at(obs.times_s[last])) continue;
    Eigen::Matrix<Scalar, Dim, 1> target = model.rest[window.id];
    for (int k = last; k >= 0 && window.active_at(obs.times_s[k]); --k) {
      if (obs.observed(k, window.id)) {
        target = obs.point(k, window.id);
        break;
      }
    }
    ws.target_ids[count] = window.id;
    ws.targets[count] = target;
    ++count;
  }
  return count;
}

// Quasi-static relaxation to equilibrium, warm-started from the workspace state.
template <int Dim, typename Scalar>
void run_final(const MsmModel<Dim, Scalar>& model, const MsmParams<Dim, Scalar>& params,
               const ObservationSequence<Dim, Scalar>& obs, const DeformabilityConfig& config,
               DeformabilityWorkspace<Dim, Scalar>& ws, TrajectoryError& error) noexcept {
  MsmState<Dim, Scalar>& state = ws.state;
  MsmStepInput<Dim, Scalar> input;
  input.dt = static_cast<Scalar>((obs.times_s[obs.frame_count - 1] - obs.times_s[0]) / (obs.frame_count - 1));
  input.driven.count = final_targets(model, obs, ws);
  input.driven.ids = ws.target_ids;
  input.driven.positions = ws.targets;
  const double limit = config.equilibrium_tolerance * static_cast<double>(model.spacing);
  error.converged = false;
  for (int iteration = 0; iteration < config.equilibrium_max_iterations; ++iteration) {
    for (int i = 0; i < model.particle_count; ++i) {
      ws.previous[i] = state.position[i];
      state.velocity[i].setZero();
    }
    (void)msm_step(model, params, input, state);
    double largest = 0;
    for (int i = 0; i < model.particle_count; ++i) {
      largest = std::max(largest, static_cast<double>((state.position[i] - ws.previous[i]).norm()));
    }
    if (largest <= limit) {
      error.converged = true;
      break;
    }
  }
  accumulate_frame<false>(model, obs, obs.frame_count - 1, state, static_cast<Eigen::Matrix<double, Dim, 1>*>(nullptr),
                          nullptr, error);
}

// Whether the curvature of the sum of squares at the estimate may come from the refinement's
// own samples next to it (a second difference over ~tolerance / 4), which spares the two probes
// 0.01 either side. That difference is small (S'' d^2 ~ 1e-5 S at the default tolerance), so
// it needs errors that are smooth in beta to far below that: trajectory mode in double.
// In float the simulation's rounding makes E(beta) rough at ~1e-5 relative, and the final mode
// warm-starts each relaxation from the last and stops it at equilibrium_tolerance; both keep
// the probes.
template <typename Scalar>
bool local_curvature_possible(const DeformabilityConfig& config) noexcept {
  return config.mode == FitMode::trajectory && sizeof(Scalar) >= sizeof(double);
}

// evaluate_deformability_error with all_observed(obs) known.
template <int Dim, typename Scalar>
Status evaluate_error(const MsmModel<Dim, Scalar>& model, const MsmParams<Dim, Scalar>& params,
                      const ObservationSequence<Dim, Scalar>& obs, const DeformabilityConfig& config,
                      bool observed_everywhere, DeformabilityWorkspace<Dim, Scalar>& ws,
                      TrajectoryError& error) noexcept {
  error = TrajectoryError{};
  if (config.mode == FitMode::trajectory) {
    run_trajectory(model, params, obs, config.steps_per_frame, observed_everywhere, ws, error);
  } else {
    run_final(model, params, obs, config, ws, error);
  }
  if (error.count == 0) return Status::no_observations;
  error.mean_distance /= static_cast<double>(error.count);
  return Status::ok;
}

// Evaluations one beta search plans: grid, Brent steps (bounded by the golden-section count,
// which Brent's fallback never exceeds by more than a few), two curvature probes when needed.
int planned_search_evaluations(const DeformabilityConfig& config, bool probes) noexcept {
  const double bracket = 2.0 / (config.grid_points - 1);
  const int golden = static_cast<int>(std::ceil(std::log(bracket / config.tolerance) / std::log(1.618034)));
  return config.grid_points + std::min(golden, config.max_refinements) + (probes ? 2 : 0);
}

struct Minimum {
  double x = 0;
  double value = 0;
};

// Golden-section search for the minimum of f on [lo, hi]: stops when the bracket is narrower
// than `tolerance` or after `max_evaluations` calls of f (at least two).
template <typename F>
Minimum golden_section_minimum(F&& f, double lo, double hi, double tolerance, int max_evaluations) noexcept {
  const double ratio = 0.5 * (std::sqrt(5.0) - 1.0);
  double a = hi - ratio * (hi - lo);
  double b = lo + ratio * (hi - lo);
  double fa = f(a);
  double fb = f(b);
  for (int evaluations = 2; evaluations < max_evaluations && hi - lo > tolerance; ++evaluations) {
    if (fa <= fb) {
      hi = b;
      b = a;
      fb = fa;
      a = hi - ratio * (hi - lo);
      fa = f(a);
    } else {
      lo = a;
      a = b;
      fa = fb;
      b = lo + ratio * (hi - lo);
      fb = f(b);
    }
  }
  return fa <= fb ? Minimum{a, fa} : Minimum{b, fb};
}

// Brent's minimisation (golden-section steps with parabolic interpolation where it is safe) on
// the bracket [a, b] that holds the best known point x; w and v are the next best known points
// (here the neighbouring grid samples, so the first step is already a parabola through three
// samples). Stops when the bracket around x is narrower than `tolerance` on both sides or after
// `max_evaluations` calls of f.
// A parabolic step that would land within 2 tol1 of a bracket end becomes a step of tol1; Brent
// takes it toward the bracket's middle. With `smooth` (f smooth, as the trajectory error is)
// it goes the parabola's way instead unless that side is already closed: when the minimum lies
// between x and the near end, that one sample both improves x and closes the bracket, where
// the step toward the middle costs a sample on the far side first. The estimate is the same.
struct Point {
  double x = 0;
  double value = 0;
};
template <typename F>
Minimum brent_minimum(F&& f, double a, double b, Point x, Point w, Point v, double tolerance, int max_evaluations,
                      bool smooth) noexcept {
  constexpr double kGolden = 0.38196601125010515;  // (3 - sqrt 5) / 2
  const double tol1 = 0.25 * tolerance;
  double step = 0.0;       // last step taken
  double earlier = b - a;  // the step before it
  for (int evaluations = 0; evaluations < max_evaluations; ++evaluations) {
    const double middle = 0.5 * (a + b);
    if (std::max(x.x - a, b - x.x) <= 2.0 * tol1) break;
    bool parabolic = false;
    if (std::abs(earlier) > tol1) {
      // Vertex of the parabola through x, w, v, as an offset p / q from x.
      const double r = (x.x - w.x) * (x.value - v.value);
      double q = (x.x - v.x) * (x.value - w.value);
      double p = (x.x - v.x) * q - (x.x - w.x) * r;
      q = 2.0 * (q - r);
      if (q > 0.0) p = -p;
      q = std::abs(q);
      const double before = earlier;
      earlier = step;
      // Accept only a step inside the bracket and smaller than half the step before last.
      if (q > 0.0 && std::abs(p) < std::abs(0.5 * q * before) && p > q * (a - x.x) && p < q * (b - x.x)) {
        step = p / q;
        const double u = x.x + step;
        if (u - a < 2.0 * tol1 || b - u < 2.0 * tol1) {
          if (!smooth) {
            step = middle >= x.x ? tol1 : -tol1;
          } else if (b - x.x <= 2.0 * tol1) {
            step = -tol1;
          } else if (x.x - a <= 2.0 * tol1) {
            step = tol1;
          } else {
            step = step >= 0.0 ? tol1 : -tol1;
          }
        }
        parabolic = true;
      }
    }
    if (!parabolic) {
      earlier = x.x >= middle ? a - x.x : b - x.x;
      step = kGolden * earlier;
    }
    const double u = x.x + (std::abs(step) >= tol1 ? step : (step >= 0.0 ? tol1 : -tol1));
    const Point trial{u, f(u)};
    if (trial.value <= x.value) {
      if (u >= x.x)
        a = x.x;
      else
        b = x.x;
      v = w;
      w = x;
      x = trial;
    } else {
      if (u < x.x)
        a = u;
      else
        b = u;
      if (trial.value <= w.value || w.x == x.x) {
        v = w;
        w = trial;
      } else if (trial.value <= v.value || v.x == x.x || v.x == w.x) {
        v = trial;
      }
    }
  }
  return Minimum{x.x, x.value};
}

struct Progress {
  const DeformabilityConfig* config = nullptr;
  int done = 0;
  int planned = 0;
  void tick() noexcept {
    ++done;
    if (config->progress != nullptr) config->progress(config->progress_context, done, std::max(done, planned));
  }
};

struct Sample {
  double beta;
  TrajectoryError error;
};

// One beta search at fixed alpha: a grid over [range_lo, range_hi] (all of [0, 1] unless the
// msm_alpha profile narrows it), then Brent. Records the curve in the workspace when `record` is
// set; without `uncertainty` only the estimate and its error are filled in (the profile).
template <int Dim, typename Scalar>
Status search_beta(const MsmModel<Dim, Scalar>& model, MsmParams<Dim, Scalar> params,
                   const ObservationSequence<Dim, Scalar>& obs, const DeformabilityConfig& config,
                   bool observed_everywhere, DeformabilityWorkspace<Dim, Scalar>& ws, bool record, bool uncertainty,
                   Progress& progress, DeformabilityResult& result, double range_lo = 0.0,
                   double range_hi = 1.0) noexcept {
  int curve = 0;
  Sample best{0, {}};
  best.error.mean_distance = std::numeric_limits<double>::infinity();
  int evaluations = 0;
  bool any_observed = false;
  auto evaluate = [&](double beta) -> TrajectoryError {
    params.msm_beta = static_cast<Scalar>(beta);
    TrajectoryError error;
    (void)evaluate_error(model, params, obs, config, observed_everywhere, ws, error);
    ++evaluations;
    progress.tick();
    if (!error.converged) ++result.unconverged_equilibria;
    if (error.count > 0) any_observed = true;
    if (curve < ws.curve_capacity) {
      ws.curve_beta[curve] = beta;
      ws.curve_error[curve] = error.mean_distance;
      ws.curve_sum_squares[curve] = error.count > 0 ? error.sum_squares : std::numeric_limits<double>::quiet_NaN();
      ++curve;
    }
    if (error.count > 0 && error.mean_distance < best.error.mean_distance) best = Sample{beta, error};
    return error;
  };

  if (config.mode == FitMode::final_equilibrium) msm_state_reset(model, ws.state);
  const int grid = config.grid_points;
  int best_grid = 0;
  double best_grid_error = std::numeric_limits<double>::infinity();
  double* grid_errors = ws.grid_error;
  const double step = (range_hi - range_lo) / (grid - 1);
  for (int i = 0; i < grid; ++i) {
    const double beta = range_lo + static_cast<double>(i) * step;
    const TrajectoryError e = evaluate(beta);
    grid_errors[i] = e.count > 0 ? e.mean_distance : std::numeric_limits<double>::infinity();
    if (e.count > 0 && e.mean_distance < best_grid_error) {
      best_grid_error = e.mean_distance;
      best_grid = i;
    }
  }
  if (!any_observed) return Status::no_observations;
  const bool grid_single = record ? single_basin(ws.curve_error, grid) : true;
  result.frames_without_observations = best.error.frames_without_observations;

  // Brent refinement inside the bracket of the best grid point's neighbours, started from the
  // three grid samples around it.
  const auto grid_point = [&](int i) {
    const int k = std::clamp(i, 0, grid - 1);
    return Point{range_lo + static_cast<double>(k) * step, grid_errors[k]};
  };
  const double lo = std::max(range_lo, range_lo + (best_grid - 1) * step);
  const double hi = std::min(range_hi, range_lo + (best_grid + 1) * step);
  // w and v of Brent's method: the better and the worse neighbour (at an end of the grid, the
  // next two points inward).
  Point near_better = best_grid > 0 ? grid_point(best_grid - 1) : grid_point(best_grid + 2);
  Point near_worse = best_grid < grid - 1 ? grid_point(best_grid + 1) : grid_point(best_grid - 2);
  if (near_worse.value < near_better.value) std::swap(near_better, near_worse);
  // The trajectory error is a mean over every frame, smooth in beta; the final mode's has few
  // residuals and relaxations stopped at a tolerance.
  const bool smooth = config.mode == FitMode::trajectory;
  (void)brent_minimum([&](double beta) { return evaluate(beta).mean_distance; }, lo, hi, grid_point(best_grid),
                      near_better, near_worse, config.tolerance, config.max_refinements, smooth);

  // Uncertainty from the curvature of the sum of squares at the estimate. Brent leaves samples
  // within tolerance / 2 on both sides of it; where E is smooth enough (see
  // local_curvature_possible) their second difference is the curvature. Otherwise, or when
  // those neighbours are missing (the estimate at a bound, refinement cut short), the estimate
  // itself and one probe h either side (the centre moves inward only at a bound).
  const double h = std::max(0.01, 2.0 * config.tolerance);
  double curvature = 0;
  bool have_curvature = false;
  if (uncertainty && local_curvature_possible<Scalar>(config)) {
    // Nearest samples either side, not closer than kMinSpacing (the difference must not vanish
    // in rounding) nor farther than h (it must stay local).
    constexpr double kMinSpacing = 1e-5;
    int below = -1;
    int above = -1;
    for (int i = 0; i < std::min(curve, ws.curve_capacity); ++i) {
      const double offset = ws.curve_beta[i] - best.beta;
      if (!std::isfinite(ws.curve_sum_squares[i]) || std::abs(offset) < kMinSpacing || std::abs(offset) > h) continue;
      if (offset < 0 && (below < 0 || offset > ws.curve_beta[below] - best.beta)) below = i;
      if (offset > 0 && (above < 0 || offset < ws.curve_beta[above] - best.beta)) above = i;
    }
    if (below >= 0 && above >= 0) {
      curvature = second_difference(ws.curve_beta[below], ws.curve_sum_squares[below], best.beta,
                                    best.error.sum_squares, ws.curve_beta[above], ws.curve_sum_squares[above]);
      have_curvature = true;
    }
  }
  if (uncertainty && !have_curvature) {
    const double centre = std::clamp(best.beta, h, 1.0 - h);
    const TrajectoryError left = evaluate(centre - h);
    const TrajectoryError middle = std::abs(centre - best.beta) < 1e-15 ? best.error : evaluate(centre);
    const TrajectoryError right = evaluate(centre + h);
    curvature = fit_parabola(centre, h, left.sum_squares, middle.sum_squares, right.sum_squares).curvature;
  }
  const long scalars = best.error.count * Dim;

  result.msm_beta = best.beta;
  result.msm_alpha = static_cast<double>(params.msm_alpha);
  // A particle's residuals are correlated in time: the rest shape and the tool path are observed
  // with noise once and every frame inherits that. Treat each particle as a cluster of samples
  // and widen the std by the design effect 1 + (m - 1) icc (m samples per particle, icc the
  // share of residual variance that persists over the recording).
  double design_effect = 1.0;
  if (best.error.compared_particles > 0 && best.error.sum_squares > 0) {
    const double per_particle = static_cast<double>(best.error.count) / best.error.compared_particles;
    if (per_particle > 1.0) {
      const double share = best.error.between_squares / best.error.sum_squares;
      const double icc = std::clamp((share - 1.0 / per_particle) / (1.0 - 1.0 / per_particle), 0.0, 1.0);
      design_effect = 1.0 + (per_particle - 1.0) * icc;
      result.residual_correlation = icc;
      result.design_effect = design_effect;
    }
  }
  result.msm_beta_std = least_squares_std(best.error.sum_squares, curvature, scalars) * std::sqrt(design_effect);
  result.unique_minimum = grid_single && curvature > 0;
  result.error = best.error.mean_distance;
  result.residual_count = best.error.count;
  result.rms = best.error.count > 0 ? std::sqrt(best.error.sum_squares / static_cast<double>(scalars)) : 0.0;
  result.evaluations += evaluations;
  if (record) {
    // Insertion sort: the curve is small (grid + refinements) and must be ascending in beta.
    curve = std::min(curve, ws.curve_capacity);
    for (int i = 1; i < curve; ++i) {
      const double kb = ws.curve_beta[i];
      const double ke = ws.curve_error[i];
      const double ks = ws.curve_sum_squares[i];
      int j = i - 1;
      while (j >= 0 && ws.curve_beta[j] > kb) {
        ws.curve_beta[j + 1] = ws.curve_beta[j];
        ws.curve_error[j + 1] = ws.curve_error[j];
        ws.curve_sum_squares[j + 1] = ws.curve_sum_squares[j];
        --j;
      }
      ws.curve_beta[j + 1] = kb;
      ws.curve_error[j + 1] = ke;
      ws.curve_sum_squares[j + 1] = ks;
    }
    result.curve_count = curve;
  }
  return Status::ok;
}

}  // namespace

template <int Dim, typename Scalar>
std::size_t deformability_workspace_size(const MsmModel<Dim, Scalar>& model, int driven_capacity,
                                         const DeformabilityConfig& config) noexcept {
  Arena measure;
  DeformabilityWorkspace<Dim, Scalar> scratch;
  (void)deformability_workspace_init(measure, model, driven_capacity, config, scratch);
  return measure.required_bytes();
}

template <int Dim, typename Scalar>
Status deformability_workspace_init(Arena& arena, const MsmModel<Dim, Scalar>& model, int driven_capacity,
                                    const DeformabilityConfig& config,
                                    DeformabilityWorkspace<Dim, Scalar>& workspace) noexcept {
  using Vec = Eigen::Matrix<Scalar, Dim, 1>;
  workspace = DeformabilityWorkspace<Dim, Scalar>{};
  if (!model.initialized()) return Status::not_initialized;
  if (driven_capacity < 0 || config.grid_points < 3 || config.max_refinements < 0) return Status::invalid_argument;
  DeformabilityWorkspace<Dim, Scalar> ws;
  const Status state_status = msm_state_init(arena, model, ws.state);
  const auto driven = static_cast<std::size_t>(driven_capacity);
  ws.driven_capacity = driven_capacity;
  ws.target_ids = arena.carve<int>(driven);
  ws.targets = arena.carve<Vec>(driven);
  ws.held = arena.carve<Vec>(driven);
  ws.interval_start = arena.carve<Vec>(driven);
  ws.step_targets = arena.carve<Vec>(driven);
  ws.window_active = arena.carve<std::uint8_t>(driven);
  ws.previous = arena.carve<Vec>(static_cast<std::size_t>(model.particle_count));
  ws.residual_sum = arena.carve<Eigen::Matrix<double, Dim, 1>>(static_cast<std::size_t>(model.particle_count));
  ws.residual_samples = arena.carve<double>(static_cast<std::size_t>(model.particle_count));
  ws.curve_capacity = config.grid_points + config.max_refinements + 4;
  ws.curve_beta = arena.carve<double>(static_cast<std::size_t>(ws.curve_capacity));
  ws.curve_error = arena.carve<double>(static_cast<std::size_t>(ws.curve_capacity));
  ws.curve_sum_squares = arena.carve<double>(static_cast<std::size_t>(ws.curve_capacity));
  ws.grid_capacity = config.grid_points;
  ws.grid_error = arena.carve<double>(static_cast<std::size_t>(config.grid_points));
  if (arena.exhausted() || state_status != Status::ok) return Status::capacity_exceeded;
  workspace = ws;
  return Status::ok;
}

template <int Dim, typename Scalar>
Status evaluate_deformability_error(const MsmModel<Dim, Scalar>& model, const MsmParams<Dim, Scalar>& params,
                                    const ObservationSequence<Dim, Scalar>& observations,
                                    const DeformabilityConfig& config, DeformabilityWorkspace<Dim, Scalar>& workspace,
                                    TrajectoryError& error) noexcept {
  return evaluate_error(model, params, observations, config,
                        config.mode == FitMode::trajectory && all_observed(observations), workspace, error);
}

template <int Dim, typename Scalar>
Status estimate_deformability(const MsmModel<Dim, Scalar>& model, const MsmParams<Dim, Scalar>& base,
                              const ObservationSequence<Dim, Scalar>& observations, const DeformabilityConfig& config,
                              DeformabilityWorkspace<Dim, Scalar>& workspace, DeformabilityResult& result) noexcept {
  result = DeformabilityResult{};
  const Status valid = check_inputs(model, observations, config, workspace);
  if (valid != Status::ok) return valid;
  Progress progress;
  progress.config = &config;
  const bool probes = !local_curvature_possible<Scalar>(config);
  const bool observed_everywhere = config.mode == FitMode::trajectory && all_observed(observations);
  progress.planned = planned_search_evaluations(config, probes);
  if (!config.estimate_alpha || config.mode != FitMode::trajectory) {
    return search_beta(model, base, observations, config, observed_everywhere, workspace, true, true, progress, result);
  }
  // msm_alpha: coarse grid, then golden-section on the profile min_beta E(alpha, beta). The
  // profile's beta moves little between the alphas golden-section visits, so there each beta
  // search starts from the beta of the best alpha so far, on a grid of 3 over +-kWarmBeta; a
  // minimum on that grid's inner edge is searched again over all of [0, 1].
  constexpr double kWarmBeta = 0.1;
  DeformabilityConfig inner = config;
  inner.grid_points = std::min(config.grid_points, 6);
  inner.tolerance = std::max(config.tolerance, 5e-3);
  DeformabilityConfig warm = inner;
  warm.grid_points = 3;
  progress.planned = (5 + 14) * planned_search_evaluations(inner, false) + planned_search_evaluations(config, probes);
  MsmParams<Dim, Scalar> params = base;
  double best_profile = std::numeric_limits<double>::infinity();
  double best_profile_beta = std::numeric_limits<double>::quiet_NaN();
  double last_beta = 0.0;  // the beta of the last profile value
  auto profile = [&](double alpha) -> double {
    params.msm_alpha = static_cast<Scalar>(alpha);
    DeformabilityResult trial;
    Status s = Status::no_observations;
    bool searched = false;
    if (std::isfinite(best_profile_beta)) {
      const double lo = std::max(0.0, best_profile_beta - kWarmBeta);
      const double hi = std::min(1.0, best_profile_beta + kWarmBeta);
      s = search_beta(model, params, observations, warm, observed_everywhere, workspace, false, false, progress, trial,
                      lo, hi);
      const bool on_inner_edge =
          (lo > 0.0 && trial.msm_beta <= lo + warm.tolerance) || (hi < 1.0 && trial.msm_beta >= hi - warm.tolerance);
      searched = s == Status::ok && !on_inner_edge;
      result.evaluations += trial.evaluations;
    }
    if (!searched) {
      trial = DeformabilityResult{};
      s = search_beta(model, params, observations, inner, observed_everywhere, workspace, false, false, progress,
                      trial);
      result.evaluations += trial.evaluations;
    }
    if (s != Status::ok) return std::numeric_limits<double>::infinity();
    last_beta = trial.msm_beta;
    return trial.error;
  };
  // Golden-section's profile: warm-started from, and updating, the best alpha so far.
  auto refined_profile = [&](double alpha) -> double {
    const double value = profile(alpha);
    if (value < best_profile) {
      best_profile = value;
      best_profile_beta = last_beta;
    }
    return value;
  };
  constexpr int kAlphaGrid = 5;
  double grid_best_beta = std::numeric_limits<double>::quiet_NaN();
  double best_alpha = 1.0;
  double best_value = std::numeric_limits<double>::infinity();
  int best_index = kAlphaGrid - 1;
  const double span = 1.0 - config.alpha_min;
  for (int i = 0; i < kAlphaGrid; ++i) {
    const double alpha = config.alpha_min + span * i / (kAlphaGrid - 1);
    const double value = profile(alpha);  // over all of [0, 1]: the grid's alphas are far apart
    if (value < best_value) {
      best_value = value;
      best_alpha = alpha;
      best_index = i;
      grid_best_beta = last_beta;
    }
  }
  best_profile = best_value;
  best_profile_beta = grid_best_beta;
  double lo = config.alpha_min + span * std::max(0, best_index - 1) / (kAlphaGrid - 1);
  double hi = config.alpha_min + span * std::min(kAlphaGrid - 1, best_index + 1) / (kAlphaGrid - 1);
  const Minimum refined = golden_section_minimum(refined_profile, lo, hi, 5e-3, 14);
  if (refined.value < best_value) best_alpha = refined.x;
  params.msm_alpha = static_cast<Scalar>(best_alpha);
  // search_beta adds its evaluations to those of the profile already in result.evaluations.
  return search_beta(model, params, observations, config, observed_everywhere, workspace, true, true, progress, result);
}

#define PLIANT_INSTANTIATE_DEFORMABILITY(DIM, SCALAR)                                                       \
  template std::size_t deformability_workspace_size<DIM, SCALAR>(const MsmModel<DIM, SCALAR>&, int,         \
                                                                 const DeformabilityConfig&) noexcept;      \
  template Status deformability_workspace_init<DIM, SCALAR>(Arena&, const MsmModel<DIM, SCALAR>&, int,      \
                                                            const DeformabilityConfig&,                     \
                                                            DeformabilityWorkspace<DIM, SCALAR>&) noexcept; \
  template Status evaluate_deformability_error<DIM, SCALAR>(                                                \
      const MsmModel<DIM, SCALAR>&, const MsmParams<DIM, SCALAR>&, const ObservationSequence<DIM, SCALAR>&, \
      const DeformabilityConfig&, DeformabilityWorkspace<DIM, SCALAR>&, TrajectoryError&) noexcept;         \
  template Status estimate_deformability<DIM, SCALAR>(                                                      \
      const MsmModel<DIM, SCALAR>&, const MsmParams<DIM, SCALAR>&, const ObservationSequence<DIM, SCALAR>&, \
      const DeformabilityConfig&, DeformabilityWorkspace<DIM, SCALAR>&, DeformabilityResult&) noexcept;
PLIANT_INSTANTIATE_DEFORMABILITY(2, float)
PLIANT_INSTANTIATE_DEFORMABILITY(2, double)
PLIANT_INSTANTIATE_DEFORMABILITY(3, float)
PLIANT_INSTANTIATE_DEFORMABILITY(3, double)
#undef PLIANT_INSTANTIATE_DEFORMABILITY

}  // namespace pliant
