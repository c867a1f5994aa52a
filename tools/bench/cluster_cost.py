# SPDX-License-Identifier: MIT
"""Issue 15's time bound in exact counts: the clustering stage's instructions per scan (valgrind callgrind,
inclusive cost of lidet_cluster_run_buffers, `lidet cluster --repeat 1`) with today's defaults against the
clustering before issue 15 (no proposal refinement; on <= 16 beams also the 16-beam values of then: max_steps 4,
rescue_gap_m 0.8, join_gap_m 0.5), on the scans bench_cluster.py caches in data/ (simulated default and crowd
scenes). CPU-time ratios on a shared 2-core machine scatter by +-10 % from run to run; instruction counts do not.

    python tools/bench/cluster_cost.py [--build build] [--scans 10]
"""
from __future__ import annotations

import argparse
import os
import pathlib
import re
import subprocess
import tempfile

ROOT = pathlib.Path(__file__).resolve().parents[2]
BEFORE = {"vlp16": ["split_people=0", "join_cars=0", "max_steps=4", "rescue_gap_m=0.8", "join_gap_m=0.5"],
          "hdl64": ["split_people=0", "join_cars=0"]}
SETS = [("simulated vlp16 crowd", "vlp16", "sim_crowd_vlp16"), ("simulated vlp16", "vlp16", "sim_vlp16"),
        ("simulated hdl64 crowd", "hdl64", "sim_crowd_hdl64"), ("simulated hdl64", "hdl64", "sim_hdl64")]


def instructions(exe: pathlib.Path, scan: pathlib.Path, sensor: str, sets: list[str]) -> int:
    with tempfile.TemporaryDirectory() as td:
        out = os.path.join(td, "callgrind.out")
        cmd = ["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}",
               "--toggle-collect=lidet_cluster_run_buffers", str(exe), "cluster", str(scan), "--sensor", sensor,
               "--json", "--repeat", "1"]
        for kv in sets:
            cmd += ["--set", kv]
        subprocess.run(cmd, capture_output=True, check=True)
        m = re.search(r"^(?:summary|totals):\s+(\d+)", pathlib.Path(out).read_text(), re.M)
        return int(m.group(1))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default=str(ROOT / "build"))
    ap.add_argument("--scans", type=int, default=10, help="scans per set (the first N)")
    a = ap.parse_args()
    exe = pathlib.Path(a.build) / "ports" / "host" / "lidet"
    print("| scans | before issue 15 (M instructions / scan) | now | ratio |\n|---|---:|---:|---:|")
    for name, sensor, folder in SETS:
        scans = sorted((ROOT / "data" / folder / "velodyne").glob("*.bin"))[: a.scans]
        if not scans:
            print(f"| {name} | (data/{folder} not cached: run tools/bench/bench_cluster.py first) | | |")
            continue
        b = sum(instructions(exe, s, sensor, BEFORE[sensor]) for s in scans)
        n = sum(instructions(exe, s, sensor, []) for s in scans)
        print(f"| {name} ({len(scans)}) | {b / len(scans) / 1e6:.2f} | {n / len(scans) / 1e6:.2f} | {n / b:.3f} |",
              flush=True)


if __name__ == "__main__":
    main()
