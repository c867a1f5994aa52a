# SPDX-License-Identifier: MIT
"""Writes the seed corpora of the fuzz harnesses (tests/fuzz/corpus/<harness>/) from the simulated scans
of tests/data (byte layout: tests/fuzz/README.md and fuzz_common.h). Deterministic; run from the
repository root:

    PYTHONPATH=tools .venv/bin/python tests/fuzz/make_corpus.py

Each seed is a few KiB: 8 beams of a simulated scan (the lowest of the sensor's table) on a 64-column
image, a few hundred points, as the small-capacity library of the harnesses (8 x 64, 512 points) takes."""
from __future__ import annotations

import struct
from pathlib import Path

import numpy as np

from lidet_tools.sensors import get_sensor

ROOT = Path(__file__).resolve().parents[2]
OUT = ROOT / "tests" / "fuzz" / "corpus"
ROWS, COLS, NPTS = 8, 64, 360
FLAG_TABLE, FLAG_RINGS = 0x01, 0x02
NO_POKE = struct.pack("<Bf", 255, 0.0)  # fz_poke_f32 selector past every field: nothing overwritten


def load(sensor: str):
    d = ROOT / "tests" / "data" / f"sim_{sensor}"
    pts = np.fromfile(d / "velodyne" / "000000.bin", dtype=np.float32).reshape(-1, 4)
    ring = np.fromfile(d / "ring" / "000000.bin", dtype=np.uint16)
    boxes = [ln.split() for ln in (d / "boxes" / "000000.txt").read_text().splitlines() if ln.strip()]
    return pts, ring, boxes


def _selection(sensor, table, rings, stride, tile, seed):
    """What both scan layouts take: the sensor, its points, its beam elevations (float64), the lowest ROWS beams
    (ground and road users), NPTS points of them within 40 m (seeded), their rings renumbered, and the four
    header bytes (rows, cols, flags, tile)."""
    s = get_sensor(sensor)
    pts, ring, _ = load(sensor)
    elev = np.asarray(s.beam_elev_rad, dtype=np.float64)
    keep_rings = np.argsort(elev)[:ROWS]
    sel = np.flatnonzero(np.isin(ring, keep_rings) & (np.hypot(pts[:, 0], pts[:, 1]) < 40.0))
    rng = np.random.default_rng(seed)
    sel = np.sort(rng.choice(sel, size=min(NPTS, sel.size), replace=False))
    new_ring = np.searchsorted(np.sort(keep_rings), ring[sel]).astype(np.uint16)
    flags = (FLAG_TABLE if table else 0) | (FLAG_RINGS if rings else 0) | ((stride - 3) << 2)
    head = struct.pack("<BBBB", ROWS - 1, COLS - 8, flags, tile - 1)
    return s, pts, elev, keep_rings, sel, new_ring, head


def scan_parts(sensor: str, table: bool, rings: bool, stride: int, tile: int, seed: int):
    """(header, payload) of a scan input: the header ends before the harness's knobs."""
    s, pts, elev, keep_rings, sel, new_ring, head = _selection(sensor, table, rings, stride, tile, seed)
    elev = elev.astype(np.float32)
    if table:
        head += b"".join(struct.pack("<f", float(elev[r])) for r in np.sort(keep_rings))
    else:
        head += struct.pack("<ff", float(elev[keep_rings].max()) + 0.01, float(elev[keep_rings].min()) - 0.01)
    head += struct.pack("<B", int(round(s.mount_height_m / 0.25)))
    rec = np.zeros((sel.size, stride), dtype=np.float32)
    rec[:, :min(stride, 4)] = pts[sel, :min(stride, 4)]
    body = b""
    for i in range(sel.size):
        body += rec[i].tobytes()
        if rings:
            body += struct.pack("<H", int(new_ring[i]))
    return head, body


SCANS = {  # name: (sensor, beam table, rings, stride, tile)
    "vlp16_table_rings": ("vlp16", True, True, 4, 1),
    "hdl64_uniform": ("hdl64", False, False, 3, 1),
    "hdl64_table_over_capacity": ("hdl64", True, False, 4, 3),  # 4 x 360 points > 512
}

