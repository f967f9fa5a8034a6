// Recording directories: reading with containment checks, cross-file validation, writing.
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "pliant/host/recording.hpp"
#include "pliant/host/vtk_mesh.hpp"
#include "pliant/host/text_fields.hpp"

namespace pliant::host {
namespace {

namespace fs = std::filesystem;
using detail::format_double;
using detail::printable;

constexpr std::uintmax_t kMaxFileBytes = std::uintmax_t{2} << 30;  // 2 GiB
const std::string kJsonLabel = "recording.json";

std::string file_label(const Recording& recording, const std::string& role, const std::string& fallback) {
  const auto it = recording.files.find(role);
  return it == recording.files.end() ? fallback : it->second;
}

[[noreturn]] void fail(const std::string& label, const std::string& cause) {
  throw RecordingError(label + ": " + cause);
}

// ------------------------------------------------------------------------------------------
// Reading

bool is_inside(const fs::path& root, const fs::path& target) {
  auto r = root.begin();
  auto t = target.begin();
  for (; r != root.end(); ++r, ++t) {
    if (t == target.end() || *r != *t) return false;
  }
  return true;
}

// Resolves `relative` under the canonical `root`, following symlinks, and refuses anything that
// does not exist or ends up outside root. `origin` says where the name came from.
fs::path resolve_inside(const fs::path& root, const std::string& relative, const std::string& origin) {
  std::error_code error;
  const fs::path target = fs::canonical(root / relative, error);
  if (error) {
    if (error == std::errc::no_such_file_or_directory) fail(relative, "no such file" + origin);
    fail(relative, "cannot access: " + error.message() + origin);
  }
  if (!is_inside(root, target)) fail(relative, "resolves outside the recording directory" + origin);
  return target;
}

std::string read_text(const fs::path& path, const std::string& label) {
  std::error_code error;
  if (!fs::is_regular_file(path, error)) fail(label, "not a regular file");
  const std::uintmax_t size = fs::file_size(path, error);
  if (error) fail(label, "cannot read: " + error.message());
  if (size > kMaxFileBytes) {
    fail(label,
         "file too large (" + std::to_string(size) + " bytes, the limit is " + std::to_string(kMaxFileBytes) + ")");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(label, std::string("cannot open: ") + std::strerror(errno));
  std::string text(static_cast<std::size_t>(size), '\0');
  in.read(text.data(), static_cast<std::streamsize>(size));
  if (in.gcount() != static_cast<std::streamsize>(size)) {
    fail(label, "cannot read: the file changed or an I/O error occurred");
  }
  return text;
}

std::string directory_name(const fs::path& directory, const fs::path& root) {
  fs::path normal = directory.lexically_normal();
  if (!normal.has_filename()) normal = normal.parent_path();
  std::string name = normal.filename().string();
  if (name.empty() || name == "." || name == "..") name = root.filename().string();
  return name;
}

// ------------------------------------------------------------------------------------------
// Writing

std::runtime_error write_error(const std::string& what) { return std::runtime_error("write_recording: " + what); }

void check_writable(const Recording& r) {
  if (r.dimension != 2 && r.dimension != 3) throw write_error("dimension must be 2 or 3");
  if (r.particle_count <= 0) throw write_error("particle_count must be positive");
  const auto n = static_cast<std::size_t>(r.particle_count);
  if (r.masses.size() != n) throw write_error("masses must have particle_count entries");
  if (r.positions.size() != r.frame_times_s.size() * n * static_cast<std::size_t>(r.dimension)) {
    throw write_error("positions must hold frame_count * particle_count * dimension values");
  }
  if (r.gravity && r.gravity->size() != static_cast<std::size_t>(r.dimension)) {
    throw write_error("gravity must have dimension components");
  }
}

// Roles whose files this writer produces, with their default names.
std::map<std::string, std::string> files_to_write(const Recording& r) {
  std::map<std::string, std::string> files = r.files;
  files.emplace("particles", "particles.csv");
  if (!r.wrench.empty()) files.emplace("wrench", "wrench.csv");
  if (!r.gripper.empty()) files.emplace("gripper", "gripper.csv");
  if (r.mesh) files.emplace("mesh", "mesh.vtk");
  if (files.count("mesh") != 0 && !r.mesh) throw write_error("files.mesh is set but mesh is empty");
  std::set<std::string> written = {kJsonLabel};
  for (const auto& [role, path] : files) {
    if (const char* problem = detail::relative_path_problem(path)) {
      throw write_error("files." + printable(role) + ": " + problem);
    }
    const bool produced = role == "particles" || role == "wrench" || role == "gripper" || role == "mesh";
    if (produced && !written.insert(fs::path(path).lexically_normal().string()).second) {
      throw write_error("files." + printable(role) + ": '" + printable(path) +
                        "' is already used by another file of the recording");
    }
  }
  return files;
}

nlohmann::ordered_json driven_entry(const DrivenWindow& window) {
  if (std::isinf(window.from_s) && std::isinf(window.to_s)) return window.id;
  nlohmann::ordered_json entry;
  entry["id"] = window.id;
  if (std::isfinite(window.from_s)) entry["from"] = window.from_s;
  if (std::isfinite(window.to_s)) entry["to"] = window.to_s;
  return entry;
}

std::string recording_json_text(const Recording& r, const std::map<std::string, std::string>& files) {
  nlohmann::ordered_json doc;
  doc["format"] = "pliant-recording";
  doc["version"] = 1;
  doc["dimension"] = r.dimension;
  doc["length_unit"] = r.length_unit;
  if (r.gravity) doc["gravity"] = *r.gravity;

  nlohmann::ordered_json particles;
  particles["count"] = r.particle_count;
  bool uniform = true;
  for (const double mass : r.masses) uniform = uniform && mass == r.masses.front();
  if (uniform) {
    particles["mass"] = r.masses.front();
  } else {
    particles["mass"] = r.masses;
  }
  if (!r.fixed.empty()) particles["fixed"] = r.fixed;
  if (!r.driven.empty()) {
    nlohmann::ordered_json driven = nlohmann::ordered_json::array();
    for (const DrivenWindow& window : r.driven) driven.push_back(driven_entry(window));
    particles["driven"] = std::move(driven);
  }
  doc["particles"] = std::move(particles);

  nlohmann::ordered_json file_names;
  file_names["particles"] = files.at("particles");
  for (const auto& [role, path] : files) {
    if (role != "particles") file_names[role] = path;
  }
  doc["files"] = std::move(file_names);
  if (!r.wrench_applied_to.empty()) doc["wrench"]["applied_to"] = r.wrench_applied_to;
  if (!r.material.empty()) {
    for (const auto& [name, value] : r.material) doc["material"][name] = value;
  }
  if (!(r.meta.is_object() && r.meta.empty())) doc["meta"] = nlohmann::ordered_json(r.meta);
  if (r.unknown_keys.is_object()) {
    for (const auto& item : r.unknown_keys.items()) {
      if (!doc.contains(item.key())) doc[item.key()] = nlohmann::ordered_json(item.value());
    }
  }
  try {
    return doc.dump(2) + "\n";
  } catch (const nlohmann::json::exception& error) {
    throw write_error(std::string("recording.json: ") + error.what());
  }
}

// Buffered text output that appends into `out` in large chunks.
class TextSink {
 public:
  explicit TextSink(std::ostream& out) : out_(out) {}
  ~TextSink() { flush(); }
  TextSink(const TextSink&) = delete;
  TextSink& operator=(const TextSink&) = delete;
  TextSink& operator<<(std::string_view text) {
    buffer_ += text;
    if (buffer_.size() > (std::size_t{1} << 20)) flush();
    return *this;
  }
  TextSink& number(double value) { return *this << format_double(value); }
  void flush() {
    out_.write(buffer_.data(), static_cast<std::streamsize>(buffer_.size()));
    buffer_.clear();
  }

 private:
  std::ostream& out_;
  std::string buffer_;
};

void write_particles(const Recording& r, std::ostream& out) {
  TextSink sink(out);
  const int dimension = r.dimension;
  sink << (dimension == 2 ? "t,id,x,y\n" : "t,id,x,y,z\n");
  for (int frame = 0; frame < r.frame_count(); ++frame) {
    const std::string t = format_double(r.frame_times_s[static_cast<std::size_t>(frame)]);
    bool wrote = false;
    for (int id = 0; id < r.particle_count; ++id) {
      bool any = false;
      for (int axis = 0; axis < dimension; ++axis) {
        any = any || !std::isnan(r.position(frame, id, axis));
      }
      if (!any) continue;
      sink << t << "," << std::to_string(id);
      for (int axis = 0; axis < dimension; ++axis) {
        sink << ",";
        sink.number(r.position(frame, id, axis));
      }
      sink << "\n";
      wrote = true;
    }
    // A frame observing nothing still exists; one all-nan row keeps its timestamp.
    if (!wrote) sink << t << (dimension == 2 ? ",0,nan,nan\n" : ",0,nan,nan,nan\n");
  }
}

void write_wrench(const Recording& r, std::ostream& out) {
  TextSink sink(out);
  sink << "t,fx,fy,fz,tx,ty,tz\n";
  for (const WrenchSample& s : r.wrench) {
    sink.number(s.t_s);
    for (const double force : s.force_n) {
      sink << ",";
      sink.number(force);
    }
    for (const double torque : s.torque_nm) {
      sink << ",";
      sink.number(torque);
    }
    sink << "\n";
  }
}

void write_gripper(const Recording& r, std::ostream& out) {
  TextSink sink(out);
  sink << "t,width,force\n";
  for (const GripperSample& s : r.gripper) {
    sink.number(s.t_s) << ",";
    sink.number(s.width) << ",";
    sink.number(s.force_n) << "\n";
  }
}

fs::path temporary_name(const fs::path& final_path) {
  fs::path temp = final_path;
  temp += ".pliant-tmp";
  return temp;
}

template <typename Writer>
void write_temporary(const fs::path& final_path, Writer&& writer) {
  std::error_code error;
  fs::create_directories(final_path.parent_path(), error);
  if (error) throw write_error(final_path.parent_path().string() + ": " + error.message());
  const fs::path temp = temporary_name(final_path);
  std::ofstream out(temp, std::ios::binary | std::ios::trunc);
  if (!out) throw write_error(temp.string() + ": cannot create: " + std::strerror(errno));
  writer(out);
  out.close();
  if (!out) throw write_error(temp.string() + ": write failed");
}

}  // namespace

// ------------------------------------------------------------------------------------------

void finalize_recording(Recording& r) {
  const std::string particles_label = file_label(r, "particles", "particles.csv");
  if (r.dimension != 2 && r.dimension != 3) fail(kJsonLabel, "dimension: must be 2 or 3");
  if (r.particle_count <= 0 || r.particle_count > detail::kMaxParticles) {
    fail(kJsonLabel, "particles.count: must be a positive integer");
  }
  const auto n = static_cast<std::size_t>(r.particle_count);
  const auto dimension = static_cast<std::size_t>(r.dimension);
  if (r.masses.size() != n) {
    fail(kJsonLabel, "particles.mass: must have " + std::to_string(n) + " entries");
  }
  if (r.frame_times_s.empty()) fail(particles_label, "no frames (the file has a header only)");
  if (r.positions.size() != r.frame_times_s.size() * n * dimension) {
    fail(particles_label, "positions do not hold frame_count * particles.count * dimension values");
  }
  for (std::size_t f = 0; f < r.frame_times_s.size(); ++f) {
    if (!std::isfinite(r.frame_times_s[f]) || (f > 0 && !(r.frame_times_s[f] > r.frame_times_s[f - 1]))) {
      fail(particles_label, "frame times must be finite and strictly increasing");
    }
  }
  const auto check_ids = [&](const std::vector<int>& ids, const std::string& key) {
    for (const int id : ids) {
      if (id < 0 || id >= r.particle_count) {
        fail(kJsonLabel,
             key + ": id " + std::to_string(id) + " out of range 0.." + std::to_string(r.particle_count - 1));
      }
    }
  };
  check_ids(r.fixed, "particles.fixed");
  std::vector<int> driven_ids;
  for (const DrivenWindow& window : r.driven) driven_ids.push_back(window.id);
  check_ids(driven_ids, "particles.driven");
  check_ids(r.wrench_applied_to, "wrench.applied_to");
  if ((r.files.count("wrench") != 0 || !r.wrench.empty()) && r.wrench_applied_to.empty()) {
    fail(kJsonLabel, "wrench.applied_to: required when files.wrench is present");
  }

  std::vector<double> rest(n * dimension);
  if (r.mesh) {
    const std::string mesh_label = file_label(r, "mesh", "mesh.vtk");
    const TetMesh& mesh = *r.mesh;
    if (mesh.points.size() != 3 * n) {
      fail(mesh_label, std::to_string(mesh.points.size() / 3) + " points but particles.count is " + std::to_string(n) +
                           " (point i is particle i)");
    }
    for (const int index : mesh.tetrahedra) {
      if (index < 0 || index >= r.particle_count) {
        fail(mesh_label, "point index " + std::to_string(index) + " out of range");
      }
    }
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t axis = 0; axis < dimension; ++axis) {
        rest[i * dimension + axis] = mesh.points[3 * i + axis];
      }
    }
  } else {
    for (int id = 0; id < r.particle_count; ++id) {
      if (!r.observed(0, id)) {
        fail(particles_label, "the first frame (t=" + format_double(r.frame_times_s[0]) +
                                  ") does not observe particle " + std::to_string(id) +
                                  "; without a mesh it is the rest shape and must observe every particle");
      }
    }
    rest.assign(r.positions.begin(), r.positions.begin() + static_cast<std::ptrdiff_t>(n * dimension));
  }
  r.rest_positions = std::move(rest);
}

