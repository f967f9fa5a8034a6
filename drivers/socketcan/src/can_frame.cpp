#include "pliant/drivers/socketcan/can_frame.hpp"

#include <cstring>

namespace pliant::drivers::socketcan {

CanFrame make_standard_frame(std::uint32_t id11, const std::uint8_t* payload, std::uint8_t dlc) noexcept {
  CanFrame f;
  f.id = id11 & kCanSffMask;
  f.dlc = dlc > kCanMaxDlc ? kCanMaxDlc : dlc;
  if (payload != nullptr && f.dlc > 0) std::memcpy(f.data, payload, f.dlc);
  return f;
}

float load_be_f32(const std::uint8_t* p) noexcept {
  const std::uint32_t bits = load_be_u32(p);
  float v = 0;
  static_assert(sizeof v == sizeof bits, "binary32");
  std::memcpy(&v, &bits, sizeof v);
  return v;
}

void store_be_f32(std::uint8_t* p, float v) noexcept {
  std::uint32_t bits = 0;
  std::memcpy(&bits, &v, sizeof bits);
  store_be_u32(p, bits);
}

}  // namespace pliant::drivers::socketcan
