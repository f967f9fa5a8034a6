// guard_bench: 1e6 grasp-guard cycles on a realistic grasp; latency percentiles and allocations.
//
// Scene: a 60 mm soft ball (3D, lattice of 123 particles at 10 mm, default clusters) grasped by
// a parallel gripper at 1 kHz, episodes of 4 s replayed until the cycle count is reached. The
// gripper closes at 10 mm/s to 90 % of the guard's safe closure, holds on limit and obeys stop
// (open backs off, freeze holds); its width follows the command with a 10 ms lag and
// 20 um noise; the grip force is Hertz-like (10 N at 5 mm past contact, 0.05 N noise). The wrist
// F/T streams at 1 kHz (1 N load, 0.01 N noise; 100 ms of 40 Hz, 0.3 N slip jitter per
// episode). The camera delivers a frame every 33 cycles, 30 ms after capture: the tracked
// particles (the ball compressed along the squeeze axis, 50 um noise) whose strain
// grasp_guard_measure_strain computes in that cycle; the estimator's msm_beta settles from
// "unknown" to 0.5 +- 0.03. Every 10th episode has a NaN force sample, a 200 ms camera dropout
// and a 5 ms F/T bus-off. Each episode ends with grasp_guard_reset.
//
// Timed (CPU time of the thread, and wall time): the guard cycle, grasp_guard_update (plus the
// reset at episode ends); separately the camera frame's grasp_guard_measure_strain, which
// belongs to the tracker's frame loop (it produces the DeformationSample), and, for a caller
// that runs both on one thread, the cycles that carry a frame (strain + update). The scene's
// own simulation is outside the timed parts. Each figure includes one timer interval (printed).
// Allocations: the tests' counting allocator (operator new/delete and, on glibc without
// sanitizers, malloc/free) armed over all cycles, the strain measurements included.
//
// Budget: guard cycle p99.9 <= 20 us (CPU time), zero allocations.
// Flags: --cycles N (default 1000000), --pliant_enforce_budgets (exit 2 on a missed budget).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "bench_support.hpp"
#include "pliant/core/grasp_guard.hpp"
#include "support/counting_allocator.hpp"

namespace pliant::bench {
namespace {

constexpr double kSpacing = 0.01;
constexpr int kRadiusCells = 3;
constexpr double kRateHz = 1000;
constexpr int kEpisodeCycles = 4000;
constexpr int kFrameCycles = 33;
constexpr double kCameraLatency = 0.03;
constexpr double kContactWidth = 0.064;  // pad to pad at first touch
constexpr double kPi = 3.14159265358979323846;

struct Percentiles {
  double p50 = 0, p99 = 0, p999 = 0, max = 0;
  std::size_t count = 0;
};

Percentiles percentiles(std::vector<double> values) {
  Percentiles p;
  p.count = values.size();
  if (values.empty()) return p;
  std::sort(values.begin(), values.end());
  auto at = [&](double q) {
    const auto index = static_cast<std::size_t>(std::ceil(q * static_cast<double>(values.size()))) - 1;
    return values[std::min(index, values.size() - 1)];
  };
  p.p50 = at(0.5);
  p.p99 = at(0.99);
  p.p999 = at(0.999);
  p.max = values.back();
  return p;
}

double wall_ns() {
  return static_cast<double>(
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
          .count());
}

int run(int argc, char** argv) {
  long cycles = 1000000;
  bool enforce = false;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--pliant_enforce_budgets") {
      enforce = true;
    } else if (arg == "--cycles" && i + 1 < argc) {
      cycles = std::atol(argv[++i]);
    } else {
      std::fprintf(stderr, "usage: guard_bench [--cycles N] [--pliant_enforce_budgets]\n");
      return 1;
    }
  }
  if (cycles < 1) return 1;

