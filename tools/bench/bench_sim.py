# SPDX-License-Identifier: MIT
"""Benchmark of the scan simulator (issue 4): scans per second on one core, files written.

Contract of tools/bench/run_bench.py: `run(args) -> str` returns a markdown section
(args.real, args.build are not needed here). Alone: `python tools/bench/bench_sim.py [--scans N]`.

Each measurement runs `lidet-sim` in a child process pinned to one core (taskset -c 0 where
available) with every BLAS / OpenMP pool limited to one thread; the rate is the CLI's own timing
of its scan loop (simulation + writing all six files per scan), Python start-up excluded.
"""
from __future__ import annotations

import argparse
import os
import platform
import re
import shutil
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
THREAD_VARS = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMEXPR_NUM_THREADS")


def _cmd(sensor, scans, out):
    cmd = [sys.executable, "-m", "lidet_tools.sim.cli", "--sensor", sensor, "--scenes", str(scans),
           "--seed", "0", "--out", out, "--no-progress"]
    if shutil.which("taskset"):
        cmd = ["taskset", "-c", "0"] + cmd
    return cmd


def measure(sensor="hdl64", scans=20):
    env = dict(os.environ)
    for v in THREAD_VARS:
        env[v] = "1"
    env["PYTHONPATH"] = os.path.join(ROOT, "tools") + os.pathsep + env.get("PYTHONPATH", "")
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, sensor)
        cmd = _cmd(sensor, scans, out)
        p = subprocess.run(cmd, env=env, capture_output=True, text=True, check=True)
        m = re.search(r"in ([0-9.]+) s \(([0-9.]+) scans/s; CPU ([0-9.]+) s, ([0-9.]+) scans/s\)", p.stderr)
        size = sum(os.path.getsize(os.path.join(d, f)) for d, _, fs in os.walk(out) for f in fs)
    shown = " ".join(THREAD_VARS[:2]) .replace("_THREADS", "_THREADS=1") + " " + " ".join(
        c if c != sys.executable else "python" for c in cmd).replace(out, "/tmp/sim_bench")
    return float(m.group(2)), float(m.group(1)), float(m.group(4)), size / scans, shown


def run(args=None) -> str:
    scans = getattr(args, "sim_scans", None) or 20
    lines = ["## Scan simulator (lidet-sim)", "",
             f"One core ({platform.processor() or platform.machine()}, `taskset -c 0`, one BLAS/OpenMP thread), "
             f"{scans} scans per sensor, seed 0, every output file written (velodyne, labels, label_2, calib, "
             "boxes, ring). Target (issue 4): >= 2 HDL-64 scans/s.", "",
             "Wall clock is the figure that counts; the CPU-time rate of the same loop shows how much of it was "
             "lost to other load on the machine.", "",
             "| sensor | rays/scan | scans/s (wall) | s/scan | scans/s (CPU time) | MB written/scan | command |",
             "|---|---|---|---|---|---|---|"]
    sys.path.insert(0, os.path.join(ROOT, "tools"))
    from lidet_tools.sensors import get_sensor
    for sensor in ("hdl64", "vlp16", "os1-128"):
        n = scans if sensor != "os1-128" else max(4, scans // 4)
        rate, dt, cpu_rate, size, cmd = measure(sensor, n)
        s = get_sensor(sensor)
        lines.append(f"| {sensor} | {s.rows * s.cols} | **{rate:.2f}** | {dt / n:.3f} | {cpu_rate:.2f} | "
                     f"{size / 1e6:.2f} | `{cmd}` |")
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scans", dest="sim_scans", type=int, default=20)
    print(run(ap.parse_args()))
