// Image sequences listed from the file system: patterns, globs, directories (image_files.hpp).
#include <glob.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "pliant/drivers/opencv/image_files.hpp"

namespace pliant::drivers::opencv_files {

namespace {

namespace fs = std::filesystem;

bool is_file(const std::string& path) {
  std::error_code ec;
  return fs::is_regular_file(path, ec);
}

bool fail(FileError& error, hal::HalStatus status, std::string message) {
  error.status = status;
  error.message = std::move(message);
  return false;
}

bool list_pattern(const std::string& location, int first_index, std::vector<std::string>& files, FileError& error) {
  SequencePattern pattern;
  std::string words;
  if (!parse_sequence_pattern(location, pattern, words)) {
    return fail(error, hal::HalStatus::invalid_argument, words + ": " + location);
  }
  std::uint64_t first = 0;
  if (first_index >= 0) {
    first = static_cast<std::uint64_t>(first_index);
    if (!is_file(sequence_name(pattern, first))) {
      return fail(error, hal::HalStatus::io_error,
                  "image sequence " + location + ": no file " + sequence_name(pattern, first));
    }
  } else if (!is_file(sequence_name(pattern, 0))) {
    first = 1;
    if (!is_file(sequence_name(pattern, 1))) {
      return fail(error, hal::HalStatus::io_error,
                  "image sequence " + location + ": no file matches (no file for number 0 or 1: " +
                      sequence_name(pattern, 0) + ", " + sequence_name(pattern, 1) + ")");
    }
  }
  for (std::uint64_t index = first; files.size() < kMaxSequenceFiles; ++index) {
    std::string name = sequence_name(pattern, index);
    if (!is_file(name)) break;
    files.push_back(std::move(name));
  }
  return true;
}

bool list_glob(const std::string& location, std::vector<std::string>& files, FileError& error) {
  glob_t matches{};
  const int status = glob(location.c_str(), 0, nullptr, &matches);
  if (status == 0) {
    for (std::size_t i = 0; i < matches.gl_pathc && files.size() < kMaxSequenceFiles; ++i) {
      if (is_file(matches.gl_pathv[i])) files.emplace_back(matches.gl_pathv[i]);
    }
  }
  globfree(&matches);
  if (status == GLOB_NOSPACE || status == GLOB_ABORTED) {
    return fail(error, hal::HalStatus::io_error, "image sequence " + location + ": cannot list the matching files");
  }
  if (files.empty()) return fail(error, hal::HalStatus::io_error, "image sequence " + location + ": no file matches");
  // Byte order whatever the locale (glob(3) sorts by the collation of the locale).
  std::sort(files.begin(), files.end());
  return true;
}

bool list_directory(const std::string& location, std::vector<std::string>& files, FileError& error) {
  std::vector<std::string> names;
  std::error_code ec;
  for (fs::directory_iterator it(location, ec), end; !ec && it != end && names.size() < kMaxSequenceFiles;
       it.increment(ec)) {
    std::string name = it->path().filename().string();
    std::error_code file_ec;
    if (has_image_extension(name) && it->is_regular_file(file_ec)) names.push_back(std::move(name));
  }
  if (ec) {
    return fail(error, hal::HalStatus::io_error,
                "image directory " + location + ": cannot list (" + ec.message() + ")");
  }
  if (names.empty()) return fail(error, hal::HalStatus::io_error, "image directory " + location + ": no image files");
  std::sort(names.begin(), names.end(), [](const std::string& a, const std::string& b) { return natural_less(a, b); });
  files.reserve(names.size());
  for (const std::string& name : names) files.push_back((fs::path(location) / name).string());
  return true;
}

}  // namespace

SequenceForm sequence_form(const std::string& location) {
  std::error_code ec;
  if (fs::is_directory(location, ec)) return SequenceForm::directory;
  SequencePattern pattern;
  std::string words;
  if (parse_sequence_pattern(location, pattern, words)) return SequenceForm::pattern;
  if (has_glob_characters(location)) return SequenceForm::glob;
  return SequenceForm::not_a_sequence;
}

bool list_image_sequence(const std::string& location, SequenceForm form, int first_index,
                         std::vector<std::string>& files, FileError& error) {
  files.clear();
  switch (form) {
    case SequenceForm::directory: return list_directory(location, files, error);
    case SequenceForm::glob: return list_glob(location, files, error);
    case SequenceForm::pattern:
    case SequenceForm::not_a_sequence: break;
  }
  // A location that is not a sequence gets the pattern parser's reason.
  return list_pattern(location, first_index, files, error);
}

}  // namespace pliant::drivers::opencv_files
