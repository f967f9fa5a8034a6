#include "cli_registry.hpp"

namespace pliant::cli {

const CliRegistry& cli_registry() {
  static const CliRegistry registry = [] {
    CliRegistry r;
    register_built_parts(r);
    return r;
  }();
  return registry;
}

std::string missing_command_message(const CliRegistry& registry, std::string_view name) {
  for (const CommandPart& part : registry.commands) {
    if (part.name == name) return "";
  }
  for (const OptionalCommandNeed& need : kOptionalCommands) {
    if (need.name == name) {
      return "this pliant was built without " + std::string(need.built_without) + ": " + std::string(name) +
             " is not available";
    }
  }
  return "";
}

}  // namespace pliant::cli
