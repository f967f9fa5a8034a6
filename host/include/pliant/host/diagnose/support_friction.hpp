// Coulomb friction of FEM support nodes on a plane: the contact law of the `friction` effect of
// `pliant diagnose --model fem` (FemRunSettings::support_friction, fem_model_run.hpp).
//
// Vectors are node-major, 3 entries per support node in the order of the support list, SI (m,
// N). "Reaction" is the force the support exerts on the body, as FemSolver::reaction_n(). Host
// code: allocates, never throws.
#pragma once

#include <vector>

#include <Eigen/Core>

namespace pliant::host {

struct SupportPlane {
  bool valid = false;
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();                            ///< unit, from the plane into the body
  Eigen::Matrix<double, 3, 2> tangents = Eigen::Matrix<double, 3, 2>::Zero();  ///< orthonormal, in the plane
};

/// The plane through `nodes` at positions `position_m` (3n): valid when there are at least three
/// nodes, they do not lie on a line, and none is off their best-fit plane by more than 1e-3 of
/// their extent. The normal points toward `body_centre_m`.
SupportPlane find_support_plane(const Eigen::VectorXd& position_m, const std::vector<int>& nodes,
                                const Eigen::Vector3d& body_centre_m);

/// The slips (3 per support, in the plane) that satisfy Coulomb's law with friction coefficient
/// mu >= 0 on a linear model of the reactions: reactions(u) = held + stiffness (u - slip), where
/// `held` are the reactions measured with the supports displaced by `slip` from their anchors
/// and `stiffness` the condensed stiffness of the supports (3m x 3m). A support sticks (zero
/// slip) while its tangential reaction is at most mu times its normal reaction (pressing on the
/// plane; a pulling support has no friction); otherwise its reaction is exactly that, opposite
/// to its slip. Projected (block) Gauss-Seidel from `slip`, each support solved exactly against
/// the others, at most 500 sweeps, until no slip changes by
/// more than `tolerance_m`.
Eigen::VectorXd coulomb_slip(const SupportPlane& plane, double mu, const Eigen::VectorXd& held,
                             const Eigen::MatrixXd& stiffness, const Eigen::VectorXd& slip, double tolerance_m);

}  // namespace pliant::host
