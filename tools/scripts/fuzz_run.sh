#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Runs every libFuzzer harness of a fuzz build (make fuzz): each for FUZZ_SECONDS seconds (or FUZZ_RUNS
# executions when set), FUZZ_JOBS harnesses at a time, new inputs kept in BUILD/fuzz-corpus/<harness>
# (the committed corpus and crash regressions of tests/fuzz are replayed first), crashes written to
# BUILD/fuzz-artifacts/. Prints one line per harness: executions, exec/s, coverage (edges), features,
# and the findings; exits 1 when a harness found a crash, a timeout or a leak.
# Usage: tools/scripts/fuzz_run.sh BUILD [harness ...]
set -uo pipefail
cd "$(dirname "$0")/../.."
BUILD=${1:?usage: fuzz_run.sh BUILD [harness ...]}
shift
SECONDS_EACH=${FUZZ_SECONDS:-60}
RUNS=${FUZZ_RUNS:-}
JOBS=${FUZZ_JOBS:-1}
NICE=${FUZZ_NICE:-0}
harnesses=("$@")
if [ ${#harnesses[@]} -eq 0 ]; then
  harnesses=(proj ground cluster proposal pointnet pn_check detector pointnet_q detector_q velodyne ouster track track_q)
fi
mkdir -p "$BUILD/fuzz-artifacts" "$BUILD/fuzz-logs"
run_one() {
  local h=$1 exe="$BUILD/tests/fuzz/fuzz_$1" limit
  [ -x "$exe" ] || { echo "fuzz_run: $exe missing (make fuzz builds it)"; return 1; }
  mkdir -p "$BUILD/fuzz-corpus/$h"
  if [ -n "$RUNS" ]; then limit="-runs=$RUNS"; else limit="-max_total_time=$SECONDS_EACH"; fi
  nice -n "$NICE" "$exe" "$limit" -max_len=8192 -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
    -artifact_prefix="$BUILD/fuzz-artifacts/${h}_" "$BUILD/fuzz-corpus/$h" \
    "tests/fuzz/corpus/$h" "tests/fuzz/regressions/$h" >"$BUILD/fuzz-logs/$h.log" 2>&1
  local rc=$? log="$BUILD/fuzz-logs/$h.log"
  local execs rate cov ft
  execs=$(grep -oE 'stat::number_of_executed_units: +[0-9]+' "$log" | awk '{print $2}')
  rate=$(grep -oE 'stat::average_exec_per_sec: +[0-9]+' "$log" | awk '{print $2}')
  cov=$(grep -E '^#[0-9]+' "$log" | tail -1 | grep -o 'cov: [0-9]*' | awk '{print $2}')
  ft=$(grep -E '^#[0-9]+' "$log" | tail -1 | grep -o 'ft: [0-9]*' | awk '{print $2}')
  if [ $rc -eq 0 ]; then
    echo "fuzz_$h: ${execs:-?} executions, ${rate:-?} exec/s, cov ${cov:-?}, ft ${ft:-?}, no finding"
  else
    echo "fuzz_$h: FINDING after ${execs:-?} executions (exit $rc): $(grep -m1 -E 'ERROR|invariant failed|runtime error' "$log")"
    grep -o "Test unit written to .*" "$log" | head -1
    return 1
  fi
}
fail=0
pids=()
for h in "${harnesses[@]}"; do
  run_one "$h" &
  pids+=($!)
  # a free slot as soon as any harness ends (not the oldest: a long one would hold the others back)
  while [ "$(jobs -rp | wc -l)" -ge "$JOBS" ]; do
    wait -n || fail=1
  done
done
for p in "${pids[@]}"; do wait "$p" || fail=1; done
exit $fail
