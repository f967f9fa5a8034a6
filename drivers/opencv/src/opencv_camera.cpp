// The OpenCV colour camera: a decoder (thread, or read() itself in stepped mode) fills a ring of
// converted frames; read() hands out views into it (contract in the public header).
#include "pliant/drivers/opencv/opencv_camera.hpp"

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <exception>
#include <limits>
#include <new>
#include <thread>
#include <utility>

#include <opencv2/core.hpp>

#include "convert.hpp"
#include "frame_ring.hpp"
#include "frame_source.hpp"
#include "pliant/drivers/opencv/image_files.hpp"

namespace pliant::drivers {

namespace {

using hal::HalStatus;
using opencv_detail::SourceStatus;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr int kMaxSide = 16384;
constexpr std::size_t kMaxRingBytes = std::size_t{1} << 30;
// A frame is due when its due time is at most this far after now (absorbs the rounding of
// k / fps against a clock advanced k times by 1 / fps).
constexpr double kDueTolerance_s = 1e-9;
constexpr auto kIdlePoll = std::chrono::milliseconds(2);
constexpr double kFirstFrameWait_s = 5.0;  // a non-blocking source's first frame, at configure

// Real time, for what the injected Clock cannot measure: the age of a grabbed frame (the grab
// thread must not read the Clock; see the header) and the real-time caps of blocking waits (a
// ManualClock does not move while its only thread is blocked here).
double steady_now_s() noexcept {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// Bumps a counter that only one thread writes but any thread may read.
void bump(std::atomic<std::uint64_t>& counter, std::uint64_t by = 1) noexcept {
  counter.store(counter.load(std::memory_order_relaxed) + by, std::memory_order_relaxed);
}

// The config check of configure; an empty string when the config is valid.
const char* config_problem(const OpenCvCameraConfig& c) noexcept {
  if (c.location.empty()) return "location is empty";
  if (c.width < 0 || c.width > kMaxSide || c.height < 0 || c.height > kMaxSide) return "width/height outside 0..16384";
  if (!(c.fps == 0 || opencv_files::valid_file_rate(c.fps))) return "fps outside [0, 1000]";
  if (c.first_index < -1) return "first_index below -1";
  if (c.ring_frames < 2 || c.ring_frames > 64) return "ring_frames outside 2..64";
  if (!(c.reconnect_interval_s > 0 && c.reconnect_interval_s <= 60)) return "reconnect_interval_s outside (0, 60]";
  if (c.source == OpenCvSource::v4l2_device && c.playback == OpenCvPlayback::stepped)
    return "stepped playback is for files; a device is always live";
  switch (c.format) {
    case hal::PixelFormat::mono8:
    case hal::PixelFormat::rgb8:
    case hal::PixelFormat::bgr8: break;
    default: return "unknown pixel format";
  }
  switch (c.source) {
    case OpenCvSource::v4l2_device:
    case OpenCvSource::video_file:
    case OpenCvSource::image_sequence: break;
    default: return "unknown source kind";
  }
  return "";
}

}  // namespace

const char* opencv_source_name(OpenCvSource source) noexcept {
  switch (source) {
    case OpenCvSource::v4l2_device: return "v4l2_device";
    case OpenCvSource::video_file: return "video_file";
    case OpenCvSource::image_sequence: return "image_sequence";
  }
  return "unknown";
}

struct OpenCvCamera::Impl {
  enum class Step : std::uint8_t { published, dropped, idle, ended, lost };

  Impl(std::shared_ptr<opencv_detail::SourceFactory> source_factory, const OpenCvCameraConfig& config)
      : factory(std::move(source_factory)),
        format(config.format),
        live(factory->live()),
        stepped(!live && config.playback == OpenCvPlayback::stepped),
        reconnect_interval_s(config.reconnect_interval_s) {}

  ~Impl() {
    quit.store(true, std::memory_order_relaxed);
    if (thread.joinable()) thread.join();
  }
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;

  // ---- fixed at configure
  std::shared_ptr<opencv_detail::SourceFactory> factory;
  hal::PixelFormat format;
  bool live;
  bool stepped;
  double reconnect_interval_s;
  int width = 0;
  int height = 0;
  int stride = 0;
  double first_media_s = 0;
  opencv_detail::FrameRing ring;

