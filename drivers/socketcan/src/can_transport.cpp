#include "pliant/drivers/socketcan/can_transport.hpp"

namespace pliant::drivers::socketcan {

const char* can_io_name(CanIo io) noexcept {
  switch (io) {
    case CanIo::ok: return "ok";
    case CanIo::empty: return "empty";
    case CanIo::busy: return "busy";
    case CanIo::malformed: return "malformed";
    case CanIo::disconnected: return "disconnected";
    case CanIo::io_error: return "io_error";
  }
  return "unknown";
}

hal::HalStatus CanTransport::set_receive_filter(const std::uint32_t* ids, std::size_t count) noexcept {
  if (count > kMaxCanFilterIds || (count > 0 && ids == nullptr)) return hal::HalStatus::invalid_argument;
  for (std::size_t i = 0; i < count; ++i) {
    if (ids[i] > kCanSffMask) return hal::HalStatus::invalid_argument;
  }
  for (std::size_t i = 0; i < count; ++i) filter_ids_[i] = ids[i];
  filter_count_ = count;
  return hal::HalStatus::ok;
}

}  // namespace pliant::drivers::socketcan
