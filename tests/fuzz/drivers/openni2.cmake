# libFuzzer targets of drivers/openni2 (included by tests/fuzz/CMakeLists.txt when the driver is
# built). Both compile the driver's pure sources with the fuzzer and sanitizer instrumentation;
# neither links OpenNI2:
#   openni2_oni_fuzz    the .oni structural check (oni_file.cpp): every recording goes through
#                       it before OpenNI2's player parses it, so it is the gate to fuzz
#   openni2_depth_fuzz  depth frames as the driver sees them: arbitrary sizes, strides, scales,
#                       intrinsics and buffers into copy_depth_image and depth_to_points
set(openni2_dir ${pliant_root}/drivers/openni2)
set(openni2_fuzz_options -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer)
foreach(fuzzer openni2_oni_fuzz openni2_depth_fuzz)
  if(fuzzer STREQUAL "openni2_oni_fuzz")
    set(openni2_fuzz_source ${openni2_dir}/src/oni_file.cpp)
  else()
    set(openni2_fuzz_source ${openni2_dir}/src/depth_points.cpp)
  endif()
  add_executable(${fuzzer} drivers/${fuzzer}.cpp ${openni2_fuzz_source})
  target_include_directories(${fuzzer} PRIVATE ${openni2_dir}/include ${pliant_root}/hal/include)
  target_compile_options(${fuzzer} PRIVATE ${openni2_fuzz_options})
  target_link_options(${fuzzer} PRIVATE -fsanitize=fuzzer,address,undefined)
  pliant_set_warnings(${fuzzer})
endforeach()
