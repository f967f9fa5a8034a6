// Conversions between Python values and what the C++ side holds: JSON documents, paths, option
// values and NumPy arrays. Every function here needs the GIL.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <pybind11/numpy.h>

#include "bindings.hpp"

namespace pliant::python {

/// A JSON document as Python values (dict, list, str, int, float, bool, None). Numbers that are
/// not finite become None, as the command line writes them.
py::object to_python(const nlohmann::json& value);

/// Python values (dict with str keys, list, tuple, str, int, float, bool, None) as JSON.
/// TypeError naming `what` for anything else.
nlohmann::json to_json(py::handle value, const std::string& what);

/// A str or os.PathLike as a path. TypeError naming `what` for anything else (None included).
std::string path_of(py::handle value, const char* what);

/// An option the command line takes as text ("auto", "fixed=0.5", "2", ...): None is "not
/// given", a str is itself, an int or float is written as Python writes it.
std::optional<std::string> option_text(py::handle value, const char* what);

/// A NumPy view of `data` that keeps `owner` alive and cannot be written to.
py::array readonly_view(const py::dtype& dtype, std::vector<py::ssize_t> shape, std::vector<py::ssize_t> strides,
                        const void* data, py::handle owner);

/// `value` as a C-contiguous float64 array (integers converted, a copy only when needed) whose
/// shape is `shape`, -1 standing for any length. TypeError for something that is not an array
/// of real numbers, ValueError for another shape; both name `what` and `axes` (e.g.
/// "(n_frames, n_particles, dim)").
py::array_t<double> real_array(py::handle value, const char* what, const std::vector<py::ssize_t>& shape,
                               const char* axes);

/// The same for an array of booleans (dtype bool only).
py::array_t<bool> bool_array(py::handle value, const char* what, const std::vector<py::ssize_t>& shape,
                             const char* axes);

/// The same for integer ids (any integer dtype), one dimension, as ints.
std::vector<int> id_list(py::handle value, const char* what);

}  // namespace pliant::python