  // The object: lattice points inside a 30 mm radius ball, every particle drivable.
  std::vector<double> rest;
  for (int z = -kRadiusCells; z <= kRadiusCells; ++z) {
    for (int y = -kRadiusCells; y <= kRadiusCells; ++y) {
      for (int x = -kRadiusCells; x <= kRadiusCells; ++x) {
        if (x * x + y * y + z * z > kRadiusCells * kRadiusCells) continue;
        rest.insert(rest.end(), {kSpacing * x, kSpacing * y, kSpacing * z});
      }
    }
  }
  const int n = static_cast<int>(rest.size() / 3);
  std::vector<int> all(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) all[static_cast<std::size_t>(i)] = i;
  OwnedModel<3, double> model(rest, std::vector<std::uint8_t>(static_cast<std::size_t>(n), 0), all);
  if (model.status != Status::ok) {
    std::fprintf(stderr, "model: %s\n", status_name(model.status));
    return 1;
  }
  GraspGuardConfig config;
  config.max_strain = 0.08;
  config.max_force_n = 15;
  config.nominal_force_n = 8;
  GraspObject<3, double> object;
  object.squeeze_axis = Eigen::Vector3d(1, 0, 0);
  std::vector<unsigned char> block(grasp_guard_workspace_size(model.model, config));
  Arena arena(block.data(), block.size());
  GraspGuard<3, double> guard;
  const double init_start = thread_cpu_ns();
  const Status built = grasp_guard_init(arena, model.model, object, config, guard);
  const double init_s = (thread_cpu_ns() - init_start) * 1e-9;
  if (built != Status::ok) {
    std::fprintf(stderr, "grasp_guard_init: %s\n", status_name(built));
    return 1;
  }

  // Everything the loop touches, allocated up front.
  const auto total = static_cast<std::size_t>(cycles);
  std::vector<double> cycle_cpu(total), cycle_wall(total);
  std::vector<double> strain_cpu, frame_cycle_cpu;
  strain_cpu.reserve(total / kFrameCycles + 2);
  frame_cycle_cpu.reserve(total / kFrameCycles + 2);
  std::vector<Eigen::Vector3d> tracked(static_cast<std::size_t>(n));
  long verdicts[3] = {0, 0, 0};
  long slip_cycles = 0, frames = 0, not_ok_transitions = 0;
  Status worst_status = Status::ok;
  GraspGuardInput in;
  GraspGuardOutput out;
  GraspStrainMeasurement measured;

  // Scene state.
  double width_cmd = 0.08, width = 0.08;
  double captured_closure = 0, captured_stamp = 0;
  bool frame_pending = false;
  GraspVerdict previous = GraspVerdict::ok;

  // Timer overhead: an empty timed interval.
  std::vector<double> overhead(20000);
  for (double& o : overhead) {
    const double a = thread_cpu_ns();
    o = thread_cpu_ns() - a;
  }
  const Percentiles timer = percentiles(overhead);

