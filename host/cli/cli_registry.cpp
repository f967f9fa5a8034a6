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

}  // namespace pliant::cli
