# SPDX-License-Identifier: MIT
"""Integer projection (lidet_proj_q, issue 16) against the float projection on the same scans: the share of points
in the same pixel and of pixels with the same winning point, with the integer input round(1000 x) mm and the float
input either the same points (x = mm / 1000: the two algorithms alone) or the original float32 points (the mm
quantization of the input included); and where the two disagree, which one the float64 reference
(codegen/lidet_ref/proj.py) sides with. Speed: bench_proj.py."""
from __future__ import annotations

import pathlib

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[2]


def _scan_sets(real: pathlib.Path):
    from lidet_tools import kitti
    from lidet_tools.sim import simulate_scan
    sets = []
    for s in ("hdl64", "vlp16"):
        scans = [kitti.read_bin(ROOT / f"tests/data/sim_{s}/velodyne/000000.bin")]
        scans += [simulate_scan(s, seed, 0).points for seed in (101, 202)]
        sets.append((f"simulated {s} (sample + seeds 101, 202)", s, scans))
    for sub, label in (("kitti", "real KITTI"), ("semantickitti", "real SemanticKITTI")):
        files = sorted((real / sub).rglob("velodyne/*.bin"))
        if files:
            sets.append((f"{label} ({len(files)} scans)", "hdl64", [kitti.read_bin(f) for f in files]))
    return sets


def measure(points, sensor: str) -> dict:
    """Counts for one scan: points, same pixel / same winner for both float inputs, and for the points whose
    pixel differs with the same input, how many the float64 reference puts where the integer path does."""
    from lidet_ref.proj import project_ref
    from lidet_tools import native, sensors
    s = sensors.get_sensor(sensor)
    mm = np.round(np.asarray(points, dtype=np.float64)[:, :3] * 1000.0).astype(np.int32)
    q = native.project_q(mm, sensor)
    x = mm / 1000.0
    same = native.project(x.astype(np.float32), sensor)
    raw = native.project(points, sensor)
    ref, _, _ = project_ref(x, s.beam_elev_rad, s.cols)
    d = same.point_pixel != q["point_pixel"]
    return dict(n=len(mm), pixels=q["point_idx"].size,
                pix_same=int((~d).sum()), win_same=int((same.point_idx.ravel() == q["point_idx"]).sum()),
                pix_raw=int((raw.point_pixel == q["point_pixel"]).sum()),
                win_raw=int((raw.point_idx.ravel() == q["point_idx"]).sum()),
                diff=int(d.sum()), diff_ref_int=int((ref[d] == q["point_pixel"][d]).sum()),
                diff_row=int(((same.point_pixel[d] // s.cols) != (q["point_pixel"][d] // s.cols)).sum()))


def run(args) -> str:
    real = pathlib.Path(args.real)
    lines = ["## Integer projection against the float one (issue 16)", "",
             "| scans | points | same pixel, same input | same winner, same input | same pixel, float32 input "
             "| same winner, float32 input | differing points (row / column) | of which float64 sides with integer |",
             "|---|---|---|---|---|---|---|---|"]
    for label, sensor, scans in _scan_sets(real):
        tot: dict = {}
        for p in scans:
            for k, v in measure(p, sensor).items():
                tot[k] = tot.get(k, 0) + v
        n, px = tot["n"], tot["pixels"]
        lines.append(f"| {label} | {n:,} | {tot['pix_same'] / n:.5f} | {tot['win_same'] / px:.5f} "
                     f"| {tot['pix_raw'] / n:.5f} | {tot['win_raw'] / px:.5f} "
                     f"| {tot['diff']} ({tot['diff_row']} / {tot['diff'] - tot['diff_row']}) | {tot['diff_ref_int']} |")
    lines += ["", "Command: `python tools/bench/bench_proj_q.py` (integer input round(1000 x) mm; \"same input\": the "
              "float projection of x = mm / 1000, the two algorithms alone; \"float32 input\": of the original points, "
              "the mm quantization included). Same winner: share of all pixels (empty ones included) holding the "
              "same point index.", ""]
    return "\n".join(lines)


if __name__ == "__main__":
    from run_bench import standalone  # the script's own folder is on sys.path

    standalone(run)
