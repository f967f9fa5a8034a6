// The simulated press: an object pressed by a tool on one particle, stepped with the core
// msm_step, every particle recorded every frame with position noise. The one press loop behind
// the core tests, the benchmarks and the host's scenario generators.
//
// Timing: frames at k / rate_hz, k = 0 .. round(duration_s * rate_hz); frame 0 is the rest
// shape; steps_per_frame MSM steps per frame interval, the tool's target moving on between them.
// Tool: target = its rest position + travel * clamp((t - lead_in_s) / ramp_s, 0, 1) at step time
// t, driven while t <= release_s and free after. Test support (heap allowed, no exceptions).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "pliant/core/msm.hpp"
#include "pliant/core_testing/position_noise.hpp"
#include "pliant/core_testing/press_grid.hpp"

namespace pliant::core_testing {

/// How step and frame times are rounded: the same times up to the last bit, kept apart because
/// the recorded presses depend on the bits.
enum class PressClock {
  /// step dt = (1 / rate_hz) / steps; step n (from 1) at n * dt; frame k at k * (1 / rate_hz).
  /// The host scenarios and the benchmarks.
  step_count,
  /// step dt = 1 / (rate_hz * steps); step j (1..steps) of interval k at (k - 1 + j / steps) /
  /// rate_hz; frame k at k / rate_hz. The core tests.
  frame_division,
};

/// The tool's motion and the recording's timing.
struct PressMotion {
  int tool = 0;                  ///< driven particle id; must be drivable in the model
  double travel[3] = {0, 0, 0};  ///< tool displacement at full depth, length unit (Dim entries used)
  double lead_in_s = 0.0;        ///< seconds the tool holds still before it moves
  double ramp_s = 1.0;           ///< seconds from rest to full depth, linear; > 0
  double release_s = HUGE_VAL;   ///< the tool is driven at step times <= release_s, free after
  double duration_s = 4.0;       ///< seconds recorded, > 0
  double rate_hz = 30.0;         ///< frames per second, > 0
  int steps_per_frame = 1;       ///< MSM steps per frame interval, >= 1
  PressClock clock = PressClock::step_count;
};

/// A recorded press: frame times and observed positions.
template <typename Scalar>
struct PressFrames {
  std::vector<double> times_s;    ///< [frame], seconds from 0
  std::vector<Scalar> positions;  ///< [frame][particle][axis], simulated position + noise, cast to Scalar
};

/// Presses `model` from rest with `params` and records every frame into `out` (cleared first).
/// Each recorded coordinate is static_cast<Out>(double(position) + noise). Returns the first
/// status other than ok (state init or a step; `out` then holds the frames recorded so far).
template <int Dim, typename Scalar, typename Out>
Status simulate_press(const MsmModel<Dim, Scalar>& model, const MsmParams<Dim, Scalar>& params,
                      const PressMotion& motion, const PositionNoise& noise, PressFrames<Out>& out) {
  out.times_s.clear();
  out.positions.clear();
  std::vector<unsigned char> block(msm_state_workspace_size(model));
  Arena arena(block.data(), block.size());
  MsmState<Dim, Scalar> state;
  const Status initialised = msm_state_init(arena, model, state);
  if (initialised != Status::ok) return initialised;

  const int n = model.particle_count;
  const int frames = static_cast<int>(std::lround(motion.duration_s * motion.rate_hz)) + 1;
  const int steps = motion.steps_per_frame;
  out.times_s.reserve(static_cast<std::size_t>(frames));
  out.positions.reserve(static_cast<std::size_t>(frames) * static_cast<std::size_t>(n) * Dim);
  NoiseStream stream(noise);
  auto record = [&](int frame, double t) {
    out.times_s.push_back(t);
    for (int i = 0; i < n; ++i) {
      for (int d = 0; d < Dim; ++d) {
        const double observed = static_cast<double>(state.position[i](d)) + stream.next(frame, i * Dim + d);
        out.positions.push_back(static_cast<Out>(observed));
      }
    }
  };
  record(0, 0.0);

  const bool by_count = motion.clock == PressClock::step_count;
  const double frame_dt = 1.0 / motion.rate_hz;
  const double step_dt = by_count ? frame_dt / steps : 1.0 / (motion.rate_hz * steps);
  MsmStepInput<Dim, Scalar> input;
  input.dt = static_cast<Scalar>(step_dt);
  Eigen::Matrix<Scalar, Dim, 1> target;
  for (int k = 1; k < frames; ++k) {
    for (int j = 1; j <= steps; ++j) {
      const double t = by_count ? static_cast<double>((k - 1) * steps + j) * step_dt
                                : (k - 1 + static_cast<double>(j) / steps) / motion.rate_hz;
      const double progress = std::clamp((t - motion.lead_in_s) / motion.ramp_s, 0.0, 1.0);
      for (int d = 0; d < Dim; ++d) {
        target(d) = static_cast<Scalar>(static_cast<double>(model.rest[motion.tool](d)) + motion.travel[d] * progress);
      }
      input.driven.ids = &motion.tool;
      input.driven.positions = &target;
      input.driven.count = t <= motion.release_s ? 1 : 0;
      const Status stepped = msm_step(model, params, input, state);
      if (stepped != Status::ok) return stepped;
    }
    record(k, by_count ? k * frame_dt : k / motion.rate_hz);
  }
  return Status::ok;
}

/// A grid press: the model built on grid_rest (in Scalar) with the support layer fixed, the
/// tool the only drivable particle and default clusters, then simulate_press. Returns
/// invalid_argument for an empty grid, else as msm_model_init and simulate_press.
template <int Dim, typename Scalar, typename Out>
Status simulate_grid_press(const PressGrid& grid, const MsmParams<Dim, Scalar>& params, const PressMotion& motion,
                           const PositionNoise& noise, PressFrames<Out>& out) {
  const std::vector<Scalar> rest = grid_rest<Dim, Scalar>(grid);
  const std::vector<std::uint8_t> fixed = grid_support<Dim>(grid);
  MsmModelConfig<Dim, Scalar> config;
  config.particle_count = static_cast<int>(rest.size()) / Dim;
  config.rest_positions = rest.data();
  config.fixed = fixed.data();
  config.drivable_ids = &motion.tool;
  config.drivable_count = 1;
  std::vector<unsigned char> block(msm_model_workspace_size(config));
  if (block.empty()) return Status::invalid_argument;
  Arena arena(block.data(), block.size());
  MsmModel<Dim, Scalar> model;
  const Status built = msm_model_init(arena, config, model);
  if (built != Status::ok) return built;
  return simulate_press(model, params, motion, noise, out);
}

}  // namespace pliant::core_testing
