// Shared helpers for the pliant benchmark programs: lattices, press recordings simulated with
// the core MSM step (core_testing's press, no host library), and a console reporter that checks
// time budgets.
#pragma once

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <map>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include <time.h>
#include <unistd.h>

#include "pliant/core/msm.hpp"
#include "pliant/core/observations.hpp"
#include "pliant/core_testing/press.hpp"

#ifndef PLIANT_BENCH_BUILD_TYPE
#define PLIANT_BENCH_BUILD_TYPE "unknown"
#endif

namespace pliant::bench {

// --- lattices ----------------------------------------------------------------------------------

/// Lattice extents with product n, as close to a square (Dim 2) or cube (Dim 3) as n allows:
/// minimises the largest / smallest extent. Returned largest first (x, y[, z]).
template <int Dim>
std::vector<int> near_regular_extents(int n) {
  std::vector<int> best;
  double best_ratio = HUGE_VAL;
  if (Dim == 2) {
    for (int a = 1; a <= n; ++a) {
      if (n % a != 0) continue;
      const int b = n / a;
      if (a < b) continue;
      const double ratio = static_cast<double>(a) / b;
      if (ratio < best_ratio) {
        best_ratio = ratio;
        best = {a, b};
      }
    }
  } else {
    for (int a = 1; a <= n; ++a) {
      if (n % a != 0) continue;
      for (int b = 1; b <= a; ++b) {
        if ((n / a) % b != 0) continue;
        const int c = n / a / b;
        if (c > b) continue;
        const double ratio = static_cast<double>(a) / c;
        if (ratio < best_ratio) {
          best_ratio = ratio;
          best = {a, b, c};
        }
      }
    }
  }
  return best;
}

/// The grid of the given extents standing on its last axis (core_testing::PressGrid).
template <int Dim>
core_testing::PressGrid press_grid(const std::vector<int>& extents, double spacing, double x0 = 0, double y0 = 0,
                                   double y_step_sign = 1) {
  core_testing::PressGrid grid;
  for (int d = 0; d < Dim; ++d) grid.extents[d] = extents[static_cast<std::size_t>(d)];
  grid.spacing = spacing;
  grid.origin[0] = x0;
  grid.origin[1] = y0;
  grid.sign[1] = y_step_sign;
  grid.support_axis = Dim - 1;
  return grid;
}

/// Regular lattice, x fastest: id = (z * ny + y) * nx + x; the last axis is "up".
template <int Dim, typename Scalar>
std::vector<Scalar> lattice(const std::vector<int>& extents, double spacing, double x0 = 0, double y0 = 0,
                            double y_step_sign = 1) {
  return core_testing::grid_rest<Dim, Scalar>(press_grid<Dim>(extents, spacing, x0, y0, y_step_sign));
}

/// An MSM model with its memory. Not copyable: the model points into `block`.
template <int Dim, typename Scalar>
struct OwnedModel {
  std::vector<unsigned char> block;
  MsmModel<Dim, Scalar> model;
  Status status = Status::not_initialized;

  OwnedModel(const std::vector<Scalar>& rest, const std::vector<std::uint8_t>& fixed, const std::vector<int>& drivable,
             const ClusterConfig& clusters = ClusterConfig{}) {
    MsmModelConfig<Dim, Scalar> config;
    config.particle_count = static_cast<int>(rest.size() / Dim);
    config.rest_positions = rest.data();
    config.fixed = fixed.data();
    config.drivable_ids = drivable.data();
    config.drivable_count = static_cast<int>(drivable.size());
    config.clusters = clusters;
    block.resize(msm_model_workspace_size(config));
    Arena arena(block.data(), block.size());
    status = block.empty() ? Status::invalid_argument : msm_model_init(arena, config, model);
  }
  OwnedModel(const OwnedModel&) = delete;
  OwnedModel& operator=(const OwnedModel&) = delete;
};

/// A state with its memory.
template <int Dim, typename Scalar>
struct OwnedState {
  std::vector<unsigned char> block;
  MsmState<Dim, Scalar> state;
  Status status = Status::not_initialized;

