// pliant hal mocks: devices that play a recording back (a force/torque sensor, a gripper and a
// particle observer), so that a pipeline runs on recorded data exactly as on live devices.
//
// Each device replays one RecordedChannel (replay_cursor.hpp: timing, sequence numbers, end of
// stream, scripted faults); the caller owns the channel and keeps it alive and unchanged while
// the device is configured. Host code fills the channels from a recording-v1 directory
// (pliant/host/replay_channels.hpp); these classes read no files.
//
//   ReplayForceTorque       width 6: Fx Fy Fz (N), Tx Ty Tz (N m), as recorded. Status word 0
//                           (ATI layout, force_torque.hpp); fault_bits default kFtSupplyLow |
//                           kFtAnyError; also accepts bus_off.
//   ReplayGripper           width 2: opening (m), grip force (N; NaN when not recorded).
//                           Status kGripperActivated; fault_bits default over-current (0x0e).
//                           A replay cannot move: every command is refused with unsupported
//                           (counted as a rejected write); limits() spans the recorded openings.
//   ReplayParticleObserver  width particle_count * dimension, particle-major, NaN unobserved.
//                           occlude hides the fraction `value` (default 0.5) of the particles
//                           with the largest coordinate 1 (y) in the first recorded sample and
//                           marks the frame kFramePartial, as the simulated observer does.
// Real-time safety: configure allocates; read and write are bounded, allocation-free, noexcept.
#pragma once

#include <vector>

#include "pliant/hal/camera.hpp"
#include "pliant/hal/clock.hpp"
#include "pliant/hal/force_torque.hpp"
#include "pliant/hal/gripper.hpp"
#include "pliant/hal/mock/replay_cursor.hpp"

namespace pliant::hal {

class ReplayForceTorque final : public ForceTorqueSensor {
 public:
  ReplayForceTorque(const RecordedChannel& channel, const Clock& clock, const ReplayTiming& timing = {}) noexcept
      : channel_(channel), clock_(clock), timing_(timing) {}
  HalStatus set_fault_schedule(const FaultSchedule& schedule) noexcept { return cursor_.set_schedule(schedule); }
  HalStatus add_fault(const FaultEvent& event) noexcept { return cursor_.add_fault(event); }
  const FaultCounters& fault_counters() const noexcept { return cursor_.fault_counters(); }
  bool finished() const noexcept { return cursor_.finished(); }
  double next_due_s() const noexcept { return cursor_.next_due_s(); }  ///< replay_cursor.hpp

 protected:
  HalStatus on_configure() override;
  HalStatus on_start() noexcept override;
  HalStatus on_read(WrenchReading& out) noexcept override;

 private:
  const RecordedChannel& channel_;
  const Clock& clock_;
  ReplayTiming timing_;
  ReplayCursor cursor_;
};

class ReplayGripper final : public Gripper {
 public:
  ReplayGripper(const RecordedChannel& channel, const Clock& clock, const ReplayTiming& timing = {}) noexcept
      : channel_(channel), clock_(clock), timing_(timing) {}
  HalStatus set_fault_schedule(const FaultSchedule& schedule) noexcept { return cursor_.set_schedule(schedule); }
  HalStatus add_fault(const FaultEvent& event) noexcept { return cursor_.add_fault(event); }
  const FaultCounters& fault_counters() const noexcept { return cursor_.fault_counters(); }
  bool finished() const noexcept { return cursor_.finished(); }
  double next_due_s() const noexcept { return cursor_.next_due_s(); }  ///< replay_cursor.hpp
  GripperLimits limits() const noexcept override { return limits_; }

 protected:
  HalStatus on_configure() override;
  HalStatus on_start() noexcept override;
  HalStatus on_read(GripperReading& out) noexcept override;
  HalStatus on_write(const GripperCommand& command) noexcept override;

 private:
  const RecordedChannel& channel_;
  const Clock& clock_;
  ReplayTiming timing_;
  ReplayCursor cursor_;
  GripperLimits limits_;
};

class ReplayParticleObserver final : public ParticleObserver {
 public:
  /// dimension 2 or 3; the channel's width must be a multiple of it.
  ReplayParticleObserver(const RecordedChannel& channel, int dimension, const Clock& clock,
                         const ReplayTiming& timing = {}) noexcept
      : channel_(channel), dimension_(dimension), clock_(clock), timing_(timing) {}
  HalStatus set_fault_schedule(const FaultSchedule& schedule) noexcept { return cursor_.set_schedule(schedule); }
  HalStatus add_fault(const FaultEvent& event) noexcept { return cursor_.add_fault(event); }
  const FaultCounters& fault_counters() const noexcept { return cursor_.fault_counters(); }
  bool finished() const noexcept { return cursor_.finished(); }
  double next_due_s() const noexcept { return cursor_.next_due_s(); }  ///< replay_cursor.hpp
  /// The recorded frame the last delivered frame came from (-1 before the first).
  int last_index() const noexcept { return cursor_.last_index(); }

 protected:
  HalStatus on_configure() override;
  HalStatus on_start() noexcept override;
  HalStatus on_read(ParticleFrame& out) noexcept override;

 private:
  const RecordedChannel& channel_;
  int dimension_;
  const Clock& clock_;
  ReplayTiming timing_;
  ReplayCursor cursor_;
  std::vector<double> frame_;         ///< the delivered frame (occlusion applied)
  std::vector<int> occlusion_order_;  ///< particles by decreasing first-sample y
};

}  // namespace pliant::hal
