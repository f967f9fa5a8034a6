// One frame interval of an MSM simulation driven by targets observed only at the frames: shared
// by the offline (deformability.cpp) and online (online_deformability.cpp) estimators.
// Private to core/src. Real-time safe: no allocation, no exceptions.
#pragma once

#include "pliant/core/msm.hpp"

namespace pliant::detail {

/// Advances `state` by dt: one msm_step straight to the targets `end`, or `steps` steps of
/// dt / steps toward targets interpolated linearly from `start` to `end` (`scratch` holds them;
/// [count] each, for the particles `ids`). Returns the first status other than ok (stopping at
/// invalid_argument or not_initialized), else ok.
template <int Dim, typename Scalar>
Status step_frame_interval(const MsmModel<Dim, Scalar>& model, const MsmParams<Dim, Scalar>& params, Scalar dt,
                           const int* ids, const Eigen::Matrix<Scalar, Dim, 1>* start,
                           const Eigen::Matrix<Scalar, Dim, 1>* end, int count, int steps,
                           Eigen::Matrix<Scalar, Dim, 1>* scratch, MsmState<Dim, Scalar>& state) noexcept {
  MsmStepInput<Dim, Scalar> input;
  input.driven.ids = ids;
  input.driven.count = count;
  if (steps == 1) {
    input.dt = dt;
    input.driven.positions = end;
    return msm_step(model, params, input, state);
  }
  input.dt = dt / static_cast<Scalar>(steps);
  input.driven.positions = scratch;
  Status worst = Status::ok;
  for (int j = 1; j <= steps; ++j) {
    const Scalar share = static_cast<Scalar>(j) / static_cast<Scalar>(steps);
    for (int c = 0; c < count; ++c) scratch[c] = start[c] + (end[c] - start[c]) * share;
    const Status stepped = msm_step(model, params, input, state);
    if (stepped == Status::invalid_argument || stepped == Status::not_initialized) return stepped;
    if (worst == Status::ok) worst = stepped;
  }
  return worst;
}

}  // namespace pliant::detail