  explicit OwnedState(const MsmModel<Dim, Scalar>& model) : block(msm_state_workspace_size(model)) {
    Arena arena(block.data(), block.size());
    status = msm_state_init(arena, model, state);
  }
  OwnedState(const OwnedState&) = delete;
  OwnedState& operator=(const OwnedState&) = delete;
};

// --- deterministic noise -------------------------------------------------------------------------

using core_testing::mix;         // splitmix64
using core_testing::unit_noise;  // zero-mean, unit-variance noise from a key

// --- press recordings ------------------------------------------------------------------------------

/// A particle grid resting on a support (bottom layer fixed) pressed by a tool on one top
/// particle, simulated with the core msm_step (one step per frame, as the estimators assume),
/// with deterministic position noise. The estimators' rest shape is the first noisy frame, as a
/// camera would see it. Everything is in double, then cast to Scalar.
template <int Dim, typename Scalar>
struct PressRecording {
  using Vec = Eigen::Matrix<Scalar, Dim, 1>;
  int particle_count = 0;
  int tool = 0;
  double spacing = 0;
  std::vector<Scalar> rest;  // first observed frame
  std::vector<std::uint8_t> fixed;
  std::vector<int> drivable;
  std::vector<double> times;
  std::vector<Scalar> positions;  // [frame][particle][axis]
  std::vector<Vec> frames;        // the same, as vectors: [frame * particle_count + particle]
  std::vector<Vec> tool_targets;  // [frame]: the tool's observed position
  DrivenWindow window;
  Status status = Status::not_initialized;

  int frame_count() const { return static_cast<int>(times.size()); }
  const Vec* frame(int k) const { return frames.data() + static_cast<std::ptrdiff_t>(k) * particle_count; }

