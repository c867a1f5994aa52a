# SPDX-License-Identifier: MIT
# Cross toolchain: Debian gcc-aarch64-linux-gnu + libc6-dev-arm64-cross, 64-bit Arm Linux (Raspberry Pi 4/5,
# Jetson and other Cortex-A boards running a glibc Linux). The C library and headers are searched in the
# cross sysroot only, so host packages (libpng, cJSON, Eigen) are not picked up: the host CLI then builds
# without them, as on a host that lacks them. With qemu-aarch64 (Debian qemu-user) installed, the built
# programs run under it: ctest and CMake's try_run use it as the emulator.
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)
set(LIDET_CROSS_SYSROOT /usr/aarch64-linux-gnu CACHE PATH "aarch64 glibc sysroot (libc6-dev-arm64-cross)")
find_program(CMAKE_C_COMPILER aarch64-linux-gnu-gcc REQUIRED)
find_program(CMAKE_AR aarch64-linux-gnu-ar)
find_program(CMAKE_NM aarch64-linux-gnu-nm)
find_program(CMAKE_RANLIB aarch64-linux-gnu-ranlib)
# C++ only when the cross g++ is there (no project target needs it; without it check_language(CXX) finds none
# instead of the host's compiler)
find_program(LIDET_CROSS_CXX aarch64-linux-gnu-g++)
if(LIDET_CROSS_CXX)
  set(CMAKE_CXX_COMPILER ${LIDET_CROSS_CXX})
else()
  set(CMAKE_CXX_COMPILER CMAKE_CXX_COMPILER-NOTFOUND)
endif()
find_program(LIDET_QEMU_AARCH64 qemu-aarch64)
if(LIDET_QEMU_AARCH64)
  set(CMAKE_CROSSCOMPILING_EMULATOR ${LIDET_QEMU_AARCH64} -L ${LIDET_CROSS_SYSROOT})
endif()
set(CMAKE_FIND_ROOT_PATH ${LIDET_CROSS_SYSROOT})
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)
