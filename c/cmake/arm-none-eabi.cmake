# cmake/arm-none-eabi.cmake -- CMake toolchain file for Cortex-M parts with GCC's
# arm-none-eabi toolchain and newlib (Debian: gcc-arm-none-eabi, libnewlib-arm-none-eabi).
#
#     cmake -S c -B build-m4 -DCMAKE_TOOLCHAIN_FILE=cmake/arm-none-eabi.cmake \
#           -DSR_CPU=cortex-m4 -DSR_USE_FLOAT=ON -DSR_BUILD_TESTS=OFF
#     cmake -S c -B build-m7 -DCMAKE_TOOLCHAIN_FILE=cmake/arm-none-eabi.cmake \
#           -DSR_CPU=cortex-m7 -DSR_BUILD_TESTS=OFF
#
# SR_CPU picks the CPU and FPU flags: cortex-m4 (single-precision FPU fpv4-sp-d16: use it with
# SR_USE_FLOAT=ON; double would be emulated in software) or cortex-m7 (double-precision FPU
# fpv5-d16).  For another part set SR_CPU=custom and give the flags in SR_CPU_FLAGS.  The C
# tests need a start-up file and a linker script for the board (c/cross/), so build them with
# `make -C c cross-test` or turn them off here (SR_BUILD_TESTS=OFF).  Link your firmware with
# -lm; newlib's libm is a separate library.
set(CMAKE_SYSTEM_NAME Generic)
set(CMAKE_SYSTEM_PROCESSOR arm)

set(SR_CROSS_PREFIX "arm-none-eabi-" CACHE STRING "Prefix of the cross tools")
set(CMAKE_C_COMPILER ${SR_CROSS_PREFIX}gcc)
set(CMAKE_AR ${SR_CROSS_PREFIX}ar CACHE FILEPATH "Archiver")
set(CMAKE_RANLIB ${SR_CROSS_PREFIX}ranlib CACHE FILEPATH "Ranlib")

# No executable can be linked without a board's start-up code: test the compiler on a library.
set(CMAKE_TRY_COMPILE_TARGET_TYPE STATIC_LIBRARY)

set(SR_CPU "cortex-m4" CACHE STRING "Target CPU: cortex-m4, cortex-m7 or custom")
set_property(CACHE SR_CPU PROPERTY STRINGS cortex-m4 cortex-m7 custom)
if(SR_CPU STREQUAL "cortex-m4")
    set(SR_CPU_FLAGS "-mcpu=cortex-m4 -mthumb -mfpu=fpv4-sp-d16 -mfloat-abi=hard")
elseif(SR_CPU STREQUAL "cortex-m7")
    set(SR_CPU_FLAGS "-mcpu=cortex-m7 -mthumb -mfpu=fpv5-d16 -mfloat-abi=hard")
elseif(NOT SR_CPU STREQUAL "custom")
    message(FATAL_ERROR "SR_CPU must be cortex-m4, cortex-m7 or custom (with SR_CPU_FLAGS), not '${SR_CPU}'")
endif()
set(SR_CPU_FLAGS "${SR_CPU_FLAGS}" CACHE STRING "CPU and FPU flags of the target")
set(CMAKE_C_FLAGS_INIT "${SR_CPU_FLAGS}")
# Pass SR_CPU and SR_CPU_FLAGS on to CMake's compiler checks (try_compile).
list(APPEND CMAKE_TRY_COMPILE_PLATFORM_VARIABLES SR_CPU SR_CPU_FLAGS SR_CROSS_PREFIX)

# Look for programs on the host, for libraries and headers in the target's sysroot only.
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
