// The grasp guard's HIL through the real stacks (issue 20, items 1 and 2; docs/hil_wire.md).
//
// The HIL supervisor closes a Robotiq 2F-85 over Modbus TCP (RobotiqGripper against the modbus
// emulator's server thread on 127.0.0.1, its fingers squeezing the simulated object) and reads an
// ATI NETCANOEM finger sensor over CAN (AtiNetCanForceTorque against the ATI emulator on a
// SOCK_SEQPACKET pair, gauges from the object's grip force), on a stepped 1 kHz clock.
//
// 1. Soft to stiff: the HAL HIL's 12 objects (4 under the sanitizers). Each time the guard says
//    limit or stop before the true strain reaches the object's limit, the peak true strain stays
//    within 5 % over it, and the grasp really squeezed (peak > half the limit).
// 2. Faults on the wire (wire_faults.hpp), each at two points of the squeeze (one under the
//    sanitizers) on two objects: the verdict was ok just before, is not ok in the onset cycle or
//    the next (within 2 cycles), the stack counted the fault, every source is free of faults
//    again within kRecoveryCycles of the fault clearing, and the object is never strained more
//    than 5 % past its limit.
// 3. No allocation: the supervisor's cycles through the drivers, faults included, touch no heap.
#include "support/counting_allocator.hpp"  // first: configures eigen_assert before any Eigen header

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "grasp_log.hpp"
#include "wire_faults.hpp"
#include "wire_rig.hpp"

