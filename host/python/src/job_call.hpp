// How the module runs the command line's jobs (host/cli/job.hpp): the recording from a
// pliant.Recording or a path, the job without the GIL, its warnings issued afterwards as
// pliant.PliantWarning (also when the job fails, before its exception).
#pragma once

#include <mutex>
#include <string>
#include <vector>

#include "bindings.hpp"
#include "errors.hpp"
#include "job.hpp"
#include "model_form.hpp"

namespace pliant::python {

/// Warning lines a job reports while it runs without the GIL.
class WarningLines {
 public:
  cli::WarningSink sink() {
    return [this](const std::string& line) {
      const std::lock_guard<std::mutex> lock(mutex_);
      lines_.push_back(line);
    };
  }
  void add(const std::string& line) { sink()(line); }
  /// Issues the lines collected (with the GIL).
  void emit() const { emit_warnings(lines_); }

 private:
  std::mutex mutex_;
  std::vector<std::string> lines_;
};

/// A pliant.Recording (copied when the job takes it) or a str / os.PathLike directory (read when
/// the job takes it). TypeError for anything else.
cli::RecordingSource recording_source(py::handle recording_or_path);

/// The model form options as given to a Python call (None: not given).
cli::ModelFormText model_form_text(py::handle alpha, py::handle msm_alpha, py::handle steps_per_frame,
                                   py::handle cluster_radius);

/// An optional output path: None or "" is none.
std::string optional_path(py::handle value, const char* what);

/// Runs `work` without the GIL; if it throws, the collected warnings are issued before the
/// exception reaches Python.
template <typename Work>
auto without_gil(Work&& work, const WarningLines& warnings) -> decltype(work()) {
  try {
    py::gil_scoped_release release;
    return work();
  } catch (...) {
    warnings.emit();
    throw;
  }
}

}  // namespace pliant::python
