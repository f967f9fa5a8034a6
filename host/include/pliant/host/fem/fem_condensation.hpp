// Static condensation of the FEM stiffness onto a few nodes: the stiffness those nodes show when
// some other nodes are held and all the rest relax. Used where a small set of nodes carries a
// contact law (the frictional supports of diagnose --model fem): the contact is solved on the
// condensed matrix, and the full model only checks the answer.
//
// Units SI: the matrix maps displacements of the probed nodes (m) to the forces that hold them
// there (N), node-major (x y z per node, in the order of `probed`). Host code: allocates,
// throws. Cost: one sparse Cholesky factorization of the relaxed nodes (the same supernodal
// factor the solvers use) and 3 p solves for p probed nodes.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "pliant/host/fem/fem_model.hpp"

namespace pliant::host::fem {

/// S = A_pp - A_pf A_ff^-1 A_fp with A = stiffness_coefficient K(x) + mass_coefficient M, K the
/// corotational tangent at positions position_m (3n; the linear stiffness at the rest shape), M
/// the lumped mass, p the `probed` nodes, f every node neither probed nor `clamped`. A static
/// problem uses (1, 0); one implicit step of length h uses the step's effective matrix, e.g.
/// Newmark's (1 + 2 beta / h, 4 / h^2 + 2 alpha / h) with Rayleigh coefficients alpha, beta.
/// Returns 3p x 3p, symmetric. Throws std::invalid_argument on an index out of range, a repeat,
/// a node both probed and clamped, or negative coefficients; std::runtime_error when A_ff is not
/// positive definite (the relaxed nodes are not held against rigid motion).
Eigen::MatrixXd condensed_stiffness(const FemModel& model, const Eigen::Ref<const Eigen::VectorXd>& position_m,
                                    const std::vector<int>& probed, const std::vector<int>& clamped,
                                    double stiffness_coefficient = 1.0, double mass_coefficient = 0.0);

}  // namespace pliant::host::fem
