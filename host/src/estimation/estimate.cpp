#include "pliant/host/estimate.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <random>
#include <vector>
#include <stdexcept>

namespace pliant::host {
namespace {

std::string explain(Status status) {
  switch (status) {
    case Status::no_free_particles: return "every particle is fixed or driven: nothing to estimate";
    case Status::no_observations: return "no free particle is observed in the frames compared";
    case Status::invalid_argument: return "the recording needs at least two frames with increasing times";
    default: return std::string("estimation failed: ") + status_name(status);
  }
}

template <int Dim>
EstimateReport run(const Recording& recording, const EstimateOptions& options);

// Progress over several estimator runs: run `stage` of `stages` maps onto one overall bar.
struct StagedProgress {
  ProgressCallback callback = nullptr;
  void* context = nullptr;
  int stage = 0;
  int stages = 1;
  static void forward(void* self, int done, int total) {
    const auto* p = static_cast<const StagedProgress*>(self);
    p->callback(p->context, p->stage * total + done, p->stages * total);
  }
};

// Spread of msm_beta when the inputs the model is built on (rest shape, driven tracks) are
// perturbed by the measured noise: a parametric bootstrap of the input-noise contribution.
template <int Dim>
double input_noise_std(const Recording& recording, const EstimateOptions& options, const HostMsmModel<Dim>& base,
                       double noise_std) {
  if (options.input_noise_samples < 2 || !(noise_std > 0)) return 0.0;
  EstimateOptions refit = options;
  refit.input_noise_samples = 0;
  refit.grid_points = 6;
  refit.tolerance = 2e-3;
  refit.estimate_alpha = false;
  refit.setup.rest = RestSource::first_frame;
  StagedProgress staged{options.progress, options.progress_context, 0, options.input_noise_samples + 1};
  if (options.progress != nullptr) {
    refit.progress = &StagedProgress::forward;
    refit.progress_context = &staged;
  }
  std::mt19937_64 rng(0x5eed);
  std::normal_distribution<double> normal(0.0, 1.0);
  const double rest_sigma = noise_std / std::sqrt(static_cast<double>(base.rest_frames));
  std::vector<double> betas;
  for (int sample = 0; sample < options.input_noise_samples; ++sample) {
    staged.stage = sample + 1;
    Recording perturbed = recording;
    perturbed.rest_positions = base.rest;
    for (double& x : perturbed.rest_positions) x += rest_sigma * normal(rng);
    for (const DrivenWindow& window : base.driven) {
      for (int k = 0; k < perturbed.frame_count(); ++k) {
        if (!window.active_at(perturbed.frame_times_s[static_cast<std::size_t>(k)]) ||
            !perturbed.observed(k, window.id))
          continue;
        for (int d = 0; d < Dim; ++d) {
          perturbed.positions[(static_cast<std::size_t>(k) * static_cast<std::size_t>(perturbed.particle_count) +
                               static_cast<std::size_t>(window.id)) *
                                  Dim +
                              static_cast<std::size_t>(d)] += noise_std * normal(rng);
        }
      }
    }
    try {
      betas.push_back(run<Dim>(perturbed, refit).result.msm_beta);
    } catch (const std::runtime_error&) {
      // A perturbed refit that cannot run says nothing about the spread; skip it.
    }
  }
  if (betas.size() < 2) return 0.0;
  double mean = 0;
  for (double b : betas) mean += b;
  mean /= static_cast<double>(betas.size());
  double squares = 0;
  for (double b : betas) squares += (b - mean) * (b - mean);
  return std::sqrt(squares / static_cast<double>(betas.size() - 1));
}

template <int Dim>
EstimateReport run(const Recording& recording, const EstimateOptions& options) {
  const auto started = std::chrono::steady_clock::now();
  auto model = build_msm_model<Dim>(recording, options.setup);
  DeformabilityConfig config;
  config.mode = options.mode;
  config.estimate_alpha = options.estimate_alpha;
  config.grid_points = options.grid_points;
  config.tolerance = options.tolerance;
  StagedProgress staged{options.progress, options.progress_context, 0, std::max(1, options.input_noise_samples + 1)};
  if (options.progress != nullptr && options.input_noise_samples >= 2) {
    config.progress = &StagedProgress::forward;
    config.progress_context = &staged;
  } else {
    config.progress = options.progress;
    config.progress_context = options.progress_context;
  }
  const int driven = static_cast<int>(model->driven.size());
  const std::size_t bytes = deformability_workspace_size(model->model, driven, config);
  auto block = std::make_unique<unsigned char[]>(bytes);
  Arena arena(block.get(), bytes);
  DeformabilityWorkspace<Dim, double> workspace;
  require_ok(deformability_workspace_init(arena, model->model, driven, config, workspace), "estimator workspace");

  EstimateReport report;
  const ObservationSequence<Dim, double> obs = observations_of<Dim>(recording, *model);
  const Status status = estimate_deformability(model->model, base_params<Dim>(recording, options.msm_alpha), obs,
                                               config, workspace, report.result);
  if (status != Status::ok) throw std::runtime_error(explain(status));
  report.curve_beta.assign(workspace.curve_beta, workspace.curve_beta + report.result.curve_count);
  report.curve_error.assign(workspace.curve_error, workspace.curve_error + report.result.curve_count);
  report.cluster_count = model->model.cluster_count;
  report.rest_frames = model->rest_frames;
  report.spacing = model->model.spacing;
  const int frames = recording.frame_count();
  report.frame_interval_s =
      frames > 1 ? (recording.frame_times_s.back() - recording.frame_times_s.front()) / (frames - 1) : 0.0;
  // Without fixed particles to measure noise on, the fit's residual is a conservative stand-in.
  report.noise_std = model->noise_std > 0 ? model->noise_std : report.result.rms;
  report.msm_beta_std_curvature = report.result.msm_beta_std;
  report.msm_beta_std_input = input_noise_std<Dim>(recording, options, *model, report.noise_std);
  report.msm_beta_std = std::hypot(report.msm_beta_std_curvature, report.msm_beta_std_input);
  report.runtime_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return report;
}

// JSON has no infinity: an unidentifiable beta gets the width of its whole range.
double finite_or(double value, double fallback) { return std::isfinite(value) ? value : fallback; }

}  // namespace

EstimateReport estimate_recording(const Recording& recording, const EstimateOptions& options) {
  if (recording.frame_count() < 2) throw std::runtime_error("the recording has fewer than two frames");
  return recording.dimension == 2 ? run<2>(recording, options) : run<3>(recording, options);
}

const char* fit_mode_name(FitMode mode) { return mode == FitMode::trajectory ? "trajectory" : "final"; }

FitMode parse_fit_mode(const std::string& name) {
  if (name == "trajectory") return FitMode::trajectory;
  if (name == "final") return FitMode::final_equilibrium;
  throw std::invalid_argument("--mode must be 'final' or 'trajectory', not '" + name + "'");
}

nlohmann::json estimate_json(const Recording& recording, const EstimateOptions& options, const EstimateReport& report) {
  const DeformabilityResult& r = report.result;
  nlohmann::json uncertainty = {{"msm_beta", finite_or(report.msm_beta_std, 1.0)}};
  nlohmann::json out = {
      {"format", "pliant-estimate"},
      {"version", 1},
      {"recording", recording.name},
      {"model", "msm"},
      {"mode", fit_mode_name(options.mode)},
      {"parameters", {{"msm_beta", r.msm_beta}, {"msm_alpha", r.msm_alpha}}},
      {"uncertainty", uncertainty},
      {"unique_minimum", r.unique_minimum},
      {"rms", r.rms},
      {"curve", {{"msm_beta", report.curve_beta}, {"error", report.curve_error}}},
  };
  // Choices that change the fitted value (PHYSICS.md): recorded so results are comparable.
  out["model_options"] = {
      {"time_step_s", report.frame_interval_s},
      {"steps_per_frame", 1},
      {"clusters", report.cluster_count},
      {"cluster_layout", options.setup.clusters.layout == ClusterLayout::radius      ? "radius"
                         : options.setup.clusters.layout == ClusterLayout::k_nearest ? "k_nearest"
                                                                                     : "grid_blocks"},
      {"cluster_radius_factor", options.setup.clusters.radius_factor},
      {"driven_mass_factor", options.setup.driven_mass_factor},
      {"rest_source", options.setup.rest == RestSource::still_frames ? "still_frames" : "first_frame"},
      {"rest_frames", report.rest_frames},
      {"msm_alpha_estimated", options.estimate_alpha && options.mode == FitMode::trajectory},
      {"gravity_declared", recording.gravity.has_value()},
  };
  out["diagnostics"] = {
      {"error", r.error},
      {"residual_count", r.residual_count},
      {"evaluations", r.evaluations},
      {"frames_without_observations", r.frames_without_observations},
      {"unconverged_equilibria", r.unconverged_equilibria},
      {"spacing", report.spacing},
      {"noise_std", report.noise_std},
      {"msm_beta_std_curvature", finite_or(report.msm_beta_std_curvature, 1.0)},
      {"msm_beta_std_input_noise", report.msm_beta_std_input},
      {"input_noise_samples", options.input_noise_samples},
      {"runtime_s", report.runtime_s},
  };
  if (!std::isfinite(r.msm_beta_std)) out["diagnostics"]["msm_beta_identifiable"] = false;
  return out;
}

}  // namespace pliant::host
