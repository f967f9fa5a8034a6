#include "pliant/host/least_squares_fit.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>
#include <utility>

#include <ceres/ceres.h>

namespace pliant::host {
namespace {

// The optimiser's coordinates: log(value) for log-scale parameters, value otherwise.
struct Coordinates {
  const std::vector<FitParameter>* parameters;

  double to_internal(int j, double value) const {
    return (*parameters)[static_cast<size_t>(j)].log_scale ? std::log(value) : value;
  }
  double to_value(int j, double internal) const {
    return (*parameters)[static_cast<size_t>(j)].log_scale ? std::exp(internal) : internal;
  }
  double internal_lower(int j) const { return to_internal(j, (*parameters)[static_cast<size_t>(j)].lower); }
  double internal_upper(int j) const { return to_internal(j, (*parameters)[static_cast<size_t>(j)].upper); }
  double step(int j, double difference_step) const {
    const FitParameter& p = (*parameters)[static_cast<size_t>(j)];
    return p.log_scale ? difference_step : difference_step * (p.upper - p.lower);
  }
};

// Runs the user's model for internal coordinates; counts calls; treats non-finite residuals
// as a failed evaluation so one NaN never reaches the optimiser. Ceres asks for the same point
// more than once (a trial point, then its Jacobian once accepted; our own evaluations before and
// after the solve): the last few points asked for and the last Jacobian are remembered, so that a
// model run is never repeated.
class ModelEvaluator {
 public:
  ModelEvaluator(const Coordinates& coordinates, int residual_count, const ResidualFunction& f,
                 const JacobianFunction* exact = nullptr)
      : coordinates_(coordinates), residual_count_(residual_count), function_(f), exact_(exact) {}

  // Residuals at a point (remembered), the optimiser's trial points and the solution.
  bool evaluate(const double* internal, std::vector<double>& residuals) const {
    const std::vector<double> point(internal, internal + parameter_count());
    for (const Remembered& r : remembered_) {
      if (r.point != point) continue;
      residuals = r.residuals;
      return r.ok;
    }
    const bool ok = run(internal, residuals);
    if (remembered_.size() == kRemembered) remembered_.erase(remembered_.begin());
    remembered_.push_back({point, residuals, ok});
    return ok;
  }

  // Central differences in internal coordinates, one-sided at a bound (forward differences when
  // !central: the plus side only, the minus side where there is no plus). Row-major m x n.
  // Columns with `skip[j]` (held coordinates; may be empty) are left zero and cost nothing;
  // columns taken before at the same point are reused.
  bool jacobian(const double* internal, const std::vector<double>& at, double difference_step, bool central,
                double* out, const std::vector<bool>& skip = {}) const {
    const int n = parameter_count();
    const std::vector<double> center(internal, internal + n);
    if (exact_ != nullptr) return exact_jacobian(center, out, skip);
    for (int j = 0; j < n; ++j) {
      std::vector<double> column;
      const bool skipped = !skip.empty() && skip[static_cast<size_t>(j)];
      if (!skipped && !remembered_column(center, j, difference_step, central, column)) {
        if (!difference_column(internal, at, difference_step, central, j, column)) return false;
        if (columns_.size() == kRememberedColumns * static_cast<size_t>(n)) columns_.erase(columns_.begin());
        columns_.push_back({center, j, difference_step, central, column});
      }
      for (int i = 0; i < residual_count_; ++i) {
        out[static_cast<size_t>(i) * static_cast<size_t>(n) + static_cast<size_t>(j)] =
            skipped ? 0.0 : column[static_cast<size_t>(i)];
      }
    }
    return true;
  }

  int evaluations() const { return evaluations_; }

 private:
  // The solution's Jacobian can be a few back: Ceres may take the Jacobian of trial points it
  // then does not keep.
  static constexpr std::size_t kRemembered = 6;
  static constexpr std::size_t kRememberedColumns = 3;  // per parameter
  struct Remembered {
    std::vector<double> point;
    std::vector<double> residuals;
    bool ok = false;
  };
  struct RememberedColumn {
    std::vector<double> center;
    int j = 0;
    double step = 0.0;
    bool central = true;
    std::vector<double> values;
  };