  test::AllocationCounts allocations;
  {
    test::AllocationCounter counter;
    for (long c = 0; c < cycles; ++c) {
      const long episode = c / kEpisodeCycles;
      const int k = static_cast<int>(c % kEpisodeCycles);
      const double t = 1.0 + static_cast<double>(c) / kRateHz;
      const double te = k / kRateHz;  // time in the episode
      const bool faulty = episode % 10 == 9;
      const std::uint64_t key = static_cast<std::uint64_t>(c) * 16;

      // The gripper: first-order lag to the command, Hertz-like contact force.
      width += (width_cmd - width) * (1.0 / kRateHz) / 0.01;
      const double depth = std::max(0.0, kContactWidth - width);
      in.now_s = t;
      in.gripper.stamp_s = t;
      in.gripper.valid = true;
      in.gripper.width_m = width + 20e-6 * unit_noise(key);
      in.gripper.force_n = (depth > 0 ? 10.0 * std::pow(depth / 0.005, 1.5) : 0.0) + 0.05 * unit_noise(key + 1);
      if (faulty && k == 3000) in.gripper.force_n = std::numeric_limits<double>::quiet_NaN();
      // The wrist.
      in.wrench.stamp_s = t;
      in.wrench.valid = true;
      in.wrench.bus_off = faulty && k >= 3500 && k < 3505;
      const double slip = te >= 2.0 && te < 2.1 ? 0.3 * std::sin(2 * kPi * 40 * (te - 2.0)) : 0.0;
      for (int d = 0; d < 6; ++d) in.wrench.wrench[d] = 0.01 * unit_noise(key + 2 + static_cast<std::uint64_t>(d));
      in.wrench.wrench[2] += -1.0;
      in.wrench.wrench[1] += slip;
      // The estimator (30 Hz).
      if (k % kFrameCycles == 0) {
        in.estimate.stamp_s = t;
        in.estimate.valid = true;
        in.estimate.msm_beta = 0.5;
        in.estimate.msm_beta_std = te < 0.5 ? std::numeric_limits<double>::infinity() : (te < 1.0 ? 0.2 : 0.03);
      }
      // The camera: captured now, delivered kCameraLatency later (a dropout in faulty episodes).
      const bool dropout = faulty && te >= 3.2 && te < 3.4;
      bool frame_now = false;
      if (k % kFrameCycles == 0 && !dropout) {
        captured_closure = depth;
        captured_stamp = t;
        frame_pending = true;
      }
      if (frame_pending && t >= captured_stamp + kCameraLatency - 1e-9) {
        frame_pending = false;
        frame_now = true;
        const double squeeze = 1.0 - captured_closure / (2 * kRadiusCells * kSpacing);
        for (int i = 0; i < n; ++i) {
          Eigen::Vector3d p = model.model.rest[i];
          p(0) *= squeeze;
          for (int d = 0; d < 3; ++d) {
            p(d) += 50e-6 * unit_noise(key + 8 + static_cast<std::uint64_t>(i * 3 + d));
          }
          tracked[static_cast<std::size_t>(i)] = p;
        }
      }

      // --- timed: the camera frame (tracker side) ---
      double strain_ns = 0;
      if (frame_now) {
        const double cpu0 = thread_cpu_ns();
        const Status s = grasp_guard_measure_strain(model.model, guard, tracked.data(), measured);
        strain_ns = thread_cpu_ns() - cpu0;
        in.deformation.stamp_s = captured_stamp;
        in.deformation.valid = s == Status::ok;
        in.deformation.strain = measured.strain;
      }
      // --- timed: the guard cycle ---
      const double wall1 = wall_ns();
      const double cpu1 = thread_cpu_ns();
      const Status status = grasp_guard_update(guard, in, out);
      if (k == kEpisodeCycles - 1) grasp_guard_reset(guard);
      const double cpu2 = thread_cpu_ns();
      const double wall2 = wall_ns();
      // --- end timed ---
      const auto u = static_cast<std::size_t>(c);
      cycle_cpu[u] = cpu2 - cpu1;
      cycle_wall[u] = wall2 - wall1;
      if (frame_now) {
        strain_cpu.push_back(strain_ns);
        frame_cycle_cpu.push_back(strain_ns + cycle_cpu[u]);
        ++frames;
      }
      if (status != Status::ok) worst_status = status;
      ++verdicts[static_cast<int>(out.verdict)];
      if (out.slip) ++slip_cycles;
      if (out.verdict != GraspVerdict::ok && previous == GraspVerdict::ok) ++not_ok_transitions;
      previous = out.verdict;

      // The controller.
      if (k == kEpisodeCycles - 1) {
        width_cmd = width = 0.08;  // release, next object
      } else if (out.verdict == GraspVerdict::ok) {
        width_cmd -= 0.01 / kRateHz;
        if (out.in_contact) width_cmd = std::max(width_cmd, out.contact_width_m - 0.9 * out.safe_closure_m);
      } else if (out.verdict == GraspVerdict::limit) {
        width_cmd = std::max(width_cmd, width);  // close no further
      } else if (out.stop_action == StopAction::open) {
        width_cmd = std::min(0.08, width_cmd + 0.02 / kRateHz);
      }  // freeze: keep the command
    }
    allocations = counter.stop();
  }