KNOBS = {
    "proj": lambda: b"",
    # flags (require_descending), sectors 8, iters 20, steps 1, 1, eval 128, min samples / inliers 10,
    # refine 1, fallback 2, seed, no poke
    "ground": lambda: struct.pack("<BBBBBBBBBBI", 0x04, 7, 19, 0, 0, 126, 8, 8, 1, 2, 7) + NO_POKE,
    # mode (float + ground), max_steps 5, min_points 5, rescue window 2 x 6, rescue budget 8 x 16 pixels, join
    # budget 0 (none), no poke
    "cluster": lambda: struct.pack("<BBBBBBB", 0x08, 5, 5, 2, 6, 16, 0) + NO_POKE,
    "proposal": lambda: struct.pack("<BBBBBBB", 0x08, 5, 5, 2, 6, 16, 0) + NO_POKE + struct.pack("<HI", 64, 0x5EED1234)
    + NO_POKE + struct.pack("<IH", 100, 64),
    # gates on, max proposals 16, max boxes 8, min_points 5, 8 ground sectors, no poke (hdl64 models; vlp16 for
    # the vlp16 scan)
    "detector": lambda: struct.pack("<BBBBB", 0x0C, 16, 8, 4, 7) + NO_POKE,
}


def proposal_seed(sensor: str, model_index: int, cls: int) -> bytes:
    """pointnet input: a car's points centred on their mean (64 of them), its mean and voxel."""
    pts, _, boxes = load(sensor)
    cx, cy, cz = (float(v) for v in boxes[0][1:4])
    near = pts[np.hypot(pts[:, 0] - cx, pts[:, 1] - cy) < 2.0][:, :3]
    rng = np.random.default_rng(1)
    idx = rng.choice(near.shape[0], size=128, replace=near.shape[0] < 128)
    mean = near.mean(axis=0)
    xyz = (near[idx] - mean).astype(np.float32)
    az, rg = np.arctan2(mean[1], mean[0]), np.hypot(mean[0], mean[1])
    vox = np.array([np.floor(az / np.radians(10)), np.floor(np.arctan2(mean[2], rg) / np.radians(10)),
                    np.floor(np.linalg.norm(mean))], dtype=np.float32)
    out = struct.pack("<BBB", model_index, 0, cls)
    for i in range(3):
        out += struct.pack("<ff", float(vox[i]), float(mean[i]))
    out += xyz.tobytes()
    out += struct.pack("<hhh", *(int(v) for v in vox))
    return out


def scan_parts_q(sensor: str, table: bool, rings: bool, stride: int, tile: int, seed: int):
    """(header, payload) of an integer scan input (fuzz_detector_q.c): microradians and int32 millimetres."""
    s, pts, elev, keep_rings, sel, new_ring, head = _selection(sensor, table, rings, stride, tile, seed)
    urad = np.round(elev * 1e6).astype(np.int64)
    if table:
        head += b"".join(struct.pack("<i", int(urad[r])) for r in np.sort(keep_rings))
    else:
        head += struct.pack("<ii", int(urad[keep_rings].max()) + 10000, int(urad[keep_rings].min()) - 10000)
    head += struct.pack("<B", int(round(s.mount_height_m / 0.25)))
    rec = np.zeros((sel.size, stride), dtype=np.int32)
    rec[:, :3] = np.round(pts[sel, :3].astype(np.float64) * 1000.0).astype(np.int32)
    if stride > 3:
        rec[:, 3] = np.round(pts[sel, 3] * 255.0).astype(np.int32)
    body = b""
    for i in range(sel.size):
        body += rec[i].tobytes()
        if rings:
            body += struct.pack("<H", int(new_ring[i]))
    return head, body


# fuzz_detector_q.c: flags (gates on, diagonals), max proposals 16, min_points 5, 8 sectors, 5 steps, no poke;
# bit 0 of the flags (64 points per proposal) set for the vlp16 scan
KNOBS_Q = struct.pack("<BBBBB", 0x4C, 16, 4, 7, 5) + struct.pack("<BI", 255, 0)


