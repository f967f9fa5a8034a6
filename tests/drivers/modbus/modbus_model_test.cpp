// The emulator's Robotiq 2F model on its own: activation, motion at the commanded speed, stops
// on rigid and soft objects (force limit) or at the position, opening, stop, faults.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "pliant/drivers/modbus/emulator/robotiq_2f_model.hpp"

namespace pliant::drivers::modbus {
namespace {

namespace r2f = robotiq2f;

r2f::Command command(std::uint8_t action, std::uint8_t position = 0, std::uint8_t speed = 0, std::uint8_t force = 0) {
  r2f::Command c;
  c.action = action;
  c.position = position;
  c.speed = speed;
  c.force = force;
  return c;
}

constexpr std::uint8_t kGo = r2f::kActionActivate | r2f::kActionGoTo;

Robotiq2fModel activated_model(const Robotiq2fModelConfig& config = {}) {
  Robotiq2fModel m(config);
  m.write_command(command(r2f::kActionActivate));
  m.step(config.activation_time_s);
  return m;
}

TEST(Robotiq2fModel, Activation) {
  Robotiq2fModelConfig c;
  c.activation_time_s = 0.5;
  Robotiq2fModel m(c);
  EXPECT_EQ(m.status().gsta, r2f::kStaReset);
  m.write_command(command(r2f::kActionActivate));
  EXPECT_EQ(m.status().gsta, r2f::kStaActivating);
  m.step(0.49);
  EXPECT_EQ(m.status().gsta, r2f::kStaActivating);
  EXPECT_EQ(m.status().gact, 0);
  m.step(0.02);
  EXPECT_EQ(m.status().gsta, r2f::kStaActivated);
  EXPECT_EQ(m.status().gact, 1);
  EXPECT_DOUBLE_EQ(m.width_m(), 0.085);
  m.write_command(command(0));  // reset
  EXPECT_EQ(m.status().gsta, r2f::kStaReset);
  EXPECT_EQ(m.status().gact, 0);
}

TEST(Robotiq2fModel, MinorFaultsBeforeActivation) {
  Robotiq2fModel m;
  m.write_command(command(r2f::kActionGoTo, 255, 255, 255));  // rGTO without rACT
  EXPECT_EQ(m.status().gflt, r2f::kFaultActivationBitNotSet);
  m.write_command(command(kGo, 255, 255, 255));  // activating, asked to move
  EXPECT_EQ(m.status().gflt, r2f::kFaultActionDelayed);
  m.step(1.0);
  m.write_command(command(r2f::kActionActivate));
  EXPECT_EQ(m.status().gflt, 0);
}

TEST(Robotiq2fModel, ClosesAtTheCommandedSpeedToThePosition) {
  Robotiq2fModel m = activated_model();
  m.write_command(command(kGo, 255, 255, 0));  // fully closed at 150 mm/s
  EXPECT_TRUE(m.moving());
  m.step(0.1);
  EXPECT_NEAR(m.width_m(), 0.085 - 0.015, 1e-12);
  r2f::Status s = m.status();
  EXPECT_EQ(s.gobj, r2f::kObjMoving);
  EXPECT_EQ(s.ggto, 1);
  EXPECT_EQ(s.current, 5);  // 0.05 A moving current
  m.step(1.0);
  EXPECT_DOUBLE_EQ(m.width_m(), 0.0);
  s = m.status();
  EXPECT_EQ(s.gobj, r2f::kObjAtPosition);
  EXPECT_EQ(s.position, 255);
  EXPECT_EQ(s.position_request, 255);
  EXPECT_FALSE(m.moving());
  EXPECT_DOUBLE_EQ(m.grip_force_n(), 0.0);
}

TEST(Robotiq2fModel, RigidObjectStopsTheFingersWithObjectDetected) {
  Robotiq2fModelConfig c;
  c.object_width_m = 0.05;
  Robotiq2fModel m = activated_model(c);
  m.write_command(command(kGo, 255, 0, 51));  // 20 mm/s, force byte 51 = 63 N
  m.step(10.0);
  EXPECT_DOUBLE_EQ(m.width_m(), 0.05);
  const r2f::Status s = m.status();
  EXPECT_EQ(s.gobj, r2f::kObjContactClosing);
  EXPECT_NEAR(m.grip_force_n(), 20 + 51 * 215.0 / 255.0, 1e-9);
  EXPECT_EQ(s.current, static_cast<std::uint8_t>(std::lround(0.003 * m.grip_force_n() / 0.01)));
}

TEST(Robotiq2fModel, SoftObjectIsSqueezedUntilTheForceLimit) {
  Robotiq2fModelConfig c;
  c.object_width_m = 0.05;
  c.object_stiffness_n_per_m = 1000;  // 1 N/mm
  Robotiq2fModel m = activated_model(c);
  m.write_command(command(kGo, 255, 255, 0));  // force byte 0: 20 N
  m.step(0.1);
  EXPECT_NEAR(m.width_m(), 0.070, 1e-12);
  EXPECT_DOUBLE_EQ(m.grip_force_n(), 0.0);
  m.step(0.15);  // would reach 0.0475: inside the object, 2.5 N
  EXPECT_NEAR(m.width_m(), 0.0475, 1e-12);
  EXPECT_NEAR(m.grip_force_n(), 2.5, 1e-9);
  m.step(1.0);
  EXPECT_NEAR(m.width_m(), 0.03, 1e-12);  // 0.05 - 20 N / 1000 N/m
  EXPECT_NEAR(m.grip_force_n(), 20.0, 1e-9);
  EXPECT_EQ(m.status().gobj, r2f::kObjContactClosing);
  // A higher force limit continues the squeeze.
  m.write_command(command(kGo, 255, 255, 255));  // 235 N: the fingers close fully first
  m.step(1.0);
  EXPECT_DOUBLE_EQ(m.width_m(), 0.0);
  EXPECT_EQ(m.status().gobj, r2f::kObjAtPosition);
  EXPECT_NEAR(m.grip_force_n(), 50.0, 1e-9);
}

// An object of the caller's replaces the spring: a quadratic law F = q (w0 - w)^2 past w0.
class QuadraticObject final : public Robotiq2fObject {
 public:
  double force_n(double width_m) const noexcept override {
    const double c = kTouch - width_m;
    return c > 0 ? kGain * c * c : 0.0;
  }
  double width_at_force(double force_n) const noexcept override { return kTouch - std::sqrt(force_n / kGain); }
  static constexpr double kTouch = 0.06;  // m
  static constexpr double kGain = 1e5;    // N/m^2: 20 N at 14.1 mm closure
};

TEST(Robotiq2fModel, ObjectModelReplacesTheSpring) {
  Robotiq2fModelConfig c;
  c.object_width_m = 0.05;  // the spring: ignored while the object model is set
  c.object_stiffness_n_per_m = 1000;
  Robotiq2fModel m = activated_model(c);
  const QuadraticObject object;
  m.set_object_model(&object);
  m.write_command(command(kGo, 255, 255, 0));  // force byte 0: 20 N
  m.step(0.1);                                 // 150 mm/s: at 0.07, before the object
  EXPECT_NEAR(m.width_m(), 0.070, 1e-12);
  EXPECT_DOUBLE_EQ(m.grip_force_n(), 0.0);
  m.step(0.1);  // would reach 0.055: 5 mm into the object, 2.5 N
  EXPECT_NEAR(m.width_m(), 0.055, 1e-12);
  EXPECT_NEAR(m.grip_force_n(), 2.5, 1e-9);
  EXPECT_EQ(m.status().gobj, r2f::kObjMoving);
  EXPECT_EQ(m.status().current, static_cast<std::uint8_t>(std::lround((0.05 + 0.003 * 2.5) / 0.01)));
  m.step(1.0);  // stops where the object's force reaches 20 N
  EXPECT_NEAR(m.width_m(), QuadraticObject::kTouch - std::sqrt(20 / QuadraticObject::kGain), 1e-12);
  EXPECT_NEAR(m.grip_force_n(), 20.0, 1e-9);
  EXPECT_EQ(m.status().gobj, r2f::kObjContactClosing);
  // Without it the spring is back: at this width it pushes 1000 N/m x (0.05 - w).
  m.set_object_model(nullptr);
  EXPECT_NEAR(m.grip_force_n(), 1000 * (0.05 - m.width_m()), 1e-9);
}

TEST(Robotiq2fModel, PositionLimitedSqueezeEndsAtPosition) {
  Robotiq2fModelConfig c;
  c.object_width_m = 0.05;
  c.object_stiffness_n_per_m = 1000;
  Robotiq2fModel m = activated_model(c);
  const std::uint8_t p = r2f::width_to_position(0.04, c.scaling);
  m.write_command(command(kGo, p, 255, 255));
  m.step(1.0);
  EXPECT_NEAR(m.width_m(), r2f::position_to_width(p, c.scaling), 1e-12);
  EXPECT_EQ(m.status().gobj, r2f::kObjAtPosition);
  EXPECT_NEAR(m.grip_force_n(), 1000 * (0.05 - m.width_m()), 1e-9);
  // Opening releases the object.
  m.write_command(command(kGo, 0, 255, 0));
  m.step(1.0);
  EXPECT_DOUBLE_EQ(m.width_m(), 0.085);
  EXPECT_EQ(m.status().gobj, r2f::kObjAtPosition);
  EXPECT_DOUBLE_EQ(m.grip_force_n(), 0.0);
}

TEST(Robotiq2fModel, ClearingGotoStopsAndFaultsFreeze) {
  Robotiq2fModel m = activated_model();
  m.write_command(command(kGo, 255, 255, 0));
  m.step(0.1);
  m.write_command(command(r2f::kActionActivate, 255, 255, 0));
  m.step(1.0);
  EXPECT_NEAR(m.width_m(), 0.070, 1e-12);
  EXPECT_EQ(m.status().ggto, 0);
  EXPECT_EQ(m.status().gobj, r2f::kObjMoving);  // not meaningful without gGTO
  m.write_command(command(kGo, 255, 255, 0));
  m.step(0.1);
  m.set_fault(0x0e);
  m.step(1.0);
  EXPECT_NEAR(m.width_m(), 0.055, 1e-12);
  EXPECT_EQ(m.status().gflt, 0x0e);
  m.set_fault(0xa3);
  EXPECT_EQ(m.status().gflt, 0x03);
  EXPECT_EQ(m.status().kflt, 0x0a);
  m.set_fault(0);
  EXPECT_EQ(m.status().gflt, 0);
  m.step(1.0);
  EXPECT_NEAR(m.width_m(), 0.055, 1e-12);  // stays until the next command
  m.write_command(command(r2f::kActionActivate, 255, 255, 0));
  m.write_command(command(kGo, 255, 255, 0));
  m.step(1.0);
  EXPECT_DOUBLE_EQ(m.width_m(), 0.0);
  m.step(-1.0);
  m.step(std::numeric_limits<double>::quiet_NaN());
  EXPECT_DOUBLE_EQ(m.width_m(), 0.0);
}

}  // namespace
}  // namespace pliant::drivers::modbus