  int parameter_count() const { return static_cast<int>(coordinates_.parameters->size()); }

  bool remembered_column(const std::vector<double>& center, int j, double step, bool central,
                         std::vector<double>& column) const {
    for (const RememberedColumn& c : columns_) {
      if (c.j != j || c.step != step || c.central != central || c.center != center) continue;
      column = c.values;
      return true;
    }
    return false;
  }

  // The caller's exact Jacobian at `center` (remembered), in internal coordinates.
  bool exact_jacobian(const std::vector<double>& center, double* out, const std::vector<bool>& skip) const {
    const int n = parameter_count();
    if (exact_center_ != center || !exact_ok_) {
      values_.resize(static_cast<size_t>(n));
      for (int j = 0; j < n; ++j)
        values_[static_cast<size_t>(j)] = coordinates_.to_value(j, center[static_cast<size_t>(j)]);
      std::vector<double> residuals(static_cast<size_t>(residual_count_), 0.0);
      ++evaluations_;
      exact_center_ = center;
      exact_ok_ = (*exact_)(values_, residuals, exact_matrix_) &&
                  residuals.size() == static_cast<size_t>(residual_count_) && exact_matrix_.rows() == residual_count_ &&
                  exact_matrix_.cols() == n && exact_matrix_.allFinite() &&
                  std::all_of(residuals.begin(), residuals.end(), [](double r) { return std::isfinite(r); });
      if (!exact_ok_) return false;
      for (int j = 0; j < n; ++j) {
        // d r / d internal: log-scale coordinates carry the chain factor d value / d log value.
        if ((*coordinates_.parameters)[static_cast<size_t>(j)].log_scale)
          exact_matrix_.col(j) *= values_[static_cast<size_t>(j)];
      }
      if (remembered_.size() == kRemembered) remembered_.erase(remembered_.begin());
      remembered_.push_back({center, residuals, true});
    }
    for (int i = 0; i < residual_count_; ++i) {
      for (int j = 0; j < n; ++j) {
        const bool skipped = !skip.empty() && skip[static_cast<size_t>(j)];
        out[static_cast<size_t>(i) * static_cast<size_t>(n) + static_cast<size_t>(j)] =
            skipped ? 0.0 : exact_matrix_(i, j);
      }
    }
    return true;
  }

  // Column j of the Jacobian by differences around `internal`, where the residuals are `at`.
  bool difference_column(const double* internal, const std::vector<double>& at, double difference_step, bool central,
                         int j, std::vector<double>& column) const {
    const int n = parameter_count();
    std::vector<double> shifted(internal, internal + n);
    std::vector<double> plus, minus;
    const double h = coordinates_.step(j, difference_step);
    const double hi = std::min(internal[j] + h, coordinates_.internal_upper(j));
    const double lo = std::max(internal[j] - h, coordinates_.internal_lower(j));
    shifted[static_cast<size_t>(j)] = hi;
    const bool has_plus = hi > internal[j] && run(shifted.data(), plus);
    shifted[static_cast<size_t>(j)] = lo;
    const bool has_minus = (central || !has_plus) && lo < internal[j] && run(shifted.data(), minus);
    if (!has_plus && !has_minus) return false;
    column.resize(static_cast<size_t>(residual_count_));
    for (size_t i = 0; i < column.size(); ++i) {
      if (has_plus && has_minus) {
        column[i] = (plus[i] - minus[i]) / (hi - lo);
      } else if (has_plus) {
        column[i] = (plus[i] - at[i]) / (hi - internal[j]);
      } else {
        column[i] = (at[i] - minus[i]) / (internal[j] - lo);
      }
    }
    return true;
  }

