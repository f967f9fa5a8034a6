// pliant core: status codes and the single invariant-check macro.
//
// Contract
// - Every fallible core call returns a `Status` marked [[nodiscard]]. `Status::ok` is zero.
// - Invariant violations (programming errors, never bad data) go through PLIANT_ASSERT, whose
//   handler the integrator replaces with set_assert_handler(). The default handler calls
//   std::abort(). Bad *data* is never asserted on: it yields a Status or a counted drop.
// - Real-time safe: no allocation, no exceptions, no I/O.
#pragma once

#include <cstdint>

namespace pliant {

enum class [[nodiscard]] Status : std::uint8_t{
    ok = 0,
    invalid_argument,          ///< a size, index or option is out of its documented range
    capacity_exceeded,         ///< the caller's memory block is smaller than *_workspace_size()
    invalid_mass,              ///< a particle mass is not finite and > 0
    non_finite_input,          ///< NaN or infinity in positions, targets, forces or time step
    duplicate_rest_positions,  ///< two particles share a rest position (no spacing to build on)
    degenerate_cluster,        ///< a cluster has too few members to define a rotation
    no_free_particles,         ///< every particle is fixed or driven: nothing to simulate or fit
    no_observations,           ///< no usable observation of a free particle
    not_converged,             ///< an iteration hit its bound; the result is the last iterate
    not_initialized,           ///< the object was used before a successful init
};

/// Short, stable, human-readable name of a status ("ok", "invalid_mass", ...).
const char* status_name(Status status) noexcept;

/// Handler called by PLIANT_ASSERT on a violated invariant. It must not return normally in a
/// release controller build (reset, safe state); returning continues past the failed check.
using AssertHandler = void (*)(const char* expression, const char* file, int line);

/// Replaces the assert handler; nullptr restores the default (std::abort). Not thread-safe:
/// call once at start-up.
void set_assert_handler(AssertHandler handler) noexcept;

namespace detail {
void assert_failed(const char* expression, const char* file, int line) noexcept;
}  // namespace detail

}  // namespace pliant

#define PLIANT_ASSERT(expression)                                       \
  do {                                                                  \
    if (!(expression)) {                                                \
      ::pliant::detail::assert_failed(#expression, __FILE__, __LINE__); \
    }                                                                   \
  } while (false)
