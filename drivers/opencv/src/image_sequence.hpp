// drivers/opencv internal: naming of image sequences (no OpenCV): printf-style patterns with one
// integer conversion, parsed here rather than handed to snprintf (a user's pattern is never used
// as a format string), and the natural order of the files of a directory.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace pliant::drivers::opencv_detail {

/// A parsed pattern: name(i) = prefix + i (padded to `width` with zeros or spaces) + suffix.
struct SequencePattern {
  std::string prefix;
  std::string suffix;
  int width = 0;          ///< minimum digits, 0..20
  bool zero_pad = false;  ///< pad with '0' (else spaces)
};

/// Parses a pattern with exactly one conversion %d, %i or %u, optionally with a '0' flag and a
/// width of at most 2 digits (<= 20); "%%" is a literal '%'. false with `error` (words)
/// otherwise: no conversion, two conversions, another conversion, a stray '%'.
/// O(length); allocates (the strings).
bool parse_sequence_pattern(std::string_view pattern, SequencePattern& out, std::string& error);

/// The file name of index `index` (>= 0).
std::string sequence_name(const SequencePattern& pattern, std::uint64_t index);

/// Natural order of file names: runs of digits compare by value (leading zeros ignored, then
/// the shorter run first), other characters byte-wise. A strict weak order.
bool natural_less(std::string_view a, std::string_view b) noexcept;

/// True when the name ends in an extension imgcodecs reads (png, jpg, jpeg, bmp, tif, tiff,
/// pbm, pgm, ppm, pnm, webp, exr, hdr; any letter case).
bool has_image_extension(std::string_view name) noexcept;

}  // namespace pliant::drivers::opencv_detail
