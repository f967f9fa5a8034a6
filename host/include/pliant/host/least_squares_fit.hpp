// Bounded, robust nonlinear least squares (Ceres Levenberg-Marquardt) with parameter
// uncertainty: the one least-squares path of the host. The FEM estimators (Young's modulus,
// Rayleigh damping, rest shape, material maps) and diagnosis (the MSM and FEM baselines and every
// effect's fit) describe their parameters and hand over a residual function that runs the model;
// this file owns everything about the optimisation itself.
//
// Bounds: an active set. A coordinate on a bound whose gradient points out of the box is held
// there (a Ceres SubsetManifold) and the others are solved; the set is revised when a solve ends
// or a free coordinate reaches a bound. Every residual evaluation may be a long simulation: a
// point asked for again, and a Jacobian column already taken at a point, are reused, never
// recomputed (FitResult::evaluations counts the model runs made).
//
// Host code: allocates, may throw std::invalid_argument on a malformed problem. Not real-time.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <Eigen/Dense>

namespace pliant::host {

/// One scalar unknown. `lower < upper` and `lower <= initial <= upper` (a start on a bound is
/// allowed: its difference step then goes inwards).
/// With `log_scale` the optimiser works on log(value): steps are relative, the value stays
/// positive (lower must be > 0), and a start 10x off costs as many iterations as one 10x low.
/// Use it for moduli and damping coefficients; use a linear scale for signed quantities.
struct FitParameter {
  std::string name;  ///< reported name, a parameter name from the recording spec where one fits
  double initial = 1.0;
  double lower = 0.0;
  double upper = 1.0;
  bool log_scale = true;
};

/// Residual function: given the parameter values (same order as the FitParameter list), fill
/// `residuals` (already sized to the problem's residual count). Residuals should be whitened by
/// the caller (divided by their measurement noise) so that the robust loss scale and the
/// reported uncertainty mean what they say; unwhitened residuals still fit, and the uncertainty
/// then uses the residual scatter instead (see FitResult::residual_sigma). Return false when the
/// model cannot be evaluated at these values (solver failure, inverted elements): the optimiser
/// treats that step as rejected and shrinks its trust region.
using ResidualFunction = std::function<bool(const std::vector<double>& values, std::vector<double>& residuals)>;

/// Residuals and their exact derivatives at once (for models that propagate sensitivities, e.g.
/// the FEM trajectory fit): fill `residuals` as a ResidualFunction does and `jacobian` (resized
/// by the function to residual count x parameter count) with d residual_i / d value_j, with
/// respect to each parameter's value (not its log). Return false when the model cannot be
/// evaluated there.
using JacobianFunction =
    std::function<bool(const std::vector<double>& values, std::vector<double>& residuals, Eigen::MatrixXd& jacobian)>;

enum class RobustLoss {
  none,    ///< plain least squares
  huber,   ///< quadratic within loss_scale, linear beyond (default: mild outliers)
  cauchy,  ///< log growth beyond loss_scale (heavy outliers, e.g. tracking glitches)
};

struct FitOptions {
  RobustLoss loss = RobustLoss::huber;
  /// Residual magnitude where the robust loss bends, in residual units. 0 means automatic: a
  /// first pass without the loss, then robust passes (at most four) with the bend at 2.5 x the
  /// robust (MAD) residual scatter of the previous solution, until that scale changes < 5 %.
  double loss_scale = 0.0;
  int max_iterations = 60;            ///< per pass
  double function_tolerance = 1e-10;  ///< relative cost decrease that ends a pass
  double parameter_tolerance = 1e-9;  ///< relative step that ends a pass
  /// Central-difference step for the Jacobian: in log space for log-scale parameters (a
  /// relative step), as a fraction of (upper - lower) for linear ones. Residual functions that
  /// solve iteratively must converge well below this step's effect.
  double difference_step = 1e-4;
  /// Central differences (true, default: 2n + 1 evaluations per Jacobian, error O(step^2)) or
  /// forward differences (false: n + 1, error O(step); backward at an upper bound). Forward
  /// halves the cost of each Jacobian for models where one evaluation is a long simulation; the
  /// O(step) error only perturbs the step direction and the covariance, not where the fit ends.
  bool central_differences = true;
  /// Damping of the first Levenberg-Marquardt step, relative to the diagonal of J^T J (Ceres:
  /// the inverse of the initial trust-region radius). Small: a Gauss-Newton first step; larger:
  /// a shorter, gradient-like first step for models whose response is far from linear.
  double initial_damping = 1e-4;
  /// Ceres' projected line search after every trust-region step of a bounded problem (its
  /// default). It rescues fits whose steps run into the bounds far from the solution (the FEM
  /// trajectory fit from a start off in every parameter needs it), at a price: its cubic
  /// interpolation asks for gradients, a whole finite-difference Jacobian per trial point. Off,
  /// a step is projected onto the bounds and the trust region does the rest; diagnosis, which
  /// starts every fit from a grid point near its solution, turns it off. Either way, a
  /// coordinate on a bound whose gradient points outwards is held there (an active set).
  bool projected_line_search = true;
  /// Compute the covariance and standard deviations at the solution (one more Jacobian unless
  /// the last one was taken there). Off for fits whose caller derives its own uncertainty: the
  /// FitResult's covariance and standard_deviations are then NaN.
  bool uncertainty = true;
  /// Called after every iteration with (pass, iteration, cost); may be empty.
  std::function<void(int, int, double)> on_iteration;
};

struct FitResult {
  std::vector<std::string> names;
  std::vector<double> values;
  /// One standard deviation per parameter from the Gauss-Newton covariance at the solution
  /// (robust weights applied), scaled by residual_sigma^2; NaN when the Jacobian is rank
  /// deficient in that direction (the data do not determine the parameter).
  std::vector<double> standard_deviations;
  Eigen::MatrixXd covariance;  ///< in parameter units (log-scale parameters mapped back)
  double initial_cost = 0.0;   ///< 0.5 * sum r^2 at the initial values
  double final_cost = 0.0;     ///< 0.5 * sum r^2 at the solution (no robust loss)
  /// sqrt(sum w r^2 / (m - n)): the scatter of the residuals about the fit, in residual units;
  /// near 1 when residuals were whitened correctly and the model fits.
  double residual_sigma = 0.0;
  int iterations = 0;          ///< over all passes
  int evaluations = 0;         ///< residual function calls, including Jacobian differences
                               ///< (a point asked for again is answered from memory, not counted)
  bool converged = false;      ///< a tolerance was met (not the iteration limit)
  std::vector<bool> at_bound;  ///< per parameter: ended within 1e-6 (relative) of a bound
  std::string message;         ///< the optimiser's own summary line
};

/// Minimises the (robustified) sum of squared residuals over the bounded parameters.
/// Throws std::invalid_argument when a parameter's bounds or initial value are inconsistent,
/// residual_count < 1, or the residual function fails at the initial values.
FitResult fit_least_squares(const std::vector<FitParameter>& parameters, int residual_count,
                            const ResidualFunction& residuals, const FitOptions& options = {});

/// The same fit with the Jacobian from `jacobian` instead of finite differences (each Jacobian is
/// one call; trial points still use `residuals`, which may be cheaper). difference_step and
/// central_differences are then unused. FitResult::evaluations counts both kinds of call.
FitResult fit_least_squares(const std::vector<FitParameter>& parameters, int residual_count,
                            const ResidualFunction& residuals, const JacobianFunction& jacobian,
                            const FitOptions& options = {});

/// The names this file had when only the FEM estimators used it (pliant::host::fem::...);
/// kept so that code written against them still builds.
namespace fem {
using pliant::host::fit_least_squares;
using pliant::host::FitOptions;
using pliant::host::FitParameter;
using pliant::host::FitResult;
using pliant::host::JacobianFunction;
using pliant::host::ResidualFunction;
using pliant::host::RobustLoss;
}  // namespace fem

}  // namespace pliant::host
