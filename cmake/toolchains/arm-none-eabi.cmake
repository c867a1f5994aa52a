# SPDX-License-Identifier: MIT
# Cross toolchain: GNU Arm Embedded (Debian gcc-arm-none-eabi + libnewlib-arm-none-eabi), bare metal.
# The core flags (-mcpu, -mfpu, -mfloat-abi) come from the board (ports/firmware/CMakeLists.txt,
# LIDET_FW_BOARD), not from here, so one toolchain file serves every Cortex-M.
set(CMAKE_SYSTEM_NAME Generic)
set(CMAKE_SYSTEM_PROCESSOR arm)
set(LIDET_FW_TRIPLE arm-none-eabi)
find_program(CMAKE_C_COMPILER arm-none-eabi-gcc REQUIRED)
find_program(CMAKE_ASM_COMPILER arm-none-eabi-gcc REQUIRED)
find_program(CMAKE_OBJCOPY arm-none-eabi-objcopy)
find_program(CMAKE_SIZE arm-none-eabi-size)
# no host executable can run: configure checks build static libraries only
set(CMAKE_TRY_COMPILE_TARGET_TYPE STATIC_LIBRARY)
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
