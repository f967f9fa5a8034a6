// Where `pliant telemetry` writes: JSON lines to standard output or a file that appears only
// when complete, and recording directories that appear only when complete.
#pragma once

#include <cstdio>
#include <string>

#include "pliant/host/recording.hpp"

namespace pliant::cli {

/// JSON lines to stdout (path "" or "-"), or to `path` through a temporary file beside it that
/// commit() renames into place; a JsonLinesOutput destroyed without commit() removes it.
class JsonLinesOutput {
 public:
  /// Throws std::runtime_error when the temporary file cannot be created, UsageError when `path`
  /// is a directory. `flush_each` flushes after every line (for live sources on stdout).
  JsonLinesOutput(const std::string& path, bool flush_each);
  ~JsonLinesOutput();
  JsonLinesOutput(const JsonLinesOutput&) = delete;
  JsonLinesOutput& operator=(const JsonLinesOutput&) = delete;

  /// Writes `line` and a line break. Throws std::runtime_error on a write error.
  void write(const std::string& line);
  /// Flushes; for a file, syncs and renames it into place. Throws std::runtime_error on failure.
  void commit();
  /// "standard output" or the path.
  const std::string& label() const { return label_; }

 private:
  std::FILE* file_ = nullptr;
  std::string path_;
  std::string temp_;
  std::string label_;
  bool flush_each_ = false;
};

/// Throws UsageError when `directory` exists and is not an empty directory (checked before
/// reading the stream, so that a long capture is not lost at the end).
void check_new_recording_directory(const std::string& directory);

/// Writes `recording` (write_recording) into a temporary directory beside `directory`, then
/// renames it to `directory` (which must not exist or be empty), so the recording appears whole
/// or not at all. When that last rename fails, the complete recording is kept under the
/// temporary name, which the std::runtime_error's message gives.
void write_recording_atomically(const host::Recording& recording, const std::string& directory);

}  // namespace pliant::cli