namespace pliant::hil {
namespace {

constexpr double kMaxOvershoot = 0.05;
constexpr long kMaxLatencyCycles = 1;  // not ok in the onset cycle or the next
constexpr long kHoldCycles = 600;      // after the first not-ok verdict
constexpr long kMaxCycles = 8000;
constexpr long kRecoveryCycles = 300;  // camera faults need clear_samples (5) new frames at 30 Hz

/// Steps until `done(log)` or kMaxCycles; `each(cycle, report)` after every step.
template <typename Each, typename Done>
GraspLog run(WireRig& rig, Each&& each, Done&& done) {
  GraspLog log;
  while (log.cycles < kMaxCycles && !log.failed) {
    const CycleReport& r = rig.step();
    log.record(r, rig.plant, rig.held_at_safe_width(r.out));
    each(log.cycles - 1, r);
    if (done(log)) break;
  }
  return log;
}

/// Under the sanitizers (tests/hil_wire/CMakeLists.txt) the sweeps take a subset: the drivers and
/// the guard run the same code, a third as often.
bool reduced() {
#if defined(PLIANT_HIL_REDUCED)
  return true;
#else
  return false;
#endif
}

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

TEST(HilWire, SoftToStiffObjectsStopBeforeTheirLimit) {
  std::vector<HilObject> objects = hil_objects();
  ASSERT_GE(objects.size(), 10u);
  if (reduced()) objects = {objects[2], objects[5], objects[8], objects[11]};  // beta 0.75, 0.5, 0.25, 0.1
  const WireOptions options;
  std::printf(
      "\nWire HIL: Robotiq 2F-85 over Modbus TCP, ATI NETCANOEM over CAN (seqpacket), 1 kHz; strain margin %.0f %%\n",
      100 * options.strain_margin);
  std::printf("%-16s %5s %6s %8s %8s %9s %-18s %-16s %6s %6s %7s %7s\n", "object", "beta", "limit", "at stop", "peak",
              "overshoot", "stopped by", "verdict at end", "squeeze", "cycles", "modbus", "CAN");
  double worst = -1;
  const auto start = std::chrono::steady_clock::now();
  for (const HilObject& object : objects) {
    SCOPED_TRACE(object.name);
    WireRig rig(object, options);
    ASSERT_EQ(rig.status(), hal::HalStatus::ok);
    const GraspLog g = run(
        rig, [](long, const CycleReport&) {}, [](const GraspLog& l) { return l.since_stop() >= kHoldCycles; });
    ASSERT_FALSE(g.failed);
    const double overshoot = g.peak / object.max_strain - 1;
    worst = std::max(worst, overshoot);
    std::printf("%-16s %5.2f %6.3f %8.4f %8.4f %8.1f%% %-18s %-6s/%-9s %6ld %6ld %7llu %7llu\n", object.name.c_str(),
                object.object.msm_beta, object.max_strain, g.strain_at_stop, g.peak, 100 * overshoot,
                g.stopped_by_verdict ? guard_reason_name(g.first_reason) : "safe width",
                grasp_verdict_name(g.final_verdict), guard_reason_name(g.final_reason),
                g.first_stop >= 0 && g.contact >= 0 ? g.first_stop - g.contact : -1L, g.cycles,
                static_cast<unsigned long long>(rig.gripper->link_counters().transactions),
                static_cast<unsigned long long>(rig.sensor->link_counters().frames_received));
    ASSERT_GE(g.contact, 0) << "never touched the object";
    ASSERT_GE(g.first_stop, 0) << "the guard never stopped the squeeze";
    EXPECT_LT(g.strain_at_stop, object.max_strain);
    if (g.first_not_ok >= 0) {
      EXPECT_LT(g.strain_at_first, object.max_strain);
    }
    EXPECT_LE(g.peak, (1 + kMaxOvershoot) * object.max_strain);
    EXPECT_GT(g.peak, 0.5 * object.max_strain) << "the grasp never squeezed (the test would pass vacuously)";
    EXPECT_EQ(rig.plant.counters().step_errors, 0u);
    EXPECT_EQ(rig.gripper->link_counters().failures, 0u) << "a Modbus transaction failed without a fault";
    EXPECT_EQ(rig.sensor->protocol_counters().unanswered_polls, 0u);
  }
  std::printf("worst overshoot over the limit: %.1f %% (allowed %.0f %%); wall time %.1f s\n", 100 * worst,
              100 * kMaxOvershoot, seconds_since(start));
}

// --- faults on the wire ---------------------------------------------------------------------------

struct FaultRun {
  long onset = -1;      ///< first cycle the fault acts on (or, camera, the first faulty frame)
  long detected = -1;   ///< first cycle from the onset with a not-ok verdict
  long recovered = -1;  ///< cycles from the clearing to the first cycle free of faults
  bool ok_before = false;
  std::uint64_t counted = 0;  ///< the stack's counter of the fault, moved by this much
  GraspVerdict verdict = GraspVerdict::ok;
  GuardReason reason = GuardReason::none;
  GraspLog log;
};

/// A grasp of `object` with fault `f` injected before cycle `inject_cycle`.
FaultRun run_fault(const HilObject& object, const WireOptions& options, const WireFault& f, long inject_cycle) {
  FaultRun out;
  WireRig rig(object, options);
  if (rig.status() != hal::HalStatus::ok) return out;
  GraspVerdict previous = GraspVerdict::stop;
  std::uint64_t counted0 = 0, delivered0 = 0;
  long injected = -1, cleared = -1;
  out.log = run(
      rig,
      [&](long c, const CycleReport& r) {
        if (injected >= 0 && out.onset < 0 &&
            (f.delivered == nullptr ? c == injected + 1 : f.delivered(rig) > delivered0)) {
          out.onset = c;
          out.ok_before = previous == GraspVerdict::ok;
        }
        if (out.onset >= 0 && out.detected < 0 && r.guarded && r.out.verdict != GraspVerdict::ok) {
          out.detected = c;
          out.verdict = r.out.verdict;
          out.reason = r.out.reason;
        }
        if (cleared >= 0 && out.recovered < 0 && c > cleared && r.out.fault_sources == 0) out.recovered = c - cleared;
        previous = r.guarded ? r.out.verdict : GraspVerdict::stop;
        if (c + 1 == inject_cycle) {  // the fault acts from the next step on
          counted0 = f.counted(rig);
          delivered0 = f.delivered != nullptr ? f.delivered(rig) : 0;
          f.inject(rig);
          injected = c;
        }
        if (injected >= 0 && c == injected + f.hold_cycles) {
          if (f.clear != nullptr) f.clear(rig);
          cleared = c;
        }
      },
      [&](const GraspLog& l) {
        const long c = l.cycles - 1;
        return cleared >= 0 && (c > cleared + kRecoveryCycles || (out.recovered >= 0 && c >= out.onset + 100));
      });
  out.counted = f.counted(rig) - counted0;
  return out;
}

struct FaultRow {
  long runs = 0;
  long worst_latency = -1;
  long worst_recovery = -1;
  std::uint64_t least_counted = ~std::uint64_t{0};
  GraspVerdict verdict = GraspVerdict::ok;
  GuardReason reason = GuardReason::none;
};

TEST(HilWire, EveryWireFaultIsNotOkWithinTwoCyclesAndRecovers) {
  const std::vector<HilObject> all = hil_objects();
  const std::vector<HilObject> objects = {all[2], all[8]};  // beta 0.75 and 0.25
  std::vector<double> fractions = {0.25, 0.65};
  if (reduced()) fractions = {0.5};
  WireOptions options;
  options.base.prediction_beta_points = 6;  // the latency does not depend on the table's resolution
  options.base.prediction_closure_points = 16;
  const std::vector<WireFault> faults = wire_faults();
  std::vector<FaultRow> rows(faults.size());
  const auto start = std::chrono::steady_clock::now();
  for (const HilObject& object : objects) {
    WireRig nominal(object, options);
    ASSERT_EQ(nominal.status(), hal::HalStatus::ok);
    const GraspLog base = run(
        nominal, [](long, const CycleReport&) {}, [](const GraspLog& l) { return l.first_stop >= 0; });
    ASSERT_GE(base.first_stop, 0) << object.name;
    for (std::size_t k = 0; k < faults.size(); ++k) {
      for (double fraction : fractions) {
        SCOPED_TRACE(object.name + " / " + faults[k].name + " at " + std::to_string(fraction));
        const long at =
            base.contact + static_cast<long>(fraction * static_cast<double>(base.first_stop - base.contact));
        const FaultRun r = run_fault(object, options, faults[k], at);
        ASSERT_GE(r.onset, 0) << "the fault never reached the supervisor";
        EXPECT_TRUE(r.ok_before) << "the verdict was not ok before the fault: the latency would mean nothing";
        ASSERT_GE(r.detected, 0) << "the fault was never detected";
        EXPECT_LE(r.detected - r.onset, kMaxLatencyCycles);
        EXPECT_GT(r.counted, 0u) << "the stack did not count the fault";
        EXPECT_GE(r.recovered, 0) << "still faulted " << kRecoveryCycles << " cycles after the fault cleared";
        EXPECT_LE(r.log.peak, (1 + kMaxOvershoot) * object.max_strain);
        FaultRow& row = rows[k];
        if (r.detected - r.onset > row.worst_latency) {
          row.verdict = r.verdict;
          row.reason = r.reason;
        }
        row.worst_latency = std::max(row.worst_latency, r.detected - r.onset);
        row.worst_recovery = std::max(row.worst_recovery, r.recovered);
        row.least_counted = std::min(row.least_counted, r.counted);
        ++row.runs;
      }
    }
  }
  std::printf(
      "\nWire HIL faults (%zu objects x %zu onsets; latency = cycles from onset to not ok; recovery = cycles "
      "from the fault clearing to no fault)\n",
      objects.size(), fractions.size());
  std::printf("%-24s %-8s %-22s %4s %7s %7s %8s  %s\n", "fault", "device", "injected", "runs", "latency", "counted",
              "recovery", "verdict / reason");
  for (std::size_t k = 0; k < faults.size(); ++k) {
    const FaultRow& row = rows[k];
    std::printf("%-24s %-8s %-22s %4ld %7ld %7llu %8ld  %s / %s\n", faults[k].name, wire_device_name(faults[k].device),
                faults[k].injected, row.runs, row.worst_latency, static_cast<unsigned long long>(row.least_counted),
                row.worst_recovery, grasp_verdict_name(row.verdict), guard_reason_name(row.reason));
  }
  std::printf("wall time %.1f s\n", seconds_since(start));
}

// After learning, the supervisor's cycles through both drivers allocate nothing, faults included
// (a Modbus timeout, an exception answer, a damaged answer, a TCP drop and reconnect, the gripper's
// fault byte, a CAN bus-off and restart).
TEST(HilWire, SupervisorCyclesThroughTheDriversAllocateNothing) {
  const HilObject object = hil_objects()[4];
  WireRig rig(object, WireOptions{});
  ASSERT_EQ(rig.status(), hal::HalStatus::ok);
  while (rig.supervisor->phase() == Phase::learning) rig.step();
  ASSERT_EQ(rig.supervisor->phase(), Phase::approach);
  const std::vector<WireFault> faults = wire_faults();
  long not_ok = 0;
  test::AllocationCounts counts;
  {
    test::AllocationCounter counter;
    for (int c = 0; c < 2500; ++c) {
      if (c % 400 == 200) {
        const WireFault& f = faults[static_cast<std::size_t>(c / 400) % faults.size()];
        f.inject(rig);
        for (long h = 0; h < f.hold_cycles; ++h) not_ok += rig.step().out.verdict != GraspVerdict::ok ? 1 : 0;
        if (f.clear != nullptr) f.clear(rig);
      }
      not_ok += rig.step().out.verdict != GraspVerdict::ok ? 1 : 0;
    }
    counts = counter.stop();
  }
  EXPECT_EQ(counts.total(), 0u) << "news=" << counts.news << " mallocs=" << counts.mallocs;
  EXPECT_GT(not_ok, 0);
  EXPECT_GT(rig.gripper->link_counters().reconnects + rig.gripper->link_counters().timeouts, 0u);
  EXPECT_GT(rig.sensor->link_counters().bus_off_events, 0u);
}

}  // namespace
}  // namespace pliant::hil
