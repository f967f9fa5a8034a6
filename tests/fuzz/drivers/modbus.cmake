# libFuzzer targets over the modbus driver's pure decoders (included by tests/fuzz/CMakeLists.txt
# when pliant_driver_modbus exists). The codec sources are compiled in directly so that they carry
# the fuzzer and sanitizer instrumentation; they include no libmodbus header and need only the
# hal headers for declarations.
set(modbus_driver_root ${CMAKE_CURRENT_SOURCE_DIR}/../../drivers/modbus)
set(modbus_codec_sources
  ${modbus_driver_root}/src/modbus_crc.cpp
  ${modbus_driver_root}/src/robotiq_2f_codec.cpp
  ${modbus_driver_root}/src/ft300_codec.cpp)
foreach(fuzzer modbus_robotiq_fuzz modbus_ft300_stream_fuzz)
  add_executable(${fuzzer} ${CMAKE_CURRENT_SOURCE_DIR}/drivers/${fuzzer}.cpp ${modbus_codec_sources})
  target_include_directories(${fuzzer} PRIVATE
    ${modbus_driver_root}/include ${CMAKE_CURRENT_SOURCE_DIR}/../../hal/include)
  target_compile_options(${fuzzer} PRIVATE
    -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer)
  target_link_options(${fuzzer} PRIVATE -fsanitize=fuzzer,address,undefined)
  pliant_set_warnings(${fuzzer})
endforeach()
