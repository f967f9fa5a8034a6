// Recording format v1 (docs/spec/recording-v1.md): in-memory model, reader and writer.
//
// A recording is a directory holding recording.json, particles.csv and optional wrench.csv,
// gripper.csv and mesh.vtk. Units: time in seconds, positions in `length_unit` ("m" or "px"),
// force in N, torque in N*m, mass in kg. Host code only: these functions allocate and throw.
//
// Errors: every reader function throws RecordingError whose what() is exactly one line naming the
// file, the line (for CSV/VTK) or the JSON key, and the cause, e.g.
//   "particles.csv:118: id 40 out of range 0..31"
//   "recording.json: particles.count: must be a positive integer"
// The command line turns it into that message on stderr and exit status 2.
#pragma once

#include <nlohmann/json.hpp>

#include "pliant/core/observations.hpp"

#include <limits>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace pliant::host {

class RecordingError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A particle whose position follows its own observed trajectory while from_s <= t <= to_s
/// (the core type; unbounded windows use -infinity / +infinity).
using DrivenWindow = ::pliant::DrivenWindow;

/// One wrench sample: force (N) and torque (N*m about the centroid of the applied_to particles'
/// rest positions), recording frame. For 2D recordings only force[0..1] are meaningful.
struct WrenchSample {
  double t_s = 0.0;
  double force_n[3] = {0.0, 0.0, 0.0};
  double torque_nm[3] = {0.0, 0.0, 0.0};
};

struct GripperSample {
  double t_s = 0.0;
  double width = 0.0;  ///< finger opening, length_unit
  double force_n = 0.0;
};

/// Tetrahedral rest mesh (mesh.vtk): point i is particle i.
struct TetMesh {
  std::vector<double> points;          ///< 3 * point_count, x y z per point
  std::vector<int> tetrahedra;         ///< 4 * tet_count point indices
  std::vector<double> youngs_modulus;  ///< per tetrahedron (Pa), empty when absent
  int point_count() const { return static_cast<int>(points.size() / 3); }
  int tet_count() const { return static_cast<int>(tetrahedra.size() / 4); }
};

struct Recording {
  std::string name;  ///< directory base name, for reports
  int dimension = 2;
  std::string length_unit = "m";
  std::optional<std::vector<double>> gravity;  ///< `dimension` components when declared

  int particle_count = 0;
  std::vector<double> masses;  ///< particle_count entries (default 1 each)
  std::vector<int> fixed;      ///< sorted, unique ids pinned at rest
  std::vector<DrivenWindow> driven;

  std::map<std::string, std::string> files;  ///< role -> relative path, as in recording.json
  std::vector<int> wrench_applied_to;
  std::map<std::string, double> material;  ///< known parameters (poisson_ratio, density, ...)
  nlohmann::json meta = nlohmann::json::object();
  nlohmann::json unknown_keys = nlohmann::json::object();  ///< kept, reported as warnings

  /// Frames: times strictly increasing. positions is frame-major:
  /// positions[(frame * particle_count + id) * dimension + axis]; NaN marks unobserved.
  std::vector<double> frame_times_s;
  std::vector<double> positions;

  /// Rest configuration, particle_count * dimension: mesh points (first `dimension`
  /// coordinates) when a mesh is present, else frame 0 (which must observe every particle).
  std::vector<double> rest_positions;

  std::vector<WrenchSample> wrench;
  std::vector<GripperSample> gripper;
  std::optional<TetMesh> mesh;

  std::vector<std::string> warnings;  ///< non-fatal findings (unknown keys, ...)

  int frame_count() const { return static_cast<int>(frame_times_s.size()); }
  double position(int frame, int id, int axis) const {
    return positions[(static_cast<size_t>(frame) * static_cast<size_t>(particle_count) + static_cast<size_t>(id)) *
                         static_cast<size_t>(dimension) +
                     static_cast<size_t>(axis)];
  }
  bool observed(int frame, int id) const;  ///< every coordinate finite
};

/// Reads a recording directory. Throws RecordingError (one line: file, line or key, cause).
/// Never reads outside `directory` (paths in "files" must be relative and stay inside it) and
/// never writes into it.
Recording read_recording(const std::string& directory);

/// Parsers over in-memory text, used by read_recording and by the fuzz target. `file_label`
/// is the name used in error messages. Each throws RecordingError on malformed input.
/// parse_recording_json fills everything except frames, samples and mesh.
void parse_recording_json(std::string_view text, const std::string& file_label, Recording& out);
/// Requires out.dimension and out.particle_count set; fills frame_times_s and positions.
void parse_particles_csv(std::string_view text, const std::string& file_label, Recording& out);
std::vector<WrenchSample> parse_wrench_csv(std::string_view text, const std::string& file_label);
std::vector<GripperSample> parse_gripper_csv(std::string_view text, const std::string& file_label);
TetMesh parse_vtk_tet_mesh(std::string_view text, const std::string& file_label);

/// Checks cross-file consistency (ids in range, first frame complete unless a mesh is present,
/// mesh point count, applied_to present with a wrench, ...) and fills rest_positions.
void finalize_recording(Recording& recording);

/// Writes `recording` as a v1 directory (created if needed; existing files replaced).
/// Writes to temporary names and renames, so a crash never leaves a half-written
/// recording.json beside complete data. Media named in `files` (video, .oni) are listed as given
/// but not copied: the caller puts them in the directory. Throws std::runtime_error on I/O
/// failure, on absolute or escaping paths, and on two roles sharing one file name.
void write_recording(const Recording& recording, const std::string& directory);

}  // namespace pliant::host
