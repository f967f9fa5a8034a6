// The Robotiq emulator's fingers squeezing the HIL plant: a Robotiq2fObject whose force is the
// SimulatedGrasp's grip-force law at the fingers' width, so the emulated gripper's current and
// object detection (gOBJ) come from the simulated soft object rather than its built-in spring.
//
// force_n(width)        = plant.force_at(plant.extent_m() - width)   (0 before contact)
// width_at_force(force) = the widest width whose force reaches `force`, by bisection on the
//                         closure over [0, extent x max_closure_fraction] (the plant's hard
//                         stop); NaN when the law stays below `force` up to there.
// Thread safety: both read only the plant's configuration (its force law and extent), which is
// fixed once configure() returned; safe from the emulator's server thread while the rig steps
// the plant. Allocation-free, noexcept.
#pragma once

#include "pliant/drivers/modbus/emulator/robotiq_2f_model.hpp"
#include "pliant/hal/mock/simulated_grasp.hpp"

namespace pliant::hil {

class PlantFinger final : public drivers::modbus::Robotiq2fObject {
 public:
  /// `plant` must be configured and outlive this object.
  explicit PlantFinger(const hal::SimulatedGrasp& plant) noexcept : plant_(plant) {}

  double force_n(double width_m) const noexcept override;
  double width_at_force(double force_n) const noexcept override;

 private:
  const hal::SimulatedGrasp& plant_;
};

}  // namespace pliant::hil
