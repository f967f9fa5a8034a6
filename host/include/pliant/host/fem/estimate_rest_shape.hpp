// Rest-shape (reference-shape) estimation: from one observed static shape of a body held by fixed
// supports and loaded by gravity, find the rest shape X that the corotational model of
// fem_model.hpp would sag into exactly that shape.
//
// Why it matters: a soft object is never seen unloaded. Meshing the observed, sagging shape and
// using it as the rest shape makes every later simulation sag a second time, and a material fit
// then blames the extra sag on E. Wang et al. ("Deformation capture and modeling of soft objects",
// reference-shape optimization) solve the same equation; their Table 2 reports mean |dX| and mean
// |dx_s| against the ANM solver of Chen et al.
//
// Problem. Unknown: the rest positions X_i of the free nodes (3 per node). Given: the observed
// static positions x_s of every node, the material (E per element, Poisson ratio, density),
// gravity g and optional dead loads f_ext. Equations, one per free DOF:
//     r(X) = f_int(x_s; X) + M(X) g + f_ext = 0,
// where f_int(x; X) is FemModel's internal_force with rest shape X and M(X) is the lumped mass
// of density x REST volume (what the forward model uses, so the forward check below closes
// exactly; the mass changes with X and is iterated with it, see below). Fixed nodes are held
// where they are observed: X_i = x_s_i. This is the only choice consistent with the forward
// model, which keeps fixed nodes at their rest positions.
//
// Averaged nodal pressure (FemVolumetric::nodal_average). The residual is the model's own. The
// Jacobian's element blocks then carry the deviatoric stress and each element's pressure held
// fixed, and the change of the nodal pressures with X is added node by node (it couples nodes
// two element rings apart, which element blocks cannot). The change of the pressure's lever
// arms between elements is left out, so Newton converges a little slower, to the same answer.
//
// Method (RestShapeMethod::newton, the default). Newton's method on r(X) = 0 over the free DOFs,
// starting from X = x_s. The Jacobian dr/dX is assembled from 12x12 element blocks, each the
// central-difference derivative of the element's corner forces AND its share of the gravity load
// with respect to its four rest corners; it therefore contains the change of the rotations, of
// the element stiffness (rest geometry) and of the masses with X, and Newton converges
// quadratically (4-5 iterations for sag of 7-35 % of a bar's length in the tests). The matrix is
// not symmetric (d(R K_e (R^T x - X_e))/dX is about R K_e, not R K_e R^T), so each iteration is
// one sparse LU factorization (Eigen::SparseLU, COLAMD ordering computed once).
//  * Damping: natural monotonicity (Deuflhard). The Newton correction recomputed at the trial
//    point with the same factorization must shrink, i.e. the residual is measured in metres. |r|
//    in newtons is a poor merit function here: a good step that linearly "unbends" a sagging bar
//    stretches its nearly unloaded tip elements, and |r| rises 50-fold on the way to quadratic
//    convergence (a line search on |r| stalls). A step that would invert a rest element is halved.
//  * Load continuation, only when needed: the load is first applied in full; if the damping has
//    to go below 1/16 or 12 iterations do not converge, r_lambda = f_int + lambda (M g + f_ext)
//    is solved for a rising load factor lambda (increment quartered on failure, doubled on
//    success), each stage starting from the last. Needed when the body rotates by tens of
//    degrees (a bar sagging half its length), where the first, linear step lands outside
//    Newton's basin. This is the same idea as the ANM path following of Chen et al.
// The first Newton step from X = x_s is the linear answer X = x_s - K(x_s)^-1 (M g + f_ext).
//
// RestShapeMethod::fixed_point: the inverse-sag iteration X <- X + (x_s - x_static(X)), where
// x_static(X) is FemSolver::solve_static from rest X (warm-started at x_s). One forward static
// solve per iteration and no Jacobian, but only linear convergence, slower the more the body
// rotates (the correction is a world-frame displacement, not rotated into the rest frame): about
// 14 iterations for a bar sagging 9 % of its length, hundreds for one sagging half its length.
// An independent check of the Newton answer.
//
// Why not least_squares_fit (Ceres LM): this is a square system with an exact zero-residual
// solution and 3n unknowns. Newton with the sparse Jacobian needs one LU per iteration; LM would
// square the condition number of an already stiffness-conditioned system (J^T J), and a generic
// cost function would not exploit the per-element structure.
//
// Convergence (at full load): |r|_inf <= force_tolerance_n over free DOFs, or the full Newton
// (or inverse-sag) update |dX|_inf <= position_tolerance_m (near the solution the remaining
// error of X is about the size of the update; in the stiff limit the force tolerance is below
// rounding and this is the criterion that ends the iteration).
//
// Forward check: after the iteration, FemSolver::solve_static from the estimated rest shape
// (starting AT X, not at x_s, as a user's simulation would) must land on x_s; the largest node
// distance is reported. A large value with a small residual means x_s is an unstable or
// non-unique equilibrium of the estimated rest shape (e.g. a buckled column).
//
// Noise: the equations are satisfied for any x_s, so noise in x_s goes into X about one to one
// (X ~ x_s - sag); the forward check then reproduces the noisy x_s. Smooth x_s first if needed.
//
// Units SI (m, N, kg, Pa). 3n vectors are node-major (x y z per node), world frame, the frame of
// the mesh and of gravity. Host code: allocates, throws, not real-time, single-threaded.
// Cost: per Newton iteration 24 element evaluations per element for the Jacobian and one sparse
// LU of the free DOFs; per estimate one forward static solve for the check. Measured (Release, one
// core): 99 nodes, 240 elements: ~10 ms per estimate; 3,321 nodes, 15,360 elements: Jacobian
// 0.4 s, LU 1.7 s with 5.8 million factor entries (~70 MB), 4 iterations, ~10 s in total. The
// LU fill grows faster than the node count: budget memory for meshes beyond ~10^4 nodes.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "pliant/host/fem/fem_model.hpp"
#include "pliant/host/fem/fem_recording.hpp"
#include "pliant/host/fem/fem_solver.hpp"

