#include "pliant/drivers/modbus/modbus_crc.hpp"

namespace pliant::drivers::modbus {

std::uint16_t modbus_crc16(const std::uint8_t* data, std::size_t size) noexcept {
  std::uint16_t crc = 0xffffu;
  for (std::size_t i = 0; i < size; ++i) {
    crc = static_cast<std::uint16_t>(crc ^ data[i]);
    for (int bit = 0; bit < 8; ++bit) {
      const bool lsb = (crc & 1u) != 0;
      crc = static_cast<std::uint16_t>(crc >> 1);
      if (lsb) crc = static_cast<std::uint16_t>(crc ^ 0xa001u);
    }
  }
  return crc;
}

void append_modbus_crc16(std::uint8_t* frame, std::size_t size) noexcept {
  const std::uint16_t crc = modbus_crc16(frame, size);
  frame[size] = static_cast<std::uint8_t>(crc & 0xffu);
  frame[size + 1] = static_cast<std::uint8_t>(crc >> 8);
}

bool check_modbus_crc16(const std::uint8_t* frame, std::size_t size) noexcept {
  if (size < 3) return false;
  const std::uint16_t crc = modbus_crc16(frame, size - 2);
  return frame[size - 2] == (crc & 0xffu) && frame[size - 1] == (crc >> 8);
}

}  // namespace pliant::drivers::modbus
