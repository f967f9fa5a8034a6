#include "pliant/hal/mock/mock_cameras.hpp"

#include <algorithm>
#include <cmath>

#include "sample_faults.hpp"

namespace pliant::hal {
namespace {

using detail::SampleFate;

constexpr double kPi = 3.14159265358979323846;

// A frame's fate under its sample faults and its header (unset when dropped); the caller renders
// new pixels for a fresh frame and keeps the previous ones otherwise.
SampleFate frame_header(MockStream& stream, const ActiveFaults& f, double stamp, std::uint64_t sequence, bool has_last,
                        const SampleHeader& last, std::uint32_t default_bits, SampleHeader& header) noexcept {
  const SampleFate fate = detail::sample_fate(f, has_last, stream);
  if (fate == SampleFate::dropped) return fate;
  if (fate == SampleFate::repeat_previous) {
    header = last;
  } else {
    header.status_bits = fate == SampleFate::previous_values ? last.status_bits : 0u;
    header.stamp_s = stamp;
    detail::apply_stamp_and_status_faults(f, default_bits, stream, header.stamp_s, header.status_bits);
  }
  header.sequence = sequence;
  return fate;
}

bool valid_size(int width, int height) { return width >= 1 && width <= 4096 && height >= 1 && height <= 4096; }

}  // namespace

// --- colour -------------------------------------------------------------------------------------

HalStatus MockColorCamera::on_configure() {
  const MockColorCameraConfig& c = config_;
  if (!valid_size(c.width, c.height) || c.noise_levels < 1 || c.noise_levels > 256 ||
      (c.format != PixelFormat::mono8 && c.format != PixelFormat::rgb8 && c.format != PixelFormat::bgr8)) {
    return HalStatus::invalid_argument;
  }
  const HalStatus s = stream_.configure(c.period_s, c.latency_s, kColorCameraFaults);
  if (s != HalStatus::ok) return s;
  stream_.clear_fault_counters();
  stride_ = c.width * pixel_bytes(c.format);
  image_.assign(static_cast<std::size_t>(stride_) * static_cast<std::size_t>(c.height), 0);
  rng_.seed(c.seed);
  has_last_ = false;
  return HalStatus::ok;
}

HalStatus MockColorCamera::on_start() noexcept {
  stream_.start(clock_.now_s());
  return HalStatus::ok;
}

HalStatus MockColorCamera::on_read(ColorFrame& out) noexcept {
  const double now = clock_.now_s();
  const HalStatus link = stream_.read_fault(now);
  if (link != HalStatus::ok) return link;
  std::uint64_t index = 0, sequence = 0;
  double stamp = 0;
  if (!stream_.take(now, index, stamp, sequence)) return HalStatus::no_data;
  SampleHeader header;
  const SampleFate fate = frame_header(stream_, stream_.sample_faults(stamp), stamp, sequence, has_last_, last_header_,
                                       config_.fault_bits, header);
  if (fate == SampleFate::dropped) return HalStatus::no_data;
  if (fate == SampleFate::fresh) {
    const int channels = pixel_bytes(config_.format);
    const auto levels = static_cast<std::uint64_t>(config_.noise_levels);
    for (int y = 0; y < config_.height; ++y) {
      std::uint8_t* row = image_.data() + static_cast<std::size_t>(y) * static_cast<std::size_t>(stride_);
      for (int x = 0; x < config_.width; ++x) {
        for (int ch = 0; ch < channels; ++ch) {
          const std::uint64_t base = static_cast<std::uint64_t>(x) + 2u * static_cast<std::uint64_t>(y) + 3u * index +
                                     85u * static_cast<std::uint64_t>(ch);
          row[x * channels + ch] = static_cast<std::uint8_t>((base + rng_() % levels) & 0xffu);
        }
      }
    }
  }
  last_header_ = header;
  has_last_ = true;
  out.header = header;
  out.width = config_.width;
  out.height = config_.height;
  out.stride_bytes = stride_;
  out.format = config_.format;
  out.data = image_.data();
  return HalStatus::ok;
}

// --- depth --------------------------------------------------------------------------------------

HalStatus MockDepthCamera::on_configure() {
  const MockDepthCameraConfig& c = config_;
  if (!valid_size(c.width, c.height) || !(c.plane_depth_m > 0 && c.plane_depth_m <= 65) ||
      !std::isfinite(c.tilt_m_per_px) || !std::isfinite(c.bump_height_m) ||
      !(std::isfinite(c.noise_mm) && c.noise_mm >= 0) || !(c.fov_x_deg > 0 && c.fov_x_deg < 180)) {
    return HalStatus::invalid_argument;
  }
  const HalStatus s = stream_.configure(c.period_s, c.latency_s, kDepthCameraFaults);
  if (s != HalStatus::ok) return s;
  stream_.clear_fault_counters();
  image_.assign(static_cast<std::size_t>(c.width) * static_cast<std::size_t>(c.height), 0);
  rng_.seed(c.seed);
  has_last_ = false;
  return HalStatus::ok;
}

HalStatus MockDepthCamera::on_start() noexcept {
  stream_.start(clock_.now_s());
  return HalStatus::ok;
}

HalStatus MockDepthCamera::on_read(DepthFrame& out) noexcept {
  const double now = clock_.now_s();
  const HalStatus link = stream_.read_fault(now);
  if (link != HalStatus::ok) return link;
  std::uint64_t index = 0, sequence = 0;
  double stamp = 0;
  if (!stream_.take(now, index, stamp, sequence)) return HalStatus::no_data;
  const ActiveFaults f = stream_.sample_faults(stamp);
  SampleHeader header;
  const SampleFate fate =
      frame_header(stream_, f, stamp, sequence, has_last_, last_header_, config_.fault_bits, header);
  if (fate == SampleFate::dropped) return HalStatus::no_data;
  const MockDepthCameraConfig& c = config_;
  if (fate == SampleFate::fresh) {
    const double sigma = c.width / 8.0;
    const double centre_x = static_cast<double>(index % static_cast<std::uint64_t>(c.width));
    const double centre_y = 0.5 * c.height;
    std::uniform_real_distribution<double> noise(-c.noise_mm, c.noise_mm);
    for (int y = 0; y < c.height; ++y) {
      for (int x = 0; x < c.width; ++x) {
        const double r2 = (x - centre_x) * (x - centre_x) + (y - centre_y) * (y - centre_y);
        const double depth_m =
            c.plane_depth_m + c.tilt_m_per_px * x - c.bump_height_m * std::exp(-r2 / (2 * sigma * sigma));
        const double mm = std::clamp(std::round(depth_m * 1000 + noise(rng_)), 1.0, 65535.0);
        image_[static_cast<std::size_t>(y) * static_cast<std::size_t>(c.width) + static_cast<std::size_t>(x)] =
            static_cast<std::uint16_t>(mm);
      }
    }
    if (detail::take_fault(f, FaultKind::nan, stream_)) std::fill(image_.begin(), image_.end(), std::uint16_t{0});
  }
  last_header_ = header;
  has_last_ = true;
  out.header = header;
  out.width = c.width;
  out.height = c.height;
  out.stride_bytes = 2 * c.width;
  out.depth_scale_m = 1e-3;
  out.data = image_.data();
  out.fx = out.fy = 0.5 * c.width / std::tan(0.5 * c.fov_x_deg * kPi / 180);
  out.cx = 0.5 * (c.width - 1);
  out.cy = 0.5 * (c.height - 1);
  return HalStatus::ok;
}

}  // namespace pliant::hal
