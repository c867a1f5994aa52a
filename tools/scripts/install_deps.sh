#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Installs what `make test` needs, idempotently: Debian packages (only the missing ones), the
# Unity test framework source (tools/scripts/fetch_unity.sh), and the Python venv from the pinned
# requirements. Safe to run again: every step checks first and does nothing when satisfied.
set -euo pipefail
cd "$(dirname "$0")/../.."

PKGS="cmake make gcc g++ libeigen3-dev python3 python3-venv ca-certificates"
# libFuzzer harnesses (tests/fuzz, make test-fuzz / make fuzz): clang with its compiler-rt (libFuzzer, ASan,
# UBSan runtimes); the host CLI's PNG output: libpng (ports/host/lidet_png.c)
PKGS="$PKGS clang libclang-rt-dev libpng-dev"
# the host CLI's sensor files (--sensor-file, --ouster-meta: ports/host/cli_sensor.c): cJSON
PKGS="$PKGS libcjson-dev"
# the host CLI's Velodyne calibrations (--velodyne-calib: ports/host/cli_velodyne_calib.c): libxml2 (db.xml / VeloView
# XML) and libyaml (velodyne_pointcloud's YAML)
PKGS="$PKGS libxml2-dev libyaml-dev"
# the host CLI's packet captures (lidet detect / track --pcap: ports/host/cli_pcap.c): libpcap
PKGS="$PKGS libpcap-dev"
# the formatting check of lib/ (ctest clang_format, .clang-format)
PKGS="$PKGS clang-format"
# Firmware images under QEMU (issue 17, tests/firmware.cmake): Arm and RISC-V cross compilers with their C
# libraries, and the two QEMU system emulators. ~1 min to install on a Debian 12 CI runner once the package
# lists are fresh (docs/benchmarks/firmware.md). LIDET_NO_FIRMWARE=1 leaves them out; the firmware tests then skip.
FW_PKGS="gcc-arm-none-eabi libnewlib-arm-none-eabi qemu-system-arm gcc-riscv64-unknown-elf picolibc-riscv64-unknown-elf qemu-system-misc"
if [ "${LIDET_NO_FIRMWARE:-0}" != 1 ]; then
  PKGS="$PKGS $FW_PKGS"
fi
# 64-bit Arm Linux (Raspberry Pi, Jetson; tests/aarch64.cmake): the aarch64 GNU/Linux cross compiler with its
# glibc, and QEMU's user-mode emulator (qemu-aarch64) that runs the cross-built unit tests and CLI. ~56 MB to
# download, seconds to install. LIDET_NO_AARCH64=1 leaves them out; the test aarch64_linux then skips.
A64_PKGS="gcc-aarch64-linux-gnu libc6-dev-arm64-cross qemu-user"
if [ "${LIDET_NO_AARCH64:-0}" != 1 ]; then
  PKGS="$PKGS $A64_PKGS"
fi
missing=""
for p in $PKGS; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
done
if [ -n "$missing" ]; then
  # python3/python3-venv are not needed when a usable python3 with venv is already on PATH (pyenv)
  if python3 -c 'import venv, ensurepip' 2>/dev/null; then
    missing=$(echo "$missing" | tr ' ' '\n' | grep -vx -e python3 -e python3-venv | tr '\n' ' ' || true)
  fi
fi
if [ -n "${missing// /}" ]; then
  echo "install_deps: installing Debian packages:$missing"
  SUDO=""
  if [ "$(id -u)" != 0 ]; then
    command -v sudo >/dev/null || { echo "install_deps: need root (or sudo) to apt-get install:$missing" >&2; exit 1; }
    SUDO=sudo
  fi
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -q
  $SUDO apt-get install -y -q --no-install-recommends $missing
fi

bash tools/scripts/fetch_unity.sh

VENV=${VENV:-.venv}
stamp="$VENV/.requirements.sha256"
want=$(cat requirements.txt pyproject.toml | sha256sum | cut -d' ' -f1)
if [ ! -x "$VENV/bin/python" ] || [ "$(cat "$stamp" 2>/dev/null)" != "$want" ]; then
  echo "install_deps: creating Python venv $VENV from requirements.txt"
  python3 -m venv "$VENV"
  "$VENV/bin/python" -m pip install -q --upgrade pip
  "$VENV/bin/python" -m pip install -q -r requirements.txt
  "$VENV/bin/python" -m pip install -q --no-deps -e .
  echo "$want" > "$stamp"
fi
