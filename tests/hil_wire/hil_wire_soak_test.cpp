// The wire HIL's soak (issue 20, item 2): at least 10 minutes of simulated grasping on the stepped
// clock, grasp after grasp (a fresh rig each: emulators, TCP connection, CAN pair, supervisor),
// with wire faults (wire_faults.hpp) injected at random cycles of the squeeze and the hold.
// Asserted over the whole run:
//   - no missed stop: every grasp stopped before the object's limit, and no grasp strained it
//     more than 5 % past its limit, faults or not;
//   - every fault was not ok within 2 cycles of its onset;
//   - no allocation in the loop: the supervisor's cycles after learning (faults included) make
//     no heap call;
//   - no leak: over each grasp after the first (which also makes the process's one-time
//     allocations), from building its rig to destroying it, every heap block taken was given
//     back (new = delete, malloc = free), and the process has as many open file descriptors
//     after the soak as before.
// Seeded, so a failure repeats. Wall time: docs/hil_wire.md.
#include "support/counting_allocator.hpp"  // first: configures eigen_assert before any Eigen header

#include <dirent.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <random>
#include <vector>

#include "grasp_log.hpp"
#include "wire_faults.hpp"
#include "wire_rig.hpp"

namespace pliant::hil {
namespace {

constexpr double kSoakSeconds = 600;  // simulated
constexpr double kMaxOvershoot = 0.05;
constexpr long kHoldCycles = 300;
constexpr long kMaxCycles = 6000;
constexpr double kFaultsPerCycle = 1.0 / 150;  // while squeezing or holding

int open_descriptors() {
  int n = 0;
  DIR* d = opendir("/proc/self/fd");
  if (d == nullptr) return -1;
  while (readdir(d) != nullptr) ++n;
  closedir(d);
  return n;
}

struct SoakGrasp {
  long cycles = 0;
  long faults = 0;
  long worst_latency = -1;  ///< cycles from a fault's onset to not ok
  long missed = 0;          ///< faults never detected
  GraspLog log;
  test::AllocationCounts loop;  ///< heap calls in the cycles after learning
  long long net_news = 0;       ///< new - delete over the grasp's whole life
  long long net_mallocs = 0;    ///< malloc - free over the grasp's whole life
};

void add(test::AllocationCounts& sum, const test::AllocationCounts& c) {
  sum.news += c.news;
  sum.deletes += c.deletes;
  sum.mallocs += c.mallocs;
  sum.frees += c.frees;
  sum.eigen_violations += c.eigen_violations;
}

/// One grasp of `object`, faults drawn from `rng`. No gtest assertion runs in here: the
/// allocation counter is armed throughout.
SoakGrasp soak_grasp(const HilObject& object, const WireOptions& options, const std::vector<WireFault>& faults,
                     std::mt19937_64& rng) {
  SoakGrasp g;
  std::uniform_real_distribution<double> uniform(0, 1);
  std::uniform_int_distribution<std::size_t> pick(0, faults.size() - 1);
  test::AllocationCounts life;
  {
    test::AllocationCounter counter;
    auto rig = std::make_unique<WireRig>(object, options);
    while (rig->status() == hal::HalStatus::ok && rig->supervisor->phase() == Phase::learning) {
      g.log.record(rig->step(), rig->plant, false);
    }
    add(life, counter.stop());
    const bool ready = rig->status() == hal::HalStatus::ok && rig->supervisor->phase() == Phase::approach;
    test::AllocationCounter loop_counter;
    const WireFault* active = nullptr;
    long injected = -1, onset = -1;
    std::uint64_t delivered0 = 0;
    GraspVerdict previous = GraspVerdict::ok;
    while (ready && g.log.cycles < kMaxCycles && g.log.since_stop() < kHoldCycles) {
      const CycleReport& r = rig->step();
      const long c = g.log.cycles;
      g.log.record(r, rig->plant, rig->held_at_safe_width(r.out));
      if (active != nullptr) {
        if (onset < 0 && (active->delivered == nullptr ? c == injected + 1 : active->delivered(*rig) > delivered0)) {
          onset = previous == GraspVerdict::ok ? c : -2;  // -2: already not ok, no latency to measure
        }
        if (onset >= 0 && r.out.verdict != GraspVerdict::ok) {
          g.worst_latency = std::max(g.worst_latency, c - onset);
          onset = -2;
        }
        if (c >= injected + active->hold_cycles) {
          if (active->clear != nullptr) active->clear(*rig);
          if (onset >= 0) ++g.missed;
          active = nullptr;
        }
      } else if (g.log.contact >= 0 && uniform(rng) < kFaultsPerCycle) {
        active = &faults[pick(rng)];
        delivered0 = active->delivered != nullptr ? active->delivered(*rig) : 0;
        active->inject(*rig);
        injected = c;
        onset = -1;
        ++g.faults;
      }
      previous = r.out.verdict;
    }
    g.loop = loop_counter.stop();
    add(life, g.loop);
    test::AllocationCounter end_counter;
    rig.reset();
    add(life, end_counter.stop());
  }
  g.cycles = g.log.cycles;
  g.net_news = static_cast<long long>(life.news) - static_cast<long long>(life.deletes);
  g.net_mallocs = static_cast<long long>(life.mallocs) - static_cast<long long>(life.frees);
  return g;
}

TEST(HilWireSoak, TenMinutesOfGraspingWithRandomFaults) {
  const std::vector<HilObject> all = hil_objects();
  const std::vector<HilObject> objects = {all[11], all[8], all[10], all[6], all[3]};  // the smallest models
  WireOptions options;
  options.base.prediction_beta_points = 6;
  options.base.prediction_closure_points = 16;
  const std::vector<WireFault> faults = wire_faults();
  std::mt19937_64 rng(20);
  const int descriptors_before = open_descriptors();
  const auto start = std::chrono::steady_clock::now();
  double simulated_s = 0;
  long grasps = 0, total_faults = 0, worst_latency = -1;
  double worst_overshoot = -1;
  long long first_net = 0;
  while (simulated_s < kSoakSeconds) {
    const HilObject& object = objects[static_cast<std::size_t>(grasps) % objects.size()];
    options.base.seed = 1 + static_cast<std::uint64_t>(grasps);
    const SoakGrasp g = soak_grasp(object, options, faults, rng);
    SCOPED_TRACE(object.name + ", grasp " + std::to_string(grasps));
    ASSERT_FALSE(g.log.failed);
    ASSERT_GE(g.log.first_stop, 0) << "a missed stop: the guard never stopped the squeeze";
    EXPECT_LT(g.log.strain_at_stop, object.max_strain);
    EXPECT_LE(g.log.peak, (1 + kMaxOvershoot) * object.max_strain);
    EXPECT_EQ(g.missed, 0) << "faults never detected";
    EXPECT_LE(g.worst_latency, 1);
    EXPECT_EQ(g.loop.total(), 0u) << "news=" << g.loop.news << " mallocs=" << g.loop.mallocs;
    if (grasps > 0) {  // the first grasp also makes the process's one-time allocations (first use)
      EXPECT_EQ(g.net_news, 0) << "operator new without delete over the grasp";
      EXPECT_EQ(g.net_mallocs, 0) << "malloc without free over the grasp";
    }
    if (grasps == 0) first_net = g.net_news + g.net_mallocs;
    simulated_s += static_cast<double>(g.cycles) / options.base.rate_hz;
    total_faults += g.faults;
    worst_latency = std::max(worst_latency, g.worst_latency);
    worst_overshoot = std::max(worst_overshoot, g.log.peak / object.max_strain - 1);
    ++grasps;
  }
  const int descriptors_after = open_descriptors();
  EXPECT_EQ(descriptors_after, descriptors_before) << "file descriptors leaked";
  EXPECT_GT(total_faults, grasps) << "too few faults for a soak";
  std::printf(
      "\nWire HIL soak: %.0f s simulated in %ld grasps, %ld faults (worst latency %ld cycles), worst overshoot %.1f "
      "%%, "
      "open fds %d -> %d, first grasp's one-time heap blocks %lld; wall time %.0f s\n",
      simulated_s, grasps, total_faults, worst_latency, 100 * worst_overshoot, descriptors_before, descriptors_after,
      first_net, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
}

}  // namespace
}  // namespace pliant::hil
