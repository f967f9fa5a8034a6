// online_deformability_update: the per-frame cost of the online estimator (K = 11 candidates per
// model form), with the form held (msm_alpha 1, one step per frame: 11 candidates), with the
// default's three msm_alpha rows (33), and with replay's 3 alpha x 3 step rows (1, 2, 4 steps
// per frame: 99 candidates, 231 MSM steps per update).
//
// Recordings (bench_support.hpp), all simulated with the core msm_step at msm_beta 0.5 with
// deterministic noise: the paper's 2D foam press (4 x 8 particles, 121 frames at 30 Hz, px), the
// same 4 x 8 sheet pressed in 3D (foam_press_3d_plan), and the 3D block press (5 x 5 x 4
// particles, 91 frames, m). One benchmark iteration = one
// online_deformability_update with the frame's observed tool position as the driven target and
// the frame's observations; at the end of the recording the estimator is reset (untimed) and
// the recording replays.
//
// Budget: <= 50 us per update on the 4 x 8 foam press, 2D and 3D, float and double, with the form
// held (the budget's original 11 candidates); <= 150 us with the default's three alpha rows.
// The 3D block press (100 particles) and replay's nine forms are for information.
#include <string>

#include "bench_support.hpp"
#include "pliant/core/online_deformability.hpp"

