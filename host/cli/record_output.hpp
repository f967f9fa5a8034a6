// `pliant record -o REC`: the recording appears whole under REC or not at all.
//
// Everything is written into a new directory "REC.partial-XXXXXX" beside REC (six random
// characters; permissions 0777 less the umask, like any new directory; same file system,
// so the final rename is atomic); commit() renames it to REC. Until then the destructor removes
// it, so a failure or an exception never leaves a recording behind that looks complete (a
// process killed outright leaves the .partial-XXXXXX directory, whose name says what it is).
// An existing REC is refused unless `force`; even then only a recording (a directory with
// recording.json) or an empty directory is replaced, never any other file or directory. The
// old recording is moved aside, the new one renamed in, and the old one removed; if the rename
// fails the old one is put back.
// Host code: throws UsageError (refusals) and std::runtime_error (file system failures).
#pragma once

#include <string>

namespace pliant::cli {

class OutputDirectory {
 public:
  /// Checks `target` (see the top) and creates the partial directory.
  OutputDirectory(const std::string& target, bool force);
  ~OutputDirectory();  ///< removes the partial directory unless committed
  OutputDirectory(const OutputDirectory&) = delete;
  OutputDirectory& operator=(const OutputDirectory&) = delete;

  /// Where to write now (absolute: a library that changes the working directory, as OpenNI2's
  /// initialisation may, does not move it).
  const std::string& partial() const { return partial_; }
  /// The target as given (for messages).
  const std::string& target() const { return shown_; }
  /// The base name of the target (the recording's name).
  std::string name() const;
  /// Renames the partial directory to the target. Throws; the partial directory is then still
  /// removed by the destructor.
  void commit();

 private:
  std::string shown_;
  std::string target_;   // absolute
  std::string partial_;  // absolute
  bool force_ = false;
  bool committed_ = false;
};

}  // namespace pliant::cli
