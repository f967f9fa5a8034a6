// The job of `pliant estimate`: msm_beta (and msm_alpha) of a recording (job.hpp).
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "job.hpp"
#include "model_form.hpp"
#include "pliant/host/estimate.hpp"

namespace pliant::cli {

/// The options of `pliant estimate`, by their long names.
struct EstimateJob {
  std::string json;                 ///< --json OUT: also write the document there; "" or "-": no file
  std::string mode = "trajectory";  ///< --mode final|trajectory
  ModelFormText model_form;         ///< --alpha, --msm-alpha, --steps-per-frame, --cluster-radius
  int grid = 11;                    ///< --grid N, 3..1001
  bool progress = false;            ///< a progress bar on stderr (only on a terminal)
};

struct EstimateDone {
  host::Recording recording;
  host::EstimateOptions options;
  host::EstimateReport report;
  nlohmann::json document;  ///< pliant-estimate v1 (docs/spec/outputs-v1.md)
};

/// The estimator's options for `job`. Throws UsageError with the command line's message.
host::EstimateOptions estimate_options(const EstimateJob& job);

/// Checks the options, takes the recording from `source` (its warnings go to `warn`), estimates
/// and writes job.json. Throws as job.hpp says.
EstimateDone run_estimate_job(const EstimateJob& job, const RecordingSource& source, const WarningSink& warn);

}  // namespace pliant::cli
