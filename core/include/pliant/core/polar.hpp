// Rotation part of a linear map (polar decomposition A = R S), for shape matching.
//
// Contract
// - Returns the proper rotation R (det R = +1) that maximises trace(R^T A). For A with
//   det A > 0 this is the polar factor; for inverted (det < 0), flat, collinear or zero A it is
//   still a rotation, never NaN: degenerate directions keep the warm-start orientation.
// - 2D: closed form. 3D: Newton iterations on a unit quaternion (closed-form 3x3 solve, no
//   trigonometry; quadratic convergence near the answer, a bounded ascent step far from it),
//   warm-started from `orientation` (the previous step's result, identity at start) and
//   refined in place until a step is below `step_tolerance`; at most
//   `max_iterations` iterations of O(1) each, so cost is bounded. Warm-started inside a
//   simulation, 1-2 iterations are typical.
// - Non-finite A: the rotation is left unchanged and false is returned.
// - Real-time safe: no allocation, no exceptions.
#pragma once

#include <cmath>
#include <limits>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace pliant {

/// 2D: rotation maximising trace(R^T A). `rotation` holds the previous answer and is used
/// when A carries no rotational information (A symmetric with trace(A) = 0, A = 0).
/// Inline: shape matching calls it once per cluster and step.
template <typename Scalar>
inline bool extract_rotation(const Eigen::Matrix<Scalar, 2, 2>& a, Eigen::Matrix<Scalar, 2, 2>& rotation) noexcept {
  // trace(R^T A) = c (a00 + a11) + s (a10 - a01): maximised by the angle of that vector.
  const Scalar cos_part = a(0, 0) + a(1, 1);
  const Scalar sin_part = a(1, 0) - a(0, 1);
  const Scalar length_squared = cos_part * cos_part + sin_part * sin_part;
  const Scalar epsilon = std::numeric_limits<Scalar>::epsilon();
  // Also false for NaN: then, or with no rotational information, keep the previous rotation.
  if (!(length_squared > epsilon * epsilon * a.squaredNorm()) || !(length_squared <= std::numeric_limits<Scalar>::max())) {
    return a.allFinite();
  }
  const Scalar inverse_length = Scalar(1) / std::sqrt(length_squared);
  const Scalar c = cos_part * inverse_length;
  const Scalar s = sin_part * inverse_length;
  // Element-wise: GCC 12 at -O3 has miscompiled Eigen's comma initializer here once inlined.
  rotation(0, 0) = c;
  rotation(0, 1) = -s;
  rotation(1, 0) = s;
  rotation(1, 1) = c;
  return true;
}

/// Newton steps on the 3D rotation stop after one smaller than `step_tolerance` (radians).
/// Convergence is quadratic, so the answer is then within about its square of the exact polar
/// factor. The default (1e-5 double, 1e-3 float) gives ~1e-10 rad and ~1e-6 rad (a few float
/// ulps); shape matching uses simulation_rotation_tolerance(), where a rotation error of
/// ~1e-8 rad is far below anything a position can show and the warm start removes it the
/// next step.
template <typename Scalar>
constexpr Scalar rotation_step_tolerance() noexcept {
  return sizeof(Scalar) >= sizeof(double) ? Scalar(1e-5) : Scalar(1e-3);
}
template <typename Scalar>
constexpr Scalar simulation_rotation_tolerance() noexcept {
  return sizeof(Scalar) >= sizeof(double) ? Scalar(1e-4) : Scalar(1e-3);
}

/// 3D: `orientation` is the warm start and the result (unit quaternion).
template <typename Scalar>
bool extract_rotation(const Eigen::Matrix<Scalar, 3, 3>& a, Eigen::Quaternion<Scalar>& orientation,
                      int max_iterations = 24,
                      Scalar step_tolerance = rotation_step_tolerance<Scalar>()) noexcept;

}  // namespace pliant
