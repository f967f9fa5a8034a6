// Depth frame lists in the TUM RGB-D benchmark's format (its depth.txt):
//
//   # depth maps
//   # timestamp filename
//   1305031102.160407 depth/1305031102.160407.png
//
// One frame per line: a timestamp in seconds and a file name, separated by blanks. Lines that
// start with '#' (after optional blanks) and blank lines are skipped; CRLF line ends are
// accepted. Timestamps must increase strictly. File names are kept as written; read_depth_list
// resolves relative ones against the list's own directory.
//
// Host code: allocates; throws DepthError whose message names the list and the line
// ("depth.txt:7: timestamp 'x' is not a number").
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace pliant::vision {

struct DepthListEntry {
  double t_s = 0;    ///< capture time, s
  std::string path;  ///< image file
};

/// Parses list text; `label` names it in errors. Refuses: a line with fewer or more than two
/// fields, a timestamp that is not a finite decimal number, timestamps not strictly
/// increasing, a control character in a file name, and a list without any frame.
std::vector<DepthListEntry> parse_depth_list(std::string_view text, const std::string& label);

/// Reads and parses a list file; relative file names become paths beside the list.
std::vector<DepthListEntry> read_depth_list(const std::string& path);

}  // namespace pliant::vision
