// The tracked region and the particles seeded on a grid inside it (the MSM paper, section III-B:
// particles on a regular grid over the segmented object in the first, undeformed frame).
//
// Pixel coordinates: x to the right, y down, in pixels, with the centre of the top-left pixel
// at (0, 0) (OpenCV's convention); pixel (x, y) covers [x - 1/2, x + 1/2] x [y - 1/2, y + 1/2].
// Host code: allocates, throws InputError for malformed option text and unusable regions.
#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace pliant::vision::webcam {

/// The region to seed: a rectangle of pixels, or a mask (non-zero pixels inside).
struct Region {
  cv::Rect roi;       ///< pixels roi.x .. roi.x + roi.width - 1 (and y); used when mask is empty
  cv::Mat mask;       ///< CV_8UC1, frame size; non-zero = inside. Takes precedence over roi.
  std::string label;  ///< "--roi x,y,w,h" or the mask file, for messages
};

/// "x,y,w,h" in pixels (integers, w and h may be 0 to be refused later with a clear message).
/// Throws InputError on any other text.
Region parse_roi(const std::string& text);

/// Reads a mask image (any 8-bit image; non-zero grey = inside). Throws InputError when it
/// cannot be read.
Region read_mask(const std::string& path);

/// How particles are laid out.
///   rows x cols only: the centres of a rows x cols division of the region's bounding box, so
///     each particle is half a cell inside the boundary (spacing box width / cols, height / rows);
///   spacing only: as many rows and columns at that spacing as fit, centred in the box;
///   both: exactly rows x cols at that spacing, centred in the box (InputError if it does not fit).
/// With a mask, grid sites whose pixel is outside the mask are dropped.
struct GridSpec {
  int rows = 0;
  int cols = 0;
  double spacing_px = 0;
};

/// "RxC" (e.g. "4x8": 4 rows, 8 columns; 1..1000 each). Throws InputError otherwise.
GridSpec parse_grid(const std::string& text);

/// Particles of the first frame. Ids are row-major over the grid sites kept (row 0 at the top).
struct ParticleGrid {
  std::vector<cv::Point2d> positions;  ///< px, in the first frame
  std::vector<int> row;                ///< grid row of each particle, 0 at the top
  std::vector<int> col;                ///< grid column of each particle, 0 at the left
  int rows = 0;
  int cols = 0;
  double spacing_x_px = 0;
  double spacing_y_px = 0;
  int size() const { return static_cast<int>(positions.size()); }
};

/// Seeds `spec` in `region` for frames of `frame_size`. Throws InputError when the region is
/// empty (zero width or height, a mask without any set pixel), reaches outside the frame, the
/// mask has another size than the frame, the spec is invalid (no rows/cols and no spacing, a
/// spacing below 2 px) or fewer than 3 particles result.
ParticleGrid seed_particles(const Region& region, const GridSpec& spec, const cv::Size& frame_size);

}  // namespace pliant::vision::webcam
