// pliant command line: parses the arguments and hands over to one command.
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "cli_registry.hpp"
#include "command_batch.hpp"
#include "command_devices.hpp"
#include "command_diagnose.hpp"
#include "command_estimate.hpp"
#include "command_import.hpp"
#include "command_record.hpp"
#include "command_refine.hpp"
#include "command_replay.hpp"
#include "command_simulate.hpp"
#include "command_telemetry.hpp"
#include "exit_status.hpp"

namespace pliant::cli {
namespace {

// CLI11 reports parse errors in its own words; keep them, but as one line under our prefix.
int report_parse_error(const CLI::App& app, const CLI::ParseError& error) {
  const std::vector<CLI::App*> commands = app.get_subcommands();
  if (commands.empty()) {
    const std::vector<std::string> rest = app.remaining();
    if (!rest.empty() && rest.front().rfind('-', 0) != 0) {
      report_error("pliant", "unknown command '" + rest.front() + "'; see 'pliant --help'");
      return exit_usage;
    }
    report_error("pliant", std::string(error.what()) + "; see 'pliant --help'");
    return exit_usage;
  }
  const std::string name = "pliant " + commands.front()->get_name();
  report_error(name, std::string(error.what()) + "; see '" + name + " --help'");
  return exit_usage;
}

// The optional commands of this build (cli_registry.hpp), added to `app` in their usual place.
struct AddedCommand {
  std::string label;  // "pliant track"
  std::unique_ptr<OptionalCommand> command;
};

std::vector<AddedCommand> add_optional_commands(CLI::App& app) {
  std::vector<AddedCommand> added;
  for (const OptionalCommandNeed& need : kOptionalCommands) {
    for (const CommandPart& part : cli_registry().commands) {
      if (part.name == need.name) added.push_back({"pliant " + part.name, part.add(app)});
    }
  }
  return added;
}

int run(int argc, char** argv) {
  // `pliant batch ...`: every argument is the fleet's, before CLI11 could read one as ours.
  if (argc > 1 && std::string(argv[1]) == "batch") {
    const std::vector<std::string> arguments(argv + 2, argv + argc);
    return run_reporting_errors("pliant batch", [&] { return run_fleet(arguments); });
  }
  // A command this build was made without: say so rather than "unknown command".
  if (argc > 1) {
    const std::string missing = missing_command_message(cli_registry(), argv[1]);
    if (!missing.empty()) {
      report_error("pliant", missing);
      return exit_usage;
    }
  }
  CLI::App app{"pliant: deformability (msm_beta) of soft objects from recorded trajectories", "pliant"};
  app.set_version_flag("--version", std::string("pliant ") + PLIANT_VERSION);
  app.footer(
      "Run 'pliant COMMAND --help' for the options of a command.\n"
      "Exit status: 0 success, 1 runtime failure, 2 usage error or malformed recording.");
  EstimateCommand estimate(app);
  SimulateCommand simulate(app);
  DiagnoseCommand diagnose(app);
  ImportCommand importer(app);
  RefineCommand refine(app);
  TelemetryCommand telemetry(app);
  const std::vector<AddedCommand> optional_commands = add_optional_commands(app);  // track, track-depth
  ReplayCommand replay(app);
  DevicesCommand devices(app);
  RecordCommand record(app);
  BatchCommand batch(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& done) {  // --help, --version
    return app.exit(done);
  } catch (const CLI::ParseError& error) {
    return report_parse_error(app, error);
  }
  if (estimate.selected()) return run_reporting_errors("pliant estimate", [&] { return estimate.run(); });
  if (simulate.selected()) return run_reporting_errors("pliant simulate", [&] { return simulate.run(); });
  if (diagnose.selected()) return run_reporting_errors("pliant diagnose", [&] { return diagnose.run(); });
  if (importer.selected()) return run_reporting_errors("pliant import compression", [&] { return importer.run(); });
  if (refine.selected()) return run_reporting_errors("pliant refine", [&] { return refine.run(); });
  if (telemetry.selected()) return run_reporting_errors("pliant telemetry", [&] { return telemetry.run(); });
  for (const AddedCommand& optional : optional_commands) {
    if (optional.command->selected())
      return run_reporting_errors(optional.label, [&] { return optional.command->run(); });
  }
  if (replay.selected()) return run_reporting_errors("pliant replay", [&] { return replay.run(); });
  if (devices.selected()) return run_reporting_errors("pliant devices", [&] { return devices.run(); });
  if (record.selected()) return run_reporting_errors("pliant record", [&] { return record.run(); });
  if (batch.selected()) return run_reporting_errors("pliant batch", [&] { return batch.run(); });
  std::cerr << app.help();
  return exit_usage;
}

}  // namespace
}  // namespace pliant::cli

int main(int argc, char** argv) {
  return pliant::cli::run_reporting_errors("pliant", [&] { return pliant::cli::run(argc, argv); });
}
