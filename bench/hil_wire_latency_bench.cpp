// hil_wire_latency_bench: how long the grasp guard takes to answer a gripper sample when the
// drivers are in the loop (tests/hil_wire: a Robotiq 2F-85 over Modbus TCP to its emulator's
// thread, an ATI NETCANOEM over a CAN seqpacket pair, the HIL supervisor and the guard at 1 kHz).
// A plain program; it reports and does not judge.
//
// Per guarded cycle, on the monotonic wall clock:
//   sample -> verdict   from the gripper read returning with its sample to the guard's verdict:
//                       the stream monitors, the CAN read of the wrist sensor, the camera read and,
//                       on a camera frame (30 Hz), the strain and the online msm_beta estimate,
//                       then grasp_guard_update;
//   cycle               from the gripper read's start to the end of the cycle: the above plus the
//                       Modbus TCP round trips of the read and of the command.
// Percentiles p50, p99, p99.9 and the maximum over every guarded cycle of whole grasps of soft to
// stiff objects, first on an otherwise idle process, then with two processes spinning, one per
// core ("while another process loads both cores"). The machine's own other load is not
// controlled: quote figures with the machine's state.
//
//   hil_wire_latency_bench [--grasps N]     (N objects of the HIL suite per run, default 4)
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "hil_rig.hpp"
#include "spinning_load.hpp"
#include "wire_rig.hpp"

#ifndef PLIANT_BENCH_BUILD_TYPE
#define PLIANT_BENCH_BUILD_TYPE "unknown"
#endif

namespace {

using pliant::hil::CycleReport;
using pliant::hil::HilObject;
using pliant::hil::WireOptions;
using pliant::hil::WireRig;

constexpr long kHoldCycles = 600;  // after the squeeze stopped, as the acceptance test runs
constexpr long kMaxCycles = 8000;

double micros(std::chrono::steady_clock::time_point from, std::chrono::steady_clock::time_point to) {
  return std::chrono::duration<double, std::micro>(to - from).count();
}

struct Samples {
  std::vector<double> to_verdict_us, cycle_us;
  long grasps = 0, failed = 0;
};

// One grasp of `object`: every guarded cycle with a new gripper sample.
void grasp(const HilObject& object, Samples& out) {
  WireRig rig(object, WireOptions{});
  if (rig.status() != pliant::hal::HalStatus::ok) {
    ++out.failed;
    return;
  }
  long stopped_at = -1;
  for (long c = 0; c < kMaxCycles; ++c) {
    const CycleReport& r = rig.step();
    if (r.phase == pliant::hil::Phase::failed) {
      ++out.failed;
      return;
    }
    if (!r.guarded || r.gripper_read != pliant::hal::HalStatus::ok) continue;
    out.to_verdict_us.push_back(micros(r.gripper_sample_at, r.verdict_at));
    out.cycle_us.push_back(micros(r.cycle_start_at, r.cycle_end_at));
    if (stopped_at < 0 && r.out.in_contact && r.out.verdict != pliant::GraspVerdict::ok) stopped_at = c;
    if (stopped_at >= 0 && c - stopped_at >= kHoldCycles) break;
  }
  ++out.grasps;
}

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const auto k = static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5);
  return v[std::min(k, v.size() - 1)];
}

void print(const char* condition, const char* what, const std::vector<double>& v) {
  std::printf("%-22s %-18s %8zu %9.1f %9.1f %9.1f %9.1f\n", condition, what, v.size(), percentile(v, 0.5),
              percentile(v, 0.99), percentile(v, 0.999), v.empty() ? 0.0 : *std::max_element(v.begin(), v.end()));
}

Samples run(const std::vector<HilObject>& objects, std::size_t grasps) {
  Samples s;
  for (std::size_t i = 0; i < grasps; ++i) grasp(objects[i * objects.size() / grasps], s);
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  std::size_t grasps = 4;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--grasps") == 0 && i + 1 < argc) {
      grasps = static_cast<std::size_t>(std::max(1, std::atoi(argv[++i])));
    } else {
      std::fprintf(stderr, "usage: hil_wire_latency_bench [--grasps N]\n");
      return 2;
    }
  }
  const std::vector<HilObject> objects = pliant::hil::hil_objects();
  grasps = std::min(grasps, objects.size());
  std::printf("hil_wire_latency_bench (build type %s): %zu grasps per condition, 1 kHz, wall-clock microseconds\n",
              PLIANT_BENCH_BUILD_TYPE, grasps);
  std::printf("%-22s %-18s %8s %9s %9s %9s %9s\n", "condition", "interval", "cycles", "p50", "p99", "p99.9", "max");
  const Samples idle = run(objects, grasps);
  print("no added load", "sample -> verdict", idle.to_verdict_us);
  print("no added load", "cycle", idle.cycle_us);
  Samples loaded;
  {
    const pliant::bench::SpinningProcesses load(2);
    loaded = run(objects, grasps);
  }
  print("2 spinning processes", "sample -> verdict", loaded.to_verdict_us);
  print("2 spinning processes", "cycle", loaded.cycle_us);
  std::printf("grasps run %ld + %ld, failed to start %ld + %ld\n", idle.grasps, loaded.grasps, idle.failed,
              loaded.failed);
  return 0;
}