  ObservationSequence<Dim, Scalar> observations() const {
    ObservationSequence<Dim, Scalar> obs;
    obs.frame_count = frame_count();
    obs.particle_count = particle_count;
    obs.times_s = times.data();
    obs.positions = positions.data();
    obs.driven = &window;
    obs.driven_count = 1;
    return obs;
  }
};

struct PressPlan {
  std::vector<int> extents;  // x, y[, z]
  double spacing = 1;
  double x0 = 0, y0 = 0;
  double y_step_sign = 1;  // 2D image plane: rows go up the image, y decreases
  int tool = 0;
  std::vector<double> press;  // tool displacement at full depth (Dim entries)
  double ramp_s = 1;
  double duration_s = 4;
  double rate_hz = 30;
  double msm_beta = 0.5;
  double noise = 0.005;  // position noise std, fraction of the spacing
  std::uint64_t seed = 1;
};

/// The optical-flow MSM paper's foam press in the image plane (px): a 4 x 8 grid at 100 px
/// spacing, bottom row (ids 0..7) fixed, particle 28 driven 60 px down (+y, image rows grow
/// downward) over 1 s and held 3 s, 30 frames/s: 121 frames. Same geometry and timing as the
/// host's make_scenario("foam_press").
inline PressPlan foam_press_plan() {
  PressPlan plan;
  plan.extents = {8, 4};
  plan.spacing = 100;
  plan.x0 = 560;
  plan.y0 = 840;
  plan.y_step_sign = -1;
  plan.tool = 3 * 8 + 4;
  plan.press = {0.0, 60.0};
  plan.ramp_s = 1;
  plan.duration_s = 4;
  return plan;
}

/// The foam press in 3D: the same 8 x 4 particle sheet (one particle deep, in the x-z plane,
/// z up), bottom row fixed (ids 0..7), particle 28 pressed 60 units down (-z) over 1 s and held
/// 3 s at 30 frames/s. Same particle count, ids and motion as foam_press_plan(), 3D maths.
inline PressPlan foam_press_3d_plan() {
  PressPlan plan;
  plan.extents = {8, 1, 4};
  plan.spacing = 100;
  plan.tool = 3 * 8 + 4;
  plan.press = {0.0, 0.0, -60.0};
  plan.ramp_s = 1;
  plan.duration_s = 4;
  return plan;
}

/// A 3D block (m) of 5 x 5 x 4 particles at 10 mm, bottom layer fixed, the top-centre particle
/// pressed 6 mm down over 1 s and held 2 s, 30 frames/s (the host's "block_press" geometry).
inline PressPlan block_press_plan() {
  PressPlan plan;
  plan.extents = {5, 5, 4};
  plan.spacing = 0.01;
  plan.tool = (3 * 5 + 2) * 5 + 2;
  plan.press = {0.0, 0.0, -0.006};
  plan.ramp_s = 1;
  plan.duration_s = 3;
  return plan;
}

/// The plan's press by core_testing::simulate_grid_press (in double, hashed noise), into `out`.
template <int Dim, typename Scalar>
void simulate_press(const PressPlan& plan, PressRecording<Dim, Scalar>& out) {
  const core_testing::PressGrid grid = press_grid<Dim>(plan.extents, plan.spacing, plan.x0, plan.y0, plan.y_step_sign);
  const int n = core_testing::grid_particle_count<Dim>(grid);
  out.particle_count = n;
  out.tool = plan.tool;
  out.spacing = plan.spacing;
  out.fixed = core_testing::grid_support<Dim>(grid);
  out.drivable = {plan.tool};
  out.window = DrivenWindow{};
  out.window.id = plan.tool;

  core_testing::PressMotion motion;
  motion.tool = plan.tool;
  for (int d = 0; d < Dim; ++d) motion.travel[d] = plan.press[static_cast<std::size_t>(d)];
  motion.ramp_s = plan.ramp_s;
  motion.duration_s = plan.duration_s;
  motion.rate_hz = plan.rate_hz;
  core_testing::PositionNoise noise;
  noise.source = core_testing::NoiseSource::hashed;
  noise.std = plan.noise * plan.spacing;
  noise.seed = plan.seed;
  MsmParams<Dim, double> params;
  params.msm_beta = plan.msm_beta;
  core_testing::PressFrames<Scalar> recorded;
  out.status = core_testing::simulate_grid_press(grid, params, motion, noise, recorded);
  out.times = std::move(recorded.times_s);
  out.positions = std::move(recorded.positions);
  if (out.status != Status::ok) return;
  const int frames = out.frame_count();
  out.rest.assign(out.positions.begin(), out.positions.begin() + static_cast<std::ptrdiff_t>(n) * Dim);
  for (int k = 0; k < frames; ++k) {
    for (int i = 0; i < n; ++i) {
      out.frames.push_back(Eigen::Map<const Eigen::Matrix<Scalar, Dim, 1>>(
          out.positions.data() + (static_cast<std::ptrdiff_t>(k) * n + i) * Dim));
    }
    out.tool_targets.push_back(out.frames[static_cast<std::size_t>(k * n + plan.tool)]);
  }
}

// --- budgets and the program entry ---------------------------------------------------------------

/// Benchmark name (as printed, without aggregate suffix) -> budget in microseconds per iteration.
using Budgets = std::map<std::string, double>;

/// Console output plus a budget verdict per budgeted benchmark, printed at the end.
class BudgetReporter : public benchmark::ConsoleReporter {
 public:
  BudgetReporter(OutputOptions options, Budgets budgets)
      : benchmark::ConsoleReporter(options), budgets_(std::move(budgets)) {}

  void ReportRuns(const std::vector<Run>& runs) override {
    benchmark::ConsoleReporter::ReportRuns(runs);
    for (const Run& run : runs) {
      if (run.error_occurred) continue;
      if (run.run_type == Run::RT_Aggregate && run.aggregate_name != "median") continue;
      const auto found = budgets_.find(run.run_name.str());
      if (found == budgets_.end()) continue;
      const double to_us = 1e6 / benchmark::GetTimeUnitMultiplier(run.time_unit);
      verdicts_.push_back(
          {run.benchmark_name(), run.GetAdjustedCPUTime() * to_us, run.GetAdjustedRealTime() * to_us, found->second});
    }
  }

  void Finalize() override {
    benchmark::ConsoleReporter::Finalize();
    if (verdicts_.empty()) return;
    std::ostream& out = GetOutputStream();
    // Judged on CPU time: on a shared or loaded machine, real time also counts the time the
    // thread spent descheduled. Both are printed.
    out << "\nBudgets (per iteration; verdict on CPU time):\n";
    char line[320];
    for (const Verdict& v : verdicts_) {
      std::snprintf(line, sizeof line, "  %-50s cpu %10.3f us  real %10.3f us  budget %8.1f us  %s\n", v.name.c_str(),
                    v.cpu_us, v.real_us, v.budget_us, v.cpu_us <= v.budget_us ? "ok" : "MISSED");
      out << line;
    }
  }

