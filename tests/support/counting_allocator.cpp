// Replaceable global allocation functions that count calls while armed (see the header).
#include "counting_allocator.hpp"

#include <atomic>
#include <cerrno>
#include <cstdint>
#include <cstdlib>
#include <new>

// malloc interposition needs glibc's __libc_* entry points and must stay out of the way of
// sanitizers, which install their own malloc.
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define PLIANT_TEST_SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer) || __has_feature(memory_sanitizer)
#define PLIANT_TEST_SANITIZED 1
#endif
#endif
#if defined(__GLIBC__) && !defined(PLIANT_TEST_SANITIZED)
#define PLIANT_TEST_INTERPOSE_MALLOC 1
#endif

#if defined(PLIANT_TEST_INTERPOSE_MALLOC)
extern "C" {
void* __libc_malloc(std::size_t size) noexcept;
void* __libc_calloc(std::size_t count, std::size_t size) noexcept;
void* __libc_realloc(void* pointer, std::size_t size) noexcept;
void __libc_free(void* pointer) noexcept;
void* __libc_memalign(std::size_t alignment, std::size_t size) noexcept;
}
#endif

namespace pliant::test {
namespace detail {
void eigen_assertion_failed(const char* expression, const char* file, int line) noexcept;
}  // namespace detail

namespace {

std::atomic<bool> g_armed{false};
std::atomic<std::size_t> g_news{0};
std::atomic<std::size_t> g_deletes{0};
std::atomic<std::size_t> g_mallocs{0};
std::atomic<std::size_t> g_frees{0};
std::atomic<std::size_t> g_eigen_violations{0};
std::atomic<const char*> g_eigen_expression{nullptr};

bool armed() noexcept { return g_armed.load(std::memory_order_relaxed); }
void bump(std::atomic<std::size_t>& counter) noexcept {
  if (armed()) counter.fetch_add(1, std::memory_order_relaxed);
}

void* raw_malloc(std::size_t size) noexcept {
#if defined(PLIANT_TEST_INTERPOSE_MALLOC)
  return __libc_malloc(size);
#else
  return std::malloc(size);
#endif
}

void* raw_aligned(std::size_t alignment, std::size_t size) noexcept {
  if (alignment < sizeof(void*)) alignment = sizeof(void*);
#if defined(PLIANT_TEST_INTERPOSE_MALLOC)
  return __libc_memalign(alignment, size);
#else
  // C11 aligned_alloc wants a size that is a multiple of the alignment.
  const std::size_t rounded = (size + alignment - 1) / alignment * alignment;
  return std::aligned_alloc(alignment, rounded == 0 ? alignment : rounded);
#endif
}

void raw_free(void* pointer) noexcept {
#if defined(PLIANT_TEST_INTERPOSE_MALLOC)
  __libc_free(pointer);
#else
  std::free(pointer);
#endif
}

[[noreturn]] void out_of_memory() {
#if defined(__cpp_exceptions)
  throw std::bad_alloc();
#else
  std::abort();
#endif
}

void* counted_new(std::size_t size) noexcept {
  bump(g_news);
  return raw_malloc(size == 0 ? 1 : size);
}

void* counted_new_aligned(std::size_t size, std::align_val_t alignment) noexcept {
  bump(g_news);
  return raw_aligned(static_cast<std::size_t>(alignment), size == 0 ? 1 : size);
}

void counted_delete(void* pointer) noexcept {
  if (pointer == nullptr) return;
  bump(g_deletes);
  raw_free(pointer);
}

}  // namespace

bool malloc_interposed() noexcept {
#if defined(PLIANT_TEST_INTERPOSE_MALLOC)
  return true;
#else
  return false;
#endif
}

namespace detail {

void arm() noexcept {
  g_news.store(0, std::memory_order_relaxed);
  g_deletes.store(0, std::memory_order_relaxed);
  g_mallocs.store(0, std::memory_order_relaxed);
  g_frees.store(0, std::memory_order_relaxed);
  g_eigen_violations.store(0, std::memory_order_relaxed);
  g_eigen_expression.store(nullptr, std::memory_order_relaxed);
  // A second armed counter would reset the first one's counts: not nestable by design.
  const bool was_armed = g_armed.exchange(true, std::memory_order_seq_cst);
  if (was_armed) std::abort();
}

AllocationCounts snapshot() noexcept {
  AllocationCounts counts;
  counts.news = g_news.load(std::memory_order_relaxed);
  counts.deletes = g_deletes.load(std::memory_order_relaxed);
  counts.mallocs = g_mallocs.load(std::memory_order_relaxed);
  counts.frees = g_frees.load(std::memory_order_relaxed);
  counts.eigen_violations = g_eigen_violations.load(std::memory_order_relaxed);
  counts.eigen_expression = g_eigen_expression.load(std::memory_order_relaxed);
  return counts;
}

AllocationCounts disarm() noexcept {
  g_armed.store(false, std::memory_order_seq_cst);
  return snapshot();
}

// Called by the test translation unit's eigen_assert (see the header). Counting instead of
// aborting lets the test report which Eigen expression failed, in any build type. Counted
// whether or not armed: an Eigen assertion failure is a test failure either way.
void eigen_assertion_failed(const char* expression, const char* /*file*/, int /*line*/) noexcept {
  g_eigen_violations.fetch_add(1, std::memory_order_relaxed);
  const char* expected = nullptr;
  g_eigen_expression.compare_exchange_strong(expected, expression, std::memory_order_relaxed);
}

}  // namespace detail
}  // namespace pliant::test

