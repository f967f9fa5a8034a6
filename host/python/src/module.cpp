// The extension module pliant._pliant; the package pliant (host/python/pliant/__init__.py)
// re-exports its names.
#include "bindings.hpp"

PYBIND11_MODULE(_pliant, module) {
  module.doc() =
      "pliant: how soft an object is, from tracked particle trajectories (meshless shape matching).\n"
      "Recordings, the command line's jobs (estimate, diagnose, refine, simulate), the online estimator "
      "and the grasp guard. See docs/python.md.";
  module.attr("__version__") = PLIANT_VERSION;
  pliant::python::bind_errors(module);
  pliant::python::bind_recordings(module);
  pliant::python::bind_estimate(module);
  pliant::python::bind_diagnose(module);
  pliant::python::bind_refine(module);
  pliant::python::bind_simulate(module);
  pliant::python::bind_online(module);
  pliant::python::bind_guard(module);
}