def proposal_seed_q(sensor: str, mode: int, cls: int) -> bytes:
    """pointnet_q input (mode 0): a car's points in mm about their mean, its voxel and its mean in 4 mm."""
    pts, _, boxes = load(sensor)
    cx, cy = (float(v) for v in boxes[0][1:3])
    near = pts[np.hypot(pts[:, 0] - cx, pts[:, 1] - cy) < 2.0][:, :3].astype(np.float64)
    rng = np.random.default_rng(2)
    idx = rng.choice(near.shape[0], size=128, replace=near.shape[0] < 128)
    mean = near.mean(axis=0)
    xyz = np.round((near[idx] - mean) * 1000.0).astype(np.int16)
    vox = [int(np.floor(np.arctan2(mean[1], mean[0]) / np.radians(10))),
           int(np.floor(np.arctan2(mean[2], np.hypot(mean[0], mean[1])) / np.radians(10))),
           int(np.floor(np.linalg.norm(mean)))]
    out = struct.pack("<BBB", mode, 0, cls) + struct.pack("<hhh", *vox) + xyz.tobytes()
    for i in range(3):
        out += struct.pack("<ih", int(round(mean[i] * 250.0)), vox[i])
    return out


def main() -> None:
    OUT.mkdir(parents=True, exist_ok=True)
    for harness, knobs in KNOBS.items():
        d = OUT / harness
        d.mkdir(exist_ok=True)
        for name, (sensor, table, rings, stride, tile) in SCANS.items():
            head, body = scan_parts(sensor, table, rings, stride, tile, seed=len(name))
            k = knobs()
            if harness == "detector" and sensor == "vlp16":
                k = bytes([k[0] | 1]) + k[1:]
            (d / f"{name}.bin").write_bytes(head + k + body)
    d = OUT / "detector_q"
    d.mkdir(exist_ok=True)
    for name, (sensor, table, rings, stride, tile) in SCANS.items():
        head, body = scan_parts_q(sensor, table, rings, stride, tile, seed=len(name))
        k = KNOBS_Q if sensor != "vlp16" else bytes([KNOBS_Q[0] | 1]) + KNOBS_Q[1:]
        (d / f"{name}.bin").write_bytes(head + k + body)
    d = OUT / "pointnet_q"
    d.mkdir(exist_ok=True)
    # mode: bit 0 descriptor mutation, bit 1 box net, bit 2 64 points (fuzz_pointnet_q.c)
    for mode in (0, 2, 4, 6):
        (d / f"mode{mode}_car.bin").write_bytes(proposal_seed_q("hdl64", mode, 0))
    mut_q = {"valid": [], "wrong_version": [(0, 2)], "zero_width": [(18, 0)], "huge_width": [(18, 5000)],
             "null_weights": [(22, 0)], "bad_shift": [(25, 0)], "zero_temperature": [(10, 0)]}
    for mode in (1, 3, 5, 7):
        for name, ms in mut_q.items():
            b = struct.pack("<BBBBB", mode, 0, 0, len(ms), 0)
            for sel, v in ms:
                b += struct.pack("<BI", sel, v)
            (d / f"mode{mode}_{name}.bin").write_bytes(b + b"\x00\x00")
    d = OUT / "pointnet"
    d.mkdir(exist_ok=True)
    # the model byte picks a tiny model: bit 0 box net, bit 1 64 points (fuzz_models.h)
    for i in range(4):
        (d / f"model{i}_car.bin").write_bytes(proposal_seed("hdl64", i, 0))
    d = OUT / "pn_check"
    d.mkdir(exist_ok=True)
    mut = {  # selector, value (fuzz_pn_check.c: mutate)
        "valid": [],
        "wrong_version": [(0, 2)],
        "zero_width": [(15, 0)],
        "huge_width": [(15, 5000)],
        "null_weights": [(17, 0)],
        "too_many_layers": [(10, 9)],
        "tiny_temperature": [(9, 0x00000001)],
    }
    for i in range(4):
        for name, ms in mut.items():
            b = struct.pack("<BBB", i, len(ms), 0)
            for sel, v in ms:
                b += struct.pack("<BI", sel, v)
            (d / f"model{i}_{name}.bin").write_bytes(b + b"\x00\x00")
    for p in sorted(OUT.rglob("*.bin")):
        print(p.relative_to(ROOT), p.stat().st_size)


if __name__ == "__main__":
    main()
