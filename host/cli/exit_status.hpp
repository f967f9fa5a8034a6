// Exit statuses of the command line and the one place that turns exceptions into them.
#pragma once

#include <functional>
#include <stdexcept>
#include <string>

namespace pliant::cli {

enum ExitStatus : int {
  exit_ok = 0,
  exit_failure = 1,  // runtime failure: estimation impossible, I/O error, ...
  exit_usage = 2,    // bad command line, bad option value, or a recording the reader rejects
};

/// A mistake in how the command was invoked (bad option value, refusing to overwrite, ...).
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// `message` with line breaks folded into spaces: every diagnostic is exactly one line.
std::string single_line(std::string message);

/// Prints "<prefix>: <message>" as one line on stderr.
void report_error(const std::string& prefix, const std::string& message);

/// Prints "pliant: warning: <message>" as one line on stderr.
void report_warning(const std::string& message);

/// Runs `command` and maps what escapes it to an exit status, reporting it under `prefix`:
/// RecordingError and UsageError -> 2, any other exception -> 1.
int run_reporting_errors(const std::string& prefix, const std::function<int()>& command);

}  // namespace pliant::cli
