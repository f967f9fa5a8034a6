# libFuzzer target over the webcam option parsers and grid seeding (webcam_options_fuzz.cpp).
# Included from tests/fuzz/CMakeLists.txt (clang, PLIANT_BUILD_HOST=OFF): the two sources are
# compiled in with the fuzzer and sanitizer instrumentation; OpenCV is the system library.
find_package(OpenCV QUIET COMPONENTS core imgproc imgcodecs)
if(OpenCV_FOUND)
  set(pliant_webcam_dir ${CMAKE_CURRENT_LIST_DIR}/../../../host/vision/webcam)
  add_executable(webcam_options_fuzz
    ${CMAKE_CURRENT_LIST_DIR}/webcam_options_fuzz.cpp
    ${pliant_webcam_dir}/src/particle_grid.cpp
    ${pliant_webcam_dir}/src/particle_roles.cpp
    ${pliant_webcam_dir}/src/dense_flow.cpp
  )
  target_include_directories(webcam_options_fuzz PRIVATE ${pliant_webcam_dir}/include)
  target_link_libraries(webcam_options_fuzz PRIVATE opencv_core opencv_imgproc opencv_imgcodecs opencv_video)
  target_compile_options(webcam_options_fuzz PRIVATE
    -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer)
  target_link_options(webcam_options_fuzz PRIVATE -fsanitize=fuzzer,address,undefined)
  pliant_set_warnings(webcam_options_fuzz)
  set(PLIANT_WEBCAM_FUZZ_BUILT 1 CACHE INTERNAL "webcam_options_fuzz is defined (for .ci/fuzz.d/webcam.sh)")
else()
  message(STATUS "webcam_options_fuzz: OpenCV not found, not built")
  set(PLIANT_WEBCAM_FUZZ_BUILT 0 CACHE INTERNAL "webcam_options_fuzz is defined (for .ci/fuzz.d/webcam.sh)")
endif()
