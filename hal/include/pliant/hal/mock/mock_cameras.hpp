// pliant hal mocks: synthetic colour and depth cameras (no plant needed).
//
// Colour: a moving diagonal gradient, value (x + 2 y + 3 k + 85 c) mod 256 for pixel (x, y),
//   channel c, frame k, plus uniform noise in [0, noise_levels) so that no two live frames are
//   identical. Depth: a plane plane_depth_m away tilted by tilt_m_per_px along x, with a bump
//   (bump_height_m, Gaussian, sigma = width / 8) that moves one pixel per frame, in millimetres
//   (depth_scale_m 1e-3), plus uniform noise of noise_mm; pinhole intrinsics from fov_x_deg.
// A new frame every period_s, available latency_s after capture; buffers sized at configure,
// frame data valid until the next read or stop.
// Faults: every common kind; nan is unsupported for the colour camera (no NaN in bytes) and
//   makes every depth pixel 0 (no measurement); fault_bits sets `value` (default
//   kFrameDeviceFault).
// Real-time safety: read is O(pixels), allocation-free, noexcept.
#pragma once

#include <cstdint>
#include <random>
#include <vector>

#include "pliant/hal/camera.hpp"
#include "pliant/hal/clock.hpp"
#include "pliant/hal/mock/mock_stream.hpp"

namespace pliant::hal {

struct MockColorCameraConfig {
  int width = 64, height = 48;  ///< 1..4096
  PixelFormat format = PixelFormat::rgb8;
  double period_s = 1.0 / 30;
  double latency_s = 0;
  int noise_levels = 4;  ///< 1..256 (1: no noise)
  std::uint32_t fault_bits = kFrameDeviceFault;
  std::uint64_t seed = 4;
};

struct MockDepthCameraConfig {
  int width = 64, height = 48;  ///< 1..4096
  double period_s = 1.0 / 30;
  double latency_s = 0;
  double plane_depth_m = 0.6;  ///< (0, 65]
  double tilt_m_per_px = 5e-4;
  double bump_height_m = 0.05;
  double noise_mm = 2;    ///< >= 0
  double fov_x_deg = 58;  ///< (0, 180)
  std::uint32_t fault_bits = kFrameDeviceFault;
  std::uint64_t seed = 5;
};

class MockColorCamera final : public ColorCamera {
 public:
  explicit MockColorCamera(const Clock& clock, const MockColorCameraConfig& config = {}) noexcept
      : clock_(clock), config_(config) {}
  HalStatus set_fault_schedule(const FaultSchedule& schedule) noexcept { return stream_.set_schedule(schedule); }
  HalStatus add_fault(const FaultEvent& event) noexcept { return stream_.add_fault(event); }
  const FaultCounters& fault_counters() const noexcept { return stream_.fault_counters(); }

 protected:
  HalStatus on_configure() override;
  HalStatus on_start() noexcept override;
  HalStatus on_read(ColorFrame& out) noexcept override;

 private:
  const Clock& clock_;
  MockColorCameraConfig config_;
  MockStream stream_;
  std::mt19937_64 rng_;
  int stride_ = 0;
  std::vector<std::uint8_t> image_;
  SampleHeader last_header_;
  bool has_last_ = false;
};

class MockDepthCamera final : public DepthCamera {
 public:
  explicit MockDepthCamera(const Clock& clock, const MockDepthCameraConfig& config = {}) noexcept
      : clock_(clock), config_(config) {}
  HalStatus set_fault_schedule(const FaultSchedule& schedule) noexcept { return stream_.set_schedule(schedule); }
  HalStatus add_fault(const FaultEvent& event) noexcept { return stream_.add_fault(event); }
  const FaultCounters& fault_counters() const noexcept { return stream_.fault_counters(); }

 protected:
  HalStatus on_configure() override;
  HalStatus on_start() noexcept override;
  HalStatus on_read(DepthFrame& out) noexcept override;

 private:
  const Clock& clock_;
  MockDepthCameraConfig config_;
  MockStream stream_;
  std::mt19937_64 rng_;
  std::vector<std::uint16_t> image_;
  SampleHeader last_header_;
  bool has_last_ = false;
};

}  // namespace pliant::hal
