// Depth frame lists, in two formats told apart by the first line:
//
// 1. The TUM RGB-D benchmark's depth.txt:
//
//   # depth maps
//   # timestamp filename
//   1305031102.160407 depth/1305031102.160407.png
//
//    One frame per line: a timestamp in seconds and a file name, separated by blanks. Lines that
//    start with '#' (after optional blanks) and blank lines are skipped.
//
// 2. The depth_frames.csv that `pliant record` writes (docs/record.md), recognised by its
//    header line `index,t,file,depth_scale_m,fx,fy,cx,cy`:
//
//   0,0.0334,depth/000000.png,0.001,570.3,570.3,319.5,239.5
//
//    One frame per line, eight comma-separated fields: an integer index, the time in seconds,
//    the file name, metres per raw unit (finite, > 0) and the pinhole intrinsics in pixels
//    (numbers, or nan when the device reported none). Blank lines are skipped.
//
// Both: CRLF line ends are accepted, timestamps must increase strictly, a file name holds no
// control character. File names are kept as written; read_depth_list resolves relative ones
// against the list's own directory.
//
// Host code: allocates; throws DepthError whose message names the list and the line
// ("depth.txt:7: timestamp 'x' is not a number").
#pragma once

#include <limits>
#include <string>
#include <string_view>
#include <vector>

namespace pliant::vision {

struct DepthListEntry {
  static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  double t_s = 0;    ///< capture time, s
  std::string path;  ///< image file
  /// depth_frames.csv only (NaN in TUM lists): metres per raw unit, and the intrinsics, px
  /// (NaN when the recording device reported none).
  double depth_scale_m = kNaN;
  double fx = kNaN, fy = kNaN, cx = kNaN, cy = kNaN;
};

/// Parses list text; `label` names it in errors. Refuses: a line with the wrong number of
/// fields, a timestamp that is not a finite decimal number, timestamps not strictly
/// increasing, a control character in a file name, and a list without any frame; in
/// depth_frames.csv also an index that is not an integer, a scale that is not finite and
/// positive, and intrinsics that are neither numbers nor nan.
std::vector<DepthListEntry> parse_depth_list(std::string_view text, const std::string& label);

/// Reads and parses a list file; relative file names become paths beside the list.
std::vector<DepthListEntry> read_depth_list(const std::string& path);

}  // namespace pliant::vision
