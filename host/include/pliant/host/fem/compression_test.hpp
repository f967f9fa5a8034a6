// Uniaxial compression tests of cylindrical specimens (universal testing machine CSV exports such
// as the Instron 5900 files of examples/phantom_compression/source) and their conversion into
// recordings (recording format v1, docs/spec/recording-v1.md) that the FEM estimators fit.
// Host code only: these functions allocate and throw.
//
// ## The CSV
//
//   EF10_0T_A_sample_1                       sample name: the first line without a ':'
//   Compression test;                        further lines without ':' are kept as notes
//   Cylinder Diameter: 50mm;                 required; "Diameter: 0.05 m", "Diameter (mm): 50"
//   Cylinder Height: 30mm;                   required; same forms
//   Speed (mm/min): 10;                      optional; mm/min, mm/s, m/min or m/s
//   Machine: INSTRON 5900;                   optional
//   Load cell: 1kN;                          optional
//   Time (s),Compression (mm),Load (N),Engineering Strain [-],Engineering Stress (kPa),...
//   0.000000,0.000000,-0.009120,...          numeric rows, as many fields as the header
//
// Metadata lines ("key: value", a trailing ';' and surrounding blanks ignored, keys matched
// without regard to case) may come in any order and with unknown keys (kept in other_metadata).
// Lengths take mm, cm or m, written after the number or in parentheses after the key. The column
// header is the first line of two or more comma-separated fields of which one is named Time,
// Compression or Load (a unit in parentheses or brackets after the name); columns are found by
// name, in any order: Time (s, ms or min), Compression (mm, cm or m: crosshead travel, positive when the
// specimen shortens), Load (N or kN) are required; Engineering Strain, Engineering Stress (Pa,
// kPa, MPa or N/mm^2), True Strain and True Stress are optional, others ignored. Units are
// required wherever a scale depends on them. Blank lines are skipped anywhere; "\r\n" line
// endings and a UTF-8 byte-order mark are accepted.
//
// Rows must be complete and finite, time strictly increasing, |compression| below the height,
// |load| at most 1e7 N; diameter and height lie in [0.1 mm, 10 m]. At most kMaxCompressionRows
// rows. Anything else is malformed: the parser throws RecordingError whose what() is one line
// naming the file, the line and the cause, e.g.
//   "EF10_0T_A1.csv:12: Load: must be finite, found 'nan'"
//   "EF10_0T_A1.csv:9: expected 7 fields as in the column header, found 6"
//   "EF10_0T_A1.csv: missing 'Cylinder Diameter' line"
// and the command line exits with status 2. Signs are kept as the file gives them: in the
// phantom files compression and load are positive and the derived strain and stress negative.
//
// ## The recording (compression_test_recording)
//
// 3D, metres. mesh.vtk is cylinder_tet_mesh(diameter, height, options.mesh) (points are
// particles; see cylinder_mesh.hpp for the numbering). Frames are the test resampled (linear
// interpolation in time) every frame_interval_s seconds, or at frame_count evenly spaced times,
// from the first sample; with max_strain the frames stop at the first one whose engineering
// strain compression / height exceeds it. Only the platen faces are observed:
// - top face (z = height at rest): z = height - compression(t), all its nodes `driven`;
// - bottom face (z = 0): z stays 0;
// - every other node is unobserved (nan) in every frame: the rest shape comes from mesh.vtk.
// x and y of the platen nodes depend on options.platen_contact (PHYSICS.md: bonded and
// frictionless platens change the apparent modulus of a short cylinder by tens of percent):
// - frictionless (default): the platens let the faces slide, and the specimen deforms as under
//   homogeneous uniaxial stress, which is what the lab assumed when it fitted its reference
//   moduli. Both faces' nodes are scaled radially by the lateral stretch of that solution
//   (below) and are all `driven` (the axis node stays on the axis, so nothing drifts).
// - bonded: the faces stick to the platens. x and y stay at rest, top nodes `driven`, bottom
//   nodes `fixed`.
// Lateral platen positions are modelled, never measured; meta.platen_contact,
// meta.lateral_positions and meta.boundary_conditions say which model made them.
//
// The lateral stretch for frictionless platens (options.lateral_expansion), with engineering
// strain e = compression / height and nu = options.poisson_ratio:
// - small_strain (default): 1 + nu * e, the uniaxial solution of linear elasticity. It is the
//   stress-free lateral state of a corotational linear tetrahedron model (PHYSICS.md), so such a
//   model fitted to the recording meets the measured load with exactly the modulus of the linear
//   engineering stress-strain fit. Volume is not kept at large strain.
// - finite_strain: (1 - e)^(-nu), which keeps volume at nu = 0.5 and suits hyperelastic models.
//   A linear model measures volume change as the trace of the strain, which this stretch leaves
//   positive (+0.6 % at e = 0.1, nu = 0.49), and multiplies it by a bulk modulus of
//   E / (3 (1 - 2 nu)) = 17 E: a spurious pressure as large as the uniaxial stress itself. Do
//   not fit a corotational linear model with nu near 0.5 to it.
//
// wrench.csv: at every frame time the force the top platen applies to the specimen, fz = -load
// (N; compression pushes the top face toward -z), fx = fy = 0, torques 0; wrench.applied_to is
// the top face. recording.json: material {poisson_ratio, density}, particles.mass the lumped
// (quarter-tetrahedron) masses from the density, no gravity (the load cell reads about 0 N at
// zero compression: the specimen's weight is not in the measured load), and meta with the
// sample, source, licence, machine, speed, geometry, mesh and the boundary-condition choice.
#pragma once

