// Scripted faults on another camera's frames (faulty_cameras.hpp).
#include "pliant/hal/mock/faulty_cameras.hpp"

#include <cmath>
#include <cstring>

namespace pliant::hal {
namespace {

void count(FaultCounters& counters, FaultKind kind) noexcept { ++counters.injected[static_cast<int>(kind)]; }

}  // namespace

template <class Camera, class Frame, class Element, std::uint32_t Supported>
HalStatus FaultyCamera<Camera, Frame, Element, Supported>::set_fault_schedule(const FaultSchedule& schedule) noexcept {
  if ((schedule.kinds() & ~Supported) != 0) return HalStatus::unsupported;
  schedule_ = schedule;
  return HalStatus::ok;
}

template <class Camera, class Frame, class Element, std::uint32_t Supported>
HalStatus FaultyCamera<Camera, Frame, Element, Supported>::on_configure() {
  const HalStatus status = inner_.configure();
  if (status != HalStatus::ok) return status;
  previous_.assign(max_frame_bytes_ / sizeof(Element), 0);
  delivered_.assign(max_frame_bytes_ / sizeof(Element), 0);
  injected_ = FaultCounters{};
  oversized_ = 0;
  has_last_ = false;
  return HalStatus::ok;
}

template <class Camera, class Frame, class Element, std::uint32_t Supported>
HalStatus FaultyCamera<Camera, Frame, Element, Supported>::on_read(Frame& out) noexcept {
  const HalStatus fault = apply_read_fault(schedule_, clock_.now_s(), injected_);
  if (fault != HalStatus::ok) return fault;  // the inner camera is not read meanwhile
  Frame frame;
  const HalStatus status = inner_.read(frame);
  if (status != HalStatus::ok) return status;
  const ActiveFaults f = schedule_.active_at(frame.header.stamp_s);
  if (f.has(FaultKind::drop)) {
    count(injected_, FaultKind::drop);
    return HalStatus::no_data;  // its sequence number becomes a gap
  }
  const std::size_t bytes = static_cast<std::size_t>(frame.height > 0 ? frame.height : 0) *
                            static_cast<std::size_t>(frame.stride_bytes > 0 ? frame.stride_bytes : 0);
  const std::size_t elements = bytes / sizeof(Element);
  const bool fits = frame.data != nullptr && elements <= delivered_.size();
  const bool pixel_fault = f.has(FaultKind::freeze_data) || f.has(FaultKind::freeze_stamp) || f.has(FaultKind::nan);
  if (!fits && pixel_fault) ++oversized_;

  Frame result = frame;
  bool from_previous = false;
  if (fits && f.has(FaultKind::freeze_stamp) && has_last_) {
    count(injected_, FaultKind::freeze_stamp);
    result = last_;
    result.header.sequence = frame.header.sequence;
    from_previous = true;
  } else if (fits && f.has(FaultKind::freeze_data) && has_last_) {
    count(injected_, FaultKind::freeze_data);
    result = last_;
    result.header = frame.header;
    from_previous = true;
  } else if (fits && f.has(FaultKind::nan)) {
    count(injected_, FaultKind::nan);
    std::memset(delivered_.data(), 0, elements * sizeof(Element));
    result.data = delivered_.data();
  }
  if (f.has(FaultKind::stamp_jump)) {
    count(injected_, FaultKind::stamp_jump);
    const double v = f.value[static_cast<int>(FaultKind::stamp_jump)];
    result.header.stamp_s += std::isnan(v) ? 0.5 : v;
  }
  if (f.has(FaultKind::fault_bits)) {
    count(injected_, FaultKind::fault_bits);
    const double v = f.value[static_cast<int>(FaultKind::fault_bits)];
    result.header.status_bits |= std::isnan(v) ? kFrameDeviceFault : static_cast<std::uint32_t>(v);
  }
  // Keep what was delivered for the freeze kinds (only when the schedule has them).
  const bool freezes =
      (schedule_.kinds() & (fault_bit(FaultKind::freeze_data) | fault_bit(FaultKind::freeze_stamp))) != 0;
  if (freezes) {
    if (!fits) {
      has_last_ = false;
    } else if (!from_previous) {
      std::memcpy(previous_.data(), result.data, elements * sizeof(Element));
      last_ = result;
      last_.data = previous_.data();
      has_last_ = true;
    } else {
      last_.header = result.header;
    }
  }
  out = result;
  return HalStatus::ok;
}

template class FaultyCamera<ColorCamera, ColorFrame, std::uint8_t, kColorCameraFaults>;
template class FaultyCamera<DepthCamera, DepthFrame, std::uint16_t, kDepthCameraFaults>;

}  // namespace pliant::hal
