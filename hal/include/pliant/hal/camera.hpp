// pliant hal: colour and depth cameras, and the particle observer (the tracked points a
// camera pipeline yields per frame).
//
// Frames are views: their data pointers point into the device's buffers, valid until the next
// read() or stop() of that device. Copy what must outlive that. Stamps are capture times on
// the device's clock.
// read() returns ok with a new frame, no_data when none arrived since the last read, or a
//   transport error (disconnected, timeout, io_error).
// Real-time safety: read is bounded, non-blocking, allocation-free (buffers are sized at
//   configure), noexcept.
#pragma once

#include <cstdint>
#include <limits>

#include "pliant/hal/device.hpp"

namespace pliant::hal {

/// Status bits of frames (all three kinds).
inline constexpr std::uint32_t kFrameDeviceFault = 1u << 0;  ///< the device marks the frame unusable
inline constexpr std::uint32_t kFramePartial = 1u << 1;      ///< part of the frame is missing (e.g. occlusion)
/// The bits that mean a fault (GraspGuardConfig::camera_fault_mask for a frame's own bits).
inline constexpr std::uint32_t kFrameFaultMask = kFrameDeviceFault;

enum class PixelFormat : std::uint8_t { mono8, rgb8, bgr8 };

/// Bytes per pixel of a format (1 or 3).
constexpr int pixel_bytes(PixelFormat format) noexcept { return format == PixelFormat::mono8 ? 1 : 3; }

struct ColorFrame {
  SampleHeader header;
  int width = 0;         ///< pixels
  int height = 0;        ///< pixels
  int stride_bytes = 0;  ///< bytes from one row to the next, >= width * pixel_bytes(format)
  PixelFormat format = PixelFormat::rgb8;
  const std::uint8_t* data = nullptr;  ///< height * stride_bytes bytes, row-major, top row first
};

struct DepthFrame {
  SampleHeader header;
  int width = 0;
  int height = 0;
  int stride_bytes = 0;                 ///< >= 2 * width
  double depth_scale_m = 1e-3;          ///< metres per unit (1e-3: millimetres, OpenNI2's DEPTH_1_MM)
  const std::uint16_t* data = nullptr;  ///< depth along the optical axis; 0 = no measurement
  /// Pinhole intrinsics, px; NaN when the device does not report them.
  double fx = std::numeric_limits<double>::quiet_NaN();
  double fy = std::numeric_limits<double>::quiet_NaN();
  double cx = std::numeric_limits<double>::quiet_NaN();
  double cy = std::numeric_limits<double>::quiet_NaN();
};

/// One frame of particle observations: the tracked points of an object in the camera's
/// (world) frame, m. Particle i of every frame is the same material point.
struct ParticleFrame {
  SampleHeader header;
  int dimension = 3;  ///< 2 or 3
  int particle_count = 0;
  /// [particle_count * dimension], particle-major; a particle with any non-finite coordinate
  /// is unobserved in this frame.
  const double* positions = nullptr;
  int observed_count = 0;  ///< particles with finite coordinates
};

class ColorCamera : public Device {
 public:
  HalStatus read(ColorFrame& out) noexcept;

 protected:
  ColorCamera() noexcept : Device(kFrameFaultMask) {}
  virtual HalStatus on_read(ColorFrame& out) noexcept = 0;
};

class DepthCamera : public Device {
 public:
  HalStatus read(DepthFrame& out) noexcept;

 protected:
  DepthCamera() noexcept : Device(kFrameFaultMask) {}
  virtual HalStatus on_read(DepthFrame& out) noexcept = 0;
};

/// A source of particle observations per camera frame (a tracker front end, or a mock).
class ParticleObserver : public Device {
 public:
  HalStatus read(ParticleFrame& out) noexcept;

 protected:
  ParticleObserver() noexcept : Device(kFrameFaultMask) {}
  virtual HalStatus on_read(ParticleFrame& out) noexcept = 0;
};

}  // namespace pliant::hal
