// Implicit dynamics and statics of a FemModel with fixed and driven nodes, and the reaction
// forces the constraints exert (what a load cell at those nodes measures).
//
// Units SI (m, s, N, kg); 3n vectors are node-major (x y z per node). See fem_model.hpp for the
// element model (corotational linear tetrahedra, lumped mass, Rayleigh damping).
//
// Equations of motion, per DOF:  M a + D v = f_int(x) + f_ext + M g,  D = alpha M + beta K(x),
// with K(x) = sum_e R_e K_e R_e^T. Constraints act on whole nodes: a fixed node stays at its rest
// position, a driven node is at the position the caller prescribes at the end of every step.
// The other ("free") nodes are the unknowns; constrained DOFs are eliminated from the linear
// systems, so the matrices stay symmetric positive definite.
//
// Integrators (one call of step() advances dt, optionally in equal substeps):
//  * backward_euler: M (v+ - v) = h (f_int(x+) + f_ext + M g - D v+), x+ = x + h v+. Stable and
//    dissipative: besides Rayleigh damping it damps a mode of angular frequency omega by a ratio
//    of about omega h / 2 (for omega h << 1). Use substeps, or newmark, when damping is estimated.
//  * newmark: average acceleration (beta = 1/4, gamma = 1/2), no numerical damping for linear
//    problems (energy of an undamped free vibration is conserved), period elongation
//    ~ (omega h)^2 / 12.
// Both solve, per Newton iteration, (c_M M + c_K K(x)) dx = -residual with the corotational
// tangent K (the rotation derivative is dropped). newton_iterations = 1 (default) is the usual
// linearly implicit stiffness-warping step: one assembly, one numeric factorization, one solve.
//
// Linear solver: a supernodal sparse Cholesky on 3x3 node blocks, private to the library. The
// symbolic analysis (AMD ordering on the node graph, elimination tree, supernodes) is done once
// in the constructor; each iteration only assembles into the factor and refactorizes. Under the
// model's averaged nodal pressure (FemModel::nodal_volumetric()) the node graph joins nodes two
// element rings apart: the factor holds about 2.3-2.4 times the entries and a step costs about
// 3.5-5 times as much (bench/fem_locking_bench).
//
// Reactions: after a step, r = M a+ + D(x+) v+ - f_int(x+) - f_ext - M g evaluated at the
// constrained nodes (zero elsewhere): the force the supports and the driving tool apply to the
// body, inertia of the constrained nodes' lumped masses included. After a static solve,
// r = -(f_int + f_ext + M g). Sum them over a node set with net_force().
//
// Ownership and threads: FemSolver keeps a reference to the model (which must outlive it) and
// reads its current Young's moduli, Poisson ratio, density, Rayleigh coefficients and gravity at
// every call, so estimators change parameters with the model's setters and step again without
// rebuilding the solver. A solver holds mutable workspaces: one solver per thread.
#pragma once

#include <memory>
#include <vector>

#include <Eigen/Core>

#include "pliant/host/fem/fem_model.hpp"

