#include "pliant/host/diagnose/support_friction.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>

namespace pliant::host {

SupportPlane find_support_plane(const Eigen::VectorXd& position_m, const std::vector<int>& nodes,
                                const Eigen::Vector3d& body_centre_m) {
  SupportPlane plane;
  if (nodes.size() < 3) return plane;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (int node : nodes) centre += position_m.segment<3>(3 * node);
  centre /= static_cast<double>(nodes.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (int node : nodes) {
    const Eigen::Vector3d d = position_m.segment<3>(3 * node) - centre;
    scatter += d * d.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(scatter);  // ascending eigenvalues
  const Eigen::Vector3d normal = eigen.eigenvectors().col(0);
  const Eigen::Vector3d first = eigen.eigenvectors().col(2);
  const Eigen::Vector3d second = eigen.eigenvectors().col(1);
  double extent = 0;
  double off_plane = 0;
  double across = 0;  // spread along the second in-plane axis: zero when the nodes are on a line
  for (int node : nodes) {
    const Eigen::Vector3d d = position_m.segment<3>(3 * node) - centre;
    extent = std::max(extent, std::abs(d.dot(first)));
    across = std::max(across, std::abs(d.dot(second)));
    off_plane = std::max(off_plane, std::abs(d.dot(normal)));
  }
  if (!(extent > 0) || across <= 1e-3 * extent || off_plane > 1e-3 * extent) return plane;
  plane.valid = true;
  plane.normal = (body_centre_m - centre).dot(normal) >= 0 ? normal : Eigen::Vector3d(-normal);
  plane.tangents.col(0) = first;
  plane.tangents.col(1) = plane.normal.cross(first);
  return plane;
}

namespace {

// The slip u (tangent coordinates) of one support whose tangential reaction is
// stuck + a u (a: its own 2x2 tangential stiffness, symmetric positive definite): zero when
// |stuck| <= limit; otherwise the reaction has size limit and points against u. Writing
// u = -c t with t the reaction, t = (I + c a)^-1 stuck, and |t| falls as c grows: c is the root
// of |t(c)| = limit, found by bisection in a's eigenbasis.
Eigen::Vector2d coulomb_return(const Eigen::Vector2d& stuck, const Eigen::Matrix2d& a, double limit) {
  const double size = stuck.norm();
  if (size <= limit) return Eigen::Vector2d::Zero();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen(a);
  const Eigen::Vector2d k = eigen.eigenvalues().cwiseMax(1e-12 * std::max(eigen.eigenvalues()(1), 1e-300));
  const Eigen::Vector2d q = eigen.eigenvectors().transpose() * stuck;
  if (limit <= 0) return -(eigen.eigenvectors() * q.cwiseQuotient(k));  // slides freely: zero reaction
  auto reaction_in_basis = [&](double c) { return Eigen::Vector2d(q(0) / (1.0 + c * k(0)), q(1) / (1.0 + c * k(1))); };
  double lo = 0;
  double hi = (size / limit - 1.0) / k.minCoeff();  // |t(hi)| <= limit
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (lo + hi);
    (reaction_in_basis(mid).norm() > limit ? lo : hi) = mid;
  }
  const double c = 0.5 * (lo + hi);
  return -c * (eigen.eigenvectors() * reaction_in_basis(c));
}

}  // namespace

Eigen::VectorXd coulomb_slip(const SupportPlane& plane, double mu, const Eigen::VectorXd& held,
                             const Eigen::MatrixXd& stiffness, const Eigen::VectorXd& slip, double tolerance_m) {
  const Eigen::Index supports = held.size() / 3;
  const Eigen::Matrix<double, 3, 2>& t = plane.tangents;
  std::vector<Eigen::Matrix2d> own(static_cast<std::size_t>(supports));  // tangential block of each support
  for (Eigen::Index i = 0; i < supports; ++i) {
    own[static_cast<std::size_t>(i)] = t.transpose() * stiffness.block<3, 3>(3 * i, 3 * i) * t;
  }
  Eigen::VectorXd u = slip;
  Eigen::VectorXd reaction = held + stiffness * (u - slip);
  for (int sweep = 0; sweep < 500; ++sweep) {
    double largest_change = 0;
    for (Eigen::Index i = 0; i < supports; ++i) {
      const std::size_t s = static_cast<std::size_t>(i);
      const Eigen::Vector3d r = reaction.segment<3>(3 * i);
      const double limit = mu * std::max(0.0, r.dot(plane.normal));
      const Eigen::Vector2d current = t.transpose() * u.segment<3>(3 * i);
      // The tangential reaction this support would feel stuck at its anchor, the others as they are.
      const Eigen::Vector2d stuck = t.transpose() * r - own[s] * current;
      const Eigen::Vector3d delta = t * (coulomb_return(stuck, own[s], limit) - current);
      if (delta.squaredNorm() == 0.0) continue;
      u.segment<3>(3 * i) += delta;
      reaction += stiffness.middleCols<3>(3 * i) * delta;
      largest_change = std::max(largest_change, delta.cwiseAbs().maxCoeff());
    }
    if (largest_change <= tolerance_m) break;
  }
  return u;
}

}  // namespace pliant::host
