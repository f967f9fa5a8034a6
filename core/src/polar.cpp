#include "pliant/core/polar.hpp"

#include <cmath>

#include <limits>

namespace pliant {

template <typename Scalar>
bool extract_rotation(const Eigen::Matrix<Scalar, 3, 3>& a, Eigen::Quaternion<Scalar>& orientation,
                      int max_iterations, Scalar step_tolerance) noexcept {
  using Vec3 = Eigen::Matrix<Scalar, 3, 1>;
  using Mat3 = Eigen::Matrix<Scalar, 3, 3>;
  if (!a.allFinite()) return false;
  const Scalar length_squared = orientation.coeffs().squaredNorm();
  if (!std::isfinite(length_squared) || length_squared < Scalar(0.25)) {
    orientation.setIdentity();
  } else if (std::abs(length_squared - Scalar(1)) > Scalar(64) * std::numeric_limits<Scalar>::epsilon()) {
    orientation.normalize();
  }
  const Scalar scale_squared = a.squaredNorm();
  if (scale_squared == Scalar(0)) return true;
  const Scalar guard = std::sqrt(std::numeric_limits<Scalar>::epsilon() * scale_squared);
  const Scalar stop = step_tolerance;
  // Maximise f(R) = trace(R^T A) over R <- R exp([d]x). With M = R^T A, the gradient is 2 m
  // (m the axial vector of M's skew part) and the Hessian -(trace(M) I - sym(M)); near the
  // optimum H = trace(M) I - sym(M) is positive definite and the Newton step d = H^-1 2m
  // converges quadratically. H is solved in closed form (adjugate over determinant) when its
  // leading minors are clearly positive; otherwise (far from the optimum, or degenerate A) a
  // bounded ascent step is taken. The quaternion is advanced by q (1, d/2), renormalised: the
  // same direction as exp(d/2) with an angle error of O(|d|^3), so no trigonometry is needed.
  for (int iteration = 0; iteration < max_iterations; ++iteration) {
    const Mat3 m = orientation.toRotationMatrix().transpose() * a;
    const Vec3 gradient(m(2, 1) - m(1, 2), m(0, 2) - m(2, 0), m(1, 0) - m(0, 1));
    const Scalar trace = m.trace();
    const Scalar h00 = trace - m(0, 0);
    const Scalar h11 = trace - m(1, 1);
    const Scalar h22 = trace - m(2, 2);
    const Scalar h01 = Scalar(-0.5) * (m(0, 1) + m(1, 0));
    const Scalar h02 = Scalar(-0.5) * (m(0, 2) + m(2, 0));
    const Scalar h12 = Scalar(-0.5) * (m(1, 2) + m(2, 1));
    // Cofactors of the symmetric H.
    const Scalar c00 = h11 * h22 - h12 * h12;
    const Scalar c01 = h02 * h12 - h01 * h22;
    const Scalar c02 = h01 * h12 - h02 * h11;
    const Scalar c11 = h00 * h22 - h02 * h02;
    const Scalar c12 = h01 * h02 - h00 * h12;
    const Scalar c22 = h00 * h11 - h01 * h01;
    const Scalar det = h00 * c00 + h01 * c01 + h02 * c02;
    Vec3 step;
    if (h00 > guard && c22 > guard * guard && det > guard * guard * guard) {
      const Scalar inverse_det = Scalar(1) / det;
      step = Vec3(c00 * gradient(0) + c01 * gradient(1) + c02 * gradient(2),
                  c01 * gradient(0) + c11 * gradient(1) + c12 * gradient(2),
                  c02 * gradient(0) + c12 * gradient(1) + c22 * gradient(2)) * inverse_det;
    } else {
      step = gradient * (Scalar(1) / (std::abs(trace) + guard));
    }
    const Scalar angle_squared = step.squaredNorm();
    if (!(angle_squared > Scalar(0)) || !std::isfinite(angle_squared)) break;
    if (angle_squared > Scalar(1)) step *= Scalar(1) / std::sqrt(angle_squared);  // at most 1 rad
    const Eigen::Quaternion<Scalar> turn(Scalar(1), Scalar(0.5) * step(0), Scalar(0.5) * step(1),
                                         Scalar(0.5) * step(2));
    orientation = orientation * turn;
    orientation.normalize();
    if (angle_squared < stop * stop) break;
  }
  return true;
}

template bool extract_rotation<float>(const Eigen::Matrix<float, 3, 3>&, Eigen::Quaternion<float>&, int, float) noexcept;
template bool extract_rotation<double>(const Eigen::Matrix<double, 3, 3>&, Eigen::Quaternion<double>&, int, double) noexcept;

}  // namespace pliant
