// The grasp guard's values in Python form (pliant.GraspGuard, guard.cpp): the configuration from
// keyword arguments named as GraspGuardConfig's fields, the per-cycle samples from dicts, the
// output as a dict keyed by GraspGuardOutput's fields. Units as in pliant/core/grasp_guard.hpp:
// m, N, N m, s.
#pragma once

#include "bindings.hpp"
#include "pliant/core/grasp_guard.hpp"

namespace pliant::python {

/// GraspGuardConfig with the fields `options` names changed. Enumerations by name:
/// force_source 'force_sensor'|'motor_current'; uncertain_estimate_verdict 'ok'|'limit'|'stop';
/// exceeded_stop_action, fault_stop_action 'open'|'freeze'; fault_verdict {source: verdict}.
/// ValueError for an unknown name, TypeError for a value of the wrong type.
GraspGuardConfig guard_config(const py::dict& options);

/// Updates a sample from a dict (keys: see docs/python.md): 'valid' defaults to True, 'bus_off'
/// and 'timeout' to False; other keys left out keep their values.
void read_sample(py::handle value, GripperSample& sample);
void read_sample(py::handle value, WrenchSample& sample);
void read_sample(py::handle value, DeformationSample& sample);
void read_sample(py::handle value, EstimateSample& sample);

py::dict output_dict(const GraspGuardOutput& output);

}  // namespace pliant::python
