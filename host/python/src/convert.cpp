#include "convert.hpp"

#include <cmath>
#include <cstdint>
#include <limits>

namespace pliant::python {
namespace {

std::string shape_text(const py::array& array) {
  std::string text = "(";
  for (py::ssize_t axis = 0; axis < array.ndim(); ++axis) {
    text += (axis > 0 ? ", " : "") + std::to_string(array.shape(axis));
  }
  return text + (array.ndim() == 1 ? ",)" : ")");
}

void require_shape(const py::array& array, const char* what, const std::vector<py::ssize_t>& shape, const char* axes) {
  bool fits = array.ndim() == static_cast<py::ssize_t>(shape.size());
  for (std::size_t axis = 0; fits && axis < shape.size(); ++axis) {
    fits = shape[axis] < 0 || array.shape(static_cast<py::ssize_t>(axis)) == shape[axis];
  }
  if (fits) return;
  std::string wanted = "(";
  for (std::size_t axis = 0; axis < shape.size(); ++axis) {
    wanted += (axis > 0 ? ", " : "") + (shape[axis] < 0 ? std::string("any") : std::to_string(shape[axis]));
  }
  wanted += shape.size() == 1 ? ",)" : ")";
  throw py::value_error(std::string(what) + " must have shape " + axes + " = " + wanted + ", not " + shape_text(array));
}

// `value` as a NumPy array without conversion (None and non-sequences refused).
py::array as_array(py::handle value, const char* what) {
  if (value.is_none()) throw py::type_error(std::string(what) + " must be an array, not None");
  py::array array = py::array::ensure(value);
  if (!array) throw py::type_error(std::string(what) + " must be an array (a NumPy array or nested sequences)");
  return array;
}

}  // namespace

py::object to_python(const nlohmann::json& value) {
  switch (value.type()) {
    case nlohmann::json::value_t::null: return py::none();
    case nlohmann::json::value_t::boolean: return py::bool_(value.get<bool>());
    case nlohmann::json::value_t::number_integer: return py::int_(value.get<std::int64_t>());
    case nlohmann::json::value_t::number_unsigned: return py::int_(value.get<std::uint64_t>());
    case nlohmann::json::value_t::number_float: {
      const double number = value.get<double>();
      return std::isfinite(number) ? py::object(py::float_(number)) : py::object(py::none());
    }
    case nlohmann::json::value_t::string: return py::str(value.get_ref<const std::string&>());
    case nlohmann::json::value_t::array: {
      py::list list;
      for (const nlohmann::json& item : value) list.append(to_python(item));
      return list;
    }
    case nlohmann::json::value_t::object: {
      py::dict dict;
      for (const auto& item : value.items()) dict[py::str(item.key())] = to_python(item.value());
      return dict;
    }
    default: return py::none();  // binary and discarded values do not occur in pliant's documents
  }
}

nlohmann::json to_json(py::handle value, const std::string& what) {
  if (value.is_none()) return nullptr;
  if (py::isinstance<py::bool_>(value)) return value.cast<bool>();
  if (py::isinstance<py::int_>(value)) return value.cast<std::int64_t>();
  if (py::isinstance<py::float_>(value)) return value.cast<double>();
  if (py::isinstance<py::str>(value)) return value.cast<std::string>();
  if (py::isinstance<py::dict>(value)) {
    nlohmann::json object = nlohmann::json::object();
    for (const auto& item : value.cast<py::dict>()) {
      if (!py::isinstance<py::str>(item.first)) throw py::type_error(what + ": keys must be str");
      const std::string key = item.first.cast<std::string>();
      object[key] = to_json(item.second, what + "." + key);
    }
    return object;
  }
  if (py::isinstance<py::list>(value) || py::isinstance<py::tuple>(value)) {
    nlohmann::json array = nlohmann::json::array();
    for (const py::handle item : value) array.push_back(to_json(item, what));
    return array;
  }
  if (py::hasattr(value, "dtype") && py::hasattr(value, "item") && py::hasattr(value, "ndim") &&
      value.attr("ndim").cast<int>() == 0) {
    return to_json(value.attr("item")(), what);  // a NumPy scalar
  }
  throw py::type_error(what + ": " + py::str(py::type::of(value)).cast<std::string>() +
                       " cannot be written as JSON (use dict, list, str, int, float, bool or None)");
}

std::string path_of(py::handle value, const char* what) {
  if (py::isinstance<py::str>(value)) return value.cast<std::string>();
  if (!value.is_none() && py::hasattr(value, "__fspath__")) {
    const py::object path = value.attr("__fspath__")();
    if (py::isinstance<py::str>(path)) return path.cast<std::string>();
  }
  throw py::type_error(std::string(what) + " must be a str or os.PathLike path");
}

std::optional<std::string> option_text(py::handle value, const char* what) {
  if (value.is_none()) return std::nullopt;
  if (py::isinstance<py::str>(value)) return value.cast<std::string>();
  if (!py::isinstance<py::bool_>(value) && (py::isinstance<py::int_>(value) || py::isinstance<py::float_>(value))) {
    return py::str(value).cast<std::string>();
  }
  throw py::type_error(std::string(what) + " must be a str or a number");
}

py::array readonly_view(const py::dtype& dtype, std::vector<py::ssize_t> shape, std::vector<py::ssize_t> strides,
                        const void* data, py::handle owner) {
  py::array view(dtype, std::move(shape), std::move(strides), data, owner);
  view.attr("setflags")(py::arg("write") = false);
  return view;
}

py::array_t<double> real_array(py::handle value, const char* what, const std::vector<py::ssize_t>& shape,
                               const char* axes) {
  const py::array array = as_array(value, what);
  const char kind = array.dtype().kind();
  if (kind != 'f' && kind != 'i' && kind != 'u') {
    throw py::type_error(std::string(what) + " must hold real numbers (float64), not dtype " +
                         py::str(array.dtype()).cast<std::string>());
  }
  require_shape(array, what, shape, axes);
  return py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(array);
}

py::array_t<bool> bool_array(py::handle value, const char* what, const std::vector<py::ssize_t>& shape,
                             const char* axes) {
  const py::array array = as_array(value, what);
  if (array.dtype().kind() != 'b') {
    throw py::type_error(std::string(what) + " must be a boolean array, not dtype " +
                         py::str(array.dtype()).cast<std::string>());
  }
  require_shape(array, what, shape, axes);
  return py::array_t<bool, py::array::c_style | py::array::forcecast>::ensure(array);
}

std::vector<int> id_list(py::handle value, const char* what) {
  const py::array array = as_array(value, what);
  const char kind = array.dtype().kind();
  if (array.size() > 0 && kind != 'i' && kind != 'u') {
    throw py::type_error(std::string(what) + " must hold integer ids, not dtype " +
                         py::str(array.dtype()).cast<std::string>());
  }
  require_shape(array, what, {-1}, "(n,)");
  const auto ids = py::array_t<long long, py::array::c_style | py::array::forcecast>::ensure(array);
  std::vector<int> list;
  for (py::ssize_t i = 0; i < ids.size(); ++i) {
    const long long id = ids.at(i);
    if (id < std::numeric_limits<int>::min() || id > std::numeric_limits<int>::max()) {
      throw py::value_error(std::string(what) + ": id " + std::to_string(id) + " out of range");
    }
    list.push_back(static_cast<int>(id));
  }
  return list;
}

}  // namespace pliant::python