  // One call of the user's model.
  bool run(const double* internal, std::vector<double>& residuals) const {
    const int n = parameter_count();
    values_.resize(static_cast<size_t>(n));
    for (int j = 0; j < n; ++j) values_[static_cast<size_t>(j)] = coordinates_.to_value(j, internal[j]);
    residuals.assign(static_cast<size_t>(residual_count_), 0.0);
    ++evaluations_;
    if (!function_(values_, residuals)) return false;
    if (residuals.size() != static_cast<size_t>(residual_count_)) return false;
    return std::all_of(residuals.begin(), residuals.end(), [](double r) { return std::isfinite(r); });
  }

  const Coordinates& coordinates_;
  int residual_count_;
  const ResidualFunction& function_;
  const JacobianFunction* exact_;
  mutable std::vector<double> exact_center_;
  mutable Eigen::MatrixXd exact_matrix_;
  mutable bool exact_ok_ = false;
  mutable std::vector<double> values_;
  mutable int evaluations_ = 0;
  mutable std::vector<Remembered> remembered_;
  mutable std::vector<RememberedColumn> columns_;
};

// Weight d(rho)/d(s) at s = r^2 for the loss used in the pass (1 without a loss).
double robust_weight(RobustLoss loss, double scale, double r) {
  const double a = std::abs(r);
  switch (loss) {
    case RobustLoss::huber: return a <= scale ? 1.0 : scale / a;
    case RobustLoss::cauchy: return 1.0 / (1.0 + (r * r) / (scale * scale));
    case RobustLoss::none: break;
  }
  return 1.0;
}

// Robust losses act per residual. Ceres applies a LossFunction to a whole residual block, and the
// model is one block (one simulation yields every residual), so the loss is folded into the
// residuals instead: r~ = sign(r) sqrt(rho(r^2)) has sum r~^2 = sum rho(r^2), the robust cost.
double robust_rho(RobustLoss loss, double scale, double s) {
  const double a2 = scale * scale;
  switch (loss) {
    case RobustLoss::huber: return s <= a2 ? s : 2.0 * scale * std::sqrt(s) - a2;
    case RobustLoss::cauchy: return a2 * std::log1p(s / a2);
    case RobustLoss::none: break;
  }
  return s;
}

class ModelCost final : public ceres::CostFunction {
 public:
  ModelCost(const ModelEvaluator& model, int parameter_count, int residual_count, double difference_step, bool central)
      : model_(model), parameter_count_(parameter_count), difference_step_(difference_step), central_(central) {
    mutable_parameter_block_sizes()->push_back(parameter_count);
    set_num_residuals(residual_count);
  }

  void set_loss(RobustLoss loss, double scale) {
    loss_ = loss;
    scale_ = scale;
  }
  void set_held(const std::vector<bool>& held) { held_ = held; }

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    if (!model_.evaluate(parameters[0], at_)) return false;
    const bool want_jacobian = jacobians != nullptr && jacobians[0] != nullptr;
    if (want_jacobian && !model_.jacobian(parameters[0], at_, difference_step_, central_, jacobians[0], held_)) {
      return false;
    }
    const size_t n = static_cast<size_t>(parameter_count_);
    for (size_t i = 0; i < at_.size(); ++i) {
      const double r = at_[i];
      if (loss_ == RobustLoss::none) {
        residuals[i] = r;
        continue;
      }
      const double s = r * r;
      const double transformed = std::copysign(std::sqrt(robust_rho(loss_, scale_, s)), r);
      residuals[i] = transformed;
      if (want_jacobian) {
        const double chain = transformed != 0.0 ? robust_weight(loss_, scale_, r) * r / transformed : 1.0;
        for (size_t j = 0; j < n; ++j) jacobians[0][i * n + j] *= chain;
      }
    }
    return true;
  }

 private:
  const ModelEvaluator& model_;
  int parameter_count_;
  double difference_step_;
  bool central_;
  RobustLoss loss_ = RobustLoss::none;
  double scale_ = 1.0;
  std::vector<bool> held_;
  mutable std::vector<double> at_;
};

class ProgressCallback final : public ceres::IterationCallback {
 public:
  ProgressCallback(const std::function<void(int, int, double)>& f, int pass) : f_(f), pass_(pass) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& summary) override {
    if (f_) f_(pass_, summary.iteration, summary.cost);
    return ceres::SOLVER_CONTINUE;
  }

