#include "pliant/core/polar.hpp"

#include <cmath>

#include <Eigen/Cholesky>
#include <limits>

namespace pliant {

template <typename Scalar>
bool extract_rotation(const Eigen::Matrix<Scalar, 2, 2>& a, Eigen::Matrix<Scalar, 2, 2>& rotation) noexcept {
  if (!a.allFinite()) return false;
  // trace(R^T A) = c (a00 + a11) + s (a10 - a01): maximised by the angle of that vector.
  const Scalar cos_part = a(0, 0) + a(1, 1);
  const Scalar sin_part = a(1, 0) - a(0, 1);
  const Scalar norm = std::sqrt(cos_part * cos_part + sin_part * sin_part);
  const Scalar scale = a.cwiseAbs().maxCoeff();
  if (!(norm > std::numeric_limits<Scalar>::epsilon() * scale) || norm == Scalar(0)) {
    return true;  // no rotational information: keep the previous rotation
  }
  const Scalar c = cos_part / norm;
  const Scalar s = sin_part / norm;
  rotation << c, -s, s, c;
  return true;
}

template <typename Scalar>
bool extract_rotation(const Eigen::Matrix<Scalar, 3, 3>& a, Eigen::Quaternion<Scalar>& orientation,
                      int max_iterations) noexcept {
  using Vec3 = Eigen::Matrix<Scalar, 3, 1>;
  using Mat3 = Eigen::Matrix<Scalar, 3, 3>;
  if (!a.allFinite()) return false;
  if (!orientation.coeffs().allFinite() || orientation.norm() < Scalar(0.5)) {
    orientation.setIdentity();
  }
  orientation.normalize();
  const Scalar scale = a.norm();
  if (scale == Scalar(0)) return true;
  const Scalar guard = std::sqrt(std::numeric_limits<Scalar>::epsilon()) * scale;
  const Scalar stop = std::numeric_limits<Scalar>::epsilon() * Scalar(4);
  // Maximise f(R) = trace(R^T A) over R <- R exp([d]x). With M = R^T A, the gradient is 2 m
  // (m the axial vector of M's skew part) and the Hessian -(trace(M) I - sym(M)); near the
  // optimum that matrix is positive definite and the Newton step converges quadratically. Far
  // from it (or for degenerate A) a bounded ascent step is taken instead.
  for (int iteration = 0; iteration < max_iterations; ++iteration) {
    const Mat3 m = orientation.toRotationMatrix().transpose() * a;
    const Vec3 axial(Scalar(0.5) * (m(2, 1) - m(1, 2)), Scalar(0.5) * (m(0, 2) - m(2, 0)),
                     Scalar(0.5) * (m(1, 0) - m(0, 1)));
    const Mat3 hessian = m.trace() * Mat3::Identity() - Scalar(0.5) * (m + m.transpose());
    Vec3 step;
    const Eigen::LLT<Mat3> newton(hessian);
    if (newton.info() == Eigen::Success && newton.matrixL().toDenseMatrix().diagonal().minCoeff() > guard) {
      step = newton.solve(Scalar(2) * axial);
    } else {
      step = Scalar(2) * axial / (std::abs(m.trace()) + guard);
    }
    Scalar angle = step.norm();
    if (!(angle > stop)) break;
    if (angle > Scalar(1)) {
      step /= angle;
      angle = Scalar(1);
    }
    orientation = orientation * Eigen::Quaternion<Scalar>(Eigen::AngleAxis<Scalar>(angle, step / angle));
    orientation.normalize();
  }
  return true;
}

template bool extract_rotation<float>(const Eigen::Matrix<float, 2, 2>&, Eigen::Matrix<float, 2, 2>&) noexcept;
template bool extract_rotation<double>(const Eigen::Matrix<double, 2, 2>&, Eigen::Matrix<double, 2, 2>&) noexcept;
template bool extract_rotation<float>(const Eigen::Matrix<float, 3, 3>&, Eigen::Quaternion<float>&, int) noexcept;
template bool extract_rotation<double>(const Eigen::Matrix<double, 3, 3>&, Eigen::Quaternion<double>&, int) noexcept;

}  // namespace pliant
