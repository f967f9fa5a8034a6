# libFuzzer target over the libcamera driver's buffer handling (included by
# tests/fuzz/CMakeLists.txt when pliant_driver_libcamera exists): the pixel conversions and the
# frame pipeline, compiled in directly so that they carry the fuzzer and sanitizer
# instrumentation. Neither includes a libcamera header.
set(libcamera_driver_root ${CMAKE_CURRENT_SOURCE_DIR}/../../drivers/libcamera)
add_executable(libcamera_conversion_fuzz
  ${CMAKE_CURRENT_SOURCE_DIR}/drivers/libcamera_conversion_fuzz.cpp
  ${libcamera_driver_root}/src/pixel_conversion.cpp
  ${libcamera_driver_root}/src/frame_pipeline.cpp)
target_include_directories(libcamera_conversion_fuzz PRIVATE
  ${libcamera_driver_root}/src ${libcamera_driver_root}/include ${CMAKE_CURRENT_SOURCE_DIR}/../../hal/include)
target_compile_options(libcamera_conversion_fuzz PRIVATE
  -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer)
target_link_options(libcamera_conversion_fuzz PRIVATE -fsanitize=fuzzer,address,undefined)
pliant_set_warnings(libcamera_conversion_fuzz)
