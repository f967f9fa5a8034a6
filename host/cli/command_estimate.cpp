#include "command_estimate.hpp"

#include <iostream>
#include <stdexcept>

#include "estimate_summary.hpp"
#include "exit_status.hpp"
#include "job_estimate.hpp"

namespace pliant::cli {

EstimateCommand::EstimateCommand(CLI::App& parent) {
  app_ = parent.add_subcommand("estimate", "Estimate msm_beta (MSM deformability) of a recording");
  app_->footer(
      "Prints a summary with the error curve. Exit status: 0 ok, 1 estimation failed, 2 bad options "
      "or a malformed recording.");
  app_->add_option("REC", recording_, "Recording directory (docs/spec/recording-v1.md)")->required();
  app_->add_option("--json", json_path_,
                   "Also write the pliant-estimate v1 JSON to OUT (atomically); '-' prints it to stdout "
                   "instead of the summary")
      ->type_name("OUT");
  app_->add_option("--mode", mode_, "'trajectory': simulate every frame; 'final': match the final equilibrium only")
      ->type_name("final|trajectory")
      ->capture_default_str();
  model_form_.add_to(*app_);
  app_->add_option("--grid", grid_points_, "Grid points over msm_beta in [0, 1] before refinement (>= 3)")
      ->type_name("N")
      ->capture_default_str();
  app_->add_flag("-q,--quiet", quiet_, "No progress bar");
}

int EstimateCommand::run() const {
  EstimateJob job;
  job.json = json_path_;
  job.mode = mode_;
  job.model_form = model_form_.text(*app_);
  job.grid = grid_points_;
  job.progress = !quiet_;
  const EstimateDone done = run_estimate_job(job, recording_from(recording_), report_warning);

  if (json_path_ == "-") {
    std::cout << done.document.dump(2) << '\n';
    for (const std::string& warning : estimate_warnings(done.report)) report_warning(warning);
  } else {
    std::cout << format_estimate_summary(done.recording, done.options, done.report);
    if (!json_path_.empty()) std::cout << "\nwrote " << json_path_ << '\n';
  }
  std::cout.flush();
  if (!std::cout) throw std::runtime_error("cannot write to standard output");
  return exit_ok;
}

}  // namespace pliant::cli
