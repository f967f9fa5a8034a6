#include "pliant/core/polar.hpp"

namespace pliant {

template <typename Scalar>
bool extract_rotation(const Eigen::Matrix<Scalar, 3, 3>& a, Eigen::Quaternion<Scalar>& orientation, int max_iterations,
                      Scalar step_tolerance) noexcept {
  Eigen::Matrix<Scalar, 3, 3> rotation;
  return extract_rotation(a, orientation, rotation, max_iterations, step_tolerance);
}

template bool extract_rotation<float>(const Eigen::Matrix<float, 3, 3>&, Eigen::Quaternion<float>&, int,
                                      float) noexcept;
template bool extract_rotation<double>(const Eigen::Matrix<double, 3, 3>&, Eigen::Quaternion<double>&, int,
                                       double) noexcept;

}  // namespace pliant
