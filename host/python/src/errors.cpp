#include "errors.hpp"

#include <exception>
#include <new>

#include "exit_status.hpp"
#include "pliant/host/recording.hpp"

namespace pliant::python {
namespace {

// The classes, created once at import and kept for the life of the interpreter.
PyObject* g_pliant_error = nullptr;
PyObject* g_usage_error = nullptr;
PyObject* g_input_error = nullptr;
PyObject* g_warning = nullptr;

PyObject* new_class(py::module_& module, const char* name, py::tuple bases, const char* doc) {
  const std::string qualified = std::string("pliant.") + name;
  PyObject* type = PyErr_NewExceptionWithDoc(qualified.c_str(), doc, bases.ptr(), nullptr);
  if (type == nullptr) throw py::error_already_set();
  module.add_object(name, py::handle(type));
  return type;
}

void set_error(PyObject* type, const char* what) { PyErr_SetString(type, cli::single_line(what).c_str()); }

void translate(std::exception_ptr error) {
  try {
    if (error) std::rethrow_exception(error);
  } catch (const py::builtin_exception&) {
    throw;  // ValueError, TypeError, ... raised by the bindings themselves
  } catch (const py::error_already_set&) {
    throw;
  } catch (const std::bad_alloc&) {
    throw;  // MemoryError
  } catch (const host::RecordingError& e) {
    set_error(g_input_error, e.what());
  } catch (const cli::UsageError& e) {
    set_error(g_usage_error, e.what());
  } catch (const std::exception& e) {
    set_error(g_pliant_error, e.what());
  }
}

}  // namespace

void emit_warnings(const std::vector<std::string>& lines) {
  for (const std::string& line : lines) {
    if (PyErr_WarnEx(g_warning, cli::single_line(line).c_str(), 1) != 0) throw py::error_already_set();
  }
}

void bind_errors(py::module_& module) {
  const py::handle runtime_error(PyExc_RuntimeError);
  const py::handle value_error(PyExc_ValueError);
  g_pliant_error = new_class(module, "PliantError", py::make_tuple(runtime_error),
                             "A failure of pliant's work (the command line's exit status 1); the base of "
                             "UsageError and InputError.");
  const py::handle pliant_error(g_pliant_error);
  g_usage_error = new_class(module, "UsageError", py::make_tuple(pliant_error, value_error),
                            "An option that cannot work, in the command line's words (its exit status 2).");
  g_input_error = new_class(module, "InputError", py::make_tuple(pliant_error, value_error),
                            "A recording or mesh the readers reject: file, line or key, and the cause.");
  g_warning = new_class(module, "PliantWarning", py::make_tuple(py::handle(PyExc_UserWarning)),
                        "A finding that does not stop the work (the command line's warning lines).");
  py::register_exception_translator(&translate);
}

}  // namespace pliant::python
