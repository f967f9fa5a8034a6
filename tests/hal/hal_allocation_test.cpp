// No-heap proof for the HAL's per-cycle paths: reads and writes of every mock (with faults
// being injected), the plant's sync, the stream monitor, the guard-input conversions and the
// fault-script parser make zero heap allocations once configured.
#include "support/counting_allocator.hpp"  // first: configures eigen_assert before any Eigen header

#include <gtest/gtest.h>

#include <string>

#include "hal_fixture.hpp"
#include "pliant/hal/guard_inputs.hpp"
#include "pliant/hal/mock/fault_script.hpp"
#include "pliant/hal/mock/faulty_cameras.hpp"
#include "pliant/hal/mock/mock_cameras.hpp"
#include "pliant/hal/mock/replay_devices.hpp"
#include "pliant/hal/stream_monitor.hpp"

namespace pliant::hal {
namespace {

using pliant::test::AllocationCounter;
using pliant::test::AllocationCounts;

TEST(HalAllocation, DeviceCyclesAllocateNothing) {
  test::SteppedClock t;
  SimulatedGrasp plant(t.clock);
  ASSERT_EQ(plant.configure(test::small_grasp()), HalStatus::ok);
  MockGripper gripper(plant, t.clock);
  MockForceTorqueSensor ft(plant, t.clock);
  MockParticleObserverConfig oc;
  oc.latency_s = 0.02;
  oc.occlusion_fraction = 0.2;
  MockParticleObserver observer(plant, t.clock, oc);
  MockColorCamera color(t.clock);
  MockDepthCamera depth(t.clock);
  const std::string script =
      "1.05 freeze_data gripper 0.01\n1.1 nan ft 0.01\n1.15 bus_off ft 0.01\n1.2 timeout gripper 0.01\n"
      "1.25 disconnect observer 0.05\n1.3 freeze_stamp observer 0.1\n1.35 fault_bits gripper 0.02\n"
      "1.4 stamp_jump color 0.1\n1.45 nan depth 0.1\n1.5 occlude observer 0.1\n";
  FaultScript faults;
  FaultScriptError error;
  ASSERT_EQ(parse_fault_script(script.data(), script.size(), faults, error), HalStatus::ok);
  ASSERT_EQ(gripper.set_fault_schedule(faults.of(FaultDevice::gripper)), HalStatus::ok);
  ASSERT_EQ(ft.set_fault_schedule(faults.of(FaultDevice::force_torque)), HalStatus::ok);
  ASSERT_EQ(observer.set_fault_schedule(faults.of(FaultDevice::observer)), HalStatus::ok);
  ASSERT_EQ(color.set_fault_schedule(faults.of(FaultDevice::color_camera)), HalStatus::ok);
  ASSERT_EQ(depth.set_fault_schedule(faults.of(FaultDevice::depth_camera)), HalStatus::ok);
  for (Device* d : {static_cast<Device*>(&gripper), static_cast<Device*>(&ft), static_cast<Device*>(&observer),
                    static_cast<Device*>(&color), static_cast<Device*>(&depth)}) {
    ASSERT_EQ(d->configure(), HalStatus::ok);
    ASSERT_EQ(d->start(), HalStatus::ok);
  }
  StreamMonitor monitor;
  GripperReading g;
  WrenchReading w;
  ParticleFrame p;
  ColorFrame c;
  DepthFrame d;
  GraspGuardInput in;
  long delivered = 0;
  AllocationCounts counts;
  {
    AllocationCounter counter;
    (void)gripper.move_to(0.030, 0.004, 20);  // into contact: the plant relaxes every period
    for (int k = 0; k < 700; ++k) {
      t.step();
      const HalStatus gs = gripper.read(g);
      update_gripper_sample(gs, g, 0, in.gripper);
      const HalStatus ws = ft.read(w);
      update_wrench_sample(ws, w, ws == HalStatus::ok ? monitor.check(w.header, w.wrench, 6) : 0u, in.wrench);
      if (observer.read(p) == HalStatus::ok) ++delivered;
      delivered += color.read(c) == HalStatus::ok ? 1 : 0;
      delivered += depth.read(d) == HalStatus::ok ? 1 : 0;
      if (k == 300) (void)gripper.freeze();
      if (k == 400) (void)gripper.open(0.01);
    }
    (void)parse_fault_script(script.data(), script.size(), faults, error);
    counts = counter.stop();
  }
  EXPECT_EQ(counts.total(), 0u) << "news=" << counts.news << " mallocs=" << counts.mallocs;
  EXPECT_GT(delivered, 40);
  EXPECT_GT(plant.counters().msm_steps, 1000u);
  EXPECT_GT(gripper.fault_counters().total() + ft.fault_counters().total() + observer.fault_counters().total(), 0u);
}

// The fault wrappers of real cameras (here around fault-free mocks): every sample fault kind,
// with the frame copies the freeze kinds need.
TEST(HalAllocation, FaultyCameraReadsAllocateNothing) {
  test::SteppedClock t;
  MockColorCamera color_inner(t.clock);
  MockDepthCamera depth_inner(t.clock);
  FaultyColorCamera color(color_inner, t.clock, 64 * 48 * 3);
  FaultyDepthCamera depth(depth_inner, t.clock, 64 * 48 * 2);
  const std::string script =
      "1.02 drop color 0.02\n1.05 freeze_data color 0.05\n1.12 freeze_stamp color 0.05\n1.2 disconnect color 0.05\n"
      "1.02 nan depth 0.05\n1.1 freeze_data depth 0.05\n1.17 stamp_jump depth 0.05\n1.25 fault_bits depth 0.05\n"
      "1.3 timeout depth 0.02\n";
  FaultScript faults;
  FaultScriptError error;
  ASSERT_EQ(parse_fault_script(script.data(), script.size(), faults, error), HalStatus::ok) << error.message;
  ASSERT_EQ(color.set_fault_schedule(faults.of(FaultDevice::color_camera)), HalStatus::ok);
  ASSERT_EQ(depth.set_fault_schedule(faults.of(FaultDevice::depth_camera)), HalStatus::ok);
  ASSERT_EQ(color.configure(), HalStatus::ok);
  ASSERT_EQ(depth.configure(), HalStatus::ok);
  ASSERT_EQ(color.start(), HalStatus::ok);
  ASSERT_EQ(depth.start(), HalStatus::ok);
  ColorFrame c;
  DepthFrame d;
  long delivered = 0;
  AllocationCounts counts;
  {
    AllocationCounter counter;
    for (int k = 0; k < 400; ++k) {
      t.step();
      delivered += color.read(c) == HalStatus::ok ? 1 : 0;
      delivered += depth.read(d) == HalStatus::ok ? 1 : 0;
    }
    counts = counter.stop();
  }
  EXPECT_EQ(counts.total(), 0u) << "news=" << counts.news << " mallocs=" << counts.mallocs;
  EXPECT_GT(delivered, 10);
  for (FaultKind kind : {FaultKind::drop, FaultKind::freeze_data, FaultKind::freeze_stamp, FaultKind::disconnect}) {
    EXPECT_GT(color.fault_counters().of(kind), 0u) << fault_kind_name(kind);
  }
  for (FaultKind kind :
       {FaultKind::nan, FaultKind::freeze_data, FaultKind::stamp_jump, FaultKind::fault_bits, FaultKind::timeout}) {
    EXPECT_GT(depth.fault_counters().of(kind), 0u) << fault_kind_name(kind);
  }
}

TEST(HalAllocation, ReplayReadsAllocateNothing) {
  RecordedChannel wrench, gripper, particles;
  wrench.width = 6;
  gripper.width = 2;
  particles.width = 3 * 20;
  for (int k = 0; k < 200; ++k) {
    const double t = 0.01 * k;
    wrench.t_s.push_back(t);
    gripper.t_s.push_back(t);
    particles.t_s.push_back(t);
    for (int a = 0; a < 6; ++a) wrench.values.push_back(a + t);
    gripper.values.push_back(0.05 - 1e-4 * k);
    gripper.values.push_back(0.1 * k);
    for (int a = 0; a < particles.width; ++a) particles.values.push_back(0.001 * a + t);
  }
  test::SteppedClock t;
  ReplayForceTorque ft(wrench, t.clock);
  ReplayGripper g(gripper, t.clock);
  ReplayParticleObserver o(particles, 3, t.clock);
  const std::string script =
      "1.2 nan ft 0.1\n1.3 occlude observer 0.2\n1.4 freeze_stamp gripper 0.1\n1.6 timeout ft 0.05\n";
  FaultScript faults;
  FaultScriptError error;
  ASSERT_EQ(parse_fault_script(script.data(), script.size(), faults, error), HalStatus::ok);
  ASSERT_EQ(ft.set_fault_schedule(faults.of(FaultDevice::force_torque)), HalStatus::ok);
  ASSERT_EQ(g.set_fault_schedule(faults.of(FaultDevice::gripper)), HalStatus::ok);
  ASSERT_EQ(o.set_fault_schedule(faults.of(FaultDevice::observer)), HalStatus::ok);
  for (Device* d : {static_cast<Device*>(&ft), static_cast<Device*>(&g), static_cast<Device*>(&o)}) {
    ASSERT_EQ(d->configure(), HalStatus::ok);
    ASSERT_EQ(d->start(), HalStatus::ok);
  }
  WrenchReading w;
  GripperReading gr;
  ParticleFrame p;
  long delivered = 0;
  AllocationCounts counts;
  {
    AllocationCounter counter;
    for (int k = 0; k < 2500; ++k) {
      t.step();
      delivered += ft.read(w) == HalStatus::ok ? 1 : 0;
      delivered += g.read(gr) == HalStatus::ok ? 1 : 0;
      delivered += o.read(p) == HalStatus::ok ? 1 : 0;
      (void)g.freeze();
    }
    counts = counter.stop();
  }
  EXPECT_EQ(counts.total(), 0u) << "news=" << counts.news << " mallocs=" << counts.mallocs;
  EXPECT_GT(delivered, 500);
  EXPECT_TRUE(ft.finished() && g.finished() && o.finished());
}

}  // namespace
}  // namespace pliant::hal