Recording read_recording(const std::string& directory) {
  const std::string shown = printable(directory, 200);
  std::error_code error;
  const fs::path path(directory);
  const fs::file_status status = fs::status(path, error);
  if (status.type() == fs::file_type::not_found) fail(shown, "no such recording directory");
  if (error) fail(shown, "cannot access the recording directory: " + error.message());
  if (status.type() != fs::file_type::directory) fail(shown, "not a directory");
  const fs::path root = fs::canonical(path, error);
  if (error) fail(shown, "cannot access the recording directory: " + error.message());

  Recording recording;
  recording.name = directory_name(path, root);
  const fs::path json_path = resolve_inside(root, kJsonLabel, "");
  parse_recording_json(read_text(json_path, kJsonLabel), kJsonLabel, recording);

  std::map<std::string, fs::path> resolved;
  for (const auto& [role, relative] : recording.files) {
    resolved[role] = resolve_inside(root, relative, " (named in recording.json files." + printable(role) + ")");
  }
  const auto load = [&](const std::string& role) { return read_text(resolved.at(role), recording.files.at(role)); };
  parse_particles_csv(load("particles"), recording.files.at("particles"), recording);
  if (resolved.count("wrench") != 0) {
    recording.wrench = parse_wrench_csv(load("wrench"), recording.files.at("wrench"));
  }
  if (resolved.count("gripper") != 0) {
    recording.gripper = parse_gripper_csv(load("gripper"), recording.files.at("gripper"));
  }
  if (resolved.count("mesh") != 0) {
    recording.mesh = parse_vtk_tet_mesh(load("mesh"), recording.files.at("mesh"));
  }
  finalize_recording(recording);
  return recording;
}