 private:
  const std::function<void(int, int, double)>& f_;
  int pass_;
};

double median_absolute(std::vector<double> v) {
  for (double& x : v) x = std::abs(x);
  const size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid), v.end());
  return v[mid];
}

double half_sum_of_squares(const std::vector<double>& r) {
  double s = 0.0;
  for (double x : r) s += x * x;
  return 0.5 * s;
}

void check_problem(const std::vector<FitParameter>& parameters, int residual_count) {
  if (parameters.empty()) throw std::invalid_argument("fit: no parameters to estimate");
  if (residual_count < 1) throw std::invalid_argument("fit: no residuals");
  for (const FitParameter& p : parameters) {
    if (!(std::isfinite(p.lower) && std::isfinite(p.upper) && std::isfinite(p.initial))) {
      throw std::invalid_argument("fit: parameter " + p.name + " has a non-finite bound or start");
    }
    if (!(p.lower < p.upper)) {
      throw std::invalid_argument("fit: parameter " + p.name + " needs a lower bound below its upper bound");
    }
    if (!(p.lower <= p.initial && p.initial <= p.upper)) {
      throw std::invalid_argument("fit: parameter " + p.name + " must start within its bounds");
    }
    if (p.log_scale && p.lower <= 0.0) {
      throw std::invalid_argument("fit: log-scale parameter " + p.name + " needs a positive lower bound");
    }
  }
}

struct PassOutcome {
  int iterations = 0;
  bool converged = false;
  bool reached_bound = false;  // stopped because a free coordinate reached a bound
  std::string message;
};

bool on_lower(const Coordinates& coords, const std::vector<double>& internal, int j) {
  return internal[static_cast<size_t>(j)] <= coords.internal_lower(j);
}
bool on_upper(const Coordinates& coords, const std::vector<double>& internal, int j) {
  return internal[static_cast<size_t>(j)] >= coords.internal_upper(j);
}

// Stops a pass when a free coordinate reaches a bound it was not on when the pass began, so that
// the active set can be revised (solve). Reads the parameters Ceres updates every iteration.
class BoundWatch final : public ceres::IterationCallback {
 public:
  BoundWatch(const std::vector<double>& internal, const Coordinates& coords, const std::vector<bool>& held)
      : internal_(internal), coords_(coords), held_(held) {
    for (int j = 0; j < static_cast<int>(internal.size()); ++j) {
      started_on_bound_.push_back(on_lower(coords, internal, j) || on_upper(coords, internal, j));
    }
  }
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& summary) override {
    if (summary.iteration == 0 || !summary.step_is_successful) return ceres::SOLVER_CONTINUE;
    for (int j = 0; j < static_cast<int>(internal_.size()); ++j) {
      const size_t jj = static_cast<size_t>(j);
      if (held_[jj] || started_on_bound_[jj]) continue;
      if (on_lower(coords_, internal_, j) || on_upper(coords_, internal_, j)) {
        reached = true;
        return ceres::SOLVER_TERMINATE_SUCCESSFULLY;
      }
    }
    return ceres::SOLVER_CONTINUE;
  }
  bool reached = false;

 private:
  const std::vector<double>& internal_;
  const Coordinates& coords_;
  const std::vector<bool>& held_;
  std::vector<bool> started_on_bound_;
};

