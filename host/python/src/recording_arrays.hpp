// A host::Recording made from NumPy arrays (pliant.make_recording, pliant.write_recording).
#pragma once

#include <memory>

#include "bindings.hpp"
#include "pliant/host/recording.hpp"

namespace pliant::python {

/// The arrays and values pliant.make_recording takes (docs/python.md lists them with units).
struct RecordingArrays {
  py::object times, positions, observed, masses, fixed, driven, gravity, wrench, gripper, mesh, material, meta;
  std::string length_unit = "m";
  std::string name;
};

/// Checks the arrays' shapes and types (ValueError, TypeError), then the recording as the reader
/// checks one (host::finalize_recording: pliant.InputError naming the recording.json key).
std::shared_ptr<host::Recording> recording_from_arrays(const RecordingArrays& arrays);

}  // namespace pliant::python
