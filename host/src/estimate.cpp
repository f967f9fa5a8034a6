#include "pliant/host/estimate.hpp"

#include <chrono>
#include <cmath>
#include <memory>
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
EstimateReport run(const Recording& recording, const EstimateOptions& options) {
  const auto started = std::chrono::steady_clock::now();
  auto model = build_msm_model<Dim>(recording, options.setup);
  DeformabilityConfig config;
  config.mode = options.mode;
  config.estimate_alpha = options.estimate_alpha;
  config.grid_points = options.grid_points;
  config.tolerance = options.tolerance;
  config.progress = options.progress;
  config.progress_context = options.progress_context;
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
  report.frame_interval_s = frames > 1 ? (recording.frame_times_s.back() - recording.frame_times_s.front()) / (frames - 1) : 0.0;
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
  nlohmann::json uncertainty = {{"msm_beta", finite_or(r.msm_beta_std, 1.0)}};
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
      {"runtime_s", report.runtime_s},
  };
  if (!std::isfinite(r.msm_beta_std)) out["diagnostics"]["msm_beta_identifiable"] = false;
  return out;
}

}  // namespace pliant::host
