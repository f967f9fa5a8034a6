# libFuzzer target over the depth front end's readers (tests/fuzz/vision/depth_fuzz.cpp): the PNG
# decoder and the point-cloud conversion, the frame-list parser, and the intrinsics / pose /
# region texts, compiled in from host/vision/depth/src with the fuzzer and sanitizer
# instrumentation. Included from tests/fuzz/CMakeLists.txt (the fuzz build has no host library).
find_package(PNG REQUIRED)
find_package(Eigen3 3.3 REQUIRED NO_MODULE)
set(pliant_depth_src ${CMAKE_CURRENT_LIST_DIR}/../../../host/vision/depth/src)
add_executable(vision_depth_fuzz
  ${CMAKE_CURRENT_LIST_DIR}/depth_fuzz.cpp
  ${pliant_depth_src}/depth_png.cpp
  ${pliant_depth_src}/depth_image.cpp
  ${pliant_depth_src}/depth_cloud.cpp
  ${pliant_depth_src}/depth_list.cpp
  ${pliant_depth_src}/depth_text.cpp
)
target_include_directories(vision_depth_fuzz PRIVATE
  ${CMAKE_CURRENT_LIST_DIR}/../../../host/vision/depth/include
  ${CMAKE_CURRENT_LIST_DIR}/../../../hal/include)
target_link_libraries(vision_depth_fuzz PRIVATE PNG::PNG Eigen3::Eigen)
# Lets the decoder skip chunk CRCs in this build only, so that mutations reach the image data.
target_compile_definitions(vision_depth_fuzz PRIVATE FUZZING_BUILD_MODE_UNSAFE_FOR_PRODUCTION)
target_compile_options(vision_depth_fuzz PRIVATE
  -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer)
target_link_options(vision_depth_fuzz PRIVATE -fsanitize=fuzzer,address,undefined)
pliant_set_warnings(vision_depth_fuzz)
