# pliant_telemetry.h: the telemetry codec (docs/telemetry.md), C99, no heap.
target_sources(pliant_bridge PRIVATE
  ${CMAKE_CURRENT_SOURCE_DIR}/src/telemetry_crc.c
  ${CMAKE_CURRENT_SOURCE_DIR}/src/telemetry_cobs.c
  ${CMAKE_CURRENT_SOURCE_DIR}/src/telemetry_encode.c
  ${CMAKE_CURRENT_SOURCE_DIR}/src/telemetry_packet.c
  ${CMAKE_CURRENT_SOURCE_DIR}/src/telemetry_payload.c
  ${CMAKE_CURRENT_SOURCE_DIR}/src/telemetry_decoder.c)
