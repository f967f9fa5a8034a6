# Cross build for 64-bit Arm Linux (Raspberry Pi 4/5, Jetson, i.MX 8 class robot controllers)
# with Debian's cross compiler; the test binaries run under qemu user-mode emulation.
#
#   cmake -S . -B build-aarch64 --toolchain toolchains/aarch64-linux-gnu.cmake \
#         -DPLIANT_BUILD_HOST=OFF -DPLIANT_BUILD_BENCHMARKS=OFF
#   cmake --build build-aarch64 -j"$(nproc)" && ctest --test-dir build-aarch64
#
# Needs the Debian packages g++-aarch64-linux-gnu (compiler and the aarch64 glibc/libstdc++ in
# /usr/aarch64-linux-gnu), qemu-user (qemu-aarch64) and googletest (sources in /usr/src/googletest,
# compiled for the target by tests/CMakeLists.txt because the host's libgtest is x86-64).
# Overridable: PLIANT_AARCH64_PREFIX (compiler prefix), PLIANT_AARCH64_SYSROOT (target libraries
# for qemu and find_library), PLIANT_QEMU_AARCH64 (the emulator). See toolchains/README.md.
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)

set(PLIANT_AARCH64_PREFIX "aarch64-linux-gnu-" CACHE STRING "Cross compiler prefix")
set(PLIANT_AARCH64_SYSROOT "/usr/aarch64-linux-gnu" CACHE PATH "aarch64 libraries (qemu -L, find_library root)")
set(PLIANT_QEMU_AARCH64 "qemu-aarch64" CACHE STRING "User-mode emulator that runs aarch64 binaries")

set(CMAKE_C_COMPILER "${PLIANT_AARCH64_PREFIX}gcc")
set(CMAKE_CXX_COMPILER "${PLIANT_AARCH64_PREFIX}g++")

# ctest, gtest_discover_tests and add_test(COMMAND <target>) run target binaries through this.
# -L points the emulated dynamic loader at the aarch64 glibc and libstdc++.
find_program(PLIANT_QEMU_AARCH64_PATH NAMES ${PLIANT_QEMU_AARCH64})
if(PLIANT_QEMU_AARCH64_PATH)
  set(CMAKE_CROSSCOMPILING_EMULATOR "${PLIANT_QEMU_AARCH64_PATH};-L;${PLIANT_AARCH64_SYSROOT}")
endif()

# Target libraries come only from the aarch64 tree. Headers and CMake package files may also come
# from the host: the only ones the cross build finds are Eigen's, which is header-only and
# architecture-independent (/usr/include/eigen3, /usr/share/eigen3/cmake). Programs (tools run at
# build time) are always the host's.
set(CMAKE_FIND_ROOT_PATH "${PLIANT_AARCH64_SYSROOT}")
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE BOTH)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE BOTH)
