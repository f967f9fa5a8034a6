#include "job_estimate.hpp"

#include <stdexcept>

#include "atomic_write.hpp"
#include "exit_status.hpp"
#include "progress_bar.hpp"

namespace pliant::cli {
namespace {

// Far above any useful resolution; bounds the curve the estimator has to hold.
constexpr int max_grid_points = 1001;

}  // namespace

host::EstimateOptions estimate_options(const EstimateJob& job) {
  host::EstimateOptions options;
  try {
    options.mode = host::parse_fit_mode(job.mode);
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  const ModelFormChoice form = model_form_choice(job.model_form);
  options.alpha = form.alpha;
  options.msm_alpha = form.msm_alpha;
  options.steps_per_frame = form.steps_per_frame;
  options.cluster_radius_auto = form.cluster_radius_auto;
  options.setup.clusters.radius_factor = form.cluster_radius_factor;
  if (options.alpha == host::AlphaMode::fitted && options.mode != FitMode::trajectory) {
    throw UsageError("--alpha fit needs --mode trajectory");
  }
  if (job.grid < 3 || job.grid > max_grid_points) {
    throw UsageError("--grid must be between 3 and " + std::to_string(max_grid_points));
  }
  options.grid_points = job.grid;
  return options;
}

EstimateDone run_estimate_job(const EstimateJob& job, const RecordingSource& source, const WarningSink& warn) {
  EstimateDone done;
  done.options = estimate_options(job);
  done.recording = source();
  for (const std::string& warning : done.recording.warnings) warn(warning);
  {
    ProgressBar bar("estimating msm_beta", job.progress);
    done.options.progress = &ProgressBar::callback;
    done.options.progress_context = &bar;
    done.report = host::estimate_recording(done.recording, done.options);
    done.options.progress = nullptr;
    done.options.progress_context = nullptr;
  }
  done.document = host::estimate_json(done.recording, done.options, done.report);
  if (!job.json.empty() && job.json != "-") write_file_atomically(job.json, done.document.dump(2) + "\n");
  return done;
}

}  // namespace pliant::cli
