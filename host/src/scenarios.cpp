#include "pliant/host/scenarios.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <stdexcept>

#include "pliant/host/msm_setup.hpp"

namespace pliant::host {
namespace {

// Geometry and motion of one scenario, before simulation.
struct ScenarioPlan {
  int dimension = 2;
  std::string length_unit = "m";
  double spacing = 1.0;
  std::vector<double> rest;  // particle-major
  std::vector<int> fixed;
  int tool = 0;                    // driven particle
  double release_s = HUGE_VAL;     // the tool lets go after this time
  double duration_s = 0;
  double rate_hz = 30;
  std::function<std::vector<double>(double)> tool_offset;  // displacement from rest at time t
  std::string object;
};

// Every scenario films the object still for this long before the tool starts to move, as a
// robot camera does while the arm approaches.
constexpr double kLeadIn_s = 0.5;

double ramp(double t, double ramp_s) { return std::clamp((t - kLeadIn_s) / ramp_s, 0.0, 1.0); }

ScenarioPlan foam_press() {
  ScenarioPlan plan;
  plan.dimension = 2;
  plan.length_unit = "px";
  plan.spacing = 100.0;
  const int cols = 8;
  const int rows = 4;
  // Image coordinates: y grows downward; row 0 is the bottom row on the support.
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      plan.rest.push_back(560.0 + 100.0 * c);
      plan.rest.push_back(840.0 - 100.0 * r);
      if (r == 0) plan.fixed.push_back(r * cols + c);
    }
  }
  plan.tool = 3 * cols + 4;
  plan.duration_s = kLeadIn_s + 4.0;
  plan.rate_hz = 30.0;
  plan.tool_offset = [](double t) { return std::vector<double>{0.0, 60.0 * ramp(t, 1.0)}; };
  plan.object = "simulated foam block pressed by a tool, image plane";
  return plan;
}

ScenarioPlan block_press() {
  ScenarioPlan plan;
  plan.dimension = 3;
  plan.length_unit = "m";
  plan.spacing = 0.01;
  const int nx = 5;
  const int ny = 5;
  const int nz = 4;
  for (int z = 0; z < nz; ++z) {
    for (int y = 0; y < ny; ++y) {
      for (int x = 0; x < nx; ++x) {
        plan.rest.push_back(0.01 * x);
        plan.rest.push_back(0.01 * y);
        plan.rest.push_back(0.01 * z);
        if (z == 0) plan.fixed.push_back((z * ny + y) * nx + x);
      }
    }
  }
  plan.tool = ((nz - 1) * ny + 2) * nx + 2;
  plan.duration_s = kLeadIn_s + 3.0;
  plan.rate_hz = 30.0;
  plan.tool_offset = [](double t) { return std::vector<double>{0.0, 0.0, -0.006 * ramp(t, 1.0)}; };
  plan.object = "simulated 3D block pressed from above";
  return plan;
}

ScenarioPlan cantilever_strip() {
  ScenarioPlan plan;
  plan.dimension = 2;
  plan.length_unit = "m";
  plan.spacing = 0.01;
  const int cols = 12;
  const int rows = 3;
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      plan.rest.push_back(0.01 * c);
      plan.rest.push_back(0.01 * r);
      if (c < 2) plan.fixed.push_back(r * cols + c);
    }
  }
  plan.tool = 1 * cols + (cols - 1);
  plan.release_s = kLeadIn_s + 2.0;
  plan.duration_s = kLeadIn_s + 4.0;
  plan.rate_hz = 60.0;
  plan.tool_offset = [](double t) { return std::vector<double>{0.0, -0.02 * ramp(t, 1.0)}; };
  plan.object = "simulated clamped strip, tip pulled down and released";
  return plan;
}

ScenarioPlan plan_for(const std::string& name) {
  if (name == "foam_press") return foam_press();
  if (name == "block_press") return block_press();
  if (name == "cantilever_strip") return cantilever_strip();
  throw std::invalid_argument("unknown scenario '" + name + "' (known: foam_press, block_press, cantilever_strip)");
}

