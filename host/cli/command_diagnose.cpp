#include "command_diagnose.hpp"

#include <iostream>
#include <stdexcept>

#include "exit_status.hpp"
#include "job_diagnose.hpp"

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
  DiagnoseJob job;
  job.json = json_path_;
  job.report = report_dir_;
  job.model = model_;
  job.model_form = model_form_.text(*app_);
  job.progress = !quiet_;
  const DiagnoseDone done = run_diagnose_job(job, recording_from(recording_), report_warning);
  if (json_path_ == "-") {
    std::cout << done.document.dump(2) << '\n';
  } else {
    std::cout << host::diagnosis_summary(done.result.diagnosis, done.recording.length_unit);
    if (!json_path_.empty()) std::cout << "wrote " << json_path_ << '\n';
    if (!report_dir_.empty()) std::cout << "wrote " << report_dir_ << "/index.html\n";
  }
  std::cout.flush();
  if (!std::cout) throw std::runtime_error("cannot write to standard output");
  return exit_ok;
}

}  // namespace pliant::cli
