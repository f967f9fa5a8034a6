// Whole-file writes that never leave a truncated file behind.
#pragma once

#include <string>

namespace pliant::cli {

/// Writes `content` to a temporary file beside `path`, then renames it over `path`.
/// Throws std::runtime_error("cannot write <path>: <reason>") on failure.
void write_file_atomically(const std::string& path, const std::string& content);

}  // namespace pliant::cli
