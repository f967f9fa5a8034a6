// The parts of the `pliant` Python module (_pliant), one source file each (docs/python.md).
#pragma once

#include <pybind11/pybind11.h>

namespace pliant::python {

namespace py = pybind11;

void bind_errors(py::module_& module);      // errors.cpp: exception classes and their translation
void bind_recordings(py::module_& module);  // recordings.cpp: Recording, read, make, write
void bind_estimate(py::module_& module);    // estimate.cpp
void bind_diagnose(py::module_& module);    // diagnose.cpp
void bind_refine(py::module_& module);      // refine.cpp
void bind_simulate(py::module_& module);    // simulate.cpp
void bind_online(py::module_& module);      // online.cpp: OnlineEstimator
void bind_guard(py::module_& module);       // guard.cpp: GraspGuard

}  // namespace pliant::python
