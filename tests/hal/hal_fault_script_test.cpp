// Fault scripts: the text format, its every error with line and column, and a parsed script
// driving a mock.
#include <gtest/gtest.h>

#include <cstring>
#include <string>

#include "hal_fixture.hpp"
#include "pliant/hal/mock/fault_script.hpp"

namespace pliant::hal {
namespace {

HalStatus parse(const std::string& text, FaultScript& script, FaultScriptError& error) {
  return parse_fault_script(text.data(), text.size(), script, error);
}

TEST(HalFaultScript, ParsesEventsCommentsAndLineEndings) {
  const std::string text =
      "# a HIL fault script\n"
      "\n"
      "1.20 timeout gripper 0.05\r\n"
      "  1.5\tbus_off   ft 0.02   # CAN bus-off\n"
      "2 fault_bits gripper 0.1 0x0e00\n"
      "2.5 fault_bits ft 0.1 32\n"
      "3 stamp_jump observer 0.2 -0.25\n"
      "3.5 occlude observer 1e-1 0.5\n"
      "4 nan depth 0.1\n"
      "4 drop color 0.1";  // no final newline
  FaultScript script;
  FaultScriptError error;
  ASSERT_EQ(parse(text, script, error), HalStatus::ok) << error.line << ":" << error.column << " " << error.message;
  EXPECT_EQ(error.line, 0);
  EXPECT_EQ(script.events(), 8);
  const FaultSchedule& gripper = script.of(FaultDevice::gripper);
  ASSERT_EQ(gripper.size(), 2);
  EXPECT_EQ(gripper.event(0).kind, FaultKind::timeout);
  EXPECT_EQ(gripper.event(0).start_s, 1.2);
  EXPECT_EQ(gripper.event(0).duration_s, 0.05);
  EXPECT_TRUE(std::isnan(gripper.event(0).value));
  EXPECT_EQ(gripper.event(1).value, 3584.0);
  const FaultSchedule& ft = script.of(FaultDevice::force_torque);
  ASSERT_EQ(ft.size(), 2);
  EXPECT_EQ(ft.event(0).kind, FaultKind::bus_off);
  EXPECT_EQ(ft.event(1).value, 32.0);
  const FaultSchedule& observer = script.of(FaultDevice::observer);
  ASSERT_EQ(observer.size(), 2);
  EXPECT_EQ(observer.event(0).value, -0.25);
  EXPECT_EQ(observer.event(1).duration_s, 0.1);
  EXPECT_EQ(script.of(FaultDevice::depth_camera).event(0).kind, FaultKind::nan);
  EXPECT_EQ(script.of(FaultDevice::color_camera).event(0).kind, FaultKind::drop);
  EXPECT_EQ(parse("", script, error), HalStatus::ok);
  EXPECT_EQ(script.events(), 0);
  EXPECT_EQ(parse_fault_script(nullptr, 0, script, error), HalStatus::ok);
  EXPECT_STREQ(fault_device_name(FaultDevice::force_torque), "ft");
}

struct Malformed {
  const char* text;
  int line;
  int column;
  const char* message_part;
};

TEST(HalFaultScript, MalformedInputGivesLineColumnAndMessage) {
  const Malformed cases[] = {
      {"1 drop gripper", 1, 8, "too few fields"},
      {"1 drop gripper 0.1 2 3", 1, 22, "too many fields"},
      {"x drop gripper 0.1", 1, 1, "start time"},
      {"nan drop gripper 0.1", 1, 1, "start time"},
      {"inf drop gripper 0.1", 1, 1, "start time"},
      {"1e999 drop gripper 0.1", 1, 1, "start time"},
      {"+1 drop gripper 0.1", 1, 1, "start time"},
      {"1 dorp gripper 0.1", 1, 3, "unknown fault kind"},
      {"1 drop grabber 0.1", 1, 8, "unknown device"},
      {"1 bus_off gripper 0.1", 1, 3, "not supported"},
      {"1 occlude ft 0.1", 1, 3, "not supported"},
      {"1 nan color 0.1", 1, 3, "not supported"},
      {"1 drop gripper 0", 1, 16, "duration"},
      {"1 drop gripper -1", 1, 16, "duration"},
      {"1 drop gripper 0.1s", 1, 16, "duration"},
      {"1 fault_bits gripper 0.1 0x1ffffffff", 1, 26, "value"},
      {"1 fault_bits gripper 0.1 1.5", 1, 26, "value"},
      {"1 fault_bits gripper 0.1 0x", 1, 26, "value"},
      {"1 fault_bits gripper 0.1 -3", 1, 26, "value"},
      {"1 occlude observer 0.1 1.5", 1, 24, "out of range"},
      {"1 stamp_jump ft 0.1 nan", 1, 21, "value"},
      {"# ok\n1 drop gripper 0.1\n2 drop gripper", 3, 8, "too few fields"},
  };
  for (const Malformed& m : cases) {
    SCOPED_TRACE(m.text);
    FaultScript script;
    FaultScriptError error;
    EXPECT_EQ(parse(m.text, script, error), HalStatus::invalid_argument);
    EXPECT_EQ(error.line, m.line);
    EXPECT_EQ(error.column, m.column);
    EXPECT_NE(std::strstr(error.message, m.message_part), nullptr) << error.message;
  }
}

TEST(HalFaultScript, ReadsOnlyTheGivenBytesAndStopsAtCapacity) {
  // The length excludes the bad tail; an embedded NUL is just a bad byte.
  const std::string text = "1 drop gripper 0.1\n2 junk";
  FaultScript script;
  FaultScriptError error;
  EXPECT_EQ(parse_fault_script(text.data(), 19, script, error), HalStatus::ok);
  EXPECT_EQ(script.events(), 1);
  const std::string nul = std::string("1 drop gripper 0.1") + '\0' + "\n";
  EXPECT_EQ(parse(nul, script, error), HalStatus::invalid_argument);
  EXPECT_EQ(error.column, 16);
  std::string many;
  for (int i = 0; i <= kFaultCapacity; ++i) many += std::to_string(i) + " drop ft 0.1\n";
  EXPECT_EQ(parse(many, script, error), HalStatus::capacity_exceeded);
  EXPECT_EQ(error.line, kFaultCapacity + 1);
  EXPECT_EQ(script.of(FaultDevice::force_torque).size(), kFaultCapacity);
  EXPECT_EQ(parse_fault_script(nullptr, 5, script, error), HalStatus::invalid_argument);
}

TEST(HalFaultScript, AParsedScriptDrivesAMock) {
  const std::string text = "1.0105 timeout gripper 0.003\n1.0205 nan gripper 0.002\n";
  FaultScript script;
  FaultScriptError error;
  ASSERT_EQ(parse(text, script, error), HalStatus::ok);
  test::SteppedClock t;
  SimulatedGrasp plant(t.clock);
  ASSERT_EQ(plant.configure(test::small_grasp()), HalStatus::ok);
  MockGripper gripper(plant, t.clock);
  ASSERT_EQ(gripper.set_fault_schedule(script.of(FaultDevice::gripper)), HalStatus::ok);
  ASSERT_EQ(gripper.configure(), HalStatus::ok);
  ASSERT_EQ(gripper.start(), HalStatus::ok);
  GripperReading r;
  for (int k = 1; k <= 30; ++k) {
    t.step();
    (void)gripper.read(r);
  }
  EXPECT_EQ(gripper.fault_counters().of(FaultKind::timeout), 3u);
  EXPECT_EQ(gripper.fault_counters().of(FaultKind::nan), 2u);
  // A schedule the device cannot run is refused at configure.
  MockGripper other(plant, t.clock);
  FaultSchedule bus_off;
  FaultEvent e;
  e.kind = FaultKind::bus_off;
  e.duration_s = 1;
  ASSERT_EQ(bus_off.add(e), HalStatus::ok);
  ASSERT_EQ(other.set_fault_schedule(bus_off), HalStatus::ok);  // not configured yet: checked at configure
  EXPECT_EQ(other.configure(), HalStatus::unsupported);
}

}  // namespace
}  // namespace pliant::hal
