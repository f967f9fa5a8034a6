#include "pliant/host/estimate.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <memory>
#include <random>
#include <vector>
#include <stdexcept>

#include "pliant/host/cluster_radii.hpp"
#include "pliant/host/parallel_fits.hpp"

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
    // Stages beyond those planned (more rounds or radii than foreseen) extend the total.
    p->callback(p->context, p->stage * total + done, std::max(p->stages, p->stage + 1) * total);
  }
};

// Spread of msm_beta when the inputs the model is built on (rest shape, driven tracks) are
// perturbed by the measured noise: a parametric bootstrap of the input-noise contribution.
// `options` holds msm_alpha fixed at the value to refit with; the refits report progress as the
// stages after `first_stage` of `staged`.
template <int Dim>
double input_noise_std(const Recording& recording, const EstimateOptions& options, const HostMsmModel<Dim>& base,
                       double noise_std, StagedProgress& staged, int first_stage) {
  if (options.input_noise_samples < 2 || !(noise_std > 0)) return 0.0;
  EstimateOptions refit = options;
  refit.input_noise_samples = 0;
  refit.grid_points = 6;
  refit.tolerance = 2e-3;
  refit.setup.rest = RestSource::first_frame;
  if (options.progress != nullptr) {
    refit.progress = &StagedProgress::forward;
    refit.progress_context = &staged;
  }
  std::mt19937_64 rng(0x5eed);
  std::normal_distribution<double> normal(0.0, 1.0);
  const double rest_sigma = noise_std / std::sqrt(static_cast<double>(base.rest_frames));
  std::vector<double> betas;
  for (int sample = 0; sample < options.input_noise_samples; ++sample) {
    staged.stage = first_stage + sample;
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

// One fitted variant: the estimator's result and its error curve.
template <int Dim>
struct MsmFit {
  DeformabilityResult result;
  std::vector<double> curve_beta;
  std::vector<double> curve_error;
};

// One fit of msm_beta on an already built model, stepping `steps_per_frame` times per frame
// interval, with msm_alpha fitted too or held at `alpha`.
template <int Dim>
MsmFit<Dim> fit_msm(const Recording& recording, const EstimateOptions& options, const HostMsmModel<Dim>& model,
                    int steps_per_frame, bool fit_alpha, double alpha, StagedProgress* progress) {
  DeformabilityConfig config;
  config.mode = options.mode;
  config.estimate_alpha = fit_alpha;
  config.steps_per_frame = steps_per_frame;
  config.grid_points = options.grid_points;
  config.tolerance = options.tolerance;
  if (progress != nullptr && progress->callback != nullptr) {
    config.progress = &StagedProgress::forward;
    config.progress_context = progress;
  }
  const int driven = static_cast<int>(model.driven.size());
  const std::size_t bytes = deformability_workspace_size(model.model, driven, config);
  auto block = std::make_unique<unsigned char[]>(bytes);
  Arena arena(block.get(), bytes);
  DeformabilityWorkspace<Dim, double> workspace;
  require_ok(deformability_workspace_init(arena, model.model, driven, config, workspace), "estimator workspace");
  MsmFit<Dim> fit;
  const ObservationSequence<Dim, double> obs = observations_of<Dim>(recording, model);
  const Status status =
      estimate_deformability(model.model, base_params<Dim>(recording, alpha), obs, config, workspace, fit.result);
  if (status != Status::ok) throw std::runtime_error(explain(status));
  fit.curve_beta.assign(workspace.curve_beta, workspace.curve_beta + fit.result.curve_count);
  fit.curve_error.assign(workspace.curve_error, workspace.curve_error + fit.result.curve_count);
  return fit;
}

// The baseline selection (docs/estimation.md). Every variant is scored by the Bayesian
// information criterion with Gaussian residuals of unknown variance,
//   BIC = n_eff ln(RSS / n) + k ln(n_eff),
// k = 1 (msm_beta) or 2 (and msm_alpha). Residuals of one particle are correlated over time, so
// they count by their effective number n_eff = n / deff, deff the design effect of the variant
// that fits best (the one whose residuals are closest to plain noise); the same n_eff for every
// variant keeps the scores comparable. Steps per frame is a discrete choice of the model's form,
// not a fitted parameter. Ties go to the earlier (simpler) variant.
template <int Dim>
void score_candidates(const std::vector<MsmFit<Dim>>& fits, BaselineChoice& choice) {
  std::size_t best_fit = 0;
  for (std::size_t i = 1; i < fits.size(); ++i) {
    if (fits[i].result.rms < fits[best_fit].result.rms) best_fit = i;
  }
  const DeformabilityResult& best = fits[best_fit].result;
  const double scalars = static_cast<double>(best.residual_count) * Dim;
  const double n_eff = std::max(2.0, scalars / std::max(1.0, best.design_effect));
  choice.effective_residuals = n_eff;
  constexpr double floor = 1e-300;  // a noise-free fit: its log stays finite
  for (std::size_t i = 0; i < fits.size(); ++i) {
    BaselineCandidate& c = choice.candidates[i];
    const double parameters = c.alpha_fitted ? 2.0 : 1.0;
    c.bic = n_eff * std::log(std::max(c.rms * c.rms, floor)) + parameters * std::log(n_eff);
  }
  choice.chosen = 0;
  for (std::size_t i = 1; i < fits.size(); ++i) {
    if (choice.candidates[i].bic < choice.candidates[static_cast<std::size_t>(choice.chosen)].bic) {
      choice.chosen = static_cast<int>(i);
    }
  }
}

// A fit whose rms residual is within this factor of the position noise measured on the fixed
// particles leaves nothing systematic for a nuisance parameter to explain: there, fitting
// msm_alpha only trades it against the noise of the rest shape and the tool track (a lagging
// model filters the tool's noise) and biases msm_beta. The factor allows for that noise
// propagating through the model built on them.
constexpr double kExplainedByNoise = 1.5;
// Radii tried in each gap between fitted cluster radii (fit_baseline, step 3).
constexpr int kRadiiPerGap = 2;
// Bisections between doubled steps per frame (fit_baseline, step 2): 16 and 32 narrow to 4 apart.
constexpr int kStepBisections = 2;

bool explained_by_noise(double rms, double noise_std) { return noise_std > 0 && rms <= kExplainedByNoise * noise_std; }

std::string choice_reason(const BaselineChoice& choice, bool compared_alpha, bool compared_steps,
                          bool compared_radius) {
  const BaselineCandidate& kept = choice.candidates[static_cast<std::size_t>(choice.chosen)];
  // The runner-up: the best-scoring variant other than the one kept.
  const BaselineCandidate* next = nullptr;
  for (std::size_t i = 0; i < choice.candidates.size(); ++i) {
    if (static_cast<int>(i) == choice.chosen) continue;
    if (next == nullptr || choice.candidates[i].bic < next->bic) next = &choice.candidates[i];
  }
  auto describe = [&](const BaselineCandidate& c, bool with_value) {
    char text[160];
    if (with_value) {
      std::snprintf(text, sizeof text, "%s at %.3f, %d step%s per frame", c.alpha_fitted ? "fitted" : "held",
                    c.msm_alpha, c.steps_per_frame, c.steps_per_frame == 1 ? "" : "s");
    } else {
      std::snprintf(text, sizeof text, "%s, %d per frame", c.alpha_fitted ? "fitted" : "held", c.steps_per_frame);
    }
    std::string out = text;
    if (compared_radius) {
      std::snprintf(text, sizeof text, ", cluster radius %g", c.cluster_radius_factor);
      out += text;
    }
    return out;
  };
  std::string reason = describe(kept, true);
  if (next == nullptr) return reason;
  std::vector<std::string> compared;
  if (compared_alpha) compared.push_back("msm_alpha");
  if (compared_steps) compared.push_back("steps per frame");
  if (compared_radius) compared.push_back("cluster radius");
  std::string what;
  for (std::size_t i = 0; i < compared.size(); ++i) {
    what += (i == 0 ? "" : (i + 1 == compared.size() ? " and " : ", ")) + compared[i];
  }
  char text[200];
  std::snprintf(text, sizeof text, ": chosen over %zu variants of %s by BIC, %.1f below the next best (",
                choice.candidates.size(), what.c_str(), next->bic - kept.bic);
  reason += text;
  std::snprintf(text, sizeof text, ") over %.0f effective residuals", choice.effective_residuals);
  return reason + describe(*next, false) + text;
}

// Fits the baseline variants `options` asks for and keeps the best (docs/estimation.md):
// 1. the simplest variant (msm_alpha held, the first steps per frame, the setup's cluster
//    radius); kept at once when it fits to the measured noise;
// 2. at the current radius, every steps per frame (automatic: 1..max_auto_steps_per_frame) with
//    msm_alpha held and fitted as the options say; when the most steps win, doubled steps while
//    they keep winning (up to max_steps_per_frame), then kStepBisections bisections around the
//    kept count;
// 3. with the cluster radius automatic, the steps and msm_alpha mode kept so far at every radius
//    of the setup's and auto_cluster_radii;
//    then, in every gap between two radii fitted so far (in later rounds only beside the kept
//    radius), up to kRadiiPerGap radii at which the clusters change (cluster_radii.hpp: an
//    irregular body's clusters change between the listed radii, and the fit over the radius is
//    not unimodal, so the first round searches every gap);
// 4. when step 3 moved the radius, steps 2 and 3 again from there (at most twice more): the
//    radius trades off against msm_alpha and the steps, so each is chosen given the other.
// Every variant is fitted once. `model` is replaced by the model of the radius kept.
template <int Dim>
MsmFit<Dim> fit_baseline(const Recording& recording, const EstimateOptions& options,
                         std::unique_ptr<HostMsmModel<Dim>>& model, BaselineChoice& choice, StagedProgress& progress) {
  const bool trajectory = options.mode == FitMode::trajectory;
  const bool alpha_auto = trajectory && options.alpha == AlphaMode::automatic;
  const bool alpha_fit = trajectory && options.alpha == AlphaMode::fitted;
  const bool steps_auto = trajectory && options.steps_per_frame == 0;
  const bool radius_auto =
      trajectory && options.cluster_radius_auto && options.setup.clusters.layout == ClusterLayout::radius;
  const double setup_radius = options.setup.clusters.radius_factor;
  const int first_steps = trajectory && options.steps_per_frame > 0 ? options.steps_per_frame : 1;
  const int last_steps = steps_auto ? max_auto_steps_per_frame : first_steps;

  // Models by cluster radius, built when first needed; the setup's own is `model`.
  std::vector<std::pair<double, std::unique_ptr<HostMsmModel<Dim>>>> models;
  models.emplace_back(setup_radius, std::move(model));
  auto model_for = [&](double radius) -> const HostMsmModel<Dim>& {
    for (auto& [r, m] : models) {
      if (r == radius) return *m;
    }
    MsmSetupOptions setup = options.setup;
    setup.clusters.radius_factor = radius;
    models.emplace_back(radius, build_msm_model<Dim>(recording, setup));
    return *models.back().second;
  };

  std::vector<MsmFit<Dim>> fits;
  struct Variant {
    int steps;
    bool fit_alpha;
    double radius;
  };
  // Fits the variants not fitted yet, independently of each other on worker threads, then
  // scores every variant so far. The order of the candidates is that of `wanted`.
  auto add = [&](const std::vector<Variant>& wanted) {
    std::vector<Variant> batch;
    auto same = [](int steps, bool fit_alpha, double radius, const Variant& v) {
      return steps == v.steps && fit_alpha == v.fit_alpha && radius == v.radius;
    };
    for (const Variant& v : wanted) {
      bool fitted = false;
      for (const BaselineCandidate& c : choice.candidates) {
        fitted = fitted || same(c.steps_per_frame, c.alpha_fitted, c.cluster_radius_factor, v);
      }
      for (const Variant& b : batch) fitted = fitted || same(b.steps, b.fit_alpha, b.radius, v);
      if (fitted) continue;
      batch.push_back(v);
      (void)model_for(v.radius);  // built here; the workers only read it
    }
    std::vector<MsmFit<Dim>> made(batch.size());
    // One variant reports the progress of its run; several, a stage as each ends (so that the
    // callback is never called from two threads at once).
    StagedProgress* per_run = batch.size() == 1 ? &progress : nullptr;
    run_on_workers(
        batch.size(), worker_count(batch.size(), 0), [](bool) { return 0; },
        [&](int&, std::size_t i) {
          made[i] = fit_msm<Dim>(recording, options, model_for(batch[i].radius), batch[i].steps, batch[i].fit_alpha,
                                 options.msm_alpha, per_run);
        },
        [&]() {
          ++progress.stage;
          if (per_run == nullptr && progress.callback != nullptr) StagedProgress::forward(&progress, 0, 1);
        });
    for (std::size_t i = 0; i < batch.size(); ++i) {
      const DeformabilityResult& r = made[i].result;
      choice.candidates.push_back(
          {batch[i].steps, batch[i].fit_alpha, r.msm_alpha, r.msm_beta, r.rms, 0.0, batch[i].radius});
      fits.push_back(std::move(made[i]));
    }
    score_candidates<Dim>(fits, choice);
  };
  auto kept = [&]() { return choice.candidates[static_cast<std::size_t>(choice.chosen)]; };
  // In the kept steps and msm_alpha mode, the radii between consecutive fitted radii at which
  // the clusters change (cluster_radii.hpp), up to kRadiiPerGap per gap: in every gap, or only
  // in the two gaps beside the kept radius.
  auto radii_in_gaps = [&](const BaselineCandidate& form, bool beside_kept_only) {
    std::vector<double> fitted;
    for (const BaselineCandidate& c : choice.candidates) fitted.push_back(c.cluster_radius_factor);
    std::sort(fitted.begin(), fitted.end());
    fitted.erase(std::unique(fitted.begin(), fitted.end()), fitted.end());
    const HostMsmModel<Dim>& any = model_for(setup_radius);
    std::vector<Variant> between;
    for (std::size_t j = 0; j + 1 < fitted.size(); ++j) {
      const bool beside = fitted[j] == form.cluster_radius_factor || fitted[j + 1] == form.cluster_radius_factor;
      if (beside_kept_only && !beside) continue;
      for (double radius : membership_radii(any.rest, Dim, any.model.spacing, fitted[j], fitted[j + 1], kRadiiPerGap)) {
        between.push_back({form.steps_per_frame, form.alpha_fitted, radius});
      }
    }
    return between;
  };

  // Past the edge the counts tried are a factor of 2 apart: bisects between the kept count and the
  // nearest counts tried on either side of it (kept msm_alpha mode and radius), a few times.
  auto refine_steps_between_doublings = [&]() {
    for (int round = 0; round < kStepBisections; ++round) {
      const BaselineCandidate form = kept();
      if (form.steps_per_frame <= last_steps) return;
      int below = 0;
      int above = 0;
      for (const BaselineCandidate& c : choice.candidates) {
        if (c.alpha_fitted != form.alpha_fitted || c.cluster_radius_factor != form.cluster_radius_factor) continue;
        if (c.steps_per_frame < form.steps_per_frame) below = std::max(below, c.steps_per_frame);
        if (c.steps_per_frame > form.steps_per_frame && (above == 0 || c.steps_per_frame < above)) {
          above = c.steps_per_frame;
        }
      }
      std::vector<int> counts;
      if (below > 0 && form.steps_per_frame - below > 1) counts.push_back((below + form.steps_per_frame) / 2);
      if (above > 0 && above - form.steps_per_frame > 1) counts.push_back((form.steps_per_frame + above) / 2);
      if (counts.empty()) return;
      std::vector<Variant> forms;
      for (int count : counts) {
        if (!alpha_fit) forms.push_back({count, false, form.cluster_radius_factor});
        if (alpha_auto || alpha_fit) forms.push_back({count, true, form.cluster_radius_factor});
      }
      add(forms);
    }
  };
  // When the most steps per frame tried fits best, the object moves further between frames than
  // those steps can follow (it settles within a frame interval: a fast squeeze seen by a slow
  // camera). Doubles the steps, at the kept variant's radius and in both msm_alpha modes the
  // options allow, while the doubled count keeps winning, up to max_steps_per_frame.
  auto steps_past_the_edge = [&]() {
    for (int steps = kept().steps_per_frame; steps >= last_steps && steps < max_steps_per_frame;) {
      const int more = std::min(2 * steps, max_steps_per_frame);
      const double at = kept().cluster_radius_factor;
      std::vector<Variant> forms;
      if (!alpha_fit) forms.push_back({more, false, at});
      if (alpha_auto || alpha_fit) forms.push_back({more, true, at});
      add(forms);
      if (kept().steps_per_frame != more) break;
      steps = more;
    }
    refine_steps_between_doublings();
  };

  add({{first_steps, alpha_fit, setup_radius}});
  const bool choosing = alpha_auto || steps_auto || radius_auto;
  if (choosing && !alpha_fit && explained_by_noise(fits.front().result.rms, models.front().second->noise_std)) {
    char text[240];
    std::snprintf(text, sizeof text,
                  "held at %.3f, %d step%s per frame: it fits to within %.1f times the measured noise (rms %.3g, "
                  "noise %.3g), nothing left for msm_alpha, steps per frame or cluster radius to explain",
                  fits.front().result.msm_alpha, first_steps, first_steps == 1 ? "" : "s", kExplainedByNoise,
                  fits.front().result.rms, models.front().second->noise_std);
    choice.reason = text;
  } else {
    double radius = setup_radius;
    for (int round = 0; round < 3; ++round) {
      std::vector<Variant> forms;
      for (int steps = first_steps; steps <= last_steps; ++steps) {
        if (!alpha_fit) forms.push_back({steps, false, radius});
        if (alpha_auto || alpha_fit) forms.push_back({steps, true, radius});
      }
      add(forms);
      if (steps_auto) steps_past_the_edge();
      if (!radius_auto) break;
      const BaselineCandidate form = kept();
      std::vector<Variant> radii{{form.steps_per_frame, form.alpha_fitted, setup_radius}};
      for (double other : auto_cluster_radii) radii.push_back({form.steps_per_frame, form.alpha_fitted, other});
      add(radii);
      add(radii_in_gaps(kept(), round > 0));
      if (kept().cluster_radius_factor == radius) break;
      radius = kept().cluster_radius_factor;
    }
    if (!trajectory) {
      choice.reason = "held: the final equilibrium does not depend on msm_alpha or steps per frame";
    } else if (choice.candidates.size() == 1) {
      choice.reason = std::string(options.alpha == AlphaMode::fitted ? "fitted" : "held") + " as asked (--alpha " +
                      alpha_mode_name(options.alpha) + "), " + std::to_string(first_steps) + " step" +
                      (first_steps == 1 ? "" : "s") + " per frame";
    } else {
      choice.reason = choice_reason(choice, alpha_auto, steps_auto, radius_auto);
    }
  }
  const double kept_radius = kept().cluster_radius_factor;
  for (auto& [r, m] : models) {
    if (r == kept_radius) model = std::move(m);
  }
  return std::move(fits[static_cast<std::size_t>(choice.chosen)]);
}

template <int Dim>
EstimateReport run(const Recording& recording, const EstimateOptions& options) {
  const auto started = std::chrono::steady_clock::now();
  auto model = build_msm_model<Dim>(recording, options.setup);
  const bool trajectory = options.mode == FitMode::trajectory;
  const int alpha_variants = trajectory && options.alpha == AlphaMode::automatic ? 2 : 1;
  const int step_variants = trajectory && options.steps_per_frame == 0 ? max_auto_steps_per_frame : 1;
  const int radius_variants =
      trajectory && options.cluster_radius_auto && options.setup.clusters.layout == ClusterLayout::radius
          ? static_cast<int>(std::size(auto_cluster_radii))
          : 0;
  const int noise_stages = options.input_noise_samples >= 2 ? options.input_noise_samples : 0;
  StagedProgress staged{options.progress, options.progress_context, 0,
                        alpha_variants * step_variants + radius_variants + noise_stages};

  EstimateReport report;
  MsmFit<Dim> fit = fit_baseline<Dim>(recording, options, model, report.baseline, staged);
  const int fits = staged.stage;
  report.result = fit.result;
  report.curve_beta = std::move(fit.curve_beta);
  report.curve_error = std::move(fit.curve_error);
  report.cluster_count = model->model.cluster_count;
  report.cluster_radius_factor = report.baseline.cluster_radius_factor(options.setup.clusters.radius_factor);
  report.rest_frames = model->rest_frames;
  report.spacing = model->model.spacing;
  const int frames = recording.frame_count();
  report.frame_interval_s =
      frames > 1 ? (recording.frame_times_s.back() - recording.frame_times_s.front()) / (frames - 1) : 0.0;
  // Without fixed particles to measure noise on, the fit's residual is a conservative stand-in.
  report.noise_std = model->noise_std > 0 ? model->noise_std : report.result.rms;
  report.msm_beta_std_curvature = report.result.msm_beta_std;
  // The input-noise refits hold msm_alpha at the value chosen above: they measure the spread of
  // msm_beta within the model the fit settled on.
  EstimateOptions refit = options;
  refit.alpha = AlphaMode::fixed;
  refit.msm_alpha = report.result.msm_alpha;
  refit.steps_per_frame = report.baseline.steps_per_frame();
  refit.cluster_radius_auto = false;
  refit.setup.clusters.radius_factor = report.cluster_radius_factor;
  report.msm_beta_std_input = input_noise_std<Dim>(recording, refit, *model, report.noise_std, staged, fits);
  report.msm_beta_std_model_form = report.baseline.msm_beta_spread();
  report.msm_beta_std = std::sqrt(report.msm_beta_std_curvature * report.msm_beta_std_curvature +
                                  report.msm_beta_std_input * report.msm_beta_std_input +
                                  report.msm_beta_std_model_form * report.msm_beta_std_model_form);
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

// Each variant's weight exp(-(BIC - BIC_kept) / 2) is the Schwarz approximation of its posterior
// probability relative to the kept one (Kass and Raftery 1995). A clear choice leaves the spread
// near 0; forms within a few BIC units that read msm_beta differently (a cluster radius the frames
// do not determine) widen it.
double BaselineChoice::msm_beta_spread() const {
  if (candidates.size() < 2) return 0.0;
  const BaselineCandidate& kept = candidates[static_cast<std::size_t>(chosen)];
  if (!std::isfinite(kept.bic)) return 0.0;
  double weights = 0;
  double spread = 0;
  for (const BaselineCandidate& c : candidates) {
    if (!std::isfinite(c.bic) || !std::isfinite(c.msm_beta)) continue;
    const double weight = std::exp(-0.5 * (c.bic - kept.bic));
    weights += weight;
    spread += weight * (c.msm_beta - kept.msm_beta) * (c.msm_beta - kept.msm_beta);
  }
  return weights > 0 ? std::sqrt(spread / weights) : 0.0;
}

const char* alpha_mode_name(AlphaMode mode) {
  switch (mode) {
    case AlphaMode::automatic: return "auto";
    case AlphaMode::fitted: return "fit";
    case AlphaMode::fixed: return "fixed";
  }
  return "auto";
}

void parse_alpha_choice(const std::string& text, AlphaMode& mode, double& held_alpha) {
  if (text == "auto") {
    mode = AlphaMode::automatic;
    return;
  }
  if (text == "fit" || text.empty()) {
    mode = AlphaMode::fitted;
    return;
  }
  const std::string prefix = "fixed";
  if (text.compare(0, prefix.size(), prefix) == 0) {
    double value = 1.0;
    if (text.size() > prefix.size()) {
      const std::string number = text.substr(prefix.size() + 1);
      char* end = nullptr;
      value = number.empty() || text[prefix.size()] != '=' ? -1.0 : std::strtod(number.c_str(), &end);
      if (end == nullptr || *end != '\0') value = -1.0;
    }
    if (!(value > 0.0 && value <= 1.0)) {
      throw std::invalid_argument("--alpha fixed=A needs A in (0, 1], not '" + text + "'");
    }
    mode = AlphaMode::fixed;
    held_alpha = value;
    return;
  }
  throw std::invalid_argument("--alpha must be 'auto', 'fit' or 'fixed=A', not '" + text + "'");
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
      {"time_step_s", report.frame_interval_s / report.baseline.steps_per_frame()},
      {"steps_per_frame", report.baseline.steps_per_frame()},
      {"clusters", report.cluster_count},
      {"cluster_layout", options.setup.clusters.layout == ClusterLayout::radius      ? "radius"
                         : options.setup.clusters.layout == ClusterLayout::k_nearest ? "k_nearest"
                                                                                     : "grid_blocks"},
      {"cluster_radius_factor", report.cluster_radius_factor},
      {"cluster_radius_mode",
       options.cluster_radius_auto && options.setup.clusters.layout == ClusterLayout::radius ? "auto" : "fixed"},
      {"driven_mass_factor", options.setup.driven_mass_factor},
      {"rest_source", options.setup.rest == RestSource::still_frames ? "still_frames" : "first_frame"},
      {"rest_frames", report.rest_frames},
      {"msm_alpha_estimated", report.baseline.alpha_fitted()},
      {"msm_alpha_mode", alpha_mode_name(options.alpha)},
      {"steps_per_frame_mode", options.steps_per_frame == 0 ? "auto" : "fixed"},
      {"baseline_reason", report.baseline.reason},
      {"gravity_declared", recording.gravity.has_value()},
  };
  nlohmann::json candidates = nlohmann::json::array();
  for (const BaselineCandidate& c : report.baseline.candidates) {
    candidates.push_back({{"steps_per_frame", c.steps_per_frame},
                          {"msm_alpha_fitted", c.alpha_fitted},
                          {"cluster_radius_factor", c.cluster_radius_factor},
                          {"msm_alpha", c.msm_alpha},
                          {"msm_beta", c.msm_beta},
                          {"rms", c.rms},
                          {"bic", finite_or(c.bic, -1e300)}});
  }
  out["model_options"]["baseline_candidates"] = candidates;
  out["model_options"]["effective_residuals"] = report.baseline.effective_residuals;
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
      {"msm_beta_std_model_form", report.msm_beta_std_model_form},
      {"input_noise_samples", options.input_noise_samples},
      {"runtime_s", report.runtime_s},
  };
  if (!std::isfinite(r.msm_beta_std)) out["diagnostics"]["msm_beta_identifiable"] = false;
  return out;
}

}  // namespace pliant::host
