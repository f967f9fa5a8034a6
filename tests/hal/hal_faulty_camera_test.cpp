// FaultyColorCamera / FaultyDepthCamera (hal/mock/faulty_cameras.hpp): scripted faults on another
// camera's frames. The inner cameras here are the fault-free mocks, so every effect seen is the
// wrapper's; tests/drivers/opencv and tests/drivers/openni2 wrap real media players.
#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

#include "hal_fixture.hpp"
#include "pliant/hal/mock/fault_script.hpp"
#include "pliant/hal/mock/faulty_cameras.hpp"
#include "pliant/hal/mock/mock_cameras.hpp"

namespace pliant::hal {
namespace {

using test::SteppedClock;

FaultSchedule script_for(const std::string& text, FaultDevice device) {
  FaultScript script;
  FaultScriptError error;
  EXPECT_EQ(parse_fault_script(text.data(), text.size(), script, error), HalStatus::ok) << error.message;
  return script.of(device);
}

// Frames every 10 ms from t = 1.0 (frame k captured at 1.0 + 0.01 k), read once per frame.
TEST(HalFaultyCameras, DepthFaultsFromAScriptAreAppliedAndCounted) {
  SteppedClock t;
  MockDepthCameraConfig c;
  c.width = 16;
  c.height = 12;
  c.period_s = 0.010;
  MockDepthCamera inner(t.clock, c);
  FaultyDepthCamera camera(inner, t.clock, 16 * 12 * 2);
  // Frame 1 dropped, frame 2 all zero, frame 4 with frame 3's pixels, frame 5 a copy of the
  // delivered frame 4 (stamp included), frame 6 stamped 0.25 s late with a fault bit; the reads
  // at 1.07 and 1.08 disconnected, the one at 1.10 a timeout.
  const FaultSchedule schedule = script_for(
      "1.005 drop depth 0.01\n"
      "1.015 nan depth 0.01\n"
      "1.035 freeze_data depth 0.01\n"
      "1.045 freeze_stamp depth 0.01\n"
      "1.055 stamp_jump depth 0.01 0.25\n"
      "1.055 fault_bits depth 0.01\n"
      "1.062 disconnect depth 0.025\n"
      "1.095 timeout depth 0.01\n",
      FaultDevice::depth_camera);
  ASSERT_EQ(camera.set_fault_schedule(schedule), HalStatus::ok);
  ASSERT_EQ(camera.configure(), HalStatus::ok);
  ASSERT_EQ(inner.state(), LifecycleState::inactive);
  ASSERT_EQ(camera.start(), HalStatus::ok);
  ASSERT_EQ(inner.state(), LifecycleState::active);

  t.period_s = 0.001;
  std::vector<HalStatus> statuses;
  std::vector<DepthFrame> frames;
  std::vector<std::vector<std::uint16_t>> pixels;
  for (int k = 0; k <= 11; ++k) {
    if (k > 0) t.step(10);
    DepthFrame f;
    const HalStatus s = camera.read(f);
    statuses.push_back(s);
    frames.push_back(f);
    pixels.emplace_back(s == HalStatus::ok ? std::vector<std::uint16_t>(f.data, f.data + 16 * 12)
                                           : std::vector<std::uint16_t>());
  }
  EXPECT_EQ(statuses[0], HalStatus::ok);
  EXPECT_EQ(statuses[1], HalStatus::no_data);  // dropped
  ASSERT_EQ(statuses[2], HalStatus::ok);
  for (std::uint16_t d : pixels[2]) EXPECT_EQ(d, 0);  // nan: no measurement
  ASSERT_EQ(statuses[3], HalStatus::ok);
  for (std::uint16_t d : pixels[3]) EXPECT_GT(d, 0);  // back to normal
  ASSERT_EQ(statuses[4], HalStatus::ok);
  EXPECT_EQ(pixels[4], pixels[3]);                    // freeze_data: frame 3's pixels
  EXPECT_NEAR(frames[4].header.stamp_s, 1.04, 1e-9);  // under its own stamp
  EXPECT_EQ(frames[4].header.sequence, frames[3].header.sequence + 1);
  ASSERT_EQ(statuses[5], HalStatus::ok);
  EXPECT_EQ(pixels[5], pixels[3]);  // freeze_stamp: the previous delivered frame, stamp included
  EXPECT_NEAR(frames[5].header.stamp_s, frames[4].header.stamp_s, 1e-12);
  EXPECT_EQ(frames[5].header.sequence, frames[4].header.sequence + 1);
  ASSERT_EQ(statuses[6], HalStatus::ok);
  EXPECT_NEAR(frames[6].header.stamp_s, 1.06 + 0.25, 1e-9);
  EXPECT_EQ(frames[6].header.status_bits & kFrameDeviceFault, kFrameDeviceFault);
  EXPECT_EQ(statuses[7], HalStatus::disconnected);
  EXPECT_EQ(statuses[8], HalStatus::disconnected);
  ASSERT_EQ(statuses[9], HalStatus::ok);  // back: the newest frame (frames 7 and 8 lost)
  EXPECT_EQ(frames[9].header.sequence, frames[6].header.sequence + 3);
  EXPECT_EQ(statuses[10], HalStatus::timeout);
  EXPECT_EQ(statuses[11], HalStatus::ok);

  const FaultCounters& n = camera.fault_counters();
  EXPECT_EQ(n.of(FaultKind::drop), 1u);
  EXPECT_EQ(n.of(FaultKind::nan), 1u);
  EXPECT_EQ(n.of(FaultKind::freeze_data), 1u);
  EXPECT_EQ(n.of(FaultKind::freeze_stamp), 1u);
  EXPECT_EQ(n.of(FaultKind::stamp_jump), 1u);
  EXPECT_EQ(n.of(FaultKind::fault_bits), 1u);
  EXPECT_EQ(n.of(FaultKind::disconnect), 2u);
  EXPECT_EQ(n.of(FaultKind::timeout), 1u);
  // The consumer's counters: the dropped frame, the two lost while disconnected and the one
  // lost to the timeout are gaps; one reconnect, one fault sample; the inner camera saw none.
  const DeviceCounters& seen = camera.counters();
  EXPECT_EQ(seen.dropped, 4u);
  EXPECT_EQ(seen.disconnected, 2u);
  EXPECT_EQ(seen.disconnects, 1u);
  EXPECT_EQ(seen.reconnects, 1u);
  EXPECT_EQ(seen.timeouts, 1u);
  EXPECT_EQ(seen.fault_samples, 1u);
  EXPECT_EQ(inner.counters().faults(), 0u);
  EXPECT_EQ(camera.oversized_frames(), 0u);
  ASSERT_EQ(camera.stop(), HalStatus::ok);
  EXPECT_EQ(inner.state(), LifecycleState::inactive);
  ASSERT_EQ(camera.cleanup(), HalStatus::ok);
  EXPECT_EQ(inner.state(), LifecycleState::unconfigured);
}

TEST(HalFaultyCameras, ColourFramesFreezeBitForBitAndRefuseNan) {
  SteppedClock t;
  MockColorCameraConfig c;
  c.width = 8;
  c.height = 6;
  c.period_s = 0.010;
  MockColorCamera inner(t.clock, c);
  FaultyColorCamera camera(inner, t.clock, 8 * 6 * 3);
  EXPECT_EQ(camera.set_fault_schedule(script_for("1.0 nan depth 1\n", FaultDevice::depth_camera)),
            HalStatus::unsupported);
  FaultSchedule bus_off;
  FaultEvent e;
  e.kind = FaultKind::bus_off;
  e.start_s = 1;
  e.duration_s = 1;
  ASSERT_EQ(bus_off.add(e), HalStatus::ok);
  EXPECT_EQ(camera.set_fault_schedule(bus_off), HalStatus::unsupported);
  ASSERT_EQ(camera.set_fault_schedule(script_for("1.015 freeze_data color 0.02\n", FaultDevice::color_camera)),
            HalStatus::ok);
  ASSERT_EQ(camera.configure(), HalStatus::ok);
  ASSERT_EQ(camera.start(), HalStatus::ok);
  t.period_s = 0.001;
  std::vector<std::vector<std::uint8_t>> pixels;
  for (int k = 0; k <= 4; ++k) {
    if (k > 0) t.step(10);
    ColorFrame f;
    ASSERT_EQ(camera.read(f), HalStatus::ok) << k;
    pixels.emplace_back(f.data, f.data + f.height * f.stride_bytes);
  }
  EXPECT_NE(pixels[1], pixels[0]);  // the gradient moves every frame
  EXPECT_EQ(pixels[2], pixels[1]);  // frozen for frames 2 and 3
  EXPECT_EQ(pixels[3], pixels[1]);
  EXPECT_NE(pixels[4], pixels[3]);
  EXPECT_EQ(camera.fault_counters().of(FaultKind::freeze_data), 2u);
}

// A frame larger than the wrapper's buffers is passed through untouched and counted.
TEST(HalFaultyCameras, OversizedFramesPassUntouched) {
  SteppedClock t;
  MockDepthCameraConfig c;
  c.width = 16;
  c.height = 12;
  c.period_s = 0.010;
  MockDepthCamera inner(t.clock, c);
  FaultyDepthCamera camera(inner, t.clock, 64);  // 32 pixels
  ASSERT_EQ(camera.set_fault_schedule(script_for("1.0 nan depth 1\n", FaultDevice::depth_camera)), HalStatus::ok);
  ASSERT_EQ(camera.configure(), HalStatus::ok);
  ASSERT_EQ(camera.start(), HalStatus::ok);
  DepthFrame f;
  ASSERT_EQ(camera.read(f), HalStatus::ok);
  EXPECT_GT(f.data[0], 0);
  EXPECT_EQ(camera.oversized_frames(), 1u);
  EXPECT_EQ(camera.fault_counters().of(FaultKind::nan), 0u);
}

}  // namespace
}  // namespace pliant::hal
