// pliant hal mocks: a force/torque sensor in the finger of jaw B of a SimulatedGrasp.
//
// The object pushes jaw B along +x (world) with the plant's grip force F. The sensor reports,
// in its own frame, f = R^T (F e_x + load_n) and t = R^T (lever_m x F e_x), plus Gaussian noise
// (force_noise_n, torque_noise_nm per axis), where R (row-major, rotation[9]) holds the sensor's
// axes as columns in the world frame, lever_m is the contact point relative to the sensor
// origin (world frame, m) and load_n a constant world force on the sensor (the finger's weight).
// A new sample every period_s, stamped at its capture time; status word 0 (ATI layout).
// Faults: every common kind plus bus_off (read returns bus_off: the CAN controller is off).
//   fault_bits sets `value` (default kFtSupplyLow | kFtAnyError) in the status word.
// Real-time safety: read is bounded (one plant sync), allocation-free, noexcept.
#pragma once

#include <cstdint>
#include <random>

#include "pliant/hal/clock.hpp"
#include "pliant/hal/force_torque.hpp"
#include "pliant/hal/mock/mock_stream.hpp"
#include "pliant/hal/mock/simulated_grasp.hpp"

namespace pliant::hal {

struct MockForceTorqueConfig {
  double period_s = 0.001;
  double force_noise_n = 0.02;                       ///< sd per axis, >= 0
  double torque_noise_nm = 5e-4;                     ///< sd per axis, >= 0
  double rotation[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};  ///< sensor axes (columns) in world, row-major
  double lever_m[3] = {0, 0, -0.03};
  double load_n[3] = {0, 0, -0.5};
  std::uint32_t fault_bits = kFtSupplyLow | kFtAnyError;
  std::uint64_t seed = 2;
};

class MockForceTorqueSensor final : public ForceTorqueSensor {
 public:
  MockForceTorqueSensor(SimulatedGrasp& plant, const Clock& clock, const MockForceTorqueConfig& config = {}) noexcept
      : plant_(plant), clock_(clock), config_(config) {}

  HalStatus set_fault_schedule(const FaultSchedule& schedule) noexcept { return stream_.set_schedule(schedule); }
  HalStatus add_fault(const FaultEvent& event) noexcept { return stream_.add_fault(event); }
  const FaultCounters& fault_counters() const noexcept { return stream_.fault_counters(); }

 protected:
  HalStatus on_configure() override;
  HalStatus on_start() noexcept override;
  HalStatus on_read(WrenchReading& out) noexcept override;

 private:
  SimulatedGrasp& plant_;
  const Clock& clock_;
  MockForceTorqueConfig config_;
  MockStream stream_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_{0.0, 1.0};
  WrenchReading last_;
  bool has_last_ = false;
};

}  // namespace pliant::hal
