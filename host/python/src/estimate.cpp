// pliant.estimate: `pliant estimate` (host/cli/job_estimate.hpp) on a recording or a path.
#include "bindings.hpp"
#include "convert.hpp"
#include "estimate_summary.hpp"
#include "job_call.hpp"
#include "job_estimate.hpp"

namespace pliant::python {
namespace {

py::object estimate(py::handle recording, py::handle json, const std::string& mode, py::handle alpha,
                    py::handle msm_alpha, py::handle steps_per_frame, py::handle cluster_radius, int grid, bool quiet) {
  cli::EstimateJob job;
  job.json = optional_path(json, "json");
  job.mode = mode;
  job.model_form = model_form_text(alpha, msm_alpha, steps_per_frame, cluster_radius);
  job.grid = grid;
  job.progress = !quiet;
  const cli::RecordingSource source = recording_source(recording);
  WarningLines warnings;
  const cli::EstimateDone done =
      without_gil([&] { return cli::run_estimate_job(job, source, warnings.sink()); }, warnings);
  for (const std::string& line : cli::estimate_warnings(done.report)) warnings.add(line);
  warnings.emit();
  return to_python(done.document);
}

const char* kDoc = R"doc(estimate(recording, *, json=None, mode='trajectory', alpha=None, msm_alpha=None,
steps_per_frame=None, cluster_radius=None, grid=11, quiet=False) -> dict

msm_beta (and msm_alpha) of a recording, as `pliant estimate` computes it; returns the
pliant-estimate v1 document (docs/spec/outputs-v1.md), the dict equal to the command's --json
output. recording: a pliant.Recording or a recording directory. Options are the command's long
options (None: not given): json (also write the document there), mode ('trajectory' or
'final'), alpha ('auto', 'fit', 'fixed=A'), msm_alpha (A in (0, 1]), steps_per_frame ('auto' or
1..64), cluster_radius ('auto' or 1..4), grid (3..1001), quiet (no progress bar on a terminal).
The GIL is released while it runs. Errors: pliant.UsageError, pliant.InputError,
pliant.PliantError with the command's messages.)doc";

}  // namespace

void bind_estimate(py::module_& module) {
  module.def("estimate", &estimate, py::arg("recording"), py::kw_only(), py::arg("json") = py::none(),
             py::arg("mode") = "trajectory", py::arg("alpha") = py::none(), py::arg("msm_alpha") = py::none(),
             py::arg("steps_per_frame") = py::none(), py::arg("cluster_radius") = py::none(), py::arg("grid") = 11,
             py::arg("quiet") = false, kDoc);
}

}  // namespace pliant::python
