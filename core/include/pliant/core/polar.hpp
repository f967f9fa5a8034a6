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
  if (!(length_squared > epsilon * epsilon * a.squaredNorm()) ||
      !(length_squared <= std::numeric_limits<Scalar>::max())) {
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
                      int max_iterations = 24, Scalar step_tolerance = rotation_step_tolerance<Scalar>()) noexcept;

#if defined(__GNUC__)
#define PLIANT_INLINE inline __attribute__((always_inline))
#else
#define PLIANT_INLINE inline
#endif

namespace detail {

/// Sum of squares of a[0..8], in order.
template <typename Scalar>
PLIANT_INLINE Scalar squared_sum9(const Scalar* a) noexcept {
  Scalar total = a[0] * a[0];
  for (int e = 1; e < 9; ++e) total += a[e] * a[e];
  return total;
}

/// Rotation matrix (column-major r[9]) of the unit quaternion (w, x, y, z).
template <typename Scalar>
PLIANT_INLINE void quaternion_to_matrix(Scalar w, Scalar x, Scalar y, Scalar z, Scalar* r) noexcept {
  const Scalar tx = Scalar(2) * x;
  const Scalar ty = Scalar(2) * y;
  const Scalar tz = Scalar(2) * z;
  const Scalar twx = tx * w;
  const Scalar twy = ty * w;
  const Scalar twz = tz * w;
  const Scalar txx = tx * x;
  const Scalar txy = ty * x;
  const Scalar txz = tz * x;
  const Scalar tyy = ty * y;
  const Scalar tyz = tz * y;
  const Scalar tzz = tz * z;
  r[0] = Scalar(1) - (tyy + tzz);
  r[1] = txy + twz;
  r[2] = txz - twy;
  r[3] = txy - twz;
  r[4] = Scalar(1) - (txx + tzz);
  r[5] = tyz + twx;
  r[6] = txz + twy;
  r[7] = tyz - twx;
  r[8] = Scalar(1) - (txx + tyy);
}

/// One Newton iteration's terms for maximising trace(R^T A) at R (R, A column-major [9]):
/// with M = R^T A, the gradient g (twice the axial vector of M's skew part), trace(M), the
/// Hessian H = trace(M) I - sym(M) through h00, its cofactor c22 and det H, and the Newton
/// step H^-1 g (meaningful only while H is positive definite). Branch-free, so that shape
/// matching can run it over several clusters at once.
template <typename Scalar>
struct RotationTerms {
  Scalar g0, g1, g2, trace, h00, c22, det, n0, n1, n2;
};
template <typename Scalar>
PLIANT_INLINE RotationTerms<Scalar> rotation_terms(const Scalar* r, const Scalar* a) noexcept {
  // m[i][j] = (R^T A)(i, j) = column i of R . column j of A (written out: no loops, so that
  // callers' loops over clusters stay innermost for the vectoriser).
#define PLIANT_RTA(i, j) (r[(i)*3] * a[(j)*3] + r[(i)*3 + 1] * a[(j)*3 + 1] + r[(i)*3 + 2] * a[(j)*3 + 2])
  const Scalar m[3][3] = {{PLIANT_RTA(0, 0), PLIANT_RTA(0, 1), PLIANT_RTA(0, 2)},
                          {PLIANT_RTA(1, 0), PLIANT_RTA(1, 1), PLIANT_RTA(1, 2)},
                          {PLIANT_RTA(2, 0), PLIANT_RTA(2, 1), PLIANT_RTA(2, 2)}};
#undef PLIANT_RTA
  RotationTerms<Scalar> t;
  t.g0 = m[2][1] - m[1][2];
  t.g1 = m[0][2] - m[2][0];
  t.g2 = m[1][0] - m[0][1];
  t.trace = m[0][0] + m[1][1] + m[2][2];
  const Scalar h00 = t.trace - m[0][0];
  const Scalar h11 = t.trace - m[1][1];
  const Scalar h22 = t.trace - m[2][2];
  const Scalar h01 = Scalar(-0.5) * (m[0][1] + m[1][0]);
  const Scalar h02 = Scalar(-0.5) * (m[0][2] + m[2][0]);
  const Scalar h12 = Scalar(-0.5) * (m[1][2] + m[2][1]);
  // Cofactors of the symmetric H.
  const Scalar c00 = h11 * h22 - h12 * h12;
  const Scalar c01 = h02 * h12 - h01 * h22;
  const Scalar c02 = h01 * h12 - h02 * h11;
  const Scalar c11 = h00 * h22 - h02 * h02;
  const Scalar c12 = h01 * h02 - h00 * h12;
  t.h00 = h00;
  t.c22 = h00 * h11 - h01 * h01;
  t.det = h00 * c00 + h01 * c01 + h02 * c02;
  const Scalar inverse_det = Scalar(1) / t.det;
  t.n0 = (c00 * t.g0 + c01 * t.g1 + c02 * t.g2) * inverse_det;
  t.n1 = (c01 * t.g0 + c11 * t.g1 + c12 * t.g2) * inverse_det;
  t.n2 = (c02 * t.g0 + c12 * t.g1 + t.c22 * t.g2) * inverse_det;
  return t;
}

/// q <- normalise(q (1, t)): the quaternion advanced by the half-angle vector t.
template <typename Scalar>
PLIANT_INLINE void quaternion_advance(Scalar& w, Scalar& x, Scalar& y, Scalar& z, Scalar tx, Scalar ty,
                                      Scalar tz) noexcept {
  const Scalar nw = w - x * tx - y * ty - z * tz;
  const Scalar nx = x + w * tx + y * tz - z * ty;
  const Scalar ny = y + w * ty + z * tx - x * tz;
  const Scalar nz = z + w * tz + x * ty - y * tx;
  const Scalar inverse_norm = Scalar(1) / std::sqrt(nw * nw + nx * nx + ny * ny + nz * nz);
  w = nw * inverse_norm;
  x = nx * inverse_norm;
  y = ny * inverse_norm;
  z = nz * inverse_norm;
}

}  // namespace detail