#include <cstddef>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "pliant/host/fem/cylinder_mesh.hpp"
#include "pliant/host/recording.hpp"

namespace pliant::host {

/// Upper bound on the data rows of one compression CSV.
inline constexpr std::size_t kMaxCompressionRows = 2'000'000;
/// Upper bound on the size of a compression CSV that read_compression_csv reads.
inline constexpr std::size_t kMaxCompressionCsvBytes = std::size_t{256} << 20;

/// One compression test as read from its CSV, in SI units.
struct CompressionTest {
  std::string label;                    ///< file label used in messages (the path as given)
  std::string sample_name;              ///< empty when the file names none
  std::vector<std::string> notes;       ///< other metadata lines without ':' ("Compression test")
  double diameter_m = 0.0;              ///< specimen diameter before the test
  double height_m = 0.0;                ///< specimen height before the test
  std::optional<double> speed_m_per_s;  ///< crosshead speed, when the file gives it
  std::string machine;                  ///< empty when absent
  std::string load_cell;                ///< empty when absent, as written ("1kN")
  std::vector<std::pair<std::string, std::string>> other_metadata;  ///< unknown "key: value"

  /// Columns, one entry per row. Required:
  std::vector<double> time_s;
  std::vector<double> compression_m;  ///< crosshead travel since the start, + shortens
  std::vector<double> load_n;         ///< force on the load cell, + in compression here
  /// Optional, empty when the column is absent; signs as in the file.
  std::vector<double> engineering_strain;
  std::vector<double> engineering_stress_pa;
  std::vector<double> true_strain;
  std::vector<double> true_stress_pa;

  std::size_t row_count() const { return time_s.size(); }
  double cross_section_m2() const;  ///< pi diameter^2 / 4
};

/// Parses the CSV text described above; `file_label` names it in messages. Throws RecordingError.
CompressionTest parse_compression_csv(std::string_view text, const std::string& file_label);

/// Reads and parses the file at `path` (labelled by `path` in messages). Throws RecordingError
/// when the file cannot be read, exceeds kMaxCompressionCsvBytes or is malformed.
CompressionTest read_compression_csv(const std::string& path);

/// Least-squares line through engineering stress load / (pi d^2 / 4) (Pa) against engineering
/// strain compression / height over the rows with from_strain <= strain <= to_strain.
struct LinearModulusFit {
  double youngs_modulus_pa = 0.0;  ///< slope
  double intercept_pa = 0.0;       ///< stress at zero strain
  std::size_t rows = 0;            ///< rows in the window
};
/// Throws std::invalid_argument when the window is empty or inverted, or holds fewer than two
/// rows with distinct strains.
LinearModulusFit fit_linear_modulus(const CompressionTest& test, double from_strain, double to_strain);

enum class PlatenContact { frictionless, bonded };
enum class LateralExpansion { small_strain, finite_strain };

/// "frictionless" / "bonded", "small_strain" / "finite_strain" (the words used in meta and on
/// the command line, where '-' may replace '_').
const char* to_string(PlatenContact contact);
const char* to_string(LateralExpansion expansion);

struct CompressionRecordingOptions {
  /// Last frame kept: the first whose compression / height exceeds this; infinity keeps all.
  double max_strain = std::numeric_limits<double>::infinity();
  /// >= 2: that many frames evenly spaced from the first sample to the last (or, with
  /// max_strain, to the first sample past it). 0: use frame_interval_s.
  int frame_count = 0;
  double frame_interval_s = 1.0;  ///< > 0; frames at t0, t0 + dt, ... up to the last sample
  PlatenContact platen_contact = PlatenContact::frictionless;
  LateralExpansion lateral_expansion = LateralExpansion::small_strain;  ///< frictionless only
  double poisson_ratio = 0.49;                                          ///< material.poisson_ratio, in [0, 0.5)
  double density_kg_m3 = 1070;  ///< material.density (Ecoflex 00-30 / 00-50: 1.07 g/cm^3)
  CylinderMeshDivisions mesh;   ///< default (2, 24, 5): 582 nodes, 2520 tetrahedra
  std::string name;             ///< Recording::name; the sample name when empty
  std::string source;           ///< meta.source (dataset, URL, commit); omitted when empty
  std::string license;          ///< meta.license; omitted when empty
};

/// Upper bound on the frames of a converted recording; frames x mesh points x 3 must also stay
/// within the recording reader's limit of 2^28 stored coordinates.
inline constexpr int kMaxCompressionFrames = 1'000'000;

/// The recording described above, ready for write_recording (finalize_recording has run, so
/// rest_positions are set). Throws std::invalid_argument on options out of range (naming the
/// option), also when they leave fewer than two frames, and RecordingError (labelled with
/// test.label) when the test itself cannot make a recording: inconsistent columns, or a test
/// that never compresses (largest compression not positive). Linear in frames x platen nodes.
Recording compression_test_recording(const CompressionTest& test, const CompressionRecordingOptions& options);

/// The lateral stretch of the platen nodes for frictionless platens (see above) at engineering
/// strain `strain` = compression / height.
double frictionless_lateral_stretch(double strain, double poisson_ratio, LateralExpansion expansion);

}  // namespace pliant::host
