// Heap-allocation counting for tests that prove real-time code never touches the heap.
//
// counting_allocator.cpp replaces the global operator new / new[] / delete / delete[] (plain,
// sized, aligned and nothrow forms) with versions that count every call while a counter is
// armed. On glibc builds without AddressSanitizer it also interposes malloc, calloc, realloc,
// free, aligned_alloc, memalign and posix_memalign (forwarding to glibc's __libc_* entry
// points), so C-level allocations are caught too, including the ones Eigen would make inside
// an already compiled library such as pliant::core.
//
// Usage (link counting_allocator.cpp into the test executable):
//   pliant::test::AllocationCounter counter;   // arms counting
//   real_time_call();
//   const pliant::test::AllocationCounts counts = counter.stop();  // disarms
//   EXPECT_EQ(counts.total(), 0u);
// Run no gtest assertion while armed: a failing assertion allocates its message.
//
// Eigen: when the including translation unit defines EIGEN_RUNTIME_NO_MALLOC, the counter
// also calls Eigen::internal::set_is_malloc_allowed(false) while armed, and this header
// routes eigen_assert to a counting handler (so a forbidden Eigen allocation is counted even
// in NDEBUG builds, where Eigen's own assert is compiled out). Include this header before
// any Eigen header for that to take effect.
#pragma once

#include <cstddef>

#if defined(EIGEN_RUNTIME_NO_MALLOC)
#if defined(EIGEN_CORE_H) || defined(EIGEN_CORE_MODULE_H)
#error "include counting_allocator.hpp before any Eigen header"
#endif
#if !defined(eigen_assert)
namespace pliant::test::detail {
void eigen_assertion_failed(const char* expression, const char* file, int line) noexcept;
}  // namespace pliant::test::detail
#define eigen_assert(x)                                                       \
  do {                                                                        \
    if (!static_cast<bool>(x)) {                                              \
      ::pliant::test::detail::eigen_assertion_failed(#x, __FILE__, __LINE__); \
    }                                                                         \
  } while (false)
#endif
#include <Eigen/Core>
#endif

namespace pliant::test {

struct AllocationCounts {
  std::size_t news = 0;                    ///< operator new / new[] calls (any form)
  std::size_t deletes = 0;                 ///< operator delete / delete[] calls on non-null pointers
  std::size_t mallocs = 0;                 ///< malloc, calloc, realloc, aligned_alloc, memalign, posix_memalign
  std::size_t frees = 0;                   ///< free on non-null pointers
  std::size_t eigen_violations = 0;        ///< failed eigen_assert (e.g. a forbidden Eigen heap allocation)
  const char* eigen_expression = nullptr;  ///< the first failed eigen_assert, for the report
  /// Every heap event: a real-time call must report 0.
  std::size_t total() const noexcept { return news + deletes + mallocs + frees + eigen_violations; }
};

/// True when malloc-family calls are intercepted in this build (glibc, no sanitizer).
bool malloc_interposed() noexcept;

namespace detail {
void arm() noexcept;
AllocationCounts disarm() noexcept;
AllocationCounts snapshot() noexcept;
}  // namespace detail

/// Arms counting on construction; stop() (or the destructor) disarms. Not nestable.
class AllocationCounter {
 public:
  AllocationCounter() noexcept {
#if defined(EIGEN_RUNTIME_NO_MALLOC)
    Eigen::internal::set_is_malloc_allowed(false);
#endif
    detail::arm();
  }
  ~AllocationCounter() { (void)stop(); }
  AllocationCounter(const AllocationCounter&) = delete;
  AllocationCounter& operator=(const AllocationCounter&) = delete;

  /// Counts so far, still armed.
  AllocationCounts counts() const noexcept { return armed_ ? detail::snapshot() : final_; }

  /// Disarms and returns the counts; further calls return the same counts.
  AllocationCounts stop() noexcept {
    if (armed_) {
      final_ = detail::disarm();
      armed_ = false;
#if defined(EIGEN_RUNTIME_NO_MALLOC)
      Eigen::internal::set_is_malloc_allowed(true);
#endif
    }
    return final_;
  }

 private:
  bool armed_ = true;
  AllocationCounts final_;
};

}  // namespace pliant::test
