// pliant drivers/opencv: which files an image sequence is made of, and the frame rates a file
// source accepts. No OpenCV here: the naming is plain text and file system work.
//
// One implementation for every reader of files in pliant: OpenCvCamera's image_sequence source
// and the webcam front end (host/vision/webcam, `pliant track`) both list their sequences here,
// so a pattern means the same thing and a missing file reads the same way wherever it is given.
//
// Forms of a sequence location
//   pattern    a printf-style name with exactly one integer conversion (frame_%04d.png; %d, %i,
//              %u, an optional '0' flag and a width of at most 2 digits; %% is a literal percent).
//              It is parsed here, never handed to snprintf: a user's text is not a format string.
//              The files are consecutive indices from `first_index` (-1: 0, else 1, whichever
//              file exists) up to the first missing index.
//   glob       a name with * ? or [ (glob(3)): the matching regular files, in byte order of their
//              names (so frame_10 follows frame_09 only with zero-padded numbers).
//   directory  every regular file in it with an image extension, in natural order (2.png before
//              10.png).
// A list holds at most kMaxSequenceFiles files, so a pattern over a directory of other numbered
// files cannot make the listing run away.
//
// Errors are one line that names the location and the cause (FileError). Host-side code: the
// listing allocates and touches the file system; the naming functions are pure.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "pliant/hal/status.hpp"

namespace pliant::drivers::opencv_files {

/// Highest frame rate a file source accepts, Hz: a rate a user gives, and a rate a container
/// states (a container above it is taken as stating none: some report their time base).
inline constexpr double kMaxFileRateHz = 1000.0;

/// Most files one image sequence lists (about nine hours at 30 Hz).
inline constexpr std::size_t kMaxSequenceFiles = 1000000;

/// True for a usable frame rate of a file source: finite, > 0 and at most kMaxFileRateHz.
constexpr bool valid_file_rate(double hz) noexcept { return hz > 0 && hz <= kMaxFileRateHz; }

/// Why a file source cannot be read.
struct FileError {
  /// invalid_argument: the location is malformed (not a pattern); io_error: nothing to read.
  hal::HalStatus status = hal::HalStatus::io_error;
  std::string message;  ///< one line naming the location and the cause
};

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

/// True when the name has a glob character (* ? [).
bool has_glob_characters(std::string_view name) noexcept;

enum class SequenceForm : std::uint8_t { not_a_sequence, pattern, glob, directory };

/// The form of `location`, tried in this order: an existing directory, a pattern that
/// parse_sequence_pattern accepts, a name with glob characters; else not_a_sequence. Reads the
/// file system (one stat) but lists nothing.
SequenceForm sequence_form(const std::string& location);

/// Lists the files of the sequence at `location`, whose form sequence_form gave, in reading
/// order (see the top; `first_index` >= 0 or -1, used by patterns only). false with `error` when
/// there is nothing to read:
///   not_a_sequence  invalid_argument, the pattern parser's words ("image pattern: no %d
///                   conversion (and not a directory): <location>")
///   pattern         "image sequence <location>: no file <name>" (first_index given), or
///                   "image sequence <location>: no file matches (no file for number 0 or 1:
///                   <name 0>, <name 1>)"
///   glob            "image sequence <location>: no file matches", or "...: cannot list the
///                   matching files"
///   directory       "image directory <location>: no image files", or "...: cannot list (<why>)"
bool list_image_sequence(const std::string& location, SequenceForm form, int first_index,
                         std::vector<std::string>& files, FileError& error);

}  // namespace pliant::drivers::opencv_files
