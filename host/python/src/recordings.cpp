// pliant.Recording (a recording in memory, its arrays as read-only NumPy views), read_recording,
// make_recording and write_recording.
#include <cstddef>
#include <iterator>
#include <memory>
#include <string>
#include <vector>

#include <pybind11/stl.h>

#include "bindings.hpp"
#include "convert.hpp"
#include "errors.hpp"
#include "pliant/host/recording.hpp"
#include "recording_arrays.hpp"

namespace pliant::python {
namespace {

using host::Recording;
using RecordingPtr = std::shared_ptr<Recording>;

constexpr auto kDouble = static_cast<py::ssize_t>(sizeof(double));
constexpr auto kInt = static_cast<py::ssize_t>(sizeof(int));

static_assert(sizeof(host::WrenchSample) == 7 * sizeof(double), "WrenchSample is viewed as 7 doubles");
static_assert(sizeof(host::GripperSample) == 3 * sizeof(double), "GripperSample is viewed as 3 doubles");

const Recording& of(py::handle self) { return self.cast<const Recording&>(); }

py::ssize_t count(std::size_t n) { return static_cast<py::ssize_t>(n); }

py::array double_view(py::handle self, const std::vector<double>& values, std::vector<py::ssize_t> shape) {
  std::vector<py::ssize_t> strides(shape.size(), kDouble);
  for (std::size_t axis = shape.size() - 1; axis > 0; --axis) strides[axis - 1] = strides[axis] * shape[axis];
  return readonly_view(py::dtype::of<double>(), std::move(shape), std::move(strides), values.data(), self);
}

py::array int_view(py::handle self, const std::vector<int>& values, std::vector<py::ssize_t> shape) {
  std::vector<py::ssize_t> strides(shape.size(), kInt);
  for (std::size_t axis = shape.size() - 1; axis > 0; --axis) strides[axis - 1] = strides[axis] * shape[axis];
  return readonly_view(py::dtype::of<int>(), std::move(shape), std::move(strides), values.data(), self);
}

// A field of an array of structs of doubles, as a (samples[, width]) view.
py::array field_view(py::handle self, const void* first, std::size_t offset, std::size_t samples,
                     std::size_t struct_size, py::ssize_t width) {
  const char* base = static_cast<const char*>(first) + offset;
  std::vector<py::ssize_t> shape = {count(samples)};
  std::vector<py::ssize_t> strides = {count(struct_size)};
  if (width > 0) {
    shape.push_back(width);
    strides.push_back(kDouble);
  }
  return readonly_view(py::dtype::of<double>(), shape, strides, base, self);
}

py::array observed_mask(const Recording& r) {
  py::array_t<bool> mask({r.frame_count(), r.particle_count});
  bool* out = mask.mutable_data();
  for (int frame = 0; frame < r.frame_count(); ++frame) {
    for (int id = 0; id < r.particle_count; ++id) *out++ = r.observed(frame, id);
  }
  return mask;
}

py::list driven_list(const Recording& r) {
  py::list list;
  for (const host::DrivenWindow& window : r.driven) {
    py::dict entry;
    entry["id"] = window.id;
    entry["from"] = window.from_s;
    entry["to"] = window.to_s;
    list.append(entry);
  }
  return list;
}

py::object wrench_dict(py::handle self) {
  const Recording& r = of(self);
  if (r.wrench.empty()) return py::none();
  using host::WrenchSample;
  const std::size_t m = r.wrench.size();
  py::dict wrench;
  wrench["times"] = field_view(self, r.wrench.data(), offsetof(WrenchSample, t_s), m, sizeof(WrenchSample), 0);
  wrench["force"] = field_view(self, r.wrench.data(), offsetof(WrenchSample, force_n), m, sizeof(WrenchSample), 3);
  wrench["torque"] = field_view(self, r.wrench.data(), offsetof(WrenchSample, torque_nm), m, sizeof(WrenchSample), 3);
  wrench["applied_to"] = int_view(self, r.wrench_applied_to, {count(r.wrench_applied_to.size())});
  return wrench;
}

py::object gripper_dict(py::handle self) {
  const Recording& r = of(self);
  if (r.gripper.empty()) return py::none();
  using host::GripperSample;
  const std::size_t m = r.gripper.size();
  py::dict gripper;
  gripper["times"] = field_view(self, r.gripper.data(), offsetof(GripperSample, t_s), m, sizeof(GripperSample), 0);
  gripper["width"] = field_view(self, r.gripper.data(), offsetof(GripperSample, width), m, sizeof(GripperSample), 0);
  gripper["force"] = field_view(self, r.gripper.data(), offsetof(GripperSample, force_n), m, sizeof(GripperSample), 0);
  return gripper;
}

py::object mesh_dict(py::handle self) {
  const Recording& r = of(self);
  if (!r.mesh) return py::none();
  const host::TetMesh& mesh = *r.mesh;
  py::dict out;
  out["points"] = double_view(self, mesh.points, {mesh.point_count(), 3});
  out["tetrahedra"] = int_view(self, mesh.tetrahedra, {mesh.tet_count(), 4});
  out["youngs_modulus"] = mesh.youngs_modulus.empty()
                              ? py::object(py::none())
                              : py::object(double_view(self, mesh.youngs_modulus, {mesh.tet_count()}));
  return out;
}

std::string describe(const Recording& r) {
  return "<pliant.Recording '" + r.name + "': " + std::to_string(r.particle_count) + " particles x " +
         std::to_string(r.frame_count()) + " frames, " + std::to_string(r.dimension) + "D, " + r.length_unit + ">";
}

RecordingPtr read_from(py::handle path_like) {
  const std::string path = path_of(path_like, "path");
  RecordingPtr recording;
  {
    py::gil_scoped_release release;
    recording = std::make_shared<Recording>(host::read_recording(path));
  }
  emit_warnings(recording->warnings);
  return recording;
}

void write_to(py::handle path_like, const Recording& recording) {
  const std::string path = path_of(path_like, "path");
  py::gil_scoped_release release;
  host::write_recording(recording, path);
}

RecordingArrays arrays_of(py::object times, py::object positions, const py::kwargs& options) {
  RecordingArrays arrays;
  arrays.times = std::move(times);
  arrays.positions = std::move(positions);
  py::object* fields[] = {&arrays.observed, &arrays.masses,  &arrays.fixed, &arrays.driven,   &arrays.gravity,
                          &arrays.wrench,   &arrays.gripper, &arrays.mesh,  &arrays.material, &arrays.meta};
  const char* names[] = {"observed", "masses",  "fixed", "driven",   "gravity",
                         "wrench",   "gripper", "mesh",  "material", "meta"};
  for (py::object* field : fields) *field = py::none();
  for (const auto& item : options) {
    const std::string key = item.first.cast<std::string>();
    bool known = false;
    for (std::size_t i = 0; i < std::size(names); ++i) {
      if (key != names[i]) continue;
      *fields[i] = py::reinterpret_borrow<py::object>(item.second);
      known = true;
    }
    if (key == "length_unit") arrays.length_unit = item.second.cast<std::string>();
    if (key == "name") arrays.name = item.second.cast<std::string>();
    if (!known && key != "length_unit" && key != "name") {
      throw py::type_error("make_recording() got an unexpected keyword argument '" + key + "'");
    }
  }
  return arrays;
}

const char* kRecordingDoc = R"doc(A recording in memory (docs/spec/recording-v1.md).

Arrays are read-only NumPy views of the recording's own memory (no copy); they keep the
recording alive. Units: times in s, positions in `length_unit` ('m' or 'px'), forces in N,
torques in N m, masses in kg. Frames are the recording's own (image plane for 'px').)doc";

const char* kMakeDoc = R"doc(make_recording(times, positions, *, observed=None, masses=None, fixed=None,
driven=None, gravity=None, wrench=None, gripper=None, mesh=None, material=None, meta=None,
length_unit='m', name='') -> Recording

A recording from arrays, checked as the reader checks one.
  times      (n_frames,) s, strictly increasing
  positions  (n_frames, n_particles, dim) float, dim 2 or 3, length_unit; NaN = unobserved
  observed   (n_frames, n_particles) bool; False marks an entry unobserved (as NaN does)
  masses     float or (n_particles,) kg (default 1)
  fixed      particle ids pinned at rest
  driven     ids, (id, from_s, to_s) tuples or {'id', 'from', 'to'} dicts (None = unbounded)
  gravity    (dim,) length_unit/s^2
  wrench     {'times' (m,), 'force' (m, 3) N, 'torque' (m, 3) N m, 'applied_to' ids}
  gripper    {'times' (m,), 'width' (m,) length_unit, 'force' (m,) N}
  mesh       {'points' (n_particles, 3), 'tetrahedra' (t, 4) ids, 'youngs_modulus' (t,) Pa}
  material   {name: value} (poisson_ratio, density kg/m^3, youngs_modulus Pa, ...)
  meta       a JSON-like dict
Without a mesh, frame 0 is the rest shape and must observe every particle. Shapes and types:
ValueError and TypeError; the recording's rules: pliant.InputError.)doc";

}  // namespace