template <int Dim>
void simulate(const ScenarioPlan& plan, const ScenarioOptions& options, Recording& recording) {
  auto model = build_msm_model<Dim>(recording, MsmSetupOptions{});
  const std::size_t bytes = msm_state_workspace_size(model->model);
  auto block = std::make_unique<unsigned char[]>(bytes);
  Arena arena(block.get(), bytes);
  MsmState<Dim, double> state;
  require_ok(msm_state_init(arena, model->model, state), "scenario state");
  MsmParams<Dim, double> params = base_params<Dim>(recording, options.msm_alpha);
  params.msm_beta = options.msm_beta;

  const int frames = static_cast<int>(std::lround(plan.duration_s * plan.rate_hz)) + 1;
  const auto n = static_cast<std::size_t>(recording.particle_count);
  recording.frame_times_s.resize(static_cast<std::size_t>(frames));
  recording.positions.assign(static_cast<std::size_t>(frames) * n * Dim, 0.0);
  std::mt19937_64 rng(options.seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  const double sigma = options.noise * plan.spacing;
  auto record = [&](int frame) {
    for (std::size_t i = 0; i < n; ++i) {
      for (int d = 0; d < Dim; ++d) {
        const double noise = sigma > 0 ? sigma * normal(rng) : 0.0;
        recording.positions[(static_cast<std::size_t>(frame) * n + i) * Dim + static_cast<std::size_t>(d)] =
            state.position[i](d) + noise;
      }
    }
  };
  record(0);
  recording.frame_times_s[0] = 0.0;
  const double dt = 1.0 / plan.rate_hz;
  for (int k = 1; k < frames; ++k) {
    const double t = k * dt;
    recording.frame_times_s[static_cast<std::size_t>(k)] = t;
    Eigen::Matrix<double, Dim, 1> target = model->model.rest[plan.tool];
    const std::vector<double> offset = plan.tool_offset(t);
    for (int d = 0; d < Dim; ++d) target(d) += offset[static_cast<std::size_t>(d)];
    MsmStepInput<Dim, double> input;
    input.dt = dt;
    const bool driven = t <= plan.release_s;
    input.driven.ids = &plan.tool;
    input.driven.positions = &target;
    input.driven.count = driven ? 1 : 0;
    require_ok(msm_step(model->model, params, input, state), "scenario step");
    record(k);
  }
}

}  // namespace

std::vector<std::string> scenario_names() { return {"foam_press", "block_press", "cantilever_strip"}; }

ScenarioResult make_scenario(const std::string& name, const ScenarioOptions& options) {
  if (!(options.msm_beta >= 0.0 && options.msm_beta <= 1.0)) throw std::invalid_argument("--beta must be in [0, 1]");
  if (!(options.msm_alpha > 0.0 && options.msm_alpha <= 1.0)) throw std::invalid_argument("--alpha must be in (0, 1]");
  if (!(options.noise >= 0.0) || !std::isfinite(options.noise)) throw std::invalid_argument("--noise must be >= 0");
  if (options.rate_hz != 0.0 && !(options.rate_hz > 0.0 && std::isfinite(options.rate_hz))) {
    throw std::invalid_argument("--rate must be > 0");
  }
  ScenarioPlan plan = plan_for(name);
  if (options.rate_hz > 0.0) plan.rate_hz = options.rate_hz;

  ScenarioResult result;
  Recording& rec = result.recording;
  rec.name = name;
  rec.dimension = plan.dimension;
  rec.length_unit = plan.length_unit;
  rec.particle_count = static_cast<int>(plan.rest.size()) / plan.dimension;
  rec.masses.assign(static_cast<std::size_t>(rec.particle_count), 1.0);
  rec.fixed = plan.fixed;
  DrivenWindow window;
  window.id = plan.tool;
  if (std::isfinite(plan.release_s)) window.to_s = plan.release_s;
  rec.driven.push_back(window);
  rec.files["particles"] = "particles.csv";
  rec.meta = {{"object", plan.object}, {"generator", "pliant simulate " + name}};
  rec.rest_positions = plan.rest;
  if (plan.dimension == 2) {
    simulate<2>(plan, options, rec);
  } else {
    simulate<3>(plan, options, rec);
  }
  // The recording's rest shape is its first (noisy) frame, as a camera would see it.
  rec.rest_positions.assign(rec.positions.begin(),
                            rec.positions.begin() + static_cast<std::ptrdiff_t>(rec.particle_count * rec.dimension));

  result.truth = {
      {"format", "pliant-truth"},
      {"version", 1},
      {"scenario", name},
      {"model", "msm"},
      {"parameters", {{"msm_beta", options.msm_beta}, {"msm_alpha", options.msm_alpha}}},
      {"steps_per_frame", 1},
      {"rate_hz", plan.rate_hz},
      {"noise_fraction_of_spacing", options.noise},
      {"noise_std", options.noise * plan.spacing},
      {"spacing", plan.spacing},
      {"seed", options.seed},
  };
  return result;
}

void write_scenario(const ScenarioResult& scenario, const std::string& directory) {
  write_recording(scenario.recording, directory);
  const std::filesystem::path path = std::filesystem::path(directory) / "truth.json";
  std::ofstream out(path);
  out << scenario.truth.dump(2) << '\n';
  if (!out) throw std::runtime_error("cannot write " + path.string());
}

}  // namespace pliant::host
