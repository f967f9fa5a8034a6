#include "job_diagnose.hpp"

#include "atomic_write.hpp"
#include "exit_status.hpp"
#include "pliant/host/diagnose/html_report.hpp"
#include "progress_bar.hpp"

namespace pliant::cli {
namespace {

host::DiagnoseOptions diagnose_options(const DiagnoseJob& job) {
  if (job.model != "msm" && job.model != "fem") throw UsageError("--model must be msm or fem");
  host::DiagnoseOptions options;
  options.model = job.model;
  const ModelFormChoice form = model_form_choice(job.model_form);
  if (job.model == "fem" && job.model_form.given()) {
    throw UsageError(
        "--alpha, --msm-alpha, --steps-per-frame and --cluster-radius shape the msm baseline; "
        "--model fem takes none of them");
  }
  options.alpha = form.alpha;
  options.msm_alpha = form.msm_alpha;
  options.steps_per_frame = form.steps_per_frame;
  options.cluster_radius_auto = form.cluster_radius_auto;
  options.cluster_radius_factor = form.cluster_radius_factor;
  return options;
}

}  // namespace

DiagnoseDone run_diagnose_job(const DiagnoseJob& job, const RecordingSource& source, const WarningSink& warn) {
  host::DiagnoseOptions options = diagnose_options(job);
  DiagnoseDone done;
  done.recording = source();
  const host::Recording& recording = done.recording;
  for (const std::string& warning : recording.warnings) warn(warning);
  if (job.model == "fem" && (recording.dimension != 3 || !recording.mesh || recording.length_unit != "m")) {
    throw UsageError("--model fem needs a 3D recording in metres with a tetrahedral mesh (mesh.vtk)");
  }
  {
    ProgressBar bar("diagnosing", job.progress);
    options.progress = [&bar](const std::string&, int finished, int total) { bar.update(finished, total); };
    done.result = host::diagnose_recording(recording, options);
  }
  done.document = host::diagnosis_json(done.result.diagnosis);
  if (!job.report.empty()) host::write_diagnosis_report(done.result.diagnosis, done.result.evidence, job.report);
  if (!job.json.empty() && job.json != "-") write_file_atomically(job.json, done.document.dump(2) + "\n");
  return done;
}

}  // namespace pliant::cli