// --- replaceable global allocation functions ([new.delete]) -----------------------------------

using pliant::test::counted_delete;

void* operator new(std::size_t size) {
  void* p = pliant::test::counted_new(size);
  if (p == nullptr) pliant::test::out_of_memory();
  return p;
}
void* operator new[](std::size_t size) {
  void* p = pliant::test::counted_new(size);
  if (p == nullptr) pliant::test::out_of_memory();
  return p;
}
void* operator new(std::size_t size, const std::nothrow_t&) noexcept { return pliant::test::counted_new(size); }
void* operator new[](std::size_t size, const std::nothrow_t&) noexcept { return pliant::test::counted_new(size); }

void* operator new(std::size_t size, std::align_val_t alignment) {
  void* p = pliant::test::counted_new_aligned(size, alignment);
  if (p == nullptr) pliant::test::out_of_memory();
  return p;
}
void* operator new[](std::size_t size, std::align_val_t alignment) {
  void* p = pliant::test::counted_new_aligned(size, alignment);
  if (p == nullptr) pliant::test::out_of_memory();
  return p;
}
void* operator new(std::size_t size, std::align_val_t alignment, const std::nothrow_t&) noexcept {
  return pliant::test::counted_new_aligned(size, alignment);
}
void* operator new[](std::size_t size, std::align_val_t alignment, const std::nothrow_t&) noexcept {
  return pliant::test::counted_new_aligned(size, alignment);
}

void operator delete(void* p) noexcept { counted_delete(p); }
void operator delete[](void* p) noexcept { counted_delete(p); }
void operator delete(void* p, std::size_t) noexcept { counted_delete(p); }
void operator delete[](void* p, std::size_t) noexcept { counted_delete(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { counted_delete(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { counted_delete(p); }
void operator delete(void* p, std::align_val_t) noexcept { counted_delete(p); }
void operator delete[](void* p, std::align_val_t) noexcept { counted_delete(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { counted_delete(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { counted_delete(p); }
void operator delete(void* p, std::align_val_t, const std::nothrow_t&) noexcept { counted_delete(p); }
void operator delete[](void* p, std::align_val_t, const std::nothrow_t&) noexcept { counted_delete(p); }

// --- C allocation functions (glibc, no sanitizer) ---------------------------------------------
// Interposed in the executable, so calls from every library (libstdc++, pliant::core's Eigen
// code) land here. All forward to glibc's own allocator, so memory stays interchangeable.

#if defined(PLIANT_TEST_INTERPOSE_MALLOC)
extern "C" {

void* malloc(std::size_t size) noexcept {
  pliant::test::bump(pliant::test::g_mallocs);
  return __libc_malloc(size);
}

void* calloc(std::size_t count, std::size_t size) noexcept {
  pliant::test::bump(pliant::test::g_mallocs);
  return __libc_calloc(count, size);
}

void* realloc(void* pointer, std::size_t size) noexcept {
  pliant::test::bump(pliant::test::g_mallocs);
  return __libc_realloc(pointer, size);
}

void free(void* pointer) noexcept {
  if (pointer == nullptr) return;
  pliant::test::bump(pliant::test::g_frees);
  __libc_free(pointer);
}

void* memalign(std::size_t alignment, std::size_t size) noexcept {
  pliant::test::bump(pliant::test::g_mallocs);
  return __libc_memalign(alignment, size);
}

void* aligned_alloc(std::size_t alignment, std::size_t size) noexcept {
  pliant::test::bump(pliant::test::g_mallocs);
  return __libc_memalign(alignment, size);
}

int posix_memalign(void** out, std::size_t alignment, std::size_t size) noexcept {
  pliant::test::bump(pliant::test::g_mallocs);
  if (alignment < sizeof(void*) || (alignment & (alignment - 1)) != 0) return EINVAL;
  void* p = __libc_memalign(alignment, size);
  if (p == nullptr) return ENOMEM;
  *out = p;
  return 0;
}

}  // extern "C"
#endif
