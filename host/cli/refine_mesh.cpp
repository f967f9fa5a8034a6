#include "refine_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "exit_status.hpp"
#include "pliant/host/fem/mesh_io.hpp"

namespace pliant::cli {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A mesh whose points do not sit where frame 0 sees the particles is most likely numbered
// differently; the fit would then compare unrelated points. Median, so a sagging or moving part
// of the body does not trigger it.
void warn_if_misplaced(const host::Recording& r, const host::TetMesh& mesh, const std::string& path,
                       std::vector<std::string>& warnings) {
  double lo[3] = {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
                  std::numeric_limits<double>::infinity()};
  double hi[3] = {-lo[0], -lo[1], -lo[2]};
  for (int i = 0; i < mesh.point_count(); ++i) {
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], mesh.points[static_cast<std::size_t>(3 * i + a)]);
      hi[a] = std::max(hi[a], mesh.points[static_cast<std::size_t>(3 * i + a)]);
    }
  }
  const double diagonal = std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                                    (hi[2] - lo[2]) * (hi[2] - lo[2]));
  std::vector<double> distances;
  for (int id = 0; id < r.particle_count; ++id) {
    if (!r.observed(0, id)) continue;
    double sum = 0;
    for (int a = 0; a < 3; ++a) {
      const double d = r.position(0, id, a) - mesh.points[static_cast<std::size_t>(3 * id + a)];
      sum += d * d;
    }
    distances.push_back(std::sqrt(sum));
  }
  if (distances.empty()) return;
  const auto middle = distances.begin() + static_cast<std::ptrdiff_t>(distances.size() / 2);
  std::nth_element(distances.begin(), middle, distances.end());
  if (*middle > 0.1 * diagonal) {
    char text[64];
    std::snprintf(text, sizeof text, "%.3g", *middle);
    warnings.push_back(path + ": the median distance between a particle in frame 0 and its mesh point is " + text +
                       " m, over 10 % of the mesh's size: is mesh point i particle i?");
  }
}

}  // namespace

void attach_mesh(host::Recording& recording, const std::string& path, std::vector<std::string>& warnings) {
  if (recording.dimension != 3) throw UsageError("--mesh: the FEM needs a 3D recording");
  host::TetMesh mesh;
  host::MeshReadReport report;
  try {
    mesh = host::read_tet_mesh(path, &report);
  } catch (const host::MeshError& e) {
    throw UsageError(e.what());
  }
  for (const std::string& w : report.warnings) warnings.push_back(w);
  const int n = recording.particle_count;
  const int points = mesh.point_count();
  if (points < n) {
    throw UsageError(path + ": " + std::to_string(points) + " points but the recording has " + std::to_string(n) +
                     " particles (mesh point i is particle i)");
  }
  warn_if_misplaced(recording, mesh, path, warnings);
  if (points > n) {
    // Re-stride the frame-major positions for the added, never observed particles.
    const auto frames = static_cast<std::size_t>(recording.frame_count());
    const auto old_n = static_cast<std::size_t>(n);
    const auto new_n = static_cast<std::size_t>(points);
    std::vector<double> positions(frames * new_n * 3, kNaN);
    for (std::size_t f = 0; f < frames; ++f) {
      std::copy_n(recording.positions.begin() + static_cast<std::ptrdiff_t>(f * old_n * 3), old_n * 3,
                  positions.begin() + static_cast<std::ptrdiff_t>(f * new_n * 3));
    }
    recording.positions = std::move(positions);
    recording.masses.resize(new_n, 1.0);
    recording.particle_count = points;
    warnings.push_back(path + ": " + std::to_string(points - n) + " mesh points beyond the recording's " +
                       std::to_string(n) + " particles are unobserved nodes");
  }
  recording.rest_positions = mesh.points;
  recording.mesh = std::move(mesh);
}

}  // namespace pliant::cli
