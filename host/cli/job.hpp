// What the jobs of the command line (estimate, diagnose, refine, simulate) share with the Python
// module: each job is a function of an options struct that does the work and writes the files
// the options name, and returns what the command prints. The command line and the module call
// the same functions, so their outputs and their error messages are the same.
//
// Errors: UsageError (exit_status.hpp) for options that cannot work, host::RecordingError for a
// recording the reader rejects, std::runtime_error (or another std::exception) for a failure of
// the work itself, each with a one-line message.
#pragma once

#include <functional>
#include <string>

#include "pliant/host/recording.hpp"

namespace pliant::cli {

/// Where a job's recording comes from: read from a directory, or one already in memory. Called
/// once, after the options were checked (nothing is read for a command that cannot succeed).
using RecordingSource = std::function<host::Recording()>;

/// Receives the non-fatal findings (the recording's warnings, options that do not apply) as they
/// arise, one line each.
using WarningSink = std::function<void(const std::string&)>;

/// A RecordingSource reading `directory` with host::read_recording.
inline RecordingSource recording_from(const std::string& directory) {
  return [directory] { return host::read_recording(directory); };
}

}  // namespace pliant::cli
