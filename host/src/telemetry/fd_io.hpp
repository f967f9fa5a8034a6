// POSIX file-descriptor helpers shared by the telemetry transports.
#pragma once

#include <string>

namespace pliant::host::telemetry::detail {

enum class Ready { readable, timeout, hangup };

/// Waits up to timeout_ms for `fd` to become readable. A signal interrupting the wait counts
/// as a timeout (the caller re-checks its stop condition). Hangup without pending data is
/// `hangup`; hangup with data is `readable` (the data is read first). Throws
/// std::runtime_error("<what>: <cause>") on a poll error.
Ready wait_readable(int fd, int timeout_ms, const std::string& what);

/// strerror(error) as a string.
std::string error_text(int error);

/// Closes `fd` if it is >= 0, keeping errno.
void close_quietly(int fd);

}  // namespace pliant::host::telemetry::detail
