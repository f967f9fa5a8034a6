// Which tracked particles are the support (recording `fixed`) and which is driven by the tool
// (recording `driven`): given by option, or detected from the tracked motion.
//
// Detection (after the whole video is tracked), with motion_i the largest distance of particle
// i from its first-frame position over the video:
//   - support: the grid boundary (top row, bottom row, left column or right column of the
//     particles kept, per column or per row) whose particles move least on average: the side
//     resting on the base. All of that side's particles are supports (except the driven one);
//   - driven: the boundary particle, not a support, with the largest motion: the one under the
//     tool at the contact.
// Host code: allocates, throws InputError for malformed option text, ids out of range, and when
// detection has nothing to go on (nothing moved).
#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "pliant/vision/webcam_grid.hpp"

namespace pliant::vision::webcam {

enum class GridSide { top, bottom, left, right };
const char* grid_side_name(GridSide side);

struct SupportSpec {
  enum class Kind { detect, none, side, ids };
  Kind kind = Kind::detect;
  GridSide side = GridSide::bottom;  ///< Kind::side
  std::vector<int> ids;              ///< Kind::ids
};

/// "auto" | "none" | "top" | "bottom" | "left" | "right" | "ID[,ID...]".
SupportSpec parse_support(const std::string& text);

struct DrivenSpec {
  enum class Kind { detect, id, point };
  Kind kind = Kind::detect;
  int id = 0;         ///< Kind::id
  cv::Point2d point;  ///< Kind::point: the particle nearest to this first-frame pixel position
};

/// "auto" | "ID" | "X,Y" (pixels in the first frame).
DrivenSpec parse_driven(const std::string& text);

struct ParticleRoles {
  std::vector<int> support;  ///< sorted, unique
  int driven = -1;
  bool support_detected = false;
  bool driven_detected = false;
  GridSide support_side = GridSide::bottom;  ///< meaningful when support_detected
};

/// Particles on one side of the grid: per column (top/bottom) or per row (left/right) of the
/// particles kept, the outermost one. Sorted ids.
std::vector<int> grid_side_particles(const ParticleGrid& grid, GridSide side);

/// Resolves the specs. `motion_px[i]` is particle i's largest displacement from its first-frame
/// position (px). Throws InputError: ids out of range, the driven particle among explicit
/// supports, every particle a support, or detection asked for while the largest motion is below
/// 0.5 px (nothing moved: give the roles by option).
ParticleRoles choose_roles(const ParticleGrid& grid, const std::vector<double>& motion_px, const SupportSpec& support,
                           const DrivenSpec& driven);

}  // namespace pliant::vision::webcam
