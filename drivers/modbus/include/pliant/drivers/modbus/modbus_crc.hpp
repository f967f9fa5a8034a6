// pliant modbus driver: the Modbus RTU CRC-16, shared by the RTU frames this driver builds
// itself (the FT 300 stream start request) and the FT 300 stream frames (docs/drivers/modbus.md).
//
// CRC-16/MODBUS: reflected polynomial 0xA001 (0x8005), initial value 0xFFFF, no final XOR.
// On the wire the CRC follows the covered bytes low byte first. Check value: the CRC of the
// ASCII bytes "123456789" is 0x4B37.
// Pure: no I/O, no allocation, noexcept, O(size). Thread-safe (no state).
#pragma once

#include <cstddef>
#include <cstdint>

namespace pliant::drivers::modbus {

/// CRC-16/MODBUS of `size` bytes at `data` (`data` may be null when size is 0).
std::uint16_t modbus_crc16(const std::uint8_t* data, std::size_t size) noexcept;

/// Appends the CRC of `size` bytes at `frame` to frame[size], frame[size + 1] (low byte
/// first). `frame` must have room for size + 2 bytes.
void append_modbus_crc16(std::uint8_t* frame, std::size_t size) noexcept;

/// True when the last two of `size` bytes (size >= 3) are the CRC of the bytes before them.
bool check_modbus_crc16(const std::uint8_t* frame, std::size_t size) noexcept;

}  // namespace pliant::drivers::modbus
