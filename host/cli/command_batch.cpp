#include "command_batch.hpp"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <stdexcept>
#include <system_error>

#include "exit_status.hpp"

namespace pliant::cli {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> split_path_list(const std::string& list) {
  std::vector<std::string> parts;
  std::string::size_type start = 0;
  while (start <= list.size()) {
    const std::string::size_type end = std::min(list.find(':', start), list.size());
    if (end > start) parts.push_back(list.substr(start, end - start));
    start = end + 1;
  }
  return parts;
}

std::string joined(const std::vector<std::string>& parts, const std::string& separator) {
  std::string text;
  for (const std::string& part : parts) text += (text.empty() ? "" : separator) + part;
  return text;
}

void set_environment(const char* name, const std::string& value) {
  if (setenv(name, value.c_str(), 1) != 0) throw std::runtime_error(std::string("cannot set ") + name);
}

}  // namespace

std::vector<std::string> fleet_python_path(const char* override_list, const std::string& built_in) {
  return split_path_list(override_list != nullptr ? std::string(override_list) : built_in);
}

BatchCommand::BatchCommand(CLI::App& parent) {
  app_ = parent.add_subcommand("batch",
                               "Run diagnose, refine or estimate over many recordings on Dask distributed, one row "
                               "per recording in a results table (docs/fleet.md; options: pliant batch --help)");
  app_->set_help_flag();   // --help goes to the fleet, which knows its options
  app_->prefix_command();  // every argument after `batch` is the fleet's, unparsed
}

int BatchCommand::run() const { return run_fleet(app_->remaining()); }

int run_fleet(const std::vector<std::string>& fleet_arguments) {
  const std::string python = PLIANT_BATCH_PYTHON;
  if (access(python.c_str(), X_OK) != 0) {
    throw UsageError(python + " is missing: the fleet needs Debian's python3 and Dask (apt-get install python3 " +
                     "python3-distributed)");
  }
  const std::vector<std::string> directories =
      fleet_python_path(std::getenv("PLIANT_PYTHONPATH"), PLIANT_BATCH_PYTHONPATH);
  bool found = false;
  std::error_code error;
  for (const std::string& directory : directories)
    found = found || fs::is_regular_file(fs::path(directory) / "pliant" / "fleet.py", error);
  if (!found) {
    throw UsageError("the fleet's Python package (pliant/fleet.py) is in none of " +
                     (directories.empty() ? std::string("(no directory)") : joined(directories, ", ")) +
                     ": install python3-pliant or set PLIANT_PYTHONPATH to the directory holding pliant/");
  }
  const fs::path self = fs::read_symlink("/proc/self/exe", error);
  if (error) throw std::runtime_error("cannot find this program's path (/proc/self/exe): " + error.message());

  std::vector<std::string> python_path = directories;
  if (const char* existing = std::getenv("PYTHONPATH"); existing != nullptr && *existing != '\0') {
    python_path.emplace_back(existing);
  }
  set_environment("PYTHONPATH", joined(python_path, ":"));
  set_environment("PLIANT_CLI", self.string());
  set_environment("PLIANT_FLEET_PROG", "pliant batch");

  std::vector<std::string> arguments{python, "-m", "pliant.fleet"};
  for (const std::string& argument : fleet_arguments) arguments.push_back(argument);
  std::vector<char*> argv;
  for (std::string& argument : arguments) argv.push_back(argument.data());
  argv.push_back(nullptr);
  std::cout.flush();
  std::cerr.flush();
  execv(python.c_str(), argv.data());
  throw std::runtime_error("cannot run " + python + ": " + std::strerror(errno));
}

}  // namespace pliant::cli