  // ---- producer side (decoder thread, or read() in stepped mode)
  std::unique_ptr<opencv_detail::FrameSource> source;
  cv::Mat image;
  cv::Mat scratch;
  std::uint64_t next_sequence = 1;
  std::uint64_t reopens_served = 0;  ///< reopen requests this thread has acted on
  std::thread thread;

  // ---- shared
  std::atomic<bool> quit{false};
  std::atomic<bool> streaming{false};  ///< devices: keep (number) grabbed frames
  std::atomic<bool> ended{false};
  std::atomic<bool> ended_early{false};
  std::atomic<bool> lost{false};
  std::atomic<std::uint64_t> decoded{0};
  std::atomic<std::uint64_t> decode_errors{0};
  std::atomic<std::uint64_t> size_mismatches{0};
  std::atomic<std::uint64_t> overruns{0};
  std::atomic<std::uint64_t> skipped{0};
  std::atomic<std::uint64_t> reconnect_attempts{0};
  std::atomic<std::uint64_t> reopened{0};
  // Devices: reopen attempts are timed by read() on the injected Clock and run by the grab
  // thread (which never reads the Clock): read() raises `reopen_requests`, the thread answers
  // by raising `reopens_done` to it once the attempt is over.
  std::atomic<std::uint64_t> reopen_requests{0};
  std::atomic<std::uint64_t> reopens_done{0};

  // ---- consumer side (the thread that drives the device)
  bool holding = false;  ///< the slot at the ring's tail was delivered by the last read
  bool anchored = false;
  double anchor_s = 0;  ///< clock time at which media time first_media_s is due
  double paused_at_s = kNaN;
  bool loss_noted = false;          ///< devices: read() saw the current loss
  double next_attempt_s = 0;        ///< devices: clock time from which read() asks for a reopen
  std::uint64_t reopens_asked = 0;  ///< devices: reopen_requests as this side last raised it

  std::size_t buffered() const noexcept {
    const std::uint64_t pending = ring.head() - ring.tail();
    return static_cast<std::size_t>(pending) - (holding ? 1u : 0u);
  }

  // Decodes one frame from the source into the ring (the ring must have room for files).
  Step produce_one() noexcept {
    double media_s = kNaN;
    SourceStatus status = SourceStatus::decode_error;
    try {
      status = source->next(image, media_s);
    } catch (...) {
      // A backend that throws mid-stream: a device counts as lost; a file is not read further.
      status = live ? SourceStatus::disconnected : SourceStatus::ended_early;
    }
    switch (status) {
      case SourceStatus::end:
      case SourceStatus::ended_early:
        if (live) return Step::lost;
        if (status == SourceStatus::ended_early) ended_early.store(true, std::memory_order_relaxed);
        ended.store(true, std::memory_order_release);
        return Step::ended;
      case SourceStatus::disconnected:
        if (!live) {
          ended_early.store(true, std::memory_order_relaxed);
          ended.store(true, std::memory_order_release);
          return Step::ended;
        }
        return Step::lost;
      case SourceStatus::decode_error:
        if (live && !streaming.load(std::memory_order_relaxed)) return Step::dropped;
        bump(decoded);
        bump(decode_errors);
        ++next_sequence;
        return Step::dropped;
      case SourceStatus::idle: return Step::idle;
      case SourceStatus::frame: break;
    }
    // Frames grabbed while inactive are discarded unnumbered.
    if (live && !streaming.load(std::memory_order_relaxed)) return Step::dropped;
    bump(decoded);
    const std::uint64_t sequence = next_sequence++;
    if (image.cols != width || image.rows != height) {
      bump(size_mismatches);
      return Step::dropped;
    }
    if (ring.full()) {
      bump(overruns);
      return Step::dropped;
    }
    bool converted = false;
    try {
      converted = opencv_detail::convert_into(image, format, ring.write_slot(), stride, scratch);
    } catch (...) {
      converted = false;
    }
    if (!converted) {
      bump(decode_errors);
      return Step::dropped;
    }
    opencv_detail::SlotMeta& meta = ring.write_meta();
    meta.sequence = sequence;
    meta.media_s = std::isfinite(media_s) ? media_s : 0.0;
    meta.grab_steady_s = steady_now_s();
    ring.publish();
    return Step::published;
  }