namespace pliant::bench {
namespace {

constexpr int kCandidates = 11;

// The model forms of one benchmark: msm_alpha rows x rows of steps per frame.
struct Forms {
  int alpha_rows = 1;
  int step_rows = 1;
  int msm_steps() const { return alpha_rows * ((1 << step_rows) - 1); }  // per msm_beta candidate
};

PressPlan plan_named(const std::string& name) {
  if (name == "foam_press") return foam_press_plan();
  if (name == "foam_press_3d") return foam_press_3d_plan();
  return block_press_plan();
}

template <int Dim, typename Scalar>
void BM_OnlineUpdate(benchmark::State& bench, const char* scene_name, Forms forms) {
  const PressPlan plan = plan_named(scene_name);
  const PressScene<Dim, Scalar>& scene = scene_for<Dim, Scalar>(plan, scene_name);
  if (scene.status != Status::ok) {
    bench.SkipWithError((std::string("scene setup failed: ") + status_name(scene.status)).c_str());
    return;
  }
  const MsmModel<Dim, Scalar>& model = scene.model->model;
  const PressRecording<Dim, Scalar>& recording = scene.recording;
  OnlineDeformabilityConfig config;
  config.candidates = kCandidates;
  config.alpha_candidates = forms.alpha_rows;
  config.step_candidates = forms.step_rows;
  std::vector<unsigned char> block(online_deformability_workspace_size(model, config));
  Arena arena(block.data(), block.size());
  OnlineDeformability<Dim, Scalar> estimator;
  if (online_deformability_init(arena, model, MsmParams<Dim, Scalar>{}, config, estimator) != Status::ok) {
    bench.SkipWithError("online_deformability_init failed");
    return;
  }
  const Scalar dt = static_cast<Scalar>(recording.times[1] - recording.times[0]);
  MsmDrivenTargets<Dim, Scalar> driven;
  driven.ids = &recording.tool;
  driven.count = 1;
  const int frames = recording.frame_count();
  OnlineDeformabilityEstimate estimate;
  bool have_estimate = false;
  Status failed = Status::ok;
  int k = 1;
  CpuStopwatch stopwatch;
  stopwatch.start();
  for (auto _ : bench) {
    driven.positions = &recording.tool_targets[static_cast<std::size_t>(k)];
    const Status status = online_deformability_update(model, estimator, dt, driven, recording.frame(k));
    if (status != Status::ok) failed = status;
    if (++k == frames) {
      stopwatch.stop();
      bench.PauseTiming();
      estimate = online_deformability_estimate(estimator);
      have_estimate = true;
      online_deformability_reset(model, estimator);
      k = 1;
      bench.ResumeTiming();
      stopwatch.start();
    }
  }
  stopwatch.stop();
  if (failed != Status::ok) {
    bench.SkipWithError((std::string("online_deformability_update returned ") + status_name(failed)).c_str());
    return;
  }
  if (!have_estimate) estimate = online_deformability_estimate(estimator);
  bench.counters["particles"] = model.particle_count;
  bench.counters["candidates"] = kCandidates * forms.alpha_rows * forms.step_rows;
  bench.counters["beta"] = estimate.msm_beta;
  bench.counters["beta_truth"] = plan.msm_beta;
  bench.counters["alpha"] = estimate.msm_alpha;
  bench.counters["ns_per_particle_step"] =
      stopwatch.per(static_cast<double>(bench.iterations()) * kCandidates * forms.msm_steps() * model.particle_count);
}

// The estimate itself (O(K)), after a full recording.
template <int Dim, typename Scalar>
void BM_OnlineEstimate(benchmark::State& bench, const char* scene_name) {
  const PressPlan plan = plan_named(scene_name);
  const PressScene<Dim, Scalar>& scene = scene_for<Dim, Scalar>(plan, scene_name);
  if (scene.status != Status::ok) {
    bench.SkipWithError("scene setup failed");
    return;
  }
  const MsmModel<Dim, Scalar>& model = scene.model->model;
  const PressRecording<Dim, Scalar>& recording = scene.recording;
  OnlineDeformabilityConfig config;
  config.candidates = kCandidates;
  std::vector<unsigned char> block(online_deformability_workspace_size(model, config));
  Arena arena(block.data(), block.size());
  OnlineDeformability<Dim, Scalar> estimator;
  if (online_deformability_init(arena, model, MsmParams<Dim, Scalar>{}, config, estimator) != Status::ok) {
    bench.SkipWithError("online_deformability_init failed");
    return;
  }
  const Scalar dt = static_cast<Scalar>(recording.times[1] - recording.times[0]);
  MsmDrivenTargets<Dim, Scalar> driven;
  driven.ids = &recording.tool;
  driven.count = 1;
  for (int k = 1; k < recording.frame_count(); ++k) {
    driven.positions = &recording.tool_targets[static_cast<std::size_t>(k)];
    (void)online_deformability_update(model, estimator, dt, driven, recording.frame(k));
  }
  OnlineDeformabilityEstimate estimate;
  for (auto _ : bench) {
    estimate = online_deformability_estimate(estimator);
    benchmark::DoNotOptimize(estimate);
  }
  bench.counters["beta"] = estimate.msm_beta;
  bench.counters["beta_std"] = estimate.msm_beta_std;
}

void register_all() {
  auto add = [](const std::string& name, auto fn) {
    benchmark::RegisterBenchmark(name.c_str(), fn)->Unit(benchmark::kMicrosecond);
  };
  const struct {
    const char* suffix;
    Forms forms;
  } form_sets[] = {{"", Forms{1, 1}}, {"/alpha3", Forms{3, 1}}, {"/alpha3_steps3", Forms{3, 3}}};
  for (const auto& set : form_sets) {
    const Forms forms = set.forms;
    const std::string s = set.suffix;
    add("online_update/foam_press/2d/double" + s,
        [forms](benchmark::State& st) { BM_OnlineUpdate<2, double>(st, "foam_press", forms); });
    add("online_update/foam_press/2d/float" + s,
        [forms](benchmark::State& st) { BM_OnlineUpdate<2, float>(st, "foam_press", forms); });
    add("online_update/foam_press/3d/double" + s,
        [forms](benchmark::State& st) { BM_OnlineUpdate<3, double>(st, "foam_press_3d", forms); });
    add("online_update/foam_press/3d/float" + s,
        [forms](benchmark::State& st) { BM_OnlineUpdate<3, float>(st, "foam_press_3d", forms); });
    add("online_update/block_press/3d/double" + s,
        [forms](benchmark::State& st) { BM_OnlineUpdate<3, double>(st, "block_press", forms); });
    add("online_update/block_press/3d/float" + s,
        [forms](benchmark::State& st) { BM_OnlineUpdate<3, float>(st, "block_press", forms); });
  }
  add("online_estimate/foam_press/2d/double",
      [](benchmark::State& st) { BM_OnlineEstimate<2, double>(st, "foam_press"); });
}

}  // namespace
}  // namespace pliant::bench

int main(int argc, char** argv) {
  pliant::bench::register_all();
  const pliant::bench::Budgets budgets = {
      {"online_update/foam_press/2d/double", 50.0},         {"online_update/foam_press/2d/float", 50.0},
      {"online_update/foam_press/3d/double", 50.0},         {"online_update/foam_press/3d/float", 50.0},
      {"online_update/foam_press/2d/double/alpha3", 150.0}, {"online_update/foam_press/2d/float/alpha3", 150.0},
      {"online_update/foam_press/3d/double/alpha3", 150.0}, {"online_update/foam_press/3d/float/alpha3", 150.0},
  };
  return pliant::bench::run_benchmarks(argc, argv, budgets);
}
