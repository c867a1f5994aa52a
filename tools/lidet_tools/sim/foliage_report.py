# SPDX-License-Identifier: MIT
"""How rough the simulated surfaces are against real ones: vegetation, buildings, fences and cars.

    python -m lidet_tools.sim.foliage_report [--real ../shared/data/real] [--scans 6] [--seed 1000]
                                             [--foliage 0,0.1,0.2,0.3]

Per labelled point at 5-15 m and 15-30 m (horizontal range): the rms distance of its k = 12 nearest neighbours
(itself included) from their least-squares plane, i.e. the square root of the smallest eigenvalue of their
covariance. Flat surfaces (walls, car panels) give about the range noise; foliage, which real lasers meet at
many depths, gives more. Real: the labelled SemanticKITTI scans on the training side of
tools/lidet_tools/real/split.txt (per-point classes); simulated: `simulate_scan("hdl64", seed, i, foliage_m=F)`
for each F of --foliage. The table is the source of lidet-sim's `--foliage` value (docs/SIMULATOR.md, "Foliage").
"""
from __future__ import annotations

import argparse
import os
import sys

import numpy as np

#: SemanticKITTI classes measured (id: name)
CLASSES = {70: "vegetation", 50: "building", 51: "fence", 10: "car"}
BANDS = ((5.0, 15.0), (15.0, 30.0))
K = 12


def plane_rms(xyz: np.ndarray, sel: np.ndarray, k: int = K) -> tuple[np.ndarray, np.ndarray]:
    """For each point of xyz[sel]: the rms distance of its k nearest neighbours in xyz (itself included) from
    their least-squares plane (m), and its horizontal range (m). xyz: (N, 3); sel: a boolean mask or indices."""
    from scipy.spatial import cKDTree
    xyz = np.asarray(xyz, np.float64)
    q = xyz[sel]
    if len(q) == 0 or len(xyz) < k:
        return np.zeros(0), np.zeros(0)
    _, idx = cKDTree(xyz).query(q, k=k)
    nb = xyz[idx]
    c = nb - nb.mean(axis=1, keepdims=True)
    cov = np.einsum("nki,nkj->nij", c, c) / k
    lam = np.linalg.eigvalsh(cov)[:, 0]
    return np.sqrt(np.maximum(lam, 0.0)), np.hypot(q[:, 0], q[:, 1])


def band_medians(rms: np.ndarray, rng: np.ndarray, min_points: int = 20) -> list:
    """The median of rms per band of BANDS (None where fewer than min_points fall in it)."""
    out = []
    for lo, hi in BANDS:
        m = (rng >= lo) & (rng < hi)
        out.append(float(np.median(rms[m])) if m.sum() >= min_points else None)
    return out


def _collect(scans) -> dict:
    """scans: iterable of (xyz, sem) -> {class id: (rms, range)} over all of them."""
    acc = {c: ([], []) for c in CLASSES}
    for xyz, sem in scans:
        for c in CLASSES:
            r, d = plane_rms(xyz, np.asarray(sem) == c)
            acc[c][0].append(r)
            acc[c][1].append(d)
    return {c: (np.concatenate(v[0]), np.concatenate(v[1])) for c, v in acc.items()}


def real_scans(root):
    from .. import real
    from ..eval_real import read_split
    for source, frame_id, side in read_split():
        if source != "semantickitti" or side != "train":
            continue
        fr = real.load_frame(root, source, frame_id)
        if getattr(fr, "point_semantic", None) is not None:
            yield fr.points[:, :3], fr.point_semantic


def sim_scans(n: int, seed: int, foliage_m: float, sensor: str = "hdl64"):
    from .simulate import simulate_scan
    for i in range(n):
        r = simulate_scan(sensor, seed, i, foliage_m=foliage_m)
        yield r.points[:, :3], r.sem


def table(rows: list) -> str:
    """rows: (name, {class id: (rms, range)}) -> a markdown table of the band medians in cm."""
    head = "| scans | " + " | ".join(f"{n} {lo:g}-{hi:g} m" for n in CLASSES.values() for lo, hi in BANDS) + " |"
    L = [head, "|---|" + "---:|" * (len(CLASSES) * len(BANDS))]
    for name, res in rows:
        cells = []
        for c in CLASSES:
            for v in band_medians(*res[c]):
                cells.append("-" if v is None else f"{100 * v:.1f}")
        L.append(f"| {name} | " + " | ".join(cells) + " |")
    return "\n".join(L)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="python -m lidet_tools.sim.foliage_report", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--real", default=os.path.join("..", "shared", "data", "real"))
    p.add_argument("--scans", type=int, default=6, help="simulated HDL-64 scans per --foliage value")
    p.add_argument("--seed", type=int, default=1000)
    p.add_argument("--foliage", default="0,0.1,0.2,0.3", help="lidet-sim --foliage values (m), comma-separated")
    a = p.parse_args(argv)
    try:
        fol = [float(v) for v in a.foliage.split(",") if v]
    except ValueError:
        p.error("--foliage: comma-separated numbers")
    if a.scans < 1 or any(not 0.0 <= f <= 2.0 for f in fol):
        p.error("--scans >= 1 and --foliage values in [0, 2] m")
    rows = []
    if os.path.exists(os.path.join(a.real, "README.md")):
        rows.append(("real SemanticKITTI (training side)", _collect(real_scans(a.real))))
    else:
        print(f"foliage report: no real scans at {a.real}; simulated rows only", file=sys.stderr)
    for f in fol:
        rows.append((f"simulated, --foliage {f:g} ({a.scans} scans, seed {a.seed})",
                     _collect(sim_scans(a.scans, a.seed, f))))
    print("Median rms distance (cm) of a point's 12 nearest neighbours from their plane, by class and range:\n")
    print(table(rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