namespace pliant::host::fem {

/// Dynamic state of every node (3n vectors).
struct FemState {
  Eigen::VectorXd position_m;
  Eigen::VectorXd velocity_m_s;
  Eigen::VectorXd acceleration_m_s2;
  double time_s = 0;
  /// Whether acceleration_m_s2 satisfies the equations of motion at this state. Newmark needs
  /// it; step() computes it first when false (rest_state() leaves it false).
  bool acceleration_valid = false;
  /// Position change over the last substep step() took (3n, m) and that substep's length (s):
  /// what FemStepOptions::extrapolated_newton_start extrapolates. Empty after rest_state(); clear
  /// it when moving a state by hand (a stale value only gives a worse Newton start).
  Eigen::VectorXd last_increment_m;
  double last_substep_s = 0;
};

enum class FemIntegrator { backward_euler, newmark };

/// Velocity and acceleration given to driven nodes at the end of a Newmark step (backward Euler
/// always uses the secant). Only the prescribed positions are known; the velocities enter the
/// damping force on the neighbouring free nodes and the inertia part of the reactions.
enum class FemDrivenVelocity {
  /// v+ = (x+ - x) / dt, a+ = (v+ - v) / dt: no memory, so position noise in a recorded tool
  /// path stays local; the velocity lags the path by half a step.
  secant,
  /// The integrator's own update v+ = 2 (x+ - x) / dt - v: second-order for a smooth path that
  /// starts with the right velocity, but a mismatch or noise leaves an alternating velocity at
  /// those nodes that never decays.
  trapezoidal,
};

struct FemStepOptions {
  FemIntegrator integrator = FemIntegrator::backward_euler;
  int substeps = 1;           ///< >= 1; driven positions are interpolated linearly across them
  int newton_iterations = 1;  ///< >= 1 per substep; 1 = linearly implicit
  /// With newton_iterations > 1: stop early once the largest position correction is below this
  /// (m). 0: always run all iterations.
  double newton_tolerance_m = 0;
  FemDrivenVelocity driven_velocity = FemDrivenVelocity::secant;  ///< Newmark only
  /// Where Newton starts in each substep. false (default): at the previous positions, so with
  /// newton_iterations = 1 forces and tangent are taken at the start of the substep, and the
  /// rotation derivative the tangent drops leaves an error of first order in h in the end-of-step
  /// forces (in long free vibrations it shows as a small energy drift, i.e. a damping bias).
  /// true: at the secant prediction x + (h / h_last) state.last_increment_m (the previous
  /// substep's motion; none when the state has no increment), within O(h^2) of the solution for
  /// smooth motion, so one linearised iteration lands much closer to the converged step at no
  /// extra cost. Not x + h v + h^2 a / 2: Newmark keeps stiff modes alive (alternating sign from
  /// step to step) with velocities ~omega x and accelerations ~omega^2 x, so that prediction is
  /// off by ~(omega h)^2 times their amplitude and one iteration from there can go unstable; the
  /// secant is off by at most a few amplitudes. Linear problems give the same result either way.
  bool extrapolated_newton_start = false;
};

struct FemStepReport {
  int newton_iterations = 0;     ///< total over the substeps
  double last_correction_m = 0;  ///< largest |dx| of the last Newton iteration
};

struct FemStaticOptions {
  int max_iterations = 200;
  /// Converged when the largest position update of an iteration is below this (m);
  /// 0: 1e-10 times the diagonal of the rest bounding box.
  double displacement_tolerance_m = 0;
  /// Also converged when the largest residual force on a free DOF is below this (N); 0: off.
  double residual_tolerance_n = 0;
};

struct FemStaticResult {
  bool converged = false;
  int iterations = 0;
  double residual_n = 0;       ///< largest |f_int + f_ext + M g| over free DOFs at the end
  double last_update_m = 0;    ///< largest position update of the last iteration
  Eigen::VectorXd position_m;  ///< 3n equilibrium positions
  Eigen::VectorXd reaction_n;  ///< 3n, non-zero at constrained nodes only
};

class FemSolver {
 public:
  /// fixed_nodes and driven_nodes: node indices, each in range, no repeats, disjoint (either may
  /// be empty). driven positions passed to step()/solve_static() follow the order of
  /// driven_nodes. Throws std::invalid_argument. Performs the symbolic analysis: O(nnz(L)) memory
  /// for the factor, roughly a few tens of kB per 100 free nodes on bar-like meshes (more than
  /// twice that under the averaged nodal pressure).
  FemSolver(const FemModel& model, std::vector<int> fixed_nodes, std::vector<int> driven_nodes);
  ~FemSolver();
  FemSolver(FemSolver&&) noexcept;
  FemSolver& operator=(FemSolver&&) = delete;
  FemSolver(const FemSolver&) = delete;
  FemSolver& operator=(const FemSolver&) = delete;

  const FemModel& model() const { return *model_; }
  const std::vector<int>& fixed_nodes() const { return fixed_; }
  const std::vector<int>& driven_nodes() const { return driven_; }
  int free_node_count() const;
  bool is_constrained(int node) const;

  /// Rest positions, zero velocity and acceleration (acceleration_valid = false), time 0.
  FemState rest_state() const;

  /// Sets acceleration_m_s2 from the equations of motion at the state's positions and
  /// velocities: M a = f_int + f_ext + M g - D v at free nodes, 0 at constrained ones.
  /// nodal_force_n: 3n, or empty for none.
  void initialize_acceleration(FemState& state, const Eigen::Ref<const Eigen::VectorXd>& nodal_force_n);

  /// Advances `state` by dt_s (> 0). driven_position_m: 3 * driven_nodes().size() positions at the
  /// END of the step (substeps interpolate linearly from the state's current driven positions).
  /// nodal_force_n: external force per DOF (3n, N), held over the step, or empty for none. Fixed
  /// nodes are put at rest. Updates reaction_n(). Throws std::invalid_argument on bad sizes or
  /// non-finite input, std::runtime_error if the solve fails or produces non-finite positions.
  /// Cost per Newton iteration: one pass over the elements (forces, damping product, assembly),
  /// one numeric factorization, one solve; plus a pass over the elements touching constrained
  /// nodes for the reactions. Workspaces are allocated by the constructor.
  FemStepReport step(FemState& state, double dt_s, const Eigen::Ref<const Eigen::VectorXd>& driven_position_m,
                     const Eigen::Ref<const Eigen::VectorXd>& nodal_force_n, const FemStepOptions& options = {});

  /// Static equilibrium f_int(x) + f_ext + M g = 0 at the free nodes, with fixed nodes at rest and
  /// driven nodes at driven_position_m: Newton on the corotational energy with the tangent
  /// R K R^T and a backtracking (Armijo) line search. initial_position_m: 3n starting guess (free
  /// nodes) or empty for the rest shape. Updates reaction_n() too. Throws std::runtime_error if
  /// the stiffness is singular (e.g. the body is not held against rigid motion).
  FemStaticResult solve_static(const Eigen::Ref<const Eigen::VectorXd>& driven_position_m,
                               const Eigen::Ref<const Eigen::VectorXd>& nodal_force_n,
                               const FemStaticOptions& options = {},
                               const Eigen::Ref<const Eigen::VectorXd>& initial_position_m = Eigen::VectorXd());

