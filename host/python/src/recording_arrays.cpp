#include "recording_arrays.hpp"

#include <cmath>
#include <limits>
#include <string>

#include "convert.hpp"

namespace pliant::python {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// times (n_frames,), positions (n_frames, n_particles, dim) with unobserved entries NaN or
// masked out by `observed` (n_frames, n_particles).
void fill_frames(const RecordingArrays& arrays, host::Recording& r) {
  const py::array_t<double> positions =
      real_array(arrays.positions, "positions", {-1, -1, -1}, "(n_frames, n_particles, dim)");
  const py::ssize_t frames = positions.shape(0);
  const py::ssize_t particles = positions.shape(1);
  const py::ssize_t dim = positions.shape(2);
  if (dim != 2 && dim != 3) throw py::value_error("positions: dim (the last axis) must be 2 or 3");
  if (particles < 1) throw py::value_error("positions: at least one particle is needed");
  if (frames < 1) throw py::value_error("positions: at least one frame is needed");
  const py::array_t<double> times = real_array(arrays.times, "times", {frames}, "(n_frames,)");
  r.dimension = static_cast<int>(dim);
  r.particle_count = static_cast<int>(particles);
  r.frame_times_s.assign(times.data(), times.data() + frames);
  r.positions.assign(positions.data(), positions.data() + positions.size());
  if (arrays.observed.is_none()) return;
  const py::array_t<bool> observed =
      bool_array(arrays.observed, "observed", {frames, particles}, "(n_frames, n_particles)");
  const bool* seen = observed.data();
  for (py::ssize_t k = 0; k < frames * particles; ++k) {
    if (seen[k]) continue;
    for (py::ssize_t axis = 0; axis < dim; ++axis) r.positions[static_cast<std::size_t>(k * dim + axis)] = kNaN;
  }
}

void fill_masses(const RecordingArrays& arrays, host::Recording& r) {
  const auto n = static_cast<std::size_t>(r.particle_count);
  if (arrays.masses.is_none()) {
    r.masses.assign(n, 1.0);
  } else if (py::isinstance<py::float_>(arrays.masses) || py::isinstance<py::int_>(arrays.masses)) {
    r.masses.assign(n, arrays.masses.cast<double>());
  } else {
    const py::array_t<double> masses = real_array(arrays.masses, "masses", {r.particle_count}, "(n_particles,)");
    r.masses.assign(masses.data(), masses.data() + masses.size());
  }
}

// driven: ids (always driven), or (id, from_s, to_s) tuples, or dicts {"id", "from", "to"}.
host::DrivenWindow driven_window(py::handle item) {
  host::DrivenWindow window;
  if (py::isinstance<py::dict>(item)) {
    const py::dict entry = item.cast<py::dict>();
    if (!entry.contains("id")) throw py::value_error("driven: a dict entry needs 'id'");
    window.id = entry["id"].cast<int>();
    if (entry.contains("from") && !entry["from"].is_none()) window.from_s = entry["from"].cast<double>();
    if (entry.contains("to") && !entry["to"].is_none()) window.to_s = entry["to"].cast<double>();
  } else if (py::isinstance<py::tuple>(item) || py::isinstance<py::list>(item)) {
    const py::sequence entry = item.cast<py::sequence>();
    if (entry.size() != 3) throw py::value_error("driven: a tuple entry is (id, from_s, to_s)");
    const py::object id = entry[std::size_t{0}], from = entry[std::size_t{1}], to = entry[std::size_t{2}];
    window.id = id.cast<int>();
    if (!from.is_none()) window.from_s = from.cast<double>();
    if (!to.is_none()) window.to_s = to.cast<double>();
  } else {
    window.id = item.cast<int>();
  }
  return window;
}

void fill_constraints(const RecordingArrays& arrays, host::Recording& r) {
  if (!arrays.fixed.is_none()) r.fixed = id_list(arrays.fixed, "fixed");
  if (!arrays.driven.is_none()) {
    for (const py::handle item : arrays.driven) r.driven.push_back(driven_window(item));
  }
  if (!arrays.gravity.is_none()) {
    const py::array_t<double> g = real_array(arrays.gravity, "gravity", {r.dimension}, "(dim,)");
    r.gravity = std::vector<double>(g.data(), g.data() + g.size());
  }
}

// wrench: {"times" (m,), "force" (m, 3), "torque" (m, 3), "applied_to" ids}; torque defaults to 0.
void fill_wrench(const RecordingArrays& arrays, host::Recording& r) {
  if (arrays.wrench.is_none()) return;
  const py::dict wrench = arrays.wrench.cast<py::dict>();
  for (const char* key : {"times", "force", "applied_to"}) {
    if (!wrench.contains(key)) throw py::value_error(std::string("wrench needs '") + key + "'");
  }
  const py::array_t<double> t = real_array(wrench["times"], "wrench['times']", {-1}, "(n_samples,)");
  const py::ssize_t m = t.shape(0);
  const py::array_t<double> force = real_array(wrench["force"], "wrench['force']", {m, 3}, "(n_samples, 3)");
  const bool has_torque = wrench.contains("torque") && !wrench["torque"].is_none();
  py::array_t<double> torque;
  if (has_torque) torque = real_array(wrench["torque"], "wrench['torque']", {m, 3}, "(n_samples, 3)");
  for (py::ssize_t k = 0; k < m; ++k) {
    host::WrenchSample sample;
    sample.t_s = t.at(k);
    for (py::ssize_t axis = 0; axis < 3; ++axis) {
      sample.force_n[axis] = force.at(k, axis);
      sample.torque_nm[axis] = has_torque ? torque.at(k, axis) : 0.0;
    }
    r.wrench.push_back(sample);
  }
  r.wrench_applied_to = id_list(wrench["applied_to"], "wrench['applied_to']");
}

// gripper: {"times" (m,), "width" (m,), "force" (m,)}.
void fill_gripper(const RecordingArrays& arrays, host::Recording& r) {
  if (arrays.gripper.is_none()) return;
  const py::dict gripper = arrays.gripper.cast<py::dict>();
  for (const char* key : {"times", "width", "force"}) {
    if (!gripper.contains(key)) throw py::value_error(std::string("gripper needs '") + key + "'");
  }
  const py::array_t<double> t = real_array(gripper["times"], "gripper['times']", {-1}, "(n_samples,)");
  const py::ssize_t m = t.shape(0);
  const py::array_t<double> width = real_array(gripper["width"], "gripper['width']", {m}, "(n_samples,)");
  const py::array_t<double> force = real_array(gripper["force"], "gripper['force']", {m}, "(n_samples,)");
  for (py::ssize_t k = 0; k < m; ++k) r.gripper.push_back({t.at(k), width.at(k), force.at(k)});
}

// mesh: {"points" (p, 3), "tetrahedra" (t, 4) ids, "youngs_modulus" (t,) optional}.
void fill_mesh(const RecordingArrays& arrays, host::Recording& r) {
  if (arrays.mesh.is_none()) return;
  const py::dict mesh = arrays.mesh.cast<py::dict>();
  for (const char* key : {"points", "tetrahedra"}) {
    if (!mesh.contains(key)) throw py::value_error(std::string("mesh needs '") + key + "'");
  }
  host::TetMesh tet;
  const py::array_t<double> points = real_array(mesh["points"], "mesh['points']", {-1, 3}, "(n_points, 3)");
  tet.points.assign(points.data(), points.data() + points.size());
  const py::array tetrahedra = py::array::ensure(mesh["tetrahedra"]);
  if (!tetrahedra || tetrahedra.ndim() != 2 || tetrahedra.shape(1) != 4) {
    throw py::value_error("mesh['tetrahedra'] must have shape (n_tetrahedra, 4)");
  }
  tet.tetrahedra = id_list(tetrahedra.attr("reshape")(-1), "mesh['tetrahedra']");
  if (mesh.contains("youngs_modulus") && !mesh["youngs_modulus"].is_none()) {
    const py::array_t<double> e =
        real_array(mesh["youngs_modulus"], "mesh['youngs_modulus']", {tetrahedra.shape(0)}, "(n_tetrahedra,)");
    tet.youngs_modulus.assign(e.data(), e.data() + e.size());
  }
  r.mesh = std::move(tet);
}

void fill_descriptions(const RecordingArrays& arrays, host::Recording& r) {
  r.length_unit = arrays.length_unit;
  if (r.length_unit != "m" && r.length_unit != "px") throw py::value_error("length_unit must be 'm' or 'px'");
  r.name = arrays.name;
  if (!arrays.material.is_none()) {
    for (const auto& item : arrays.material.cast<py::dict>()) {
      r.material[item.first.cast<std::string>()] = item.second.cast<double>();
    }
  }
  if (!arrays.meta.is_none()) {
    r.meta = to_json(arrays.meta, "meta");
    if (!r.meta.is_object()) throw py::type_error("meta must be a dict");
  }
}

}  // namespace

std::shared_ptr<host::Recording> recording_from_arrays(const RecordingArrays& arrays) {
  auto recording = std::make_shared<host::Recording>();
  fill_frames(arrays, *recording);
  fill_masses(arrays, *recording);
  fill_constraints(arrays, *recording);
  fill_wrench(arrays, *recording);
  fill_gripper(arrays, *recording);
  fill_mesh(arrays, *recording);
  fill_descriptions(arrays, *recording);
  host::finalize_recording(*recording);
  return recording;
}

}  // namespace pliant::python
