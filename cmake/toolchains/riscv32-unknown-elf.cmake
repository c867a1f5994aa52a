# SPDX-License-Identifier: MIT
# Cross toolchain: Debian gcc-riscv64-unknown-elf (multilib, rv32 included) + picolibc-riscv64-unknown-elf,
# bare metal. -march/-mabi come from the board (ports/firmware/CMakeLists.txt, LIDET_FW_BOARD).
set(CMAKE_SYSTEM_NAME Generic)
set(CMAKE_SYSTEM_PROCESSOR riscv32)
set(LIDET_FW_TRIPLE riscv64-unknown-elf)
find_program(CMAKE_C_COMPILER riscv64-unknown-elf-gcc REQUIRED)
find_program(CMAKE_ASM_COMPILER riscv64-unknown-elf-gcc REQUIRED)
find_program(CMAKE_OBJCOPY riscv64-unknown-elf-objcopy)
find_program(CMAKE_SIZE riscv64-unknown-elf-size)
set(CMAKE_TRY_COMPILE_TARGET_TYPE STATIC_LIBRARY)
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
