#include "pliant/core/status.hpp"

#include <cstdlib>

namespace pliant {
namespace {
AssertHandler g_assert_handler = nullptr;
}  // namespace

const char* status_name(Status status) noexcept {
  switch (status) {
    case Status::ok: return "ok";
    case Status::invalid_argument: return "invalid_argument";
    case Status::capacity_exceeded: return "capacity_exceeded";
    case Status::invalid_mass: return "invalid_mass";
    case Status::non_finite_input: return "non_finite_input";
    case Status::duplicate_rest_positions: return "duplicate_rest_positions";
    case Status::degenerate_cluster: return "degenerate_cluster";
    case Status::no_free_particles: return "no_free_particles";
    case Status::no_observations: return "no_observations";
    case Status::not_converged: return "not_converged";
    case Status::not_initialized: return "not_initialized";
  }
  return "unknown";
}

void set_assert_handler(AssertHandler handler) noexcept { g_assert_handler = handler; }

namespace detail {
void assert_failed(const char* expression, const char* file, int line) noexcept {
  if (g_assert_handler != nullptr) {
    g_assert_handler(expression, file, line);
    return;
  }
  std::abort();
}
}  // namespace detail
}  // namespace pliant