void write_recording(const Recording& recording, const std::string& directory) {
  check_writable(recording);
  const std::map<std::string, std::string> files = files_to_write(recording);
  const std::string json_text = recording_json_text(recording, files);

  const fs::path root(directory);
  std::error_code error;
  fs::create_directories(root, error);
  if (error) throw write_error(directory + ": " + error.message());

  // Every file goes to a temporary name first; the data files are renamed into place before
  // recording.json, so a reader never sees a new recording.json beside missing data.
  std::vector<fs::path> finals;
  try {
    const auto add = [&](const std::string& role, auto&& writer) {
      const auto it = files.find(role);
      if (it == files.end()) return;
      finals.push_back(root / it->second);
      write_temporary(finals.back(), writer);
    };
    add("particles", [&](std::ostream& out) { write_particles(recording, out); });
    add("wrench", [&](std::ostream& out) { write_wrench(recording, out); });
    add("gripper", [&](std::ostream& out) { write_gripper(recording, out); });
    if (recording.mesh) {
      add("mesh", [&](std::ostream& out) { write_vtk_tet_mesh(*recording.mesh, out); });
    }
    finals.push_back(root / kJsonLabel);
    write_temporary(finals.back(), [&](std::ostream& out) { out << json_text; });
  } catch (...) {
    for (const fs::path& final_path : finals) fs::remove(temporary_name(final_path), error);
    throw;
  }
  for (std::size_t i = 0; i < finals.size(); ++i) {
    fs::rename(temporary_name(finals[i]), finals[i], error);
    if (error) {
      const std::string cause = error.message();
      for (std::size_t j = i; j < finals.size(); ++j) fs::remove(temporary_name(finals[j]), error);
      throw write_error(finals[i].string() + ": cannot rename into place: " + cause);
    }
  }
}

}  // namespace pliant::host
