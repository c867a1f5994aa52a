# SPDX-License-Identifier: MIT
"""The two memory models on the same scans, in the same run (issue 18, docs/MEMORY.md): the standalone stage
objects (every buffer of a stage in its own object, float image with R, the pixel of every input point: the
memory model before issue 18) chained by hand, against the detector workspace (one object, scratch overlaid,
the 4 mm compact image, nothing per input point unless asked for). ports/host/bench_memory.c times both
interleaved in one process, in the thread's CPU time."""
from __future__ import annotations

import json
import pathlib
import subprocess
import sys

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[2]
PARTS = ("project", "ground", "cluster")


def measure(build, sensor: str, scans, repeat: int) -> list[dict]:
    """One JSON object per scan from lidet_bench_memory."""
    exe = pathlib.Path(build) / "ports" / "host" / "lidet_bench_memory"
    out = subprocess.run([str(exe), "--sensor", sensor, "--repeat", str(repeat), *map(str, scans)], check=True,
                         capture_output=True, text=True).stdout
    return [json.loads(line) for line in out.splitlines() if line.startswith("{")]


def row(label: str, per: list[dict]) -> str:
    med = {k: float(np.median([p[k] for p in per])) for k in per[0] if k.endswith("_ms")}
    stages = " / ".join(f"{med['stages_' + p + '_ms']:.3f}" for p in PARTS)
    ws = " / ".join(f"{med['workspace_' + p + '_ms']:.3f}" for p in PARTS)
    ratio = med["workspace_ms"] / med["stages_ms"]
    g = min(p["ground_agree_pct"] for p in per)
    c = min(p["cluster_agree_pct"] for p in per)
    same = med["same_mask_cluster_compact_ms"] / med["same_mask_cluster_float_ms"]
    return (f"| {label} ({len(per)}) | {per[0]['points']:,} | {stages} | **{med['stages_ms']:.3f}** | {ws} | "
            f"**{med['workspace_ms']:.3f}** | {med['workspace_per_point_ms']:.3f} | **{ratio:.3f}** | "
            f"{med['same_mask_cluster_compact_ms']:.3f} / {med['same_mask_cluster_float_ms']:.3f} ({same:.3f}) | "
            f"{g:.2f} / {c:.2f} |")


def run(args) -> str:
    repeat = 5 if getattr(args, "quick", False) else 40
    sets = []
    for sensor in ("hdl64", "vlp16"):
        sims = sorted((ROOT / "tests" / "data" / f"sim_{sensor}" / "velodyne").glob("*.bin"))
        if sims:
            sets.append((f"simulated {sensor} sample", sensor, sims))
    real = pathlib.Path(args.real)
    kitti = sorted(real.glob("kitti/*/velodyne/*.bin"))
    sk = sorted(real.glob("semantickitti/velodyne/*.bin"))
    if kitti:
        sets.append(("real KITTI", "hdl64", kitti))
    if sk:
        sets.append(("real SemanticKITTI", "hdl64", sk))
    lines = ["## Memory model: the workspace against the stage objects (issue 18)", "",
             "Projection + ground + clustering of one scan in each memory model, same library, same run, "
             "interleaved in one process, thread CPU time, median per scan then over the scans. *Stages*: the "
             "standalone stage objects chained by hand (`lidet_proj_t`, `lidet_ground_t`, `lidet_cluster_t`: "
             "each holds its tables, outputs and scratch; float image with R; the pixel of every input point), "
             "the memory model before issue 18. *Workspace*: `lidet_workspace_run` (one object, scratch "
             "overlaid, the 4 mm compact image; what the detector runs); *+ per point*: the same with the "
             "per-point outputs asked for (cluster id and ground bit of every input point, as the stage objects "
             "always make). Bytes: `lidet_proj_bytes() + lidet_ground_bytes() + lidet_cluster_bytes()` against "
             "`lidet_workspace_bytes()` at this build's capacities (per configuration: docs/MEMORY.md). "
             "Agreement: the least over the scans, % of the points projected in both, of equal ground labels / "
             "of the same cluster membership (the compact image rounds coordinates to 4 mm: RANSAC draws move). "
             "The chains' clustering times differ also because their ground masks do; *cluster, same mask* times "
             "the clustering stage alone on the stage objects' ground mask, on the compact and on the float image "
             "(the code compared on one input).",
             "", "| scans | points (first) | stages: project / ground / cluster ms | stages ms | workspace: project "
             "/ ground / cluster ms | workspace ms | + per point ms | workspace / stages | cluster, same mask: "
             "compact / float ms | agreement ground / cluster % |", "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    per_all = []
    for label, sensor, scans in sets:
        per = measure(args.build, sensor, scans, repeat)
        per_all += per
        lines.append(row(label, per))
    if per_all:
        lines += ["", f"Bytes at this build's capacities: stage objects {per_all[0]['stages_bytes']:,} B, workspace "
                  f"{per_all[0]['workspace_bytes']:,} B ({per_all[0]['workspace_bytes'] / per_all[0]['stages_bytes']:.2f}x)."]
    lines += ["", f"Command: `build/ports/host/lidet_bench_memory --sensor S --repeat {repeat} SCANS...` "
              "(`python tools/bench/bench_memory.py`, part of `make bench`).", ""]
    return "\n".join(lines)


if __name__ == "__main__":
    sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
    from run_bench import standalone
    standalone(run, __doc__)
