#include "job_call.hpp"

#include <memory>

#include "convert.hpp"
#include "pliant/host/recording.hpp"

namespace pliant::python {

cli::RecordingSource recording_source(py::handle recording_or_path) {
  if (py::isinstance<host::Recording>(recording_or_path)) {
    auto recording = recording_or_path.cast<std::shared_ptr<host::Recording>>();
    return [recording] { return *recording; };
  }
  if (recording_or_path.is_none()) throw py::type_error("recording must be a pliant.Recording or a path, not None");
  return cli::recording_from(path_of(recording_or_path, "recording (a pliant.Recording or a path)"));
}

cli::ModelFormText model_form_text(py::handle alpha, py::handle msm_alpha, py::handle steps_per_frame,
                                   py::handle cluster_radius) {
  cli::ModelFormText text;
  text.alpha = option_text(alpha, "alpha");
  if (!msm_alpha.is_none()) {
    if (py::isinstance<py::bool_>(msm_alpha) ||
        !(py::isinstance<py::float_>(msm_alpha) || py::isinstance<py::int_>(msm_alpha))) {
      throw py::type_error("msm_alpha must be a number");
    }
    text.msm_alpha = msm_alpha.cast<double>();
  }
  text.steps_per_frame = option_text(steps_per_frame, "steps_per_frame");
  text.cluster_radius = option_text(cluster_radius, "cluster_radius");
  return text;
}

std::string optional_path(py::handle value, const char* what) {
  if (value.is_none()) return {};
  return path_of(value, what);
}

}  // namespace pliant::python
