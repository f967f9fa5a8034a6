#include "output_directory.hpp"

#include <filesystem>
#include <stdexcept>
#include <system_error>

#include "exit_status.hpp"

namespace pliant::cli {

void check_output_directory(const std::string& directory, bool force) {
  namespace fs = std::filesystem;
  std::error_code error;
  const fs::file_status status = fs::status(directory, error);
  if (!fs::exists(status)) return;
  if (!fs::is_directory(status)) throw UsageError(directory + " exists and is not a directory");
  if (force) return;
  const bool empty = fs::is_empty(directory, error);
  if (error) throw std::runtime_error("cannot read " + directory + ": " + error.message());
  if (!empty) throw UsageError(directory + " is not empty; pass --force to replace the recording in it");
}

}  // namespace pliant::cli
