// Scripted faults on another camera's frames (faulty_cameras.hpp).
#include "pliant/hal/mock/faulty_cameras.hpp"

#include <cmath>
#include <cstring>

#include "sample_faults.hpp"

namespace pliant::hal {

using detail::SampleFate;

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
  detail::FaultCounterSink counter{injected_};
  if (detail::take_fault(f, FaultKind::drop, counter)) return HalStatus::no_data;  // its sequence number: a gap
  const std::size_t bytes = static_cast<std::size_t>(frame.height > 0 ? frame.height : 0) *
                            static_cast<std::size_t>(frame.stride_bytes > 0 ? frame.stride_bytes : 0);
  const std::size_t elements = bytes / sizeof(Element);
  const bool fits = frame.data != nullptr && elements <= delivered_.size();
  const bool pixel_fault = f.has(FaultKind::freeze_data) || f.has(FaultKind::freeze_stamp) || f.has(FaultKind::nan);
  if (!fits && pixel_fault) ++oversized_;

  Frame result = frame;
  // Only a frame that fits the buffers can be repeated or blanked. drop was taken above.
  const SampleFate fate = detail::sample_fate(f, fits && has_last_, counter);
  const bool from_previous = fate != SampleFate::fresh;
  if (fate == SampleFate::repeat_previous) {
    result = last_;
    result.header.sequence = frame.header.sequence;
  } else if (fate == SampleFate::previous_values) {
    result = last_;
    result.header = frame.header;
  } else if (fits && detail::take_fault(f, FaultKind::nan, counter)) {
    std::memset(delivered_.data(), 0, elements * sizeof(Element));
    result.data = delivered_.data();
  }
  // Header faults apply to every delivered frame, a repeated one included (the mocks' own
  // freeze_stamp repeats the header as it was).
  detail::apply_stamp_and_status_faults(f, kFrameDeviceFault, counter, result.header.stamp_s,
                                        result.header.status_bits);
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
