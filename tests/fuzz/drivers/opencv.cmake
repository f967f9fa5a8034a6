# libFuzzer target over the OpenCV driver's image-sequence naming (included by
# tests/fuzz/CMakeLists.txt when pliant_driver_opencv exists). image_sequence.cpp is compiled in
# directly with the fuzzer and sanitizer instrumentation; it and its header (image_files.hpp, which
# includes the HAL's status.hpp) use no OpenCV header. (Image and video decoding is OpenCV's own
# code and is not fuzzed here.)
set(opencv_driver_root ${CMAKE_CURRENT_SOURCE_DIR}/../../drivers/opencv)
add_executable(opencv_sequence_fuzz
  ${CMAKE_CURRENT_SOURCE_DIR}/drivers/opencv_sequence_fuzz.cpp
  ${opencv_driver_root}/src/image_sequence.cpp)
target_include_directories(opencv_sequence_fuzz PRIVATE ${opencv_driver_root}/include ${pliant_root}/hal/include)
target_compile_options(opencv_sequence_fuzz PRIVATE
  -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer)
target_link_options(opencv_sequence_fuzz PRIVATE -fsanitize=fuzzer,address,undefined)
pliant_set_warnings(opencv_sequence_fuzz)
