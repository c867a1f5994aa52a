# SPDX-License-Identifier: MIT
# Cross toolchain for the bare-metal aarch64 firmware image (ports/aarch64, board virt-aarch64: QEMU's Arm `virt`
# machine with a Cortex-A72): Debian's gcc-aarch64-linux-gnu, the GNU/Linux cross compiler that the aarch64 Linux
# build uses too (cmake/toolchains/aarch64-linux-gnu.cmake), here without its C library: the image is linked with
# -nostdlib and carries the few C library functions it needs (ports/aarch64/virt_libc.c). -mcpu and the link flags
# come from the board (ports/firmware/CMakeLists.txt, LIDET_FW_BOARD).
set(CMAKE_SYSTEM_NAME Generic)
set(CMAKE_SYSTEM_PROCESSOR aarch64)
find_program(CMAKE_C_COMPILER aarch64-linux-gnu-gcc REQUIRED)
find_program(CMAKE_ASM_COMPILER aarch64-linux-gnu-gcc REQUIRED)
find_program(CMAKE_OBJCOPY aarch64-linux-gnu-objcopy)
find_program(CMAKE_SIZE aarch64-linux-gnu-size)
set(CMAKE_TRY_COMPILE_TARGET_TYPE STATIC_LIBRARY)
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
