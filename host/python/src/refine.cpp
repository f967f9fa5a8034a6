// pliant.refine: `pliant refine` (host/cli/job_refine.hpp), the FEM material card.
#include <optional>

#include <pybind11/stl.h>

#include "bindings.hpp"
#include "convert.hpp"
#include "job_call.hpp"
#include "job_refine.hpp"

namespace pliant::python {
namespace {

struct RefineArguments {
  py::handle recording, mesh, estimate, json, vtk, control_points, rest_mesh;
  std::string estimator, volumetric;
  std::optional<double> max_strain, initial_modulus, until;
  std::optional<int> rest_frame, substeps;
  bool no_force_offset = false;
  int threads = 0;
  bool quiet = false;
};

cli::RefineJob refine_job(const RefineArguments& a) {
  cli::RefineJob job;
  job.mesh = optional_path(a.mesh, "mesh");
  if (!a.estimate.is_none()) {
    // A list of names is the comma list of the command line.
    if (py::isinstance<py::str>(a.estimate)) {
      job.estimate = a.estimate.cast<std::string>();
    } else {
      std::string list;
      for (const py::handle name : a.estimate) list += (list.empty() ? "" : ",") + name.cast<std::string>();
      job.estimate = list;
    }
  }
  job.estimator = a.estimator;
  job.volumetric = a.volumetric;
  job.json = optional_path(a.json, "json");
  job.vtk = optional_path(a.vtk, "vtk");
  job.max_strain = a.max_strain;
  job.no_force_offset = a.no_force_offset;
  job.initial_modulus = a.initial_modulus;
  if (!a.control_points.is_none()) {
    job.control_points = py::isinstance<py::str>(a.control_points) || py::isinstance<py::int_>(a.control_points)
                             ? py::str(a.control_points).cast<std::string>()
                             : path_of(a.control_points, "control_points");
  }
  job.rest_frame = a.rest_frame;
  if (!a.rest_mesh.is_none()) job.rest_mesh = path_of(a.rest_mesh, "rest_mesh");
  job.until = a.until;
  job.substeps = a.substeps;
  job.threads = a.threads;
  job.progress = !a.quiet;
  return job;
}

py::object refine(const RefineArguments& arguments) {
  const cli::RefineJob job = refine_job(arguments);
  const cli::RecordingSource source = recording_source(arguments.recording);
  WarningLines warnings;
  const cli::RefineDone done = without_gil([&] { return cli::run_refine_job(job, source, warnings.sink()); }, warnings);
  warnings.emit();
  return to_python(done.card);
}

const char* kDoc = R"doc(refine(recording, *, mesh=None, estimate=None, estimator='auto', volumetric='auto',
json=None, vtk=None, max_strain=None, no_force_offset=False, initial_modulus=None,
control_points=None, rest_frame=None, rest_mesh=None, until=None, substeps=None, threads=0,
quiet=False) -> dict

FEM material parameters of a 3D recording in metres, as `pliant refine` fits them (README,
"Refining with FEM"); returns the material card (pliant-material v1, docs/spec/outputs-v1.md),
equal to the command's --json output. SI units: Pa, s, m. estimate: 'youngs_modulus,rayleigh'
or a list of names. control_points: a count or a file of 'x,y,z' lines. Files named by json,
vtk and rest_mesh are written as the command writes them. The GIL is released while it runs.
Errors: pliant.UsageError, pliant.InputError, pliant.PliantError.)doc";

}  // namespace

void bind_refine(py::module_& module) {
  module.def(
      "refine",
      [](py::handle recording, py::handle mesh, py::handle estimate, const std::string& estimator,
         const std::string& volumetric, py::handle json, py::handle vtk, std::optional<double> max_strain,
         bool no_force_offset, std::optional<double> initial_modulus, py::handle control_points,
         std::optional<int> rest_frame, py::handle rest_mesh, std::optional<double> until, std::optional<int> substeps,
         int threads, bool quiet) {
        RefineArguments a;
        a.recording = recording;
        a.mesh = mesh;
        a.estimate = estimate;
        a.estimator = estimator;
        a.volumetric = volumetric;
        a.json = json;
        a.vtk = vtk;
        a.max_strain = max_strain;
        a.no_force_offset = no_force_offset;
        a.initial_modulus = initial_modulus;
        a.control_points = control_points;
        a.rest_frame = rest_frame;
        a.rest_mesh = rest_mesh;
        a.until = until;
        a.substeps = substeps;
        a.threads = threads;
        a.quiet = quiet;
        return refine(a);
      },
      py::arg("recording"), py::kw_only(), py::arg("mesh") = py::none(), py::arg("estimate") = py::none(),
      py::arg("estimator") = "auto", py::arg("volumetric") = "auto", py::arg("json") = py::none(),
      py::arg("vtk") = py::none(), py::arg("max_strain") = py::none(), py::arg("no_force_offset") = false,
      py::arg("initial_modulus") = py::none(), py::arg("control_points") = py::none(),
      py::arg("rest_frame") = py::none(), py::arg("rest_mesh") = py::none(), py::arg("until") = py::none(),
      py::arg("substeps") = py::none(), py::arg("threads") = 0, py::arg("quiet") = false, kDoc);
}

}  // namespace pliant::python