namespace pliant::host::fem {

enum class RestShapeMethod {
  newton,       ///< Newton, element-differenced Jacobian, natural-monotonicity damping, load steps
  fixed_point,  ///< inverse sag: X <- X + (x_s - x_static(X)), one forward static solve each
};

struct RestShapeOptions {
  RestShapeMethod method = RestShapeMethod::newton;
  int max_iterations = 100;  ///< >= 1: Newton (over all load steps) or inverse-sag iterations
  /// Converged when the largest residual force on a free DOF is at most this (N).
  /// 0: 1e-9 times the largest nodal load |m_i g + f_ext_i| at X = x_s.
  double force_tolerance_n = 0;
  /// Converged when the largest component of a full update of X is at most this (m).
  /// 0: 1e-10 times the diagonal of the bounding box of x_s.
  double position_tolerance_m = 0;
  /// Dead loads on the nodes (3n, N), held constant; empty for none. Loads on fixed nodes are
  /// carried by the supports and have no effect.
  Eigen::VectorXd external_force_n;
  /// Run the forward check (one static solve from the estimated rest shape).
  bool forward_check = true;
  /// Options of the forward static solves (forward check and inverse-sag steps).
  FemStaticOptions static_options;
};

struct RestShapeResult {
  bool converged = false;
  int iterations = 0;             ///< Newton iterations (all load steps) or inverse-sag iterations
  int load_steps = 0;             ///< Newton: load steps converged (1: full load at once)
  double initial_residual_n = 0;  ///< largest |r| over free DOFs at X = x_s (the load to carry)
  double residual_n = 0;          ///< largest |r| over free DOFs at the returned X
  double last_update_m = 0;       ///< largest component of the last full update of X
  /// Rest positions (3n, m); fixed nodes equal x_s. Valid when converged; otherwise the last
  /// iterate (for a stalled load continuation: the rest shape for the last load factor reached).
  Eigen::VectorXd rest_position_m;
  double max_sag_m = 0;      ///< largest node distance |x_s_i - X_i|
  double mean_sag_m = 0;     ///< mean node distance |x_s_i - X_i| over all nodes
  double total_mass_kg = 0;  ///< density x rest volume of X
  /// Forward check (NaN when not run: disabled, failed, or no load): largest and mean node
  /// distance between x_s and the static solution from rest X, and whether that solve converged.
  /// A failed forward solve is named in `message`, never thrown.
  double forward_check_error_m = 0;
  double forward_check_mean_error_m = 0;
  bool forward_check_converged = false;
  /// The forward check's static solution (3n, m): what a simulation from the estimated rest shape
  /// settles into, to compare with x_s node by node. Empty when the check did not run or failed.
  Eigen::VectorXd forward_position_m;
  std::string message;  ///< one line: how the iteration ended
};

/// Estimates the rest shape from the observed static shape `static_shape_m` (3n, every node).
///
/// model_template supplies the mesh topology, Young's moduli (per element), Poisson ratio,
/// density and gravity; its rest positions are ignored. fixed_nodes: node indices, in range, no
/// repeats; their rest positions are taken as observed.
///
/// Throws std::invalid_argument on: static_shape_m or external_force_n of the wrong size or not
/// finite; an element inverted or degenerate in static_shape_m; a bad fixed-node index or repeat;
/// bad options (max_iterations < 1, negative or non-finite tolerances); a non-zero load with no
/// fixed nodes (internal forces sum to zero: no equilibrium exists), or with a connected part of
/// the mesh that has no fixed node or only fewer than three / collinear ones (it is not held
/// against rigid rotation: no equilibrium, or a rest shape that is not unique). With zero load
/// the answer is X = x_s (converged, 0 iterations, no forward check). model_template is copied,
/// never modified; cost and memory in the file comment.
/// Throws std::runtime_error when the Jacobian cannot be factorized or the iteration produces
/// non-finite values. Not converging within max_iterations is reported (converged = false),
/// not thrown.
RestShapeResult estimate_rest_shape(const FemModel& model_template, const std::vector<int>& fixed_nodes,
                                    const Eigen::VectorXd& static_shape_m, const RestShapeOptions& options = {});

/// The same from a recording: frame `frame_index` of `problem` is the static shape (the object
/// at rest under gravity, e.g. before the tool touches it), problem.fixed_nodes the supports,
/// problem.material the material (with problem.mesh's per-element moduli if present). A wrench
/// measured at that frame is added as a dead load on problem.applied_to (spread like the other
/// FEM estimators do) on top of options.external_force_n.
///
/// Throws std::invalid_argument, besides the cases above, when: frame_index is out of range; the
/// frame does not observe every node; a node is driven in that frame (its support force is
/// unknown); the recording declares no gravity; Young's modulus or density is not known (neither
/// in the recording's material nor as per-element moduli in the mesh): the sag scales with
/// density / E, so a default would silently scale the answer. An absent Poisson ratio takes
/// FemRecordingDefaults' value (0.45).
RestShapeResult estimate_rest_shape(const FemRecordingProblem& problem, int frame_index,
                                    const RestShapeOptions& options = {});

}  // namespace pliant::host::fem