// One Ceres solve with the `held` coordinates constant, at most `max_iterations` iterations.
PassOutcome run_pass(ModelCost& cost, std::vector<double>& internal, const Coordinates& coords, RobustLoss loss,
                     double loss_scale, const FitOptions& options, int pass, const std::vector<bool>& held,
                     int max_iterations) {
  ceres::Problem::Options problem_options;
  problem_options.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  cost.set_loss(loss, loss_scale);
  cost.set_held(held);
  problem.AddResidualBlock(&cost, nullptr, internal.data());
  const int n = static_cast<int>(internal.size());
  std::vector<int> constant;
  for (int j = 0; j < n; ++j) {
    problem.SetParameterLowerBound(internal.data(), j, coords.internal_lower(j));
    problem.SetParameterUpperBound(internal.data(), j, coords.internal_upper(j));
    if (held[static_cast<size_t>(j)]) constant.push_back(j);
  }
  if (!constant.empty()) problem.SetManifold(internal.data(), new ceres::SubsetManifold(n, constant));
  ceres::Solver::Options solver_options;
  solver_options.minimizer_type = ceres::TRUST_REGION;
  solver_options.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  solver_options.linear_solver_type = ceres::DENSE_QR;
  solver_options.max_num_iterations = max_iterations;
  solver_options.initial_trust_region_radius = 1.0 / options.initial_damping;
  // Ceres' projected line search on bounded problems (FitOptions::projected_line_search).
  solver_options.max_num_line_search_step_size_iterations = options.projected_line_search ? 20 : 0;
  solver_options.function_tolerance = options.function_tolerance;
  solver_options.parameter_tolerance = options.parameter_tolerance;
  solver_options.gradient_tolerance = 1e-14;
  solver_options.logging_type = ceres::SILENT;
  solver_options.minimizer_progress_to_stdout = false;
  solver_options.num_threads = 1;
  solver_options.update_state_every_iteration = true;
  ProgressCallback progress(options.on_iteration, pass);
  BoundWatch watch(internal, coords, held);
  solver_options.callbacks.push_back(&progress);
  solver_options.callbacks.push_back(&watch);
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &problem, &summary);
  cost.set_held({});
  PassOutcome outcome;
  outcome.iterations = static_cast<int>(summary.iterations.size());
  outcome.converged = summary.termination_type == ceres::CONVERGENCE;
  outcome.reached_bound = watch.reached;
  outcome.message = summary.BriefReport();
  return outcome;
}

// Coordinates on a bound whose gradient (of the plain sum of squares) points out of the box.
// Only their Jacobian columns are computed.
std::vector<bool> outward_at_bound(const ModelEvaluator& model, const Coordinates& coords,
                                   const std::vector<double>& internal, int residual_count, const FitOptions& options) {
  const int n = static_cast<int>(internal.size());
  std::vector<bool> skip(static_cast<size_t>(n), true);
  bool any = false;
  for (int j = 0; j < n; ++j) {
    const bool bound = on_lower(coords, internal, j) || on_upper(coords, internal, j);
    skip[static_cast<size_t>(j)] = !bound;
    any = any || bound;
  }
  std::vector<bool> held(static_cast<size_t>(n), false);
  std::vector<double> r;
  if (!any || !model.evaluate(internal.data(), r)) return held;
  std::vector<double> jacobian(static_cast<size_t>(residual_count) * static_cast<size_t>(n));
  if (!model.jacobian(internal.data(), r, options.difference_step, options.central_differences, jacobian.data(),
                      skip)) {
    return held;
  }
  for (int j = 0; j < n; ++j) {
    if (skip[static_cast<size_t>(j)]) continue;
    double gradient = 0.0;
    for (int i = 0; i < residual_count; ++i) {
      gradient += jacobian[static_cast<size_t>(i) * static_cast<size_t>(n) + static_cast<size_t>(j)] *
                  r[static_cast<size_t>(i)];
    }
    held[static_cast<size_t>(j)] =
        (on_lower(coords, internal, j) && gradient > 0.0) || (on_upper(coords, internal, j) && gradient < 0.0);
  }
  return held;
}

