// drivers/opencv internal: a single-producer single-consumer ring of fixed-size frame slots.
//
// The producer (the decoder thread, or read() itself in stepped mode) fills the slot at head()
// and publishes it; the consumer (read()) looks at the slots in [tail, head), keeps the one it
// delivered until its next read, and releases slots by advancing the tail. Indices count up
// forever (slot = index % slots). Storage is allocated once (allocate()); every other call is
// O(1), allocation-free and lock-free (two atomics).
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace pliant::drivers::opencv_detail {

struct SlotMeta {
  std::uint64_t sequence = 0;  ///< HAL sequence number of the frame
  double media_s = 0;          ///< media time (files), s
  double grab_steady_s = 0;    ///< steady_clock time of the grab (devices), s
};

class FrameRing {
 public:
  /// Sizes the ring (not concurrent with anything). Throws std::bad_alloc.
  void allocate(std::size_t slots, std::size_t slot_bytes) {
    storage_.assign(slots * slot_bytes, 0);
    meta_.assign(slots, SlotMeta{});
    slots_ = slots;
    slot_bytes_ = slot_bytes;
    head_.store(0, std::memory_order_relaxed);
    tail_.store(0, std::memory_order_relaxed);
  }
  void release_storage() noexcept {
    storage_ = std::vector<std::uint8_t>();
    meta_ = std::vector<SlotMeta>();
    slots_ = slot_bytes_ = 0;
  }
  std::size_t slots() const noexcept { return slots_; }

  // Producer side.
  bool full() const noexcept {
    return head_.load(std::memory_order_relaxed) - tail_.load(std::memory_order_acquire) >= slots_;
  }
  std::uint8_t* write_slot() noexcept { return slot(head_.load(std::memory_order_relaxed)); }
  SlotMeta& write_meta() noexcept { return meta_[head_.load(std::memory_order_relaxed) % slots_]; }
  void publish() noexcept { head_.store(head_.load(std::memory_order_relaxed) + 1, std::memory_order_release); }

  // Consumer side.
  std::uint64_t head() const noexcept { return head_.load(std::memory_order_acquire); }
  std::uint64_t tail() const noexcept { return tail_.load(std::memory_order_relaxed); }
  const std::uint8_t* read_slot(std::uint64_t index) const noexcept {
    return storage_.data() + (index % slots_) * slot_bytes_;
  }
  const SlotMeta& read_meta(std::uint64_t index) const noexcept { return meta_[index % slots_]; }
  /// Frees every slot before `index` (tail <= index <= head).
  void release_to(std::uint64_t index) noexcept { tail_.store(index, std::memory_order_release); }

 private:
  std::uint8_t* slot(std::uint64_t index) noexcept { return storage_.data() + (index % slots_) * slot_bytes_; }

  std::vector<std::uint8_t> storage_;
  std::vector<SlotMeta> meta_;
  std::size_t slots_ = 0;
  std::size_t slot_bytes_ = 0;
  std::atomic<std::uint64_t> head_{0};
  std::atomic<std::uint64_t> tail_{0};
};

}  // namespace pliant::drivers::opencv_detail