  const Percentiles all_cpu = percentiles(cycle_cpu);
  const Percentiles all_wall = percentiles(cycle_wall);
  const Percentiles strain = percentiles(strain_cpu);
  const Percentiles frame_cycles = percentiles(frame_cycle_cpu);
  std::printf("guard_bench (%s build): %ld cycles at 1 kHz, %ld episodes of 4 s\n", PLIANT_BENCH_BUILD_TYPE, cycles,
              (cycles + kEpisodeCycles - 1) / kEpisodeCycles);
  std::printf(
      "object: 3D ball, %d particles, %d clusters, %d memberships; table %d betas x %d closures "
      "(step %.3f mm); init %.3f s CPU, %ld msm_steps, %d unconverged\n",
      n, model.model.cluster_count, model.model.membership_count, guard.beta_points, guard.closure_points,
      guard.closure_step_m * 1e3, init_s, guard.relaxation_steps, guard.unconverged_relaxations);
  std::printf("\n%-52s %9s %9s %9s %9s\n", "latency (us)", "p50", "p99", "p99.9", "max");
  auto row = [](const char* name, const Percentiles& p) {
    std::printf("%-52s %9.3f %9.3f %9.3f %9.3f\n", name, p.p50 * 1e-3, p.p99 * 1e-3, p.p999 * 1e-3, p.max * 1e-3);
  };
  row("guard cycle (grasp_guard_update), CPU", all_cpu);
  row("guard cycle, wall", all_wall);
  row("camera frame (grasp_guard_measure_strain), CPU", strain);
  row("cycles carrying a frame (strain + update), CPU", frame_cycles);
  row("timer overhead (one empty interval), CPU", timer);
  std::printf(
      "\nverdicts: ok %ld, limit %ld, stop %ld; %ld transitions out of ok; slip cycles %ld; frames %ld; "
      "status %s\n",
      verdicts[0], verdicts[1], verdicts[2], not_ok_transitions, slip_cycles, frames, status_name(worst_status));
  std::printf("allocations over the %ld cycles: news %zu, deletes %zu, mallocs %zu, frees %zu (malloc %s)\n", cycles,
              allocations.news, allocations.deletes, allocations.mallocs, allocations.frees,
              test::malloc_interposed() ? "interposed" : "not interposed in this build: new/delete only");
  std::printf("counters: refused gripper %u wrench %u camera %u estimate %u; stale camera cycles %u\n",
              guard.counters.refused[0], guard.counters.refused[1], guard.counters.refused[2],
              guard.counters.refused[3], guard.counters.stale_cycles[2]);

  constexpr double kBudgetUs = 20.0;
  const double p999_us = all_cpu.p999 * 1e-3;
  const bool latency_ok = p999_us <= kBudgetUs;
  const bool allocation_ok = allocations.total() == 0;
  std::printf("\nBudgets (per cycle; verdict on CPU time):\n");
  std::printf("  %-50s cpu %10.3f us  wall %10.3f us  budget %8.1f us  %s\n", "guard cycle p99.9", p999_us,
              all_wall.p999 * 1e-3, kBudgetUs, latency_ok ? "ok" : "MISSED");
  std::printf("  %-50s %14zu  budget %8d     %s\n", "heap allocations", allocations.total(), 0,
              allocation_ok ? "ok" : "MISSED");
  return enforce && !(latency_ok && allocation_ok) ? 2 : 0;
}

}  // namespace
}  // namespace pliant::bench

int main(int argc, char** argv) { return pliant::bench::run(argc, argv); }
