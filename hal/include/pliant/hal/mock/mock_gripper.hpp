// pliant hal mocks: a parallel gripper driving the jaws of a SimulatedGrasp.
//
// read(): the plant's width and grip force with Gaussian noise (width_noise_m, force_noise_n),
//   the motor current current_offset_a + force / current_gain_n_per_a (+ noise), and Robotiq-like
//   status bits (activated, moving, object detected, at target; fault code in bits 8-15). A new
//   sample every period_s (a Modbus poll rate), stamped at its capture time.
// write(): move / stop / open go to the plant's actuator (rate-limited jaw motion, stop at the
//   force limit). A refused or failed write leaves the previous command running, as a real
//   gripper keeps executing its last command when the bus is down.
// Faults (fault_schedule.hpp): every common kind. While `fault_bits` is active the status word
//   carries the fault code (value, default over-current 0x0E) and the actuator stops at once
//   and refuses motion: writes return device_fault and are not latched; after the fault the
//   jaws hold until the next command. `timeout` and `disconnect` fail reads and writes.
// Real-time safety: read and write are bounded (one plant sync), allocation-free, noexcept.
#pragma once

#include <cstdint>
#include <random>

#include "pliant/hal/clock.hpp"
#include "pliant/hal/gripper.hpp"
#include "pliant/hal/mock/mock_stream.hpp"
#include "pliant/hal/mock/simulated_grasp.hpp"

namespace pliant::hal {

struct MockGripperConfig {
  double period_s = 0.001;            ///< > 0
  double width_noise_m = 5e-6;        ///< sd, >= 0
  double force_noise_n = 0.005;       ///< sd, >= 0
  double current_gain_n_per_a = 100;  ///< > 0
  double current_offset_a = 0.05;
  double current_noise_a = 2e-4;  ///< sd, >= 0
  double min_force_n = 0;         ///< reported in limits()
  double max_force_n = 235;
  double max_speed_m_per_s = 0.15;
  std::uint8_t fault_code = kGripperFaultOverCurrent;  ///< default fault_bits code
  std::uint64_t seed = 1;
};

class MockGripper final : public Gripper {
 public:
  MockGripper(SimulatedGrasp& plant, const Clock& clock, const MockGripperConfig& config = {}) noexcept
      : plant_(plant), clock_(clock), config_(config) {}

  GripperLimits limits() const noexcept override;
  HalStatus set_fault_schedule(const FaultSchedule& schedule) noexcept { return stream_.set_schedule(schedule); }
  HalStatus add_fault(const FaultEvent& event) noexcept { return stream_.add_fault(event); }
  const FaultCounters& fault_counters() const noexcept { return stream_.fault_counters(); }

 protected:
  HalStatus on_configure() override;
  HalStatus on_start() noexcept override;
  HalStatus on_read(GripperReading& out) noexcept override;
  HalStatus on_write(const GripperCommand& command) noexcept override;

 private:
  bool update_actuator_fault(double now_s) noexcept;

  SimulatedGrasp& plant_;
  const Clock& clock_;
  MockGripperConfig config_;
  MockStream stream_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_{0.0, 1.0};
  GripperReading last_;
  bool has_last_ = false;
  bool faulted_ = false;
};

}  // namespace pliant::hal
