# Bare-metal build for an Arm Cortex-M7 with the double-precision FPU (STM32F7/H7, i.MX RT1xxx
# class motor controllers), hard-float ABI, newlib-nano, no exceptions, no RTTI.
#
#   cmake -S examples/firmware -B build-cortex-m7 --toolchain toolchains/arm-none-eabi-cortex-m7.cmake
#   cmake --build build-cortex-m7 -j"$(nproc)"      # pliant_core, pliant_bridge, the example ELF
#
# The pliant project itself also configures with this file (PLIANT_BUILD_HOST, _TESTS and
# _BENCHMARKS OFF) and then builds the two static libraries a firmware links.
# Needs the Debian packages gcc-arm-none-eabi, libnewlib-arm-none-eabi and
# libstdc++-arm-none-eabi-newlib. What each flag is for: toolchains/README.md.
set(CMAKE_SYSTEM_NAME Generic)
set(CMAKE_SYSTEM_PROCESSOR arm)

set(PLIANT_ARM_PREFIX "arm-none-eabi-" CACHE STRING "Bare-metal Arm compiler prefix")
set(CMAKE_C_COMPILER "${PLIANT_ARM_PREFIX}gcc")
set(CMAKE_CXX_COMPILER "${PLIANT_ARM_PREFIX}g++")
set(CMAKE_ASM_COMPILER "${PLIANT_ARM_PREFIX}gcc")
set(CMAKE_OBJCOPY "${PLIANT_ARM_PREFIX}objcopy" CACHE FILEPATH "objcopy for the target")
set(CMAKE_SIZE "${PLIANT_ARM_PREFIX}size" CACHE FILEPATH "size for the target")

# There is no operating system to link a test executable against: CMake's compiler checks build
# a static library instead.
set(CMAKE_TRY_COMPILE_TARGET_TYPE STATIC_LIBRARY)

# CPU and ABI. fpv5-d16 is the M7's double-precision FPU, so pliant's double build runs in
# hardware too; hard float passes float/double in FPU registers (every object must agree).
# nano.specs selects newlib-nano (small stdio/malloc; also at compile time, for its headers).
# -ffunction-sections/-fdata-sections with --gc-sections drop every unused function and object.
set(PLIANT_CORTEX_M7_FLAGS
    "-mcpu=cortex-m7 -mthumb -mfpu=fpv5-d16 -mfloat-abi=hard --specs=nano.specs -ffunction-sections -fdata-sections")
set(CMAKE_C_FLAGS_INIT "${PLIANT_CORTEX_M7_FLAGS}")
set(CMAKE_ASM_FLAGS_INIT "${PLIANT_CORTEX_M7_FLAGS}")
# No exceptions or RTTI anywhere in the image (pliant's real-time code never needs them and the
# unwinder costs flash); function-local statics need no guard (initialised before the control
# loop starts, from one thread: no __cxa_guard_* calls).
set(CMAKE_CXX_FLAGS_INIT "${PLIANT_CORTEX_M7_FLAGS} -fno-exceptions -fno-rtti -fno-threadsafe-statics")
set(CMAKE_EXE_LINKER_FLAGS_INIT "-Wl,--gc-sections")

# Target libraries only from the newlib tree. Headers and CMake package files may also come from
# the host: the only package the build looks for is Eigen, header-only and CPU-independent
# (/usr/include/eigen3, /usr/share/eigen3/cmake). Programs are the host's.
set(CMAKE_FIND_ROOT_PATH "/usr/lib/arm-none-eabi")
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE BOTH)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE BOTH)
