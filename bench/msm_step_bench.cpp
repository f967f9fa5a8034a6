// msm_step: one real-time MSM step on regular lattices, 2D and 3D, float and double.
//
// Scene per N: a near-square (2D) or near-cubic (3D) lattice of N particles at 10 mm spacing,
// default clusters (one per particle, radius 1.5 x median nearest-neighbour distance), bottom
// layer fixed, the top-centre particle driven up and down (3 mm, 1 Hz) at a 1 kHz step rate;
// msm_beta 0.5, msm_alpha 1. One benchmark iteration = one msm_step.
//
// Budget: 3D, N = 1024: <= 100 us per step.
#include <cmath>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "bench_support.hpp"

namespace pliant::bench {
namespace {

constexpr double kSpacing = 0.01;
constexpr double kStepRateHz = 1000;
constexpr int kCycleSteps = 1000;  // 1 Hz press cycle
constexpr double kPi = 3.14159265358979323846;

template <int Dim, typename Scalar>
struct StepScene {
  using Vec = Eigen::Matrix<Scalar, Dim, 1>;
  std::vector<int> extents;
  std::vector<Scalar> rest;
  std::vector<std::uint8_t> fixed;
  std::vector<int> drivable;
  int tool = 0;
  std::unique_ptr<OwnedModel<Dim, Scalar>> model;
  std::unique_ptr<OwnedState<Dim, Scalar>> state;
  std::vector<Vec> targets;  // [kCycleSteps] the tool's path
  Status status = Status::not_initialized;

  explicit StepScene(int n) {
    extents = near_regular_extents<Dim>(n);
    rest = lattice<Dim, Scalar>(extents, kSpacing);
    const int nx = extents[0];
    const int ny = extents[1];
    const int layer = Dim == 2 ? nx : nx * ny;  // particles per horizontal layer
    fixed.assign(static_cast<std::size_t>(n), 0);
    for (int i = 0; i < layer; ++i) fixed[static_cast<std::size_t>(i)] = 1;
    tool = Dim == 2 ? (ny - 1) * nx + nx / 2 : ((extents[2] - 1) * ny + ny / 2) * nx + nx / 2;
    drivable = {tool};
    model = std::make_unique<OwnedModel<Dim, Scalar>>(rest, fixed, drivable);
    status = model->status;
    if (status != Status::ok) return;
    state = std::make_unique<OwnedState<Dim, Scalar>>(model->model);
    status = state->status;
    for (int k = 0; k < kCycleSteps; ++k) {
      const double depth = 0.3 * kSpacing * 0.5 * (1.0 - std::cos(2.0 * kPi * k / kCycleSteps));
      Vec target = model->model.rest[tool];
      target(Dim - 1) -= static_cast<Scalar>(depth);
      targets.push_back(target);
    }
  }
};

// Model init is O(N^2); build each scene once per process.
template <int Dim, typename Scalar>
StepScene<Dim, Scalar>& scene_for(int n) {
  static std::map<int, std::unique_ptr<StepScene<Dim, Scalar>>> cache;
  auto& slot = cache[n];
  if (!slot) slot = std::make_unique<StepScene<Dim, Scalar>>(n);
  return *slot;
}

template <int Dim, typename Scalar>
void BM_MsmStep(benchmark::State& bench) {
  const int n = static_cast<int>(bench.range(0));
  StepScene<Dim, Scalar>& scene = scene_for<Dim, Scalar>(n);
  if (scene.status != Status::ok) {
    bench.SkipWithError((std::string("scene setup failed: ") + status_name(scene.status)).c_str());
    return;
  }
  const MsmModel<Dim, Scalar>& model = scene.model->model;
  MsmState<Dim, Scalar>& state = scene.state->state;
  msm_state_reset(model, state);
  MsmParams<Dim, Scalar> params;
  params.msm_beta = Scalar(0.5);
  MsmStepInput<Dim, Scalar> input;
  input.dt = static_cast<Scalar>(1.0 / kStepRateHz);
  input.driven.ids = &scene.tool;
  input.driven.count = 1;
  Status failed = Status::ok;
  int k = 0;
  CpuStopwatch stopwatch;
  stopwatch.start();
  for (auto _ : bench) {
    input.driven.positions = &scene.targets[static_cast<std::size_t>(k)];
    const Status status = msm_step(model, params, input, state);
    if (status != Status::ok) failed = status;
    if (++k == kCycleSteps) k = 0;
  }
  stopwatch.stop();
  if (failed != Status::ok) {
    bench.SkipWithError((std::string("msm_step returned ") + status_name(failed)).c_str());
    return;
  }
  for (int i = 0; i < n; ++i) {
    if (!state.position[i].allFinite()) {
      bench.SkipWithError("non-finite position after stepping");
      return;
    }
  }
  bench.counters["clusters"] = model.cluster_count;
  bench.counters["members"] = model.membership_count;
  bench.counters["ns_per_particle_step"] = stopwatch.per(static_cast<double>(bench.iterations()) * n);
  bench.SetLabel(std::to_string(scene.extents[0]) + "x" + std::to_string(scene.extents[1]) +
                 (Dim == 3 ? "x" + std::to_string(scene.extents[2]) : std::string()));
}

void register_all() {
  auto add = [](const char* name, void (*fn)(benchmark::State&)) {
    benchmark::RegisterBenchmark(name, fn)->ArgName("N")->Arg(32)->Arg(256)->Arg(1024)->Arg(4096)->Unit(
        benchmark::kMicrosecond);
  };
  add("msm_step/2d/float", &BM_MsmStep<2, float>);
  add("msm_step/2d/double", &BM_MsmStep<2, double>);
  add("msm_step/3d/float", &BM_MsmStep<3, float>);
  add("msm_step/3d/double", &BM_MsmStep<3, double>);
}

}  // namespace
}  // namespace pliant::bench

int main(int argc, char** argv) {
  pliant::bench::register_all();
  const pliant::bench::Budgets budgets = {
      {"msm_step/3d/float/N:1024", 100.0},
      {"msm_step/3d/double/N:1024", 100.0},
  };
  return pliant::bench::run_benchmarks(argc, argv, budgets);
}
