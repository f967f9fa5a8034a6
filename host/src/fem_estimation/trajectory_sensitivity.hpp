// Forward sensitivities of a simulated trajectory (estimate_dynamic.hpp) with respect to
// log(youngs_modulus) (one modulus for every element), log(rayleigh_alpha) and
// log(rayleigh_beta): d x / d log(theta) carried along the Newmark substeps, so that one
// simulation gives the trajectory fit its whole Jacobian.
//
// Per substep of length h, Newmark (c_d = h / 2, c_dv = c_a = c_f = h^2 / 4) solves
//   R = M (x+ - x - h v - c_a a + alpha w - c_f g) + beta K w - c_f (f_int(x+) + f_ext) = 0,
//   w = c_d (x+ - x) - c_dv v,
// and differentiating it at fixed x+ gives, for each parameter j with state sensitivities
// (S, S_v, S_a) at the start of the substep,
//   A S+ = M ((1 + alpha c_d) S + (h + alpha c_dv) S_v + c_a S_a) + beta K (c_d S + c_dv S_v)
//          - dR/d log(theta_j),
//   dR/d log E = beta K w - c_f f_int(x+)   (every elastic term is proportional to E),
//   dR/d log alpha = alpha M w,  dR/d log beta = beta K w,
// with A = (1 + c_d alpha) M + (c_d beta + c_f) K the step's derivative; then
// S_v+ = 2 (S+ - S) / h - S_v and S_a+ = 4 (S+ - S - h S_v) / h^2 - S_a. Constrained nodes have
// zero sensitivity (their positions are prescribed). The solve uses the matrix the step has just
// factorized, whose K = R K_e R^T drops the polar factor's derivative (about 1 % of K on the
// Table 1 bar, and so 1 % in the Jacobian, enough to move the fitted damping by 0.1 %); one
// defect correction with the exact elastic tangent at x+ (element formulation) takes that to its
// square. What is left is the derivative of the damping matrix K(x) along x and the difference
// between the one-iteration step and the converged one: on the reduced Table 1 bar the Jacobian
// is within 0.1 % (E), 0.13 % (alpha) and 0.3 % (beta) of central differences of the simulation
// (fem_estimate_dynamic_test).
//
// Frame 0: free nodes observed there are data (zero sensitivity); unobserved ones come from a
// static fill f_int(x) + f_ext + M g = 0, whose sensitivity to log E is K^-1 f_int(x) (from the
// fill's last factor). The initial acceleration M a = f_int + f_ext + M g (at rest) gives
// M S_a = f_int - K S for log E. A wrench applied as a load, initial velocities from the data,
// backward Euler and material maps are not covered (the estimator uses finite differences).
//
// Cost per substep: three element passes (the stiffness products of every parameter and the
// internal force; the correction's exact and damping products; one pass per product under the
// averaged nodal pressure) and two back substitutions per parameter. Not thread-safe: one per simulator.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "pliant/host/fem/fem_model.hpp"
#include "pliant/host/fem/fem_solver.hpp"

namespace pliant::host::fem::detail {

enum class SensitivityParameter { log_youngs_modulus, log_rayleigh_alpha, log_rayleigh_beta };

class TrajectorySensitivity {
 public:
  explicit TrajectorySensitivity(std::vector<SensitivityParameter> parameters);

  int parameter_count() const { return static_cast<int>(parameters_.size()); }

  /// Frame 0 at rest: `fill` is the solver that just filled the unobserved free nodes of
  /// `position_m` by a static solve (nullptr when every free node was observed); `dynamic` is the
  /// simulation's solver (its model at the current parameters).
  void start(FemSolver* fill, FemSolver& dynamic, const Eigen::VectorXd& position_m);

  /// After dynamic.step() advanced one substep of length h (Newmark) from start_m with velocity
  /// velocity_before_m_s to end_m; driven_nodes got the secant velocity.
  void substep(FemSolver& dynamic, const Eigen::VectorXd& start_m, const Eigen::VectorXd& velocity_before_m_s,
               const Eigen::VectorXd& end_m, double h);

  /// d position / d log(theta_j) (3n, m) at the current state.
  const Eigen::VectorXd& position(int j) const { return position_[static_cast<std::size_t>(j)]; }

 private:
  void correct(FemSolver& dynamic, const Eigen::VectorXd& end_m, double h);

  std::vector<SensitivityParameter> parameters_;
  std::vector<Eigen::VectorXd> position_, velocity_, acceleration_;
  std::vector<Eigen::VectorXd> rhs_, product_, next_;
  Eigen::VectorXd w_, kw_, force_, change_;
};

}  // namespace pliant::host::fem::detail
