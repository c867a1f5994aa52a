#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The pictures of real packet captures in docs/DECODING.md: a real VLP-16 rotation and a real Ouster OS2-128 frame,
# decoded by lib/'s decoders (`lidet detect --pcap`), detected by the float detector, drawn by `lidet-viz bev`.
#
#     tools/scripts/capture_pictures.sh [PACKETS_DIR] [OUT_DIR]     # defaults: ../shared/data/packets docs/img
#
# Needs the host CLI (make build) and the Python tools (.venv, make deps). The captures are not part of the
# repository (../shared/data/packets/README.md: MIT, Apache-2.0 and BSD-3 test captures of open-source drivers);
# without them the script says so and exits 0, writing nothing.
set -euo pipefail
cd "$(dirname "$0")/../.."
PKT=${1:-../shared/data/packets}
OUT=${2:-docs/img}
LIDET=${LIDET:-build/ports/host/lidet}
PY=${PYTHON:-.venv/bin/python}
VLP=$PKT/velodyne/vlp16_dual.pcap
OS2=$PKT/ouster/OS-2-128-U1_v2.3.0_1024x10
if [ ! -f "$VLP" ] || [ ! -f "$OS2.pcap" ]; then
    echo "capture_pictures: no captures under $PKT: nothing drawn"
    exit 0
fi
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
mkdir -p "$OUT"

# VLP-16, dual return (both returns of each firing): the three complete rotations; scan 2 is nebula's reference
# rotation (docs/DECODING.md). An office, sensor at the vlp16 preset's 0.5 m (the floor is out of the beams' view)
"$LIDET" detect --pcap "$VLP" --save-scans "$TMP/v16" --out "$TMP/v16/det" >/dev/null
"$PY" -m lidet_tools.viz.cli bev "$TMP/v16/velodyne/000002.bin" --pred "$TMP/v16/det/000002.txt" \
    --range 10 --ring-step 2 \
    --title "real VLP-16 rotation (vlp16_dual.pcap, scan 2): lidet_velodyne + lidet detect" \
    --out "$OUT/capture_vlp16.png"

# Ouster OS2-128, RNG19_RFL8_SIG16_NIR16: one frame, the metadata's beam table; the mount height as
# `python -m lidet_tools.mount` estimates it from this frame (1.98 m; --ouster-meta assumes 1.0 m)
"$LIDET" detect --pcap "$OS2.pcap" --lidar ouster --ouster-meta "$OS2.json" --mount-height 1.98 \
    --save-scans "$TMP/os2" --out "$TMP/os2/det" >/dev/null
"$PY" -m lidet_tools.viz.cli bev "$TMP/os2/velodyne/000000.bin" --pred "$TMP/os2/det/000000.txt" \
    --range 40 \
    --title "real Ouster OS2-128 frame (RNG19 profile): lidet_ouster + lidet detect" \
    --out "$OUT/capture_os2_128.png"
echo "capture_pictures: $OUT/capture_vlp16.png $OUT/capture_os2_128.png"
