// pliant.diagnose: `pliant diagnose` (host/cli/job_diagnose.hpp) on a recording or a path.
#include "bindings.hpp"
#include "convert.hpp"
#include "job_call.hpp"
#include "job_diagnose.hpp"

namespace pliant::python {
namespace {

py::object diagnose(py::handle recording, py::handle report, py::handle json, const std::string& model,
                    py::handle alpha, py::handle msm_alpha, py::handle steps_per_frame, py::handle cluster_radius,
                    bool quiet) {
  cli::DiagnoseJob job;
  job.report = optional_path(report, "report");
  job.json = optional_path(json, "json");
  job.model = model;
  job.model_form = model_form_text(alpha, msm_alpha, steps_per_frame, cluster_radius);
  job.progress = !quiet;
  const cli::RecordingSource source = recording_source(recording);
  WarningLines warnings;
  const cli::DiagnoseDone done =
      without_gil([&] { return cli::run_diagnose_job(job, source, warnings.sink()); }, warnings);
  warnings.emit();
  return to_python(done.document);
}

const char* kDoc = R"doc(diagnose(recording, *, report=None, json=None, model='msm', alpha=None, msm_alpha=None,
steps_per_frame=None, cluster_radius=None, quiet=False) -> dict

Where the elastic model disagrees with a recording and which physics it left out, as
`pliant diagnose` finds it (docs/diagnose.md); returns the pliant-diagnosis v1 document
(docs/spec/diagnosis-v1.md), equal to the command's --json output. report: a directory to write
the HTML report into (DIR/index.html), only when given. json: also write the document there.
model: 'msm' or 'fem' (a 3D recording in metres with a mesh). alpha, msm_alpha,
steps_per_frame, cluster_radius: the msm baseline's form, as for estimate. The GIL is released
while it runs. Errors: pliant.UsageError, pliant.InputError, pliant.PliantError.)doc";

}  // namespace

void bind_diagnose(py::module_& module) {
  module.def("diagnose", &diagnose, py::arg("recording"), py::kw_only(), py::arg("report") = py::none(),
             py::arg("json") = py::none(), py::arg("model") = "msm", py::arg("alpha") = py::none(),
             py::arg("msm_alpha") = py::none(), py::arg("steps_per_frame") = py::none(),
             py::arg("cluster_radius") = py::none(), py::arg("quiet") = false, kDoc);
}

}  // namespace pliant::python
