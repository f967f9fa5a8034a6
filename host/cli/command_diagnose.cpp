#include "command_diagnose.hpp"

#include <iostream>
#include <stdexcept>

#include "atomic_write.hpp"
#include "exit_status.hpp"
#include "progress_bar.hpp"
#include "pliant/host/diagnose/diagnose.hpp"
#include "pliant/host/diagnose/html_report.hpp"
#include "pliant/host/recording.hpp"

namespace pliant::cli {

DiagnoseCommand::DiagnoseCommand(CLI::App& parent) {
  app_ = parent.add_subcommand("diagnose",
                               "Locate where the elastic model and a recording disagree, name the physics it left "
                               "out, model it and show the fit improve");
  app_->footer(
      "Prints a short summary. Exit status: 0 ok (whatever the verdict), 1 the recording cannot be diagnosed "
      "(too few frames, nothing moves, nothing observed), 2 bad options or a malformed recording.");
  app_->add_option("REC", recording_, "Recording directory (docs/spec/recording-v1.md)")->required();
  app_->add_option("--json", json_path_, "Also write the pliant-diagnosis v1 JSON to OUT; '-' prints it instead")
      ->type_name("OUT");
  app_->add_option("--report", report_dir_, "Write an HTML report with plots to DIR/index.html")->type_name("DIR");
  app_->add_option("--model", model_,
                   "Baseline model: msm (shape matching) or fem (corotational linear FEM; needs a 3D recording "
                   "in metres with mesh.vtk)")
      ->type_name("msm|fem")
      ->capture_default_str();
  model_form_.add_to(*app_);
  app_->add_flag("-q,--quiet", quiet_, "No progress bar");
}

int DiagnoseCommand::run() const {
  if (model_ != "msm" && model_ != "fem") throw UsageError("--model must be msm or fem");
  host::DiagnoseOptions options;
  options.model = model_;
  const ModelFormChoice form = model_form_.apply(*app_);
  if (model_ == "fem" && ModelFormOptions::given(*app_)) {
    throw UsageError(
        "--alpha, --msm-alpha, --steps-per-frame and --cluster-radius shape the msm baseline; "
        "--model fem takes none of them");
  }
  options.alpha = form.alpha;
  options.msm_alpha = form.msm_alpha;
  options.steps_per_frame = form.steps_per_frame;
  options.cluster_radius_auto = form.cluster_radius_auto;
  options.cluster_radius_factor = form.cluster_radius_factor;
  const host::Recording recording = host::read_recording(recording_);
  for (const std::string& warning : recording.warnings) report_warning(warning);
  if (model_ == "fem" && (recording.dimension != 3 || !recording.mesh || recording.length_unit != "m")) {
    throw UsageError("--model fem needs a 3D recording in metres with a tetrahedral mesh (mesh.vtk)");
  }

  host::DiagnoseResult result;
  {
    ProgressBar bar("diagnosing", !quiet_);
    options.progress = [&bar](const std::string&, int done, int total) { bar.update(done, total); };
    result = host::diagnose_recording(recording, options);
  }
  const nlohmann::json document = host::diagnosis_json(result.diagnosis);
  if (!report_dir_.empty()) host::write_diagnosis_report(result.diagnosis, result.evidence, report_dir_);
  if (json_path_ == "-") {
    std::cout << document.dump(2) << '\n';
  } else {
    if (!json_path_.empty()) write_file_atomically(json_path_, document.dump(2) + "\n");
    std::cout << host::diagnosis_summary(result.diagnosis, recording.length_unit);
    if (!json_path_.empty()) std::cout << "wrote " << json_path_ << '\n';
    if (!report_dir_.empty()) std::cout << "wrote " << report_dir_ << "/index.html\n";
  }
  std::cout.flush();
  if (!std::cout) throw std::runtime_error("cannot write to standard output");
  return exit_ok;
}

}  // namespace pliant::cli
