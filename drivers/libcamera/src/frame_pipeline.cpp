#include "frame_pipeline.hpp"

#include <time.h>

#include <algorithm>

namespace pliant::drivers::libcamera_detail {

namespace {

// A sensor timestamp older than this (or in the future) is not trusted: the completion time is
// used instead.
constexpr std::uint64_t kMaxPlausibleAge_ns = 5'000'000'000ull;

void bump(std::atomic<std::uint64_t>& counter) noexcept { counter.fetch_add(1, std::memory_order_relaxed); }

}  // namespace

std::uint64_t monotonic_now_ns() noexcept {
  timespec now{};
  ::clock_gettime(CLOCK_MONOTONIC, &now);
  return static_cast<std::uint64_t>(now.tv_sec) * 1'000'000'000ull + static_cast<std::uint64_t>(now.tv_nsec);
}

FramePipeline::FramePipeline(const StreamSetup& setup, hal::PixelFormat format, CaptureBackend& backend, NowNs now_ns)
    : setup_(setup), format_(format), backend_(backend), now_ns_(now_ns) {
  stride_ = static_cast<std::size_t>(setup.width) * static_cast<std::size_t>(hal::pixel_bytes(format));
  slot_bytes_ = stride_ * static_cast<std::size_t>(setup.height);
  storage_.assign(3 * slot_bytes_, 0);
}

void FramePipeline::begin() noexcept {
  // The producer is idle here (the backend is not started): a frame converted during the last
  // stop is not delivered, and numbering continues after the camera's own restart.
  middle_.store(middle_.load(std::memory_order_relaxed) & 3u, std::memory_order_relaxed);
  have_sequence_ = false;
  running_.store(true, std::memory_order_release);
}

void FramePipeline::end() noexcept { running_.store(false, std::memory_order_release); }

void FramePipeline::on_disconnected() noexcept { lost_.store(true, std::memory_order_release); }

bool FramePipeline::convert(const Completion& completion, std::uint8_t* out) noexcept {
  if (completion.buffer < 0 || completion.buffer >= setup_.buffer_count) return false;
  const BufferPlanes planes = backend_.buffer(completion.buffer);
  if (planes.count < 1) return false;
  RawImage image;
  image.format = setup_.format;
  image.width = setup_.width;
  image.height = setup_.height;
  image.matrix = setup_.matrix;
  image.full_range = setup_.full_range;
  image.stride[0] = image.stride[1] = setup_.stride;
  // What the camera wrote: bytes used when it says, never more than the mapping.
  const auto used = [&](int plane) {
    const std::size_t reported = completion.bytes_used[plane];
    return reported > 0 ? std::min(reported, planes.length[plane]) : planes.length[plane];
  };
  image.plane[0] = planes.data[0];
  image.plane_bytes[0] = used(0);
  if (raw_format_planes(setup_.format) == 2) {
    if (planes.count >= 2) {
      image.plane[1] = planes.data[1];
      image.plane_bytes[1] = used(1);
    } else {
      // One plane: the UV rows follow the Y rows.
      const std::size_t luma_bytes = setup_.stride * static_cast<std::size_t>(setup_.height);
      if (image.plane_bytes[0] < luma_bytes) return false;
      image.plane[1] = planes.data[0] + luma_bytes;
      image.plane_bytes[1] = image.plane_bytes[0] - luma_bytes;
      image.plane_bytes[0] = luma_bytes;
    }
  }
  return convert_raw(image, format_, out, stride_, slot_bytes_) == ConvertStatus::ok;
}

void FramePipeline::on_completion(const Completion& completion) noexcept {
  bump(completed_);
  if (completion.status == CompletionStatus::cancelled) {
    bump(cancelled_);
    return;  // stop() cancels what is queued; nothing to give back
  }
  // Every frame the camera finished takes its number, delivered or not.
  std::uint64_t sequence = last_sequence_ + 1;
  if (have_sequence_ && completion.sequence > last_camera_sequence_) {
    sequence = last_sequence_ + (completion.sequence - last_camera_sequence_);
  }
  have_sequence_ = true;
  last_camera_sequence_ = completion.sequence;
  last_sequence_ = sequence;

  if (completion.status == CompletionStatus::error) {
    bump(failed_);
  } else if (convert(completion, storage_.data() + back_ * slot_bytes_)) {
    const std::uint64_t now = now_ns_();
    const std::uint64_t stamp = completion.timestamp_ns;
    meta_[back_].sequence = sequence;
    meta_[back_].capture_ns = (stamp != 0 && stamp <= now && now - stamp <= kMaxPlausibleAge_ns) ? stamp : now;
    const unsigned previous = middle_.exchange(back_ | kFresh, std::memory_order_acq_rel);
    if ((previous & kFresh) != 0) bump(overwritten_);
    back_ = previous & 3u;
    bump(converted_);
  } else {
    bump(conversion_errors_);
  }
  if (running_.load(std::memory_order_acquire) && !backend_.requeue(completion.buffer)) bump(requeue_errors_);
}

hal::HalStatus FramePipeline::take(hal::ColorFrame& out, const hal::Clock& clock) noexcept {
  if (lost_.load(std::memory_order_acquire)) return hal::HalStatus::disconnected;
  if ((middle_.load(std::memory_order_acquire) & kFresh) == 0) return hal::HalStatus::no_data;
  const unsigned previous = middle_.exchange(front_, std::memory_order_acq_rel);
  front_ = previous & 3u;
  const SlotMeta& meta = meta_[front_];
  const std::uint64_t now = now_ns_();
  const double age_s = now > meta.capture_ns ? static_cast<double>(now - meta.capture_ns) * 1e-9 : 0.0;
  out.header.stamp_s = clock.now_s() - age_s;
  out.header.sequence = meta.sequence;
  out.header.status_bits = 0;
  out.width = setup_.width;
  out.height = setup_.height;
  out.stride_bytes = static_cast<int>(stride_);
  out.format = format_;
  out.data = storage_.data() + front_ * slot_bytes_;
  return hal::HalStatus::ok;
}

LibcameraCameraStats FramePipeline::stats() const noexcept {
  LibcameraCameraStats s;
  s.completed = completed_.load(std::memory_order_relaxed);
  s.converted = converted_.load(std::memory_order_relaxed);
  s.failed_buffers = failed_.load(std::memory_order_relaxed);
  s.cancelled = cancelled_.load(std::memory_order_relaxed);
  s.conversion_errors = conversion_errors_.load(std::memory_order_relaxed);
  s.overwritten = overwritten_.load(std::memory_order_relaxed);
  s.requeue_errors = requeue_errors_.load(std::memory_order_relaxed);
  s.lost = lost_.load(std::memory_order_acquire);
  return s;
}

}  // namespace pliant::drivers::libcamera_detail
