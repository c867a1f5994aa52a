#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Build tools/bench/fw_proj_q for the Cortex-M0+ instruction set and run it under QEMU with exact instruction
# counting (-icount, as tools/firmware/run_fw.py). Prints the image's one line (on stdout). Needs arm-none-eabi-gcc and
# qemu-system-arm (tools/scripts/install_deps.sh). usage: run.sh [BUILD_DIR] (default build-fw/proj_q)
set -euo pipefail
root=$(cd "$(dirname "$0")/../../.." && pwd)
out=${1:-$root/build-fw/proj_q}
cmake -S "$root/tools/bench/fw_proj_q" -B "$out" -DCMAKE_TOOLCHAIN_FILE="$root/cmake/toolchains/arm-none-eabi.cmake" >/dev/null
cmake --build "$out" -j2 >/dev/null
timeout 600 qemu-system-arm -M mps2-an385 -icount shift=8 -display none -monitor none -kernel "$out/fw_proj_q.elf" \
    -semihosting-config enable=on,target=native -serial null 2>&1  # semihosting writes to stderr
