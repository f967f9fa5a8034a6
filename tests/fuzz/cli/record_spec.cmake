# libFuzzer target over the device specs of `pliant record` (tests/fuzz/cli/record_spec_fuzz.cpp):
# the parser's one source compiled in with the fuzzer and sanitizer instrumentation. Included from
# tests/fuzz/CMakeLists.txt; the smoke run is .ci/fuzz.d/record.sh.
set(pliant_root ${CMAKE_CURRENT_LIST_DIR}/../../..)
add_executable(record_spec_fuzz
  ${CMAKE_CURRENT_LIST_DIR}/record_spec_fuzz.cpp
  ${pliant_root}/host/cli/record_device_spec.cpp)
target_include_directories(record_spec_fuzz PRIVATE ${pliant_root}/host/cli)
target_compile_options(record_spec_fuzz PRIVATE
  -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer)
target_link_options(record_spec_fuzz PRIVATE -fsanitize=fuzzer,address,undefined)
pliant_set_warnings(record_spec_fuzz)
set(PLIANT_RECORD_SPEC_FUZZ_BUILT 1 CACHE INTERNAL "record_spec_fuzz defined (read by .ci/fuzz.d/record.sh)")