  /// Constraint forces after the last step() or solve_static() (3n, N; zero at free nodes).
  const Eigen::VectorXd& reaction_n() const;

  // Forward sensitivities (estimate_dynamic.hpp's exact Jacobian). These reuse the solver's
  // factor and element pass; they do not change the state of a simulation in progress.

  /// Solves, in place on the free DOFs of `vector` (3n), the system factorized last: after a
  /// step() of one substep, ((1 + c_d alpha) M + (c_d beta + c_f) K) of that substep's Newton
  /// iteration (Newmark: c_d = h / 2, c_f = h^2 / 4); after solve_static(), K of its last Newton
  /// iteration. Constrained DOFs are set to 0. Throws std::logic_error before any factorization.
  /// Cost: one forward and one backward substitution.
  void solve_last_factorized(Eigen::Ref<Eigen::VectorXd> vector);

  /// out += scale * K(position_m) u: the corotational tangent (rotation derivative dropped, the
  /// model's volumetric formulation, current moduli) times u, at every node (3n vectors, every
  /// node's rows, constrained ones included). Cost: one pass over the elements.
  void add_tangent_product(const Eigen::Ref<const Eigen::VectorXd>& position_m,
                           const Eigen::Ref<const Eigen::VectorXd>& u, double scale, Eigen::Ref<Eigen::VectorXd> out);

  /// Several products at once, out[k] += scales[k] * K(position_m) u[k], and, when force_out is
  /// not null, force_out += force_scale * f_int(position_m): one pass over the elements (each
  /// rotation computed once) under the element formulation; one pass per product under the
  /// averaged nodal pressure. Sizes as above; u, scales and out of equal length. With
  /// `rotation_derivative` (element formulation only; ignored under the nodal pressure) K is the
  /// exact tangent -d f_int / d x, the polar factor's derivative included.
  void add_tangent_products(const Eigen::Ref<const Eigen::VectorXd>& position_m,
                            const std::vector<const Eigen::VectorXd*>& u, const std::vector<double>& scales,
                            const std::vector<Eigen::VectorXd*>& out, double force_scale, Eigen::VectorXd* force_out,
                            bool rotation_derivative = false);

  /// out += scale * f_int(position_m) (3n, N): the elastic forces on the nodes. One element pass.
  void add_internal_force(const Eigen::Ref<const Eigen::VectorXd>& position_m, double scale,
                          Eigen::Ref<Eigen::VectorXd> out);

  /// Entries of the Cholesky factor and its supernode count (for reports and benchmarks).
  std::size_t factor_entries() const;
  int supernode_count() const;

 private:
  struct Impl;
  const FemModel* model_;
  std::vector<int> fixed_;
  std::vector<int> driven_;
  std::unique_ptr<Impl> impl_;
};

/// Adds force_n / nodes.size() to each listed node of nodal_force_n (3n; resized to model size
/// n_nodes * 3 with zeros if empty). A force spread evenly, e.g. a measured wrench's force over
/// the nodes it was applied to. Throws std::invalid_argument on an empty set or bad index.
void add_spread_force(const Eigen::Vector3d& force_n, const std::vector<int>& nodes, int node_count,
                      Eigen::VectorXd& nodal_force_n);

/// Adds the smallest (least-squares) set of nodal forces on `nodes` whose resultant is force_n and
/// whose moment about the nodes' centroid (at position_m, 3n) is torque_nm: f_i = F / k + w x r_i
/// with r_i the offset from the centroid and J w = T, J = sum(|r_i|^2 I - r_i r_i^T). Throws
/// std::invalid_argument when a non-zero torque cannot be carried (fewer than 2 nodes, or
/// collinear nodes and a torque along their line).
void add_spread_wrench(const Eigen::Vector3d& force_n, const Eigen::Vector3d& torque_nm, const std::vector<int>& nodes,
                       const Eigen::Ref<const Eigen::VectorXd>& position_m, Eigen::VectorXd& nodal_force_n);

/// Sum of a 3n per-node vector over a node set (e.g. reactions over a clamped face: N).
Eigen::Vector3d net_force(const Eigen::Ref<const Eigen::VectorXd>& nodal_n, const std::vector<int>& nodes);

/// Moment about `point_m` of the per-node forces over a node set at positions position_m (N m).
Eigen::Vector3d net_torque(const Eigen::Ref<const Eigen::VectorXd>& nodal_n, const std::vector<int>& nodes,
                           const Eigen::Ref<const Eigen::VectorXd>& position_m, const Eigen::Vector3d& point_m);

}  // namespace pliant::host::fem
