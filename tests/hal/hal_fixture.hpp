// Test helpers for the HAL: a small simulated grasp on a stepped clock, and its mock devices.
#pragma once

#include <cstdint>
#include <limits>

#include "pliant/hal/mock/mock_force_torque.hpp"
#include "pliant/hal/mock/mock_gripper.hpp"
#include "pliant/hal/mock/mock_particle_observer.hpp"
#include "pliant/hal/mock/simulated_grasp.hpp"

namespace pliant::hal::test {

/// A 5 x 4 x 3 box at 8 mm (32 mm across the jaws), msm_beta 0.5, 2000 N/m, 1 kHz plant.
inline SimulatedGraspConfig small_grasp(double beta = 0.5) {
  SimulatedGraspConfig c;
  c.object.shape = ObjectShape::box;
  c.object.nx = 5;
  c.object.ny = 4;
  c.object.nz = 3;
  c.object.spacing_m = 0.008;
  c.object.msm_beta = beta;
  c.object.stiffness_n_per_m = 2000;
  c.period_s = 0.001;
  c.initial_width_m = 0.034;
  return c;
}

/// One scheduled fault; `value` NaN: the kind's default.
inline FaultEvent event(FaultKind kind, double start_s, double duration_s,
                        double value = std::numeric_limits<double>::quiet_NaN()) {
  FaultEvent e;
  e.kind = kind;
  e.start_s = start_s;
  e.duration_s = duration_s;
  e.value = value;
  return e;
}

/// Clock at t = 1 s stepped in whole milliseconds (exact stamps: t = 1 + k / 1000 computed
/// from the integer k, never accumulated).
struct SteppedClock {
  ManualClock clock{1.0};
  std::int64_t ticks = 0;
  double period_s = 0.001;
  void step(int n = 1) {
    ticks += n;
    (void)clock.set(1.0 + static_cast<double>(ticks) * period_s);
  }
  double now() const { return clock.now_s(); }
};

}  // namespace pliant::hal::test
