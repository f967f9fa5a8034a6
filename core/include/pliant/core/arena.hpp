// Arena: carves typed arrays out of one caller-provided memory block, or only measures.
//
// The core never allocates. Objects that need arrays sized at init take an Arena and carve
// them out; the same code run over a measuring Arena (no block) yields the block size to ask
// the caller for. This is how every *_workspace_size() query is answered:
//
//   Arena measure;                   // measuring: hands out nothing, only counts bytes
//   layout(measure, config);         // returns capacity_exceeded, by design
//   std::size_t bytes = measure.required_bytes();
//   Arena arena(block, bytes);       // caller-owned block of that size
//   layout(arena, config);           // now every carve succeeds
//
// Every carve is aligned to kArenaAlignment, so fixed-size Eigen types are safe to store.
// Ownership: the arena never frees; the caller owns the block and keeps it alive for as long
// as any object carved from it. Real-time safe after init (carving is init-only by convention).
#pragma once

#include <cstddef>
#include <cstdint>
#include <new>

namespace pliant {

inline constexpr std::size_t kArenaAlignment = 64;

class Arena {
 public:
  /// Measuring arena: carve() returns nullptr but counts the bytes a real arena would need.
  Arena() noexcept = default;
  /// Arena over [block, block + size_bytes). `block` need not be aligned.
  Arena(void* block, std::size_t size_bytes) noexcept
      : base_(static_cast<std::uint8_t*>(block)), capacity_(size_bytes) {}

  /// Default-constructs `count` objects of T in the block and returns them, or nullptr when
  /// measuring or out of space (then exhausted() is true). count 0 returns nullptr.
  template <typename T>
  T* carve(std::size_t count) noexcept {
    if (count == 0) return nullptr;
    const std::size_t bytes = count * sizeof(T);
    // Worst-case padding is counted so the measured size suffices for any block address.
    const std::size_t worst = bytes + kArenaAlignment - 1;
    required_ += worst;
    if (base_ == nullptr) {
      exhausted_ = true;
      return nullptr;
    }
    const auto address = reinterpret_cast<std::uintptr_t>(base_ + used_);
    const std::size_t pad = (kArenaAlignment - address % kArenaAlignment) % kArenaAlignment;
    if (used_ + pad + bytes > capacity_) {
      exhausted_ = true;
      return nullptr;
    }
    T* out = reinterpret_cast<T*>(base_ + used_ + pad);
    used_ += pad + bytes;
    for (std::size_t i = 0; i < count; ++i) new (out + i) T();
    return out;
  }

  /// Bytes a block must have for every carve made so far to succeed, whatever its alignment.
  std::size_t required_bytes() const noexcept { return required_; }
  bool measuring() const noexcept { return base_ == nullptr; }
  /// True once any carve failed (always true for a measuring arena that carved something).
  bool exhausted() const noexcept { return exhausted_; }

 private:
  std::uint8_t* base_ = nullptr;
  std::size_t capacity_ = 0;
  std::size_t used_ = 0;
  std::size_t required_ = 0;
  bool exhausted_ = false;
};

}  // namespace pliant