// Bounded Levenberg-Marquardt with an active set: a coordinate on a bound whose gradient points
// outwards is held there (Ceres' own projection would propose steps through the bound, see them
// fail and shrink the trust region, many iterations for nothing). The set is revised when a
// pass ends or a free coordinate reaches a bound; at most options.max_iterations in all.
PassOutcome solve(ModelCost& cost, const ModelEvaluator& model, std::vector<double>& internal,
                  const Coordinates& coords, int residual_count, RobustLoss loss, double loss_scale,
                  const FitOptions& options, int pass) {
  constexpr int kMaxRounds = 6;
  PassOutcome total;
  int remaining = options.max_iterations;
  std::vector<bool> held = outward_at_bound(model, coords, internal, residual_count, options);
  for (int round = 0; round < kMaxRounds && remaining > 0; ++round) {
    if (std::all_of(held.begin(), held.end(), [](bool h) { return h; })) {
      total.converged = true;
      total.message = "every parameter is held at a bound by its gradient";
      break;
    }
    const PassOutcome outcome = run_pass(cost, internal, coords, loss, loss_scale, options, pass, held, remaining);
    total.iterations += outcome.iterations;
    remaining -= std::max(outcome.iterations - 1, 1);
    total.converged = outcome.converged || outcome.reached_bound;
    total.message = outcome.message;
    const std::vector<bool> next = outward_at_bound(model, coords, internal, residual_count, options);
    if (!outcome.reached_bound && next == held) break;
    held = next;
  }
  return total;
}

}  // namespace

FitResult fit_least_squares(const std::vector<FitParameter>& parameters, int residual_count,
                            const ResidualFunction& residuals, const FitOptions& options) {
  return fit_least_squares(parameters, residual_count, residuals, JacobianFunction(), options);
}

