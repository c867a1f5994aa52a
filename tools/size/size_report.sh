#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Detector, workspace and stage sizes for the capacity configurations of docs/MEMORY.md, as markdown tables.
# Usage: tools/size/size_report.sh [CC]   (default cc; sizes are sizeof, so any C99 compiler for the
# target gives that target's figure; a 32-bit target differs only in the few pointer fields)
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
cc="${1:-cc}"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
# name rows cols points clusters detections refine-cells refine-points (the VLP-16 board's refinement caps:
# ports/firmware/config/vlp16/lidet_user_config.h)
configs=(
  "hdl64 64 2048 131072 1024 128 4096 4096"
  "vlp16 16 1800 30000 64 64 2048 2048"
  "os1-64 64 2048 131072 1024 128 4096 4096"
  "host-default 128 2048 262144 1024 128 4096 4096"
)
kib() { awk -v b="$1" 'BEGIN { printf "%.1f", b / 1024 }'; }
# sizeof for a 32-bit target (ILP32: the layout an arm-none-eabi build gets for these structs, which hold
# no 64-bit members), read from the symbol sizes of an object compiled with -m32; "n/a" without -m32.
# Prints "<workspace KiB> <detector KiB>".
size32() {
  printf '%s\n' '#include "lidet/lidet_detector.h"' 'char sz_ws[sizeof(lidet_workspace_t)];' \
    'char sz_det[sizeof(lidet_detector_t)];' > "$tmp/p32.c"
  if "$cc" -m32 -ffreestanding -std=c99 -c -I"$root/lib/include" "$@" "$tmp/p32.c" -o "$tmp/p32.o" 2>/dev/null; then
    nm -S -t d "$tmp/p32.o" | awk '$4 == "sz_ws" { w = $2 } $4 == "sz_det" { d = $2 }
                                  END { printf "%.1f %.1f", w / 1024, d / 1024 }'
  else
    echo "n/a n/a"
  fi
}
# the integer detector's sizeof for a 32-bit target, one pixel mode (-DLIDET_Q_PIXEL_XYZ=...): "<KiB>" or "n/a"
size32q() {
  printf '%s\n' '#include "lidet/lidet_detector_q.h"' 'char sz_q[sizeof(lidet_detector_q_t)];' > "$tmp/q32.c"
  if "$cc" -m32 -ffreestanding -std=c99 -c -I"$root/lib/include" "$@" "$tmp/q32.c" -o "$tmp/q32.o" 2>/dev/null; then
    nm -S -t d "$tmp/q32.o" | awk '$4 == "sz_q" { printf "%.1f KiB (%d B)", $2 / 1024, $2 }'
  else
    echo "n/a"
  fi
}
# the library's sources (lib/src/<stage>/*.c, the folders of cmake/lidet_sources.cmake) without the packet decoders
lib_sources=()
for f in "$root"/lib/src/*/*.c; do
  case "$f" in */lib/src/decode/*) ;; *) lib_sources+=("$f") ;; esac
done
ws_rows=()
det_rows=()
q_rows=()
for c in "${configs[@]}"; do
  read -r name rows cols pts cl det rcells rpts <<<"$c"
  caps=(-DLIDET_MAX_ROWS="$rows" -DLIDET_MAX_COLS="$cols" -DLIDET_MAX_POINTS="$pts" -DLIDET_MAX_CLUSTERS="$cl"
        -DLIDET_MAX_DETECTIONS="$det" -DLIDET_REFINE_MAX_CELLS="$rcells" -DLIDET_REFINE_MAX_POINTS="$rpts")
  "$cc" -std=c99 -O1 -I"$root/lib/include" -I"$root/lib/src" "${caps[@]}" "$here/size_report.c" "${lib_sources[@]}" \
        -lm -o "$tmp/sz"
  read -r ws32 det32 <<<"$(size32 "${caps[@]}")"
  declare -A v=()
  while read -r k n; do v[$k]=$n; done < <("$tmp/sz")
  states=$(( v[proj_state] + v[ground_state] + v[cluster_state] ))
  ws_rows+=("| $name ($rows x $cols, $pts, $cl) | $(kib $states) KiB | $(kib ${v[image]}) KiB | $(kib ${v[ground_mask]}) KiB | $(kib ${v[overlay]}) KiB ($(kib ${v[overlay_proj]}) / $(kib ${v[overlay_ground]}) / $(kib ${v[overlay_cluster]})) | **$(kib ${v[workspace]}) KiB** | $ws32 KiB | $(kib ${v[stages_standalone]}) KiB ($(kib ${v[proj_t]}) + $(kib ${v[ground_t]}) + $(kib ${v[cluster_t]})) |")
  det_rows+=("| $name ($rows x $cols, $pts, $cl, $det) | $(kib ${v[det_workspace]}) KiB | $(kib ${v[det_pn_scratch]}) KiB | $(kib ${v[det_pn_states]}) KiB | $(kib ${v[det_proposal]}) KiB | $(kib ${v[det_detections]}) KiB | $(kib ${v[det_rest]}) KiB | **$(kib ${v[detector]}) KiB** | **$det32 KiB** |")
  unset v
  for xyz in 1 0; do
    "$cc" -std=c99 -I"$root/lib/include" "${caps[@]}" -DLIDET_Q_PIXEL_XYZ=$xyz "$here/size_report_q.c" -o "$tmp/szq"
    declare -A q=()
    while read -r k n; do q[$k]=$n; done < <("$tmp/szq")
    pixel=$([ "$xyz" = 1 ] && echo "x, y, z, range (8 B)" || echo "range only (2 B)")
    q_rows+=("| $name ($rows x $cols, $pts, $cl, $det) | $pixel | $(kib ${q[q_states]}) KiB | $(kib ${q[q_image]}) KiB | $(kib ${q[q_mask]}) KiB | $(kib ${q[q_overlay]}) KiB ($(kib ${q[q_overlay_proj]}) / $(kib ${q[q_overlay_ground]}) / $(kib ${q[q_overlay_cluster]})) | $(kib ${q[q_pn_scratch]}) KiB | $(kib ${q[q_rest]}) KiB | **$(kib ${q[q_detector]}) KiB** | **$(size32q "${caps[@]}" -DLIDET_Q_PIXEL_XYZ=$xyz)** |")
    unset q
  done
done
echo "Workspace (lidet_workspace_sizes):"
echo
echo "| config (rows x cols, points, clusters) | proj+ground+cluster states | image x,y,z,range (+ R: 64-bit, > 65536 pixels) | ground mask | overlay (proj / ground / cluster) | **workspace** | workspace, 32-bit target | standalone stages (proj + ground + cluster) |"
echo "|---|---|---|---|---|---|---|---|"
printf '%s\n' "${ws_rows[@]}"
echo
echo "Detector (lidet_detector_bytes: the workspace and the rest of lidet_detector_t):"
echo
echo "| config (rows x cols, points, clusters, detections) | workspace | PointNet scratch | 2 PointNet states | proposal | detections | rest (cfg, candidate order, outcomes, stats) | **detector** | **detector, 32-bit target** |"
echo "|---|---|---|---|---|---|---|---|---|"
printf '%s\n' "${det_rows[@]}"
echo
echo "Integer detector (lidet_detector_q_bytes, both pixels: LIDET_Q_PIXEL_XYZ 1 and 0; range-only, the ground mask lives in the ground scratch):"
echo
echo "| config (rows x cols, points, clusters, detections) | pixel | proj+ground+cluster states | image | ground mask | overlay (proj / ground / cluster) | PointNet scratch | rest (cfg, PointNet states, proposal, detections, stats) | **integer detector** | **integer detector, 32-bit target** |"
echo "|---|---|---|---|---|---|---|---|---|---|"
printf '%s\n' "${q_rows[@]}"