void bind_recordings(py::module_& module) {
  py::class_<Recording, RecordingPtr>(module, "Recording", kRecordingDoc)
      .def_property_readonly(
          "name", [](const Recording& r) { return r.name; }, "directory base name")
      .def_property_readonly(
          "dimension", [](const Recording& r) { return r.dimension; }, "2 or 3")
      .def_property_readonly(
          "length_unit", [](const Recording& r) { return r.length_unit; }, "'m' or 'px'")
      .def_property_readonly("particle_count", [](const Recording& r) { return r.particle_count; })
      .def_property_readonly("frame_count", [](const Recording& r) { return r.frame_count(); })
      .def_property_readonly(
          "times", [](py::handle self) { return double_view(self, of(self).frame_times_s, {of(self).frame_count()}); },
          "(n_frames,) frame times, s")
      .def_property_readonly(
          "positions",
          [](py::handle self) {
            const Recording& r = of(self);
            return double_view(self, r.positions, {r.frame_count(), r.particle_count, r.dimension});
          },
          "(n_frames, n_particles, dim) positions, length_unit; NaN where unobserved")
      .def_property_readonly("observed", &observed_mask,
                             "(n_frames, n_particles) bool: every coordinate finite (a new array)")
      .def_property_readonly(
          "rest_positions",
          [](py::handle self) {
            const Recording& r = of(self);
            return double_view(self, r.rest_positions, {r.particle_count, r.dimension});
          },
          "(n_particles, dim) rest shape: the mesh points, else frame 0")
      .def_property_readonly(
          "masses", [](py::handle self) { return double_view(self, of(self).masses, {of(self).particle_count}); },
          "(n_particles,) kg")
      .def_property_readonly(
          "fixed", [](py::handle self) { return int_view(self, of(self).fixed, {count(of(self).fixed.size())}); },
          "ids pinned at rest (int32)")
      .def_property_readonly("driven", &driven_list,
                             "[{'id', 'from', 'to'}]: particles following their observations while from <= t <= to")
      .def_property_readonly(
          "gravity", [](const Recording& r) { return r.gravity ? py::cast(*r.gravity) : py::object(py::none()); },
          "[dim components] length_unit/s^2, or None when not declared")
      .def_property_readonly("wrench", &wrench_dict,
                             "{'times', 'force' (m, 3) N, 'torque' (m, 3) N m, 'applied_to'} or None")
      .def_property_readonly("gripper", &gripper_dict, "{'times', 'width', 'force'} or None")
      .def_property_readonly("mesh", &mesh_dict, "{'points', 'tetrahedra', 'youngs_modulus'} or None")
      .def_property_readonly("material", [](const Recording& r) { return py::cast(r.material); })
      .def_property_readonly("meta", [](const Recording& r) { return to_python(r.meta); })
      .def_property_readonly("files", [](const Recording& r) { return py::cast(r.files); })
      .def_property_readonly("warnings", [](const Recording& r) { return py::cast(r.warnings); })
      .def(
          "write", [](const Recording& r, py::handle path) { write_to(path, r); }, py::arg("path"),
          "Writes the recording as a v1 directory (see write_recording).")
      .def("__repr__", [](const Recording& r) { return describe(r); });

  module.def("read_recording", &read_from, py::arg("path"),
             "read_recording(path) -> Recording\n\nReads a recording directory (recording-v1). pliant.InputError "
             "names the file, the line or key, and the cause; the reader's warnings are PliantWarning.");
  module.def(
      "make_recording",
      [](py::object times, py::object positions, const py::kwargs& options) {
        return recording_from_arrays(arrays_of(std::move(times), std::move(positions), options));
      },
      py::arg("times"), py::arg("positions"), kMakeDoc);
  module.def(
      "write_recording", [](py::handle path, const Recording& recording) { write_to(path, recording); },
      py::arg("path"), py::arg("recording"),
      "write_recording(path, recording)\nwrite_recording(path, times, positions, **make_recording options)\n\n"
      "Writes a recording directory (created if needed; files of the same names replaced, each through a "
      "temporary file). The second form makes the recording with make_recording first.");
  module.def(
      "write_recording",
      [](py::handle path, py::object times, py::object positions, const py::kwargs& options) {
        const RecordingPtr recording =
            recording_from_arrays(arrays_of(std::move(times), std::move(positions), options));
        write_to(path, *recording);
        return recording;
      },
      py::arg("path"), py::arg("times"), py::arg("positions"));
}

}  // namespace pliant::python