  void sleep_idle() const { std::this_thread::sleep_for(kIdlePoll); }

  // Devices (grab thread): one reopen attempt when read() asked for one, else a short sleep.
  void serve_reopen() {
    const std::uint64_t asked = reopen_requests.load(std::memory_order_acquire);
    if (asked == reopens_served) {
      sleep_idle();
      return;
    }
    reopens_served = asked;
    bump(reconnect_attempts);
    opencv_detail::OpenError error;
    try {
      source = factory->open(error);
    } catch (...) {
      source.reset();
    }
    if (source) {
      bump(reopened);
      lost.store(false, std::memory_order_release);
    }
    reopens_done.store(asked, std::memory_order_release);
  }

  // Devices (read(), the driving thread): paces reopen attempts on the injected Clock while the
  // device is lost. The first attempt is due reconnect_interval_s after the read that saw the
  // loss, each next one reconnect_interval_s after the read that asked for the previous one
  // (later while that attempt is still running).
  void pace_reopen(double now_s) noexcept {
    if (!loss_noted) {
      loss_noted = true;
      next_attempt_s = now_s + reconnect_interval_s;
      return;
    }
    if (now_s < next_attempt_s) return;
    if (reopens_done.load(std::memory_order_acquire) != reopens_asked) return;  // still running
    reopen_requests.store(++reopens_asked, std::memory_order_release);
    next_attempt_s = now_s + reconnect_interval_s;
  }

