// `pliant batch ...`: the fleet (docs/fleet.md), diagnose, refine or estimate over many recordings
// on Dask distributed. The fleet is Python (host/python/pliant/fleet.py): this command replaces
// the process with Debian's python3 running `-m pliant.fleet` on the same arguments, with
//   PLIANT_CLI        this program (/proc/self/exe), which the fleet's tasks run;
//   PYTHONPATH        PLIANT_PYTHONPATH if set, else the package directories this build knows
//                     (CMake: the package directory of the build, then the install prefix's
//                     lib/python3/dist-packages), before any PYTHONPATH already set;
//   PLIANT_FLEET_PROG "pliant batch", the name the fleet's messages and --help use.
// Every argument, --help included, goes to the fleet unparsed: main.cpp hands `pliant batch ...`
// to run_fleet() before CLI11 parses anything, so no argument (a directory named like another
// command, a `--`) is read as pliant's own. Without python3, or without the fleet's package, it
// exits 2 naming what to install; the fleet itself does the same for Dask.
#pragma once

#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace pliant::cli {

/// Replaces the process with the fleet on `arguments` (those after `batch`); returns only by
/// throwing (exit_status.hpp: UsageError when python3 or the package is missing).
int run_fleet(const std::vector<std::string>& arguments);

class BatchCommand {
 public:
  /// Registers `batch` on `parent` (for `pliant --help`), taking every argument after it as the
  /// fleet's should CLI11 parse it after all.
  explicit BatchCommand(CLI::App& parent);

  bool selected() const { return app_->parsed(); }
  /// run_fleet() on the arguments after `batch`.
  int run() const;

 private:
  CLI::App* app_ = nullptr;
};

/// The directories to put before PYTHONPATH: `override_list` (PLIANT_PYTHONPATH, ':'-separated)
/// when not null, else `built_in` (this build's list, ':'-separated); empty entries dropped.
std::vector<std::string> fleet_python_path(const char* override_list, const std::string& built_in);

}  // namespace pliant::cli
