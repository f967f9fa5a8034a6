// pliant hal mocks: scripted faults on any real camera's frames (a video file, an image
// sequence or an .oni recording played by drivers/opencv or drivers/openni2, or a live device).
//
// FaultyColorCamera and FaultyDepthCamera wrap another camera of their kind (the "inner" one,
// owned by the caller, which must outlive the wrapper) and apply a FaultSchedule
// (fault_schedule.hpp; scripts: fault_script.hpp, devices "color" and "depth") to what it
// delivers, with the kinds' meanings of the mocks:
//   read faults, at the call's time on `clock` (disconnect, then timeout): the wrapper returns
//     the status without reading the inner camera, so a real-time source keeps playing and the
//     frames due meanwhile are lost, as with a live camera that went away;
//   sample faults, at the frame's capture stamp: drop (the frame is never delivered; its
//     sequence number becomes a gap), freeze_data (the previous delivered frame's pixels, bit
//     for bit, under the new header), freeze_stamp (the previous delivered frame, its stamp
//     included, under the new sequence number), nan (depth only: every pixel 0, no
//     measurement), stamp_jump (stamp + value s, default +0.5), fault_bits (status word |=
//     value, default kFrameDeviceFault).
// Unsupported (refused when set): bus_off and occlude for both, nan for colour.
// Lifecycle calls are forwarded to the inner camera; counters() are the wrapper's own (what the
// consumer saw), the inner camera keeps its own.
//
// Memory: two frame buffers of max_frame_bytes each, allocated at configure (the previous
// frame, kept for the freeze kinds, and the frame delivered when a fault changes the pixels).
// A frame larger than that is delivered untouched by pixel faults and counted in
// oversized_frames. Real-time safety: read is O(pixels) (one copy of each frame),
// allocation-free, noexcept; the frame it delivers is valid until the next read or stop.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "pliant/hal/camera.hpp"
#include "pliant/hal/clock.hpp"
#include "pliant/hal/mock/fault_schedule.hpp"

namespace pliant::hal {

/// Frame buffer size of the wrappers unless configured: a 1920 x 1080 RGB frame.
inline constexpr std::size_t kFaultyCameraDefaultFrameBytes = std::size_t{1920} * 1080 * 3;

/// A camera of kind Camera (ColorCamera or DepthCamera) whose frames (Frame, pixels of
/// Element) get the faults of a schedule restricted to Supported kinds. Use the aliases below.
template <class Camera, class Frame, class Element, std::uint32_t Supported>
class FaultyCamera final : public Camera {
 public:
  FaultyCamera(Camera& inner, const Clock& clock, std::size_t max_frame_bytes = kFaultyCameraDefaultFrameBytes) noexcept
      : inner_(inner), clock_(clock), max_frame_bytes_(max_frame_bytes) {}
  /// unsupported when the schedule uses a kind outside Supported (nothing changed).
  HalStatus set_fault_schedule(const FaultSchedule& schedule) noexcept;
  const FaultCounters& fault_counters() const noexcept { return injected_; }
  std::uint64_t oversized_frames() const noexcept { return oversized_; }

 protected:
  HalStatus on_configure() override;
  HalStatus on_start() noexcept override { return inner_.start(); }
  HalStatus on_stop() noexcept override { return inner_.stop(); }
  HalStatus on_cleanup() noexcept override { return inner_.cleanup(); }
  HalStatus on_read(Frame& out) noexcept override;

 private:
  Camera& inner_;
  const Clock& clock_;
  std::size_t max_frame_bytes_;
  FaultSchedule schedule_;
  FaultCounters injected_;
  std::uint64_t oversized_ = 0;
  std::vector<Element> previous_, delivered_;
  Frame last_;  ///< the previous delivered frame (data in previous_)
  bool has_last_ = false;
};

using FaultyColorCamera = FaultyCamera<ColorCamera, ColorFrame, std::uint8_t, kColorCameraFaults>;
using FaultyDepthCamera = FaultyCamera<DepthCamera, DepthFrame, std::uint16_t, kDepthCameraFaults>;
extern template class FaultyCamera<ColorCamera, ColorFrame, std::uint8_t, kColorCameraFaults>;
extern template class FaultyCamera<DepthCamera, DepthFrame, std::uint16_t, kDepthCameraFaults>;

}  // namespace pliant::hal
