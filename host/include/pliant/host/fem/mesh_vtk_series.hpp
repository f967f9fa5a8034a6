// Time series of a deforming tetrahedral mesh for ParaView: one file per frame plus a collection
// file that gives each frame its time.
//
// Two layouts (VtkSeriesFormat):
//  - vtu_pvd (default): VTK XML UnstructuredGrid files <base>_<frame>.vtu (ASCII arrays, Float64
//    points, Int64 connectivity and offsets, a TimeValue field) listed in <base>.pvd with
//    timestep="<time_s>". Open the .pvd in ParaView. (ParaView's PVD reader reads XML files
//    only, which is why the legacy layout below uses a different collection file.)
//  - legacy_vtk_series: legacy VTK 3.0 ASCII files <base>_<frame>.vtk in exactly the layout of
//    write_vtk_tet_mesh (so parse_vtk_tet_mesh reads each frame back), point vectors written as
//    3-component SCALARS, listed in <base>.vtk.series (ParaView's JSON file-series format,
//    ParaView 5.5 and later). Open the .vtk.series in ParaView.
// <frame> is the 0-based frame number, zero-padded to 6 digits (more when needed).
//
// Every number is written as the shortest text that reads back bit for bit. Each file is written
// under a temporary name and renamed, so a reader never sees a half-written frame. Host code only:
// allocates and throws (MeshError for invalid input, std::runtime_error for I/O failures).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "pliant/host/recording.hpp"

namespace pliant::host {

/// A named per-point or per-cell array. Names: 1-64 characters from [A-Za-z0-9_], unique within
/// a frame, and not "youngs_modulus" when the mesh carries youngs_modulus (it is written from the
/// mesh in every frame).
struct VtkNamedArray {
  std::string name;
  std::vector<double> values;
};

/// One frame. Every value must be finite (ParaView's readers do not accept NaN text).
struct VtkSeriesFrame {
  double time_s = 0.0;                       ///< strictly increasing across frames
  std::vector<double> positions;             ///< 3 * point_count: current x y z of every mesh point
  std::vector<VtkNamedArray> point_vectors;  ///< each 3 * point_count (e.g. displacement, m)
  std::vector<VtkNamedArray> cell_scalars;   ///< each tet_count (e.g. von_mises_pa)
};

enum class VtkSeriesFormat { vtu_pvd, legacy_vtk_series };

struct VtkSeriesOptions {
  std::string base_name = "frame";  ///< file name stem; 1-64 characters from [A-Za-z0-9_.-]
  VtkSeriesFormat format = VtkSeriesFormat::vtu_pvd;
};

/// Writes frames one at a time, then the collection file. Holds the mesh topology (copied) and
/// the list of written frames, never the frames themselves.
class VtkSeriesWriter {
 public:
  /// Creates `directory` if needed (existing files of the same names are replaced). Throws
  /// MeshError when the mesh is inconsistent (as write_vtk_tet_mesh checks) or the options are
  /// invalid, std::runtime_error when the directory cannot be created.
  VtkSeriesWriter(const std::string& directory, const TetMesh& mesh,
                  const VtkSeriesOptions& options = VtkSeriesOptions());

  /// Validates and writes one frame file; returns its path. Throws MeshError for an invalid
  /// frame (sizes, names, non-finite values, time not after the previous frame's) and
  /// std::runtime_error on I/O failure; a rejected frame leaves the series unchanged.
  std::string write_frame(const VtkSeriesFrame& frame);

  /// Writes the collection file listing every frame written so far and returns its path. May be
  /// called again after more frames (the file is replaced). Throws std::runtime_error on I/O
  /// failure.
  std::string finish();

  std::size_t frame_count() const { return times_s_.size(); }

 private:
  std::string frame_file_name(std::size_t frame) const;

  std::string directory_;
  TetMesh mesh_;
  VtkSeriesOptions options_;
  std::vector<double> times_s_;
  std::vector<std::string> files_;
};

/// Convenience: writes every frame and the collection file; returns the collection file's path.
std::string write_vtk_time_series(const std::string& directory, const TetMesh& mesh,
                                  const std::vector<VtkSeriesFrame>& frames,
                                  const VtkSeriesOptions& options = VtkSeriesOptions());

}  // namespace pliant::host