  bool any_missed() const {
    return std::any_of(verdicts_.begin(), verdicts_.end(), [](const Verdict& v) { return v.cpu_us > v.budget_us; });
  }

 private:
  struct Verdict {
    std::string name;
    double cpu_us;
    double real_us;
    double budget_us;
  };
  Budgets budgets_;
  std::vector<Verdict> verdicts_;
};

/// Program entry shared by the benchmark programs: registers nothing itself (the caller does
/// that first), adds the build context, runs with budget checks on console output. Extra flag:
/// --pliant_enforce_budgets makes a missed budget exit with status 2.
inline int run_benchmarks(int argc, char** argv, const Budgets& budgets) {
  bool enforce = false;
  bool console = true;
  bool tabular = false;
  bool color = isatty(STDOUT_FILENO) != 0;
  std::vector<char*> args;
  for (int i = 0; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--pliant_enforce_budgets") {
      enforce = true;
      continue;
    }
    if (arg.rfind("--benchmark_format=", 0) == 0 && arg != "--benchmark_format=console") console = false;
    if (arg == "--benchmark_counters_tabular" || arg == "--benchmark_counters_tabular=true") tabular = true;
    if (arg == "--benchmark_color=false" || arg == "--benchmark_color=no") color = false;
    args.push_back(argv[i]);
  }
  int count = static_cast<int>(args.size());
  args.push_back(nullptr);
  benchmark::Initialize(&count, args.data());
  if (benchmark::ReportUnrecognizedArguments(count, args.data())) return 1;
  benchmark::AddCustomContext("pliant_build_type", PLIANT_BENCH_BUILD_TYPE);
#if defined(__OPTIMIZE__)
  benchmark::AddCustomContext("pliant_optimized", "yes");
#else
  benchmark::AddCustomContext("pliant_optimized",
                              "NO: numbers are not representative, build with -DCMAKE_BUILD_TYPE=Release");
#endif
  if (!console) {
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
  }
  int options = benchmark::ConsoleReporter::OO_None;
  if (color) options |= benchmark::ConsoleReporter::OO_Color;
  if (tabular) options |= benchmark::ConsoleReporter::OO_Tabular;
  BudgetReporter reporter(static_cast<benchmark::ConsoleReporter::OutputOptions>(options), budgets);
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  return enforce && reporter.any_missed() ? 2 : 0;
}

/// Thread CPU time in nanoseconds (the clock Google Benchmark's CPU column uses).
inline double thread_cpu_ns() {
  timespec now{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &now);
  return static_cast<double>(now.tv_sec) * 1e9 + static_cast<double>(now.tv_nsec);
}

/// Accumulates the CPU time of the timed part of a benchmark loop, for per-unit counters that
/// print plain numbers (a kInvert rate counter would print seconds with an "s" suffix).
class CpuStopwatch {
 public:
  void start() { started_ = thread_cpu_ns(); }
  void stop() { total_ += thread_cpu_ns() - started_; }
  /// Nanoseconds per unit of work, given the number of units done while running.
  double per(double units) const { return units > 0 ? total_ / units : 0.0; }

 private:
  double started_ = 0;
  double total_ = 0;
};

// A simulated press and the model fitted to it, built once per key and cached for the run.
template <int Dim, typename Scalar>
struct PressScene {
  PressRecording<Dim, Scalar> recording;
  std::unique_ptr<OwnedModel<Dim, Scalar>> model;
  Status status = Status::not_initialized;

  explicit PressScene(const PressPlan& plan) {
    simulate_press(plan, recording);
    status = recording.status;
    if (status != Status::ok) return;
    model = std::make_unique<OwnedModel<Dim, Scalar>>(recording.rest, recording.fixed, recording.drivable);
    status = model->status;
  }
};

template <int Dim, typename Scalar>
const PressScene<Dim, Scalar>& scene_for(const PressPlan& plan, const char* key) {
  static std::map<std::string, std::unique_ptr<PressScene<Dim, Scalar>>> cache;
  auto& slot = cache[key];
  if (!slot) slot = std::make_unique<PressScene<Dim, Scalar>>(plan);
  return *slot;
}

}  // namespace pliant::bench
