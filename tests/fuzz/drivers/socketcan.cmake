# libFuzzer targets of drivers/socketcan (included by tests/fuzz/CMakeLists.txt when the driver
# is built): the pure decoders, and the two sensors' read path on a scripted bus. The driver and
# hal sources are compiled in with the fuzzer and sanitizer instrumentation.
set(socketcan_dir ${pliant_root}/drivers/socketcan)
set(socketcan_fuzz_options -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer)

add_executable(socketcan_decoder_fuzz
  drivers/socketcan_decoder_fuzz.cpp
  ${socketcan_dir}/src/can_frame.cpp
  ${socketcan_dir}/src/can_error.cpp
  ${socketcan_dir}/src/ati_netcanoem_protocol.cpp
  ${socketcan_dir}/src/robotous_rft_protocol.cpp
)
target_include_directories(socketcan_decoder_fuzz PRIVATE ${socketcan_dir}/include ${pliant_root}/hal/include)
target_compile_options(socketcan_decoder_fuzz PRIVATE ${socketcan_fuzz_options})
target_link_options(socketcan_decoder_fuzz PRIVATE -fsanitize=fuzzer,address,undefined)
pliant_set_warnings(socketcan_decoder_fuzz)

add_executable(socketcan_device_fuzz
  drivers/socketcan_device_fuzz.cpp
  ${socketcan_dir}/src/can_frame.cpp
  ${socketcan_dir}/src/can_error.cpp
  ${socketcan_dir}/src/can_transport.cpp
  ${socketcan_dir}/src/can_link.cpp
  ${socketcan_dir}/src/ati_netcanoem_protocol.cpp
  ${socketcan_dir}/src/ati_netcanoem_sensor.cpp
  ${socketcan_dir}/src/robotous_rft_protocol.cpp
  ${socketcan_dir}/src/robotous_rft_sensor.cpp
  ${pliant_root}/hal/src/status.cpp
  ${pliant_root}/hal/src/clock.cpp
  ${pliant_root}/hal/src/device.cpp
  ${pliant_root}/hal/src/reads.cpp
)
target_include_directories(socketcan_device_fuzz PRIVATE ${socketcan_dir}/include ${pliant_root}/hal/include)
target_compile_options(socketcan_device_fuzz PRIVATE ${socketcan_fuzz_options})
target_link_options(socketcan_device_fuzz PRIVATE -fsanitize=fuzzer,address,undefined)
pliant_set_warnings(socketcan_device_fuzz)
