/* CRC-16/CCITT-FALSE, bitwise: the telemetry packets are at most 1 KiB, so a table buys little. */
#include "pliant_telemetry.h"
#include "telemetry_wire.h"

uint16_t pliant_tm_crc16_update(uint16_t crc, uint8_t byte) {
  /* In unsigned int, masked once at the end: no narrowing inside the loop. */
  unsigned int value = (unsigned int)crc ^ ((unsigned int)byte << 8);
  for (int bit = 0; bit < 8; ++bit) {
    value = (value & 0x8000u) != 0u ? ((value << 1) ^ 0x1021u) : (value << 1);
  }
  return (uint16_t)(value & 0xFFFFu);
}

uint16_t pliant_tm_crc16(const uint8_t* data, size_t size) {
  uint16_t crc = 0xFFFFu;
  for (size_t i = 0; i < size; ++i) crc = pliant_tm_crc16_update(crc, data[i]);
  return crc;
}