  void run() noexcept {
    try {
      while (!quit.load(std::memory_order_relaxed)) {
        if (live) {
          if (!source) {
            serve_reopen();
            continue;
          }
          const Step step = produce_one();
          if (step == Step::lost) {
            source.reset();
            lost.store(true, std::memory_order_release);
          } else if (step == Step::idle) {
            sleep_idle();
          }
          continue;
        }
        if (ended.load(std::memory_order_relaxed) || ring.full()) {
          sleep_idle();
          continue;
        }
        if (produce_one() == Step::idle) sleep_idle();
      }
    } catch (...) {
      // Only allocation in the reopen path can get here; stop decoding rather than terminate.
      if (live) lost.store(true, std::memory_order_release);
      ended_early.store(true, std::memory_order_relaxed);
      ended.store(true, std::memory_order_release);
    }
  }
};

OpenCvCamera::OpenCvCamera(const hal::Clock& clock, OpenCvCameraConfig config)
    : OpenCvCamera(clock, std::move(config), nullptr) {}

OpenCvCamera::OpenCvCamera(const hal::Clock& clock, OpenCvCameraConfig config,
                           std::shared_ptr<opencv_detail::SourceFactory> factory)
    : clock_(clock), config_(std::move(config)), factory_(std::move(factory)), media_time_s_(kNaN) {}

OpenCvCamera::~OpenCvCamera() = default;

int OpenCvCamera::width() const noexcept { return impl_ ? impl_->width : 0; }
int OpenCvCamera::height() const noexcept { return impl_ ? impl_->height : 0; }

OpenCvCameraStats OpenCvCamera::stats() const noexcept {
  OpenCvCameraStats s;
  if (!impl_) return s;
  const Impl& m = *impl_;
  s.decoded = m.decoded.load(std::memory_order_relaxed);
  s.decode_errors = m.decode_errors.load(std::memory_order_relaxed);
  s.size_mismatches = m.size_mismatches.load(std::memory_order_relaxed);
  s.overruns = m.overruns.load(std::memory_order_relaxed);
  s.skipped = m.skipped.load(std::memory_order_relaxed);
  s.reconnect_attempts = m.reconnect_attempts.load(std::memory_order_relaxed);
  s.reopened = m.reopened.load(std::memory_order_relaxed);
  s.end_of_stream = end_of_stream();
  s.ended_early = m.ended_early.load(std::memory_order_relaxed);
  s.device_lost = m.lost.load(std::memory_order_acquire);
  return s;
}

bool OpenCvCamera::end_of_stream() const noexcept {
  if (!impl_ || impl_->live) return false;
  // `ended` first: once set, head is final.
  if (!impl_->ended.load(std::memory_order_acquire)) return false;
  return impl_->buffered() == 0;
}

bool OpenCvCamera::wait_buffered(int frames, double timeout_s) const noexcept {
  if (!impl_ || impl_->stepped) return true;
  const std::size_t wanted = frames > 0 ? static_cast<std::size_t>(frames) : 0u;
  const double budget_s = std::isfinite(timeout_s) && timeout_s > 0 ? timeout_s : 0.0;
  const double deadline_s = clock_.now_s() + budget_s;
  const double real_deadline_s = steady_now_s() + budget_s;
  for (;;) {
    const bool done = impl_->ended.load(std::memory_order_acquire) || impl_->lost.load(std::memory_order_acquire);
    if (done || impl_->buffered() >= wanted) return true;
    if (clock_.now_s() >= deadline_s || steady_now_s() >= real_deadline_s) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
}

HalStatus OpenCvCamera::on_configure() {
  impl_.reset();
  last_error_.clear();
  media_time_s_ = kNaN;
  const char* problem = config_problem(config_);
  if (*problem != '\0') {
    last_error_ = problem;
    return HalStatus::invalid_argument;
  }
  try {
    std::shared_ptr<opencv_detail::SourceFactory> factory =
        factory_ ? factory_ : opencv_detail::make_opencv_source_factory(config_);
    auto impl = std::make_unique<Impl>(std::move(factory), config_);
    Impl& m = *impl;
    opencv_detail::OpenError error;
    m.source = m.factory->open(error);
    if (!m.source) {
      last_error_ = error.message.empty() ? "cannot open " + config_.location : error.message;
      return error.status == HalStatus::ok ? HalStatus::io_error : error.status;
    }
    // The first frame fixes the size of every slot.
    double media_s = kNaN;
    const double give_up_s = clock_.now_s() + kFirstFrameWait_s;
    const double real_give_up_s = steady_now_s() + kFirstFrameWait_s;
    SourceStatus first = m.source->next(m.image, media_s);
    while (first == SourceStatus::idle) {
      if (clock_.now_s() > give_up_s || steady_now_s() > real_give_up_s) {
        last_error_ = config_.location + ": no first frame within 5 s";
        return HalStatus::timeout;
      }
      std::this_thread::sleep_for(kIdlePoll);
      first = m.source->next(m.image, media_s);
    }
    if (first != SourceStatus::frame) {
      if (first == SourceStatus::disconnected) {
        last_error_ = config_.location + ": the device opened but delivered no frame";
        return HalStatus::disconnected;
      }
      last_error_ = config_.location +
                    (first == SourceStatus::decode_error ? ": the first frame cannot be decoded" : ": no frame at all");
      return HalStatus::io_error;
    }
    m.width = m.image.cols;
    m.height = m.image.rows;
    if (m.width < 1 || m.height < 1 || m.width > kMaxSide || m.height > kMaxSide) {
      last_error_ = config_.location + ": frame size outside 1..16384 px";
      return HalStatus::capacity_exceeded;
    }
    m.stride = m.width * hal::pixel_bytes(config_.format);
    const std::size_t slot_bytes = static_cast<std::size_t>(m.stride) * static_cast<std::size_t>(m.height);
    const auto slots = static_cast<std::size_t>(config_.ring_frames);
    if (slot_bytes > kMaxRingBytes / slots) {
      last_error_ = config_.location + ": ring of frames above 1 GiB (fewer ring_frames, or smaller frames)";
      return HalStatus::capacity_exceeded;
    }
    m.ring.allocate(slots, slot_bytes);
    if (!opencv_detail::convert_into(m.image, config_.format, m.ring.write_slot(), m.stride, m.scratch)) {
      last_error_ = config_.location + ": unsupported image type from the decoder";
      return HalStatus::io_error;
    }
    if (!m.live) {
      // Files: the first frame is frame 1 of the stream.
      m.first_media_s = std::isfinite(media_s) ? media_s : 0.0;
      opencv_detail::SlotMeta& meta = m.ring.write_meta();
      meta.sequence = m.next_sequence++;
      meta.media_s = m.first_media_s;
      meta.grab_steady_s = steady_now_s();
      m.ring.publish();
      bump(m.decoded);
    }
    // Devices: the first frame only sized the ring (it would be stale by start()).
    if (!m.stepped) m.thread = std::thread([&m] { m.run(); });
    impl_ = std::move(impl);
    return HalStatus::ok;
  } catch (const std::bad_alloc&) {
    last_error_ = config_.location + ": out of memory";
    return HalStatus::capacity_exceeded;
  } catch (const std::exception& e) {
    last_error_ = config_.location + ": " + e.what();
    return HalStatus::io_error;
  }
}

HalStatus OpenCvCamera::on_start() noexcept {
  Impl& m = *impl_;
  const double now = clock_.now_s();
  if (!m.anchored) {
    m.anchor_s = now;
    m.anchored = true;
  } else if (std::isfinite(m.paused_at_s) && now > m.paused_at_s) {
    m.anchor_s += now - m.paused_at_s;  // time spent stopped pauses the playback
  }
  m.paused_at_s = kNaN;
  if (m.live) {
    // Nothing grabbed before this start is delivered.
    m.ring.release_to(m.ring.head());
    m.streaming.store(true, std::memory_order_relaxed);
  }
  return HalStatus::ok;
}

HalStatus OpenCvCamera::on_stop() noexcept {
  Impl& m = *impl_;
  if (m.holding) {
    m.ring.release_to(m.ring.tail() + 1);
    m.holding = false;
  }
  m.paused_at_s = clock_.now_s();
  if (m.live) m.streaming.store(false, std::memory_order_relaxed);
  return HalStatus::ok;
}

HalStatus OpenCvCamera::on_cleanup() noexcept {
  impl_.reset();  // joins the decoder thread, closes the source, frees the ring
  return HalStatus::ok;
}

HalStatus OpenCvCamera::on_read(hal::ColorFrame& out) noexcept {
  Impl& m = *impl_;
  if (m.holding) {
    m.ring.release_to(m.ring.tail() + 1);
    m.holding = false;
  }
  std::uint64_t tail = m.ring.tail();
  std::uint64_t pick = tail;
  if (m.stepped) {
    // Deliver what configure decoded first, then decode on demand until a frame or the end.
    while (m.ring.head() == tail) {
      if (m.ended.load(std::memory_order_relaxed)) return HalStatus::no_data;
      if (m.produce_one() == Impl::Step::idle) return HalStatus::no_data;
    }
  } else if (m.live) {
    if (m.lost.load(std::memory_order_acquire)) {
      const std::uint64_t head = m.ring.head();
      bump(m.skipped, head - tail);
      m.ring.release_to(head);
      m.pace_reopen(clock_.now_s());
      return HalStatus::disconnected;
    }
    m.loss_noted = false;
    const std::uint64_t head = m.ring.head();
    if (head == tail) return HalStatus::no_data;
    pick = head - 1;  // the newest
  } else {
    const std::uint64_t head = m.ring.head();
    const double now = clock_.now_s();
    bool due = false;
    for (std::uint64_t i = tail; i < head; ++i) {
      if (m.anchor_s + (m.ring.read_meta(i).media_s - m.first_media_s) > now + kDueTolerance_s) break;
      pick = i;
      due = true;
    }
    if (!due) return HalStatus::no_data;
  }
  if (pick > tail) {
    bump(m.skipped, pick - tail);
    m.ring.release_to(pick);
  }
  m.holding = true;
  const opencv_detail::SlotMeta& meta = m.ring.read_meta(pick);
  out.header.sequence = meta.sequence;
  out.header.status_bits = 0;
  if (m.live) {
    const double age_s = steady_now_s() - meta.grab_steady_s;
    out.header.stamp_s = clock_.now_s() - (age_s > 0 ? age_s : 0.0);
    media_time_s_ = kNaN;
  } else {
    out.header.stamp_s = m.anchor_s + (meta.media_s - m.first_media_s);
    media_time_s_ = meta.media_s;
  }
  out.width = m.width;
  out.height = m.height;
  out.stride_bytes = m.stride;
  out.format = m.format;
  out.data = m.ring.read_slot(pick);
  return HalStatus::ok;
}

}  // namespace pliant::drivers
