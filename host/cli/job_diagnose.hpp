// The job of `pliant diagnose`: where the elastic model disagrees with a recording and which
// physics it left out (docs/spec/diagnosis-v1.md, job.hpp).
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "job.hpp"
#include "model_form.hpp"
#include "pliant/host/diagnose/diagnose.hpp"

namespace pliant::cli {

/// The options of `pliant diagnose`, by their long names.
struct DiagnoseJob {
  std::string json;           ///< --json OUT: also write the document there; "" or "-": no file
  std::string report;         ///< --report DIR: write DIR/index.html; "": no report
  std::string model = "msm";  ///< --model msm|fem
  ModelFormText model_form;   ///< the msm baseline's form; --model fem takes none of it
  bool progress = false;      ///< a progress bar on stderr (only on a terminal)
};

struct DiagnoseDone {
  host::Recording recording;
  host::DiagnoseResult result;
  nlohmann::json document;  ///< pliant-diagnosis v1
};

/// Checks the options, takes the recording from `source` (its warnings go to `warn`), diagnoses,
/// and writes job.report and job.json. Throws as job.hpp says.
DiagnoseDone run_diagnose_job(const DiagnoseJob& job, const RecordingSource& source, const WarningSink& warn);

}  // namespace pliant::cli
