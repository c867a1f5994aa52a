# SPDX-License-Identifier: MIT
"""A/B timing of two (or more) `lidet` CLI binaries, alternated in rounds in the same minutes, so that the
machine's state (which moves every figure by up to 15 % within an hour on a shared host) weighs on both alike.

    python tools/bench/ab_detect.py OLD_LIDET NEW_LIDET [--rounds 3] [--real ../shared/data/real]

Per set and binary: `lidet detect SCAN --sensor S [--crop] --json --repeat 20 --cpu-clock` on every scan, the
median over the scans of each stage's median (as tools/bench/bench_detect.py's speed table), then the median of
the rounds; the rounds' totals are printed too. Sets: the real KITTI scans (crop and 360 degrees) when the folder
exists, and the first 10 scans of the benchmark's simulated HDL-64 and VLP-16 sets (data/bench, written by
`make bench`) when present. Copy a build's build/ports/host/lidet aside before changing the code to compare."""
from __future__ import annotations

import argparse
import json
import pathlib
import statistics
import subprocess

ROOT = pathlib.Path(__file__).resolve().parents[2]
KEYS = ["project_ms", "ground_ms", "cluster_ms", "classify_ms", "box_ms", "total_ms"]


def _sets(real: pathlib.Path):
    out = []
    rs = sorted(real.glob("kitti/*/velodyne/*.bin"))
    if rs:
        out += [("real KITTI crop", "hdl64", ["--crop"], rs), ("real KITTI 360", "hdl64", [], rs)]
    hd = sorted((ROOT / "data/bench/sim_hdl64_s7000/velodyne").glob("*.bin"))[:10]
    if hd:
        out += [("sim HDL-64 crop", "hdl64", ["--crop"], hd), ("sim HDL-64 360", "hdl64", [], hd)]
    vd = sorted((ROOT / "data/bench/sim_vlp16_m0.5/velodyne").glob("*.bin"))[:10]
    if vd:
        out.append(("sim VLP-16", "vlp16", [], vd))
    return out


def _one(exe: str, sensor: str, extra: list, files: list, repeat: int) -> dict:
    acc = {k: [] for k in KEYS}
    for f in files:
        r = subprocess.run([exe, "detect", str(f), "--sensor", sensor, "--json", "--repeat", str(repeat),
                            "--cpu-clock", *extra], capture_output=True, text=True, check=True)
        d = json.loads(r.stdout)
        for k in KEYS:
            acc[k].append(d[k])
    return {k: statistics.median(v) for k, v in acc.items()}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("exe", nargs="+", help="lidet CLI binaries (2 or more)")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--repeat", type=int, default=20)
    ap.add_argument("--real", default=str(ROOT.parent / "shared" / "data" / "real"))
    a = ap.parse_args(argv)
    if len(a.exe) < 2:
        ap.error("give two binaries or more")
    for e in a.exe:
        if not pathlib.Path(e).is_file():
            ap.error(f"{e}: no such binary")
    sets = _sets(pathlib.Path(a.real))
    if not sets:
        ap.error("no scans: neither the real folder nor data/bench (make bench) is there")
    res = {}
    for _ in range(a.rounds):
        for name, sensor, extra, files in sets:
            for e in a.exe:
                res.setdefault((name, e), []).append(_one(e, sensor, extra, files, a.repeat))
    for (name, e), runs in res.items():
        med = {k: statistics.median(x[k] for x in runs) for k in KEYS}
        print(f"{name:16s} {e:40s} " + " ".join(f"{k[:-3]}={med[k]:.3f}" for k in KEYS) +
              "  rounds " + " ".join(f"{x['total_ms']:.2f}" for x in runs))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
