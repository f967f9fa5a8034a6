// The depth frames `pliant track-depth` reads: a TUM depth list, the depth_frames.csv of a
// `pliant record` recording (both host/vision/depth_list.hpp), or an OpenNI .oni recording
// played through the depth camera scheme `oni` of the device registry (drivers/openni2 registers
// it when it is built; cli_registry.hpp).
//
// A list's PNGs are read when asked for (one in memory at a time). An .oni file is played
// once, stepped, at open and its frames kept in memory (at most kMaxOniBytes of depth):
// tracking asks for frames in order, once per round, and OpenNI2's player cannot seek back
// cheaply. Frame times: the list's timestamps; for .oni, the file's timestamps from its first
// frame (s).
//
// Host code: allocates; throws vision::DepthError for malformed or unusable input.
#pragma once

#include <cstddef>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "pliant/vision/depth_image.hpp"

namespace pliant::cli {

/// Largest depth payload an .oni is loaded with (1 GiB: about 1700 VGA frames, 58 s at 30 Hz).
inline constexpr std::size_t kMaxOniBytes = std::size_t{1} << 30;

class DepthInput {
 public:
  virtual ~DepthInput() = default;
  /// Frame times, s, strictly increasing.
  virtual const std::vector<double>& times_s() const = 0;
  /// Frame `index` (0-based), valid until the next call.
  virtual vision::DepthImageView frame(int index) = 0;
  /// Metres per raw unit, and pinhole intrinsics (px) of the first frame, as the input states
  /// them: NaN when it does not (TUM lists; a device that reported no field of view).
  double depth_scale_m = kNaN;
  double fx = kNaN, fy = kNaN, cx = kNaN, cy = kNaN;
  /// "TUM list", "pliant record depth_frames.csv", "OpenNI recording".
  std::string kind;

 protected:
  static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
};

/// True when `path` names an .oni recording (by its extension, any case).
bool is_oni_path(const std::string& path);

/// Opens `path`: an .oni recording (see is_oni_path) or a frame list in either format. Throws
/// vision::DepthError: unreadable or malformed list, a malformed .oni (refused before OpenNI2
/// parses it), one without depth frames or beyond kMaxOniBytes, and .oni input when
/// drivers/openni2 was not built.
std::unique_ptr<DepthInput> open_depth_input(const std::string& path);

}  // namespace pliant::cli
