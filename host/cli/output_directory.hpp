// The output directory of a command that writes a recording (simulate, import, track-depth).
// Host code: throws, allocates.
#pragma once

#include <string>

namespace pliant::cli {

/// Accepts `directory` when it does not exist yet or is an empty directory; with `force`, any
/// existing directory. Throws UsageError when it is a file, or not empty without `force`;
/// std::runtime_error when its contents cannot be read.
void check_output_directory(const std::string& directory, bool force);

}  // namespace pliant::cli