FitResult fit_least_squares(const std::vector<FitParameter>& parameters, int residual_count,
                            const ResidualFunction& residuals, const JacobianFunction& exact_jacobian,
                            const FitOptions& options) {
  check_problem(parameters, residual_count);
  if (!(options.initial_damping > 0.0 && std::isfinite(options.initial_damping))) {
    throw std::invalid_argument("fit: initial_damping must be positive and finite");
  }
  const int n = static_cast<int>(parameters.size());
  const Coordinates coords{&parameters};
  ModelEvaluator model(coords, residual_count, residuals, exact_jacobian ? &exact_jacobian : nullptr);
  ModelCost cost(model, n, residual_count, options.difference_step, options.central_differences);

  std::vector<double> internal(static_cast<size_t>(n));
  for (int j = 0; j < n; ++j) {
    internal[static_cast<size_t>(j)] = coords.to_internal(j, parameters[static_cast<size_t>(j)].initial);
  }
  std::vector<double> r;
  if (!model.evaluate(internal.data(), r)) {
    throw std::invalid_argument("fit: the model cannot be evaluated at the initial values");
  }

  FitResult result;
  result.initial_cost = half_sum_of_squares(r);

  RobustLoss loss = options.loss;
  double scale = options.loss_scale;
  PassOutcome outcome;
  int pass = 0;
  if (loss != RobustLoss::none && scale <= 0.0) {
    // Automatic scale: least squares first, then robust passes, each with the scale taken
    // from the previous solution's residual scatter (MAD), until the scale settles.
    outcome = solve(cost, model, internal, coords, residual_count, RobustLoss::none, 0.0, options, pass++);
    result.iterations += outcome.iterations;
    for (int refinement = 0; refinement < 4; ++refinement) {
      if (!model.evaluate(internal.data(), r)) {
        throw std::runtime_error("fit: the model failed at an intermediate solution");
      }
      const double next_scale = 2.5 * 1.4826 * median_absolute(r);
      if (!(next_scale > 0.0)) break;  // an exact fit: nothing to be robust about
      if (scale > 0.0 && std::abs(next_scale - scale) <= 0.05 * scale) break;
      scale = next_scale;
      outcome = solve(cost, model, internal, coords, residual_count, loss, scale, options, pass++);
      result.iterations += outcome.iterations;
    }
    if (!(scale > 0.0)) loss = RobustLoss::none;
  } else {
    outcome = solve(cost, model, internal, coords, residual_count, loss, scale, options, pass++);
    result.iterations += outcome.iterations;
  }
  result.converged = outcome.converged;
  result.message = outcome.message;

  if (!model.evaluate(internal.data(), r)) {
    throw std::runtime_error("fit: the model failed at the solution");
  }
  result.final_cost = half_sum_of_squares(r);

  // Gauss-Newton covariance in internal coordinates, robust weights applied.
  const int m = residual_count;
  Eigen::MatrixXd jacobian(m, n);
  std::vector<double> row_major(static_cast<size_t>(m) * static_cast<size_t>(n));
  const bool have_jacobian = options.uncertainty && model.jacobian(internal.data(), r, options.difference_step,
                                                                   options.central_differences, row_major.data());
  for (int i = 0; i < m; ++i) {
    for (int j = 0; j < n; ++j) jacobian(i, j) = row_major[static_cast<size_t>(i * n + j)];
  }
  Eigen::VectorXd weights(m);
  double weighted_sum = 0.0;
  for (int i = 0; i < m; ++i) {
    const double ri = r[static_cast<size_t>(i)];
    weights(i) = robust_weight(loss, scale, ri);
    weighted_sum += weights(i) * ri * ri;
  }
  const int dof = std::max(1, m - n);
  result.residual_sigma = std::sqrt(weighted_sum / dof);

  result.names.reserve(static_cast<size_t>(n));
  for (const FitParameter& p : parameters) result.names.push_back(p.name);
  result.values.resize(static_cast<size_t>(n));
  result.at_bound.resize(static_cast<size_t>(n));
  for (int j = 0; j < n; ++j) {
    const FitParameter& p = parameters[static_cast<size_t>(j)];
    const double v = coords.to_value(j, internal[static_cast<size_t>(j)]);
    result.values[static_cast<size_t>(j)] = v;
    const double tol = 1e-6 * std::max(std::abs(p.upper - p.lower), 1e-300);
    result.at_bound[static_cast<size_t>(j)] = v - p.lower <= tol || p.upper - v <= tol;
  }

  const double nan = std::numeric_limits<double>::quiet_NaN();
  result.covariance = Eigen::MatrixXd::Constant(n, n, nan);
  result.standard_deviations.assign(static_cast<size_t>(n), nan);
  result.evaluations = model.evaluations();
  if (!have_jacobian) return result;
  const Eigen::MatrixXd information = jacobian.transpose() * weights.asDiagonal() * jacobian;
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(information);
  const Eigen::VectorXd lambda = eigen.eigenvalues();
  const double largest = lambda.cwiseAbs().maxCoeff();
  Eigen::VectorXd inverse_lambda = Eigen::VectorXd::Zero(n);
  std::vector<bool> undetermined(static_cast<size_t>(n), false);
  for (int k = 0; k < n; ++k) {
    if (lambda(k) > 1e-12 * largest && largest > 0.0) {
      inverse_lambda(k) = 1.0 / lambda(k);
    } else {
      for (int j = 0; j < n; ++j) {
        if (std::abs(eigen.eigenvectors()(j, k)) > 1e-6) undetermined[static_cast<size_t>(j)] = true;
      }
    }
  }
  const Eigen::MatrixXd internal_covariance = result.residual_sigma * result.residual_sigma * eigen.eigenvectors() *
                                              inverse_lambda.asDiagonal() * eigen.eigenvectors().transpose();
  Eigen::VectorXd chain(n);  // d value / d internal
  for (int j = 0; j < n; ++j) {
    chain(j) = parameters[static_cast<size_t>(j)].log_scale ? result.values[static_cast<size_t>(j)] : 1.0;
  }
  result.covariance = chain.asDiagonal() * internal_covariance * chain.asDiagonal();
  for (int j = 0; j < n; ++j) {
    if (undetermined[static_cast<size_t>(j)]) {
      result.covariance.row(j).setConstant(nan);
      result.covariance.col(j).setConstant(nan);
    } else {
      result.standard_deviations[static_cast<size_t>(j)] = std::sqrt(result.covariance(j, j));
    }
  }
  return result;
}

}  // namespace pliant::host
