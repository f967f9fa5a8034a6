// Observed particle trajectories as the core estimators read them (caller memory, read only).
#pragma once

#include <cmath>
#include <cstdint>

#include <Eigen/Core>

namespace pliant {

/// A particle driven (position prescribed by its own observation) while from_s <= t <= to_s.
/// Use -inf / +inf for unbounded windows.
struct DrivenWindow {
  int id = 0;
  double from_s = -HUGE_VAL;
  double to_s = HUGE_VAL;
  bool active_at(double t_s) const noexcept { return from_s <= t_s && t_s <= to_s; }
};

/// frame_count frames at times_s (strictly increasing, seconds); positions is frame-major,
/// [frame][particle][axis], particle_count * Dim per frame, in the model's length unit. A
/// particle with any non-finite coordinate in a frame is unobserved there.
template <int Dim, typename Scalar>
struct ObservationSequence {
  int frame_count = 0;
  int particle_count = 0;
  const double* times_s = nullptr;
  const Scalar* positions = nullptr;
  const DrivenWindow* driven = nullptr;
  int driven_count = 0;

  const Scalar* at(int frame, int particle) const noexcept {
    return positions + (static_cast<long>(frame) * particle_count + particle) * Dim;
  }
  bool observed(int frame, int particle) const noexcept {
    const Scalar* p = at(frame, particle);
    for (int d = 0; d < Dim; ++d) {
      if (!std::isfinite(p[d])) return false;
    }
    return true;
  }
  Eigen::Matrix<Scalar, Dim, 1> point(int frame, int particle) const noexcept {
    return Eigen::Map<const Eigen::Matrix<Scalar, Dim, 1>>(at(frame, particle));
  }
};

}  // namespace pliant
