// Rotation part of a linear map (polar decomposition A = R S), for shape matching.
//
// Contract
// - Returns the proper rotation R (det R = +1) that maximises trace(R^T A). For A with
//   det A > 0 this is the polar factor; for inverted (det < 0), flat, collinear or zero A it is
//   still a rotation, never NaN: degenerate directions keep the warm-start orientation.
// - 2D: closed form. 3D: Newton iterations on a unit quaternion (quadratic convergence near
//   the answer, a bounded ascent step far from it), warm-started from `orientation` (the
//   previous step's result, identity at start) and refined in place; at most `max_iterations`
//   iterations of O(1) each, so cost is bounded. Warm-started, 1-3 iterations are typical.
// - Non-finite A: the rotation is left unchanged and false is returned.
// - Real-time safe: no allocation, no exceptions.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace pliant {

/// 2D: rotation maximising trace(R^T A). `rotation` holds the previous answer and is used
/// when A carries no rotational information (A symmetric with trace(A) = 0, A = 0).
template <typename Scalar>
bool extract_rotation(const Eigen::Matrix<Scalar, 2, 2>& a, Eigen::Matrix<Scalar, 2, 2>& rotation) noexcept;

/// 3D: `orientation` is the warm start and the result (unit quaternion).
template <typename Scalar>
bool extract_rotation(const Eigen::Matrix<Scalar, 3, 3>& a, Eigen::Quaternion<Scalar>& orientation,
                      int max_iterations = 24) noexcept;

}  // namespace pliant