/// 3D, as above, and also leaves the rotation matrix of the final orientation in `rotation`,
/// which the iteration forms anyway. Inline: shape matching calls it once per cluster and step.
/// (The out-of-line overload above runs this.)
template <typename Scalar>
inline bool extract_rotation(const Eigen::Matrix<Scalar, 3, 3>& a, Eigen::Quaternion<Scalar>& orientation,
                             Eigen::Matrix<Scalar, 3, 3>& rotation, int max_iterations,
                             Scalar step_tolerance) noexcept {
  constexpr Scalar epsilon = std::numeric_limits<Scalar>::epsilon();
  const Scalar scale_squared = detail::squared_sum9(a.data());
  // A non-finite sum means a non-finite entry, or a finite A too large to square (kept).
  if (!std::isfinite(scale_squared) && !a.allFinite()) {
    rotation = orientation.toRotationMatrix();
    return false;
  }
  const Scalar length_squared = orientation.w() * orientation.w() + orientation.x() * orientation.x() +
                                orientation.y() * orientation.y() + orientation.z() * orientation.z();
  if (!(std::abs(length_squared - Scalar(1)) <= Scalar(64) * epsilon)) {
    if (!std::isfinite(length_squared) || length_squared < Scalar(0.25)) {
      orientation.setIdentity();
    } else {
      orientation.normalize();
    }
  }
  Scalar w = orientation.w();
  Scalar x = orientation.x();
  Scalar y = orientation.y();
  Scalar z = orientation.z();
  Scalar* current = rotation.data();
  detail::quaternion_to_matrix(w, x, y, z, current);
  if (scale_squared == Scalar(0)) return true;
  const Scalar guard = std::sqrt(epsilon * scale_squared);
  const Scalar guard2 = guard * guard;
  const Scalar guard3 = guard2 * guard;
  const Scalar stop2 = step_tolerance * step_tolerance;
  // Maximise f(R) = trace(R^T A) over R <- R exp([d]x). With M = R^T A, the gradient is 2 m
  // (m the axial vector of M's skew part) and the Hessian -(trace(M) I - sym(M)); near the
  // optimum H = trace(M) I - sym(M) is positive definite and the Newton step d = H^-1 2m
  // converges quadratically. H is solved in closed form (adjugate over determinant) when its
  // leading minors are clearly positive; otherwise (far from the optimum, or degenerate A) a
  // bounded ascent step is taken. The quaternion is advanced by q (1, d/2), renormalised: the
  // same direction as exp(d/2) with an angle error of O(|d|^3), so no trigonometry is needed.
  for (int iteration = 0; iteration < max_iterations; ++iteration) {
    const detail::RotationTerms<Scalar> t = detail::rotation_terms(current, a.data());
    Scalar s0 = t.n0;
    Scalar s1 = t.n1;
    Scalar s2 = t.n2;
    if (!(t.h00 > guard && t.c22 > guard2 && t.det > guard3)) {
      const Scalar gain = Scalar(1) / (std::abs(t.trace) + guard);
      s0 = t.g0 * gain;
      s1 = t.g1 * gain;
      s2 = t.g2 * gain;
    }
    const Scalar angle_squared = s0 * s0 + s1 * s1 + s2 * s2;
    if (!(angle_squared > Scalar(0)) || !std::isfinite(angle_squared)) break;
    Scalar half = Scalar(0.5);
    if (angle_squared > Scalar(1)) half = Scalar(0.5) / std::sqrt(angle_squared);  // at most 1 rad
    detail::quaternion_advance(w, x, y, z, half * s0, half * s1, half * s2);
    orientation.w() = w;
    orientation.x() = x;
    orientation.y() = y;
    orientation.z() = z;
    detail::quaternion_to_matrix(w, x, y, z, current);
    if (angle_squared < stop2) break;
  }
  return true;
}

}  // namespace pliant
