// estimate_deformability: a full offline estimate on the paper's foam press.
//
// Recording: the optical-flow MSM paper's setup (bench_support.hpp foam_press_plan): 4 x 8
// particles at 100 px, bottom row fixed, particle 28 driven 60 px down over 1 s and held 3 s,
// 30 frames/s (121 frames), simulated with the core msm_step at msm_beta 0.5 plus 0.5 px
// deterministic noise. The estimator's model: default clusters on the first observed frame.
// One benchmark iteration = one estimate_deformability call (default DeformabilityConfig).
//
// Budget: <= 2 ms per estimate, in both modes (2D double). The estimate_alpha and 3D
// (block_press) runs are for information.
#include <string>

#include "bench_support.hpp"
#include "pliant/core/deformability.hpp"

namespace pliant::bench {
namespace {

template <int Dim, typename Scalar>
void run_estimate(benchmark::State& bench, const PressScene<Dim, Scalar>& scene, const DeformabilityConfig& config,
                  double truth_beta) {
  if (scene.status != Status::ok) {
    bench.SkipWithError((std::string("scene setup failed: ") + status_name(scene.status)).c_str());
    return;
  }
  const MsmModel<Dim, Scalar>& model = scene.model->model;
  std::vector<unsigned char> block(deformability_workspace_size(model, 1, config));
  Arena arena(block.data(), block.size());
  DeformabilityWorkspace<Dim, Scalar> workspace;
  if (deformability_workspace_init(arena, model, 1, config, workspace) != Status::ok) {
    bench.SkipWithError("deformability_workspace_init failed");
    return;
  }
  const ObservationSequence<Dim, Scalar> observations = scene.recording.observations();
  const MsmParams<Dim, Scalar> base;
  DeformabilityResult result;
  Status failed = Status::ok;
  CpuStopwatch stopwatch;
  stopwatch.start();
  for (auto _ : bench) {
    const Status status = estimate_deformability(model, base, observations, config, workspace, result);
    if (status != Status::ok) failed = status;
    benchmark::DoNotOptimize(result);
  }
  stopwatch.stop();
  if (failed != Status::ok) {
    bench.SkipWithError((std::string("estimate_deformability returned ") + status_name(failed)).c_str());
    return;
  }
  bench.counters["frames"] = observations.frame_count;
  bench.counters["evaluations"] = result.evaluations;
  bench.counters["beta"] = result.msm_beta;
  bench.counters["beta_truth"] = truth_beta;
  bench.counters["alpha"] = result.msm_alpha;
  bench.counters["unconverged"] = result.unconverged_equilibria;
  bench.counters["us_per_evaluation"] =
      1e-3 * stopwatch.per(static_cast<double>(bench.iterations()) * result.evaluations);
}

template <int Dim, typename Scalar>
void BM_Estimate(benchmark::State& bench, const char* scene_name, FitMode mode, bool estimate_alpha) {
  const PressPlan plan = Dim == 2 ? foam_press_plan() : block_press_plan();
  const PressScene<Dim, Scalar>& scene = scene_for<Dim, Scalar>(plan, scene_name);
  DeformabilityConfig config;
  config.mode = mode;
  config.estimate_alpha = estimate_alpha;
  run_estimate(bench, scene, config, plan.msm_beta);
}

void register_all() {
  auto add = [](const char* name, auto fn) { benchmark::RegisterBenchmark(name, fn)->Unit(benchmark::kMillisecond); };
  add("estimate/foam_press/2d/double/trajectory",
      [](benchmark::State& s) { BM_Estimate<2, double>(s, "foam_press", FitMode::trajectory, false); });
  add("estimate/foam_press/2d/double/final_equilibrium",
      [](benchmark::State& s) { BM_Estimate<2, double>(s, "foam_press", FitMode::final_equilibrium, false); });
  add("estimate/foam_press/2d/double/trajectory+alpha",
      [](benchmark::State& s) { BM_Estimate<2, double>(s, "foam_press", FitMode::trajectory, true); });
  add("estimate/foam_press/2d/float/trajectory",
      [](benchmark::State& s) { BM_Estimate<2, float>(s, "foam_press", FitMode::trajectory, false); });
  add("estimate/block_press/3d/double/trajectory",
      [](benchmark::State& s) { BM_Estimate<3, double>(s, "block_press", FitMode::trajectory, false); });
  add("estimate/block_press/3d/double/final_equilibrium",
      [](benchmark::State& s) { BM_Estimate<3, double>(s, "block_press", FitMode::final_equilibrium, false); });
}

}  // namespace
}  // namespace pliant::bench

int main(int argc, char** argv) {
  pliant::bench::register_all();
  const pliant::bench::Budgets budgets = {
      {"estimate/foam_press/2d/double/trajectory", 2000.0},
      {"estimate/foam_press/2d/double/final_equilibrium", 2000.0},
  };
  return pliant::bench::run_benchmarks(argc, argv, budgets);
}
