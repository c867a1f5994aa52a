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


# ---- tracker streams (fuzz_track.c, fuzz_track_q.c: their file comments give the layout) ----------------------
# One encoder for both harnesses: objects are (cls, x m, y m, z m, l m, w m, h m, yaw rad, score); the float harness
# packs x, y in cm (i16), z in dm (i8), sizes in 5 cm (u8), yaw in pi / 128 (i8), score in 1 / 255 (u8); the
# integer one x, y in 10 mm, z in 100 mm, sizes in 20 mm, yaw in 2^24 BAM, score in 129 (Q15).
TRACK_FLOAT = dict(xy=0.01, z=0.1, size=0.05, score=255.0, shift=0.05, ego_xy=0.1)
TRACK_INT = dict(xy=0.01, z=0.1, size=0.02, score=32768.0 / 129.0, shift=0.05, ego_xy=0.1)
SRC_LIST, SRC_SHIFT, SRC_RAW_N, SRC_NONE = 0, 1, 2, 3


def track_cfg(greedy=False, confirm_hits=2, max_misses=12, pokes=()):
    """cfg byte, poke count, pokes (selector, u32)."""
    b = struct.pack("<BB", int(greedy) | ((confirm_hits - 1) << 1) | (max_misses << 3), len(pokes))
    for sel, v in pokes:
        b += struct.pack("<BI", sel, v & 0xFFFFFFFF)
    return b


def track_det(obj, unit, special=None, raw=None):
    """One detection: kind byte, [raw class], compact fields (or raw 32-bit words), [special byte]."""
    cls = obj[0]
    kind = (cls if cls < 3 else 3) | (4 if raw is not None else 0) | (8 if special is not None else 0)
    b = struct.pack("<B", kind)
    if cls >= 3:
        b += struct.pack("<B", cls)
    if raw is not None:
        b += struct.pack("<8I", *(w & 0xFFFFFFFF for w in raw))
    else:
        x, y, z, l, w, h, yaw, score = obj[1:]
        q = lambda v, s, lo, hi: max(lo, min(hi, int(round(v / s))))  # noqa: E731
        b += struct.pack("<hhbBBBbB", q(x, unit["xy"], -32768, 32767), q(y, unit["xy"], -32768, 32767),
                         q(z, unit["z"], -128, 127), q(l, unit["size"], 0, 255), q(w, unit["size"], 0, 255),
                         q(h, unit["size"], 0, 255), q(yaw, np.pi / 128.0, -128, 127),
                         q(score * unit["score"], 1.0, 0, 255))
    if special is not None:
        b += struct.pack("<B", special)
    return b


def track_update(unit, dets=None, shift=None, raw_n=None, dt=None, ego=None, reset=False, null_det=False,
                 out_flags=3, cap=15, out_null=False):
    """One update: op, out, [dt], [ego], then the detections. dt: None (the default 0.1 s / 100 ms),
    ("step", u8), ("raw", u32 bits) or ("special", u8); ego: None, ("small", dx m, dy m, dyaw rad), ("raw", 3 u32)
    or ("special", 3 u8); dets: a list of encoded detections (track_det) or shift (dx m, dy m) or raw_n."""
    dt_kind = {None: 0, "step": 1, "raw": 2, "special": 3}[dt[0] if dt else None]
    ego_kind = {None: 0, "small": 1, "raw": 2, "special": 3}[ego[0] if ego else None]
    src = SRC_LIST if dets is not None else SRC_SHIFT if shift is not None else SRC_RAW_N if raw_n is not None \
        else SRC_NONE
    op = dt_kind | (ego_kind << 2) | (0x10 if reset else 0) | (0x20 if null_det else 0) | (src << 6)
    out = (out_flags & 3) | ((cap & 15) << 2) | (0x40 if out_null else 0)
    b = struct.pack("<BB", op, out)
    if dt_kind == 1 or dt_kind == 3:
        b += struct.pack("<B", dt[1])
    elif dt_kind == 2:
        b += struct.pack("<I", dt[1] & 0xFFFFFFFF)
    if ego_kind == 1:
        b += struct.pack("<bbb", int(round(ego[1] / unit["ego_xy"])), int(round(ego[2] / unit["ego_xy"])),
                         int(round(ego[3] / (np.pi / 128.0))))
    elif ego_kind == 2:
        b += struct.pack("<3I", *(w & 0xFFFFFFFF for w in ego[1:]))
    elif ego_kind == 3:
        b += struct.pack("<3B", *ego[1:])
    if src == SRC_LIST:
        b += struct.pack("<B", len(dets)) + b"".join(dets)
    elif src == SRC_SHIFT:
        b += struct.pack("<bb", int(round(shift[0] / unit["shift"])), int(round(shift[1] / unit["shift"])))
    elif src == SRC_RAW_N:
        b += struct.pack("<I", raw_n & 0xFFFFFFFF)
    return b


CAR = (0, 4.2, 1.8, 1.6)
PED = (2, 0.6, 0.6, 1.7)
CYC = (1, 1.8, 0.6, 1.7)


def obj(kind, x, y, yaw=0.0, score=0.8, z=-0.8):
    cls, l, w, h = kind
    return (cls, x, y, z, l, w, h, yaw, score)


def f32_bits(v: float) -> int:
    return struct.unpack("<I", struct.pack("<f", v))[0]


def track_seeds(unit, integer: bool):
    """name -> bytes, the same scenarios for both harnesses."""
    d = lambda *a, **k: track_det(obj(*a, **k), unit)  # noqa: E731
    seeds = {}
    # one car at 10 m/s along x (0.1 s scans: 1 m a scan), reported with every flag
    s = track_cfg() + track_update(unit, dets=[d(CAR, 10.0, 2.0)])
    s += b"".join(track_update(unit, shift=(1.0, 0.0)) for _ in range(20))
    seeds["car_constant_velocity"] = s
    # a car and a pedestrian crossing (greedy and optimal), the pedestrian missed twice (coasting)
    for greedy in (False, True):
        s = track_cfg(greedy=greedy)
        for k in range(16):
            dd = [d(CAR, 5.0 + 0.8 * k, -6.0 + 0.8 * k, yaw=0.785), d(PED, 12.0 - 0.15 * k, 0.0, yaw=3.14)]
            if k in (7, 8):
                dd = dd[:1]
            s += track_update(unit, dets=dd, out_flags=1 if k % 2 else 3)
        seeds["crossing_greedy" if greedy else "crossing_optimal"] = s
    # ego motion: the sensor drives forward and turns; two parked cars stay put over the ground
    s = track_cfg(confirm_hits=3)
    x1, y1, x2, y2 = 15.0, 3.0, 25.0, -4.0
    for k in range(14):
        s += track_update(unit, dets=[d(CAR, x1, y1, yaw=0.3), d(CYC, x2, y2, yaw=-1.0)],
                          ego=("small", 0.5, 0.0, 0.0) if k else None)
        x1 -= 0.5
        x2 -= 0.5
    for k in range(6):
        c, sn = np.cos(0.05), np.sin(0.05)
        x1, y1 = c * (x1 - 0.3) + sn * y1, c * y1 - sn * (x1 - 0.3)
        x2, y2 = c * (x2 - 0.3) + sn * y2, c * y2 - sn * (x2 - 0.3)
        s += track_update(unit, dets=[d(CAR, x1, y1, yaw=0.3 - 0.05 * (k + 1)), d(CYC, x2, y2)],
                          ego=("small", 0.3, 0.0, 0.05))
    seeds["ego_motion_turn"] = s
    # capacity: 9 detections (> 6) confirmed into tracks, then 6 new ones with 2 free slots (births dropped),
    # then a raw count of 0xFFFFFFFF over the same list, then a reset and a smaller cap
    far = [d(CAR, 10.0 * i - 40.0, 20.0) for i in range(9)]
    other = [d(PED, 10.0 * i - 40.0, -20.0) for i in range(6)]
    s = track_cfg(max_misses=3) + track_update(unit, dets=far) + track_update(unit, dets=far)
    s += track_update(unit, dets=other) + track_update(unit, dets=other)
    s += track_update(unit, raw_n=0xFFFFFFFF) + track_update(unit, raw_n=7, cap=3)
    s += track_update(unit, reset=True, dets=far[:3], cap=2) + track_update(unit, dets=far[:3], out_flags=0)
    s += b"".join(track_update(unit, dets=[], out_flags=1) for _ in range(5))
    seeds["capacity_overflow"] = s
    # bad arguments between good updates: dt 0, negative / NaN / huge (float) or > 10 s (integer), NULL
    # detections with n > 0 and with n 0, an ego motion out of range
    s = track_cfg(confirm_hits=1) + track_update(unit, dets=[d(CAR, 8.0, 0.0)])
    s += track_update(unit, shift=(0.5, 0.0), dt=("special", 0))  # dt 0
    s += track_update(unit, shift=(0.5, 0.0), dt=("special", 3))  # 10 s (float) / 10.001 s (integer)
    s += track_update(unit, shift=(0.5, 0.0), dt=("raw", f32_bits(-0.1) if not integer else 0xFFFFFFFF))
    s += track_update(unit, shift=(0.5, 0.0), dt=("special", 192 if not integer else 4))  # NaN / 2^32 - 1 ms
    s += track_update(unit, shift=(0.5, 0.0), null_det=True)
    s += track_update(unit, dets=[], null_det=True)
    s += track_update(unit, shift=(0.5, 0.0), ego=("special", 0, 1, 2) if not integer else ("special", 1, 0, 0))
    s += track_update(unit, shift=(0.5, 0.0), ego=("raw", f32_bits(1000.5), 0, 0) if not integer
                      else ("raw", 1048577, 0, 0))
    s += track_update(unit, shift=(0.5, 0.0), ego=("raw", 0, 0, f32_bits(3.1416)) if not integer
                      else ("raw", 0, 0, 0x80000000))
    s += track_update(unit, shift=(0.5, 0.0), dt=("step", 255))
    s += track_update(unit, out_null=True, cap=0) + track_update(unit, out_null=True, cap=5)
    seeds["bad_arguments"] = s
    # bad detections: class 3 and 255, zero / negative / huge sizes, non-finite or extreme fields
    base = obj(CAR, 6.0, 1.0)
    bad = [track_det((3,) + base[1:], unit), track_det((255,) + base[1:], unit),
           track_det(base[:4] + (0.0,) + base[5:], unit)]
    for sp in range(19 if not integer else 16):
        bad.append(track_det(base, unit, special=(sp << 3) | (sp % 8)))
    if integer:
        raw = [[0x80000000, 0x7FFFFFFF, 0, 1000, 1000, 1000, 0, 100],
               [1048576, -1048576, 1048576, 100000, 100000, 100000, 0x40000000, 32768],
               [1048577, 0, 0, 100001, 1, 1, 0, 32769]]
    else:
        raw = [[0x7FC00000, 0, 0, f32_bits(1.0), f32_bits(1.0), f32_bits(1.0), 0, f32_bits(0.5)],
               [f32_bits(1e4), f32_bits(-1e4), f32_bits(1e4), f32_bits(100.0), f32_bits(100.0), f32_bits(100.0),
                f32_bits(1e30), f32_bits(3e38)],
               [f32_bits(10000.001), 0, 0, f32_bits(-1.0), f32_bits(1e-45), f32_bits(1.0), 0, f32_bits(-1.0)]]
    bad += [track_det(base, unit, raw=r) for r in raw]
    s = track_cfg()
    for k in range(0, len(bad), 5):
        s += track_update(unit, dets=[track_det(obj(CAR, 6.0 + 0.5 * k, 1.0), unit)] + bad[k:k + 5])
    seeds["bad_detections"] = s
    # configurations: the extremes of every range (accepted) and just outside (refused: the harness stops)
    upd = track_update(unit, dets=[d(CAR, 5.0, 0.0), d(PED, 5.5, 0.3)]) + track_update(unit, shift=(0.2, 0.1))
    if integer:
        edge = [(0, 1), (3, 100000), (6, 46340), (9, 1000000), (12, 1), (13, 1000 * 65536), (15, 1000), (16, 1000),
                (18, 0), (19, 32768), (20, 100000), (21, 7)]
        top = [(17, 32768)]
        top_score = 32768
        out = [(0, 0), (3, -1), (6, 46341), (9, 0), (12, 0), (13, 1000 * 65536 + 1), (14, 2), (15, 0), (16, 1001),
               (17, 32769), (18, -1), (19, 32769), (20, 100001), (21, 8), (0x80 | 2, 0)]
    else:
        sc = lambda v: int(round(v * 65536)) & 0xFFFFFFFF  # noqa: E731
        edge = [(0, sc(100.0)), (3, sc(100.0)), (6, 0), (9, sc(1000.0)), (12, sc(1000.0)), (13, 0),
                (15, 0), (16, sc(1.0)), (17, sc(100.0)), (19, 1000), (20, 1000), (21, 7), (0x80 | 1, f32_bits(0.001))]
        top = [(14, sc(1.0))]
        top_score = f32_bits(1.0)
        out = [(0, 0), (0x80 | 0, 0x7FC00000), (3, sc(-1.0)), (6, sc(100.5)), (9, 0), (12, sc(1000.5)),
               (0x80 | 13, 0x7F800000), (14, sc(1.5)), (16, sc(-0.5)), (18, 2), (19, 0), (20, 1001), (21, 8)]
    s = track_cfg(greedy=True, pokes=edge[:7]) + upd
    seeds["cfg_edges_a"] = s
    seeds["cfg_edges_b"] = track_cfg(pokes=edge[7:]) + upd

    def one(x: float, score: int) -> bytes:
        """A car at (x, 0) with the raw score word `score` (float bits or Q15): the birth threshold's edge."""
        if integer:
            raw = [int(round(x * 1000)), 0, 0, 4000, 1800, 1600, 0, score]
        else:
            raw = [f32_bits(x), 0, 0, f32_bits(4.0), f32_bits(1.8), f32_bits(1.6), 0, score]
        return track_det(obj(CAR, x, 0.0), unit, raw=raw)

    # birth_min_score 1: only a score of exactly 1.0 (32768) starts a track, one ulp (1) below does not
    s = track_cfg(confirm_hits=1, pokes=top) + track_update(unit, dets=[one(5.0, top_score), one(10.0, top_score - 1)])
    seeds["cfg_birth_min_score_max"] = s + track_update(unit, dets=[one(5.2, top_score - 1), one(10.0, top_score)])
    for i, p in enumerate(out):
        seeds[f"cfg_refused_{i:02d}"] = track_cfg(pokes=[p]) + upd
    return seeds


def write_track_corpora() -> None:
    for harness, unit, integer in (("track", TRACK_FLOAT, False), ("track_q", TRACK_INT, True)):
        d = OUT / harness
        d.mkdir(exist_ok=True)
        for name, b in track_seeds(unit, integer).items():
            (d / f"{name}.bin").write_bytes(b)


def ouster_cfg(profile: int, filt: int = 0, fusa: bool = False, ppc: int = 8, cpf: int = 32, cpp: int = 16,
               seam: int = 0, max_step: int = 0, offset: int = 32768, beams=None, init_id=None, sn=None,
               frame: int = 100) -> bytes:
    """The configuration bytes of fuzz_ouster.c (its comment): profile 0 LEGACY, 1 DUAL, 2 single, 3 low data
    rate; cpf 16..128 (encoded as 16 + v % 113)."""
    b0 = profile | (filt << 2) | (16 if fusa else 0) | (32 if init_id is not None else 0) | \
        (64 if sn is not None else 0) | (128 if beams is not None else 0)
    b = struct.pack("<BBHBHHH", b0, ppc - 1, cpf - 16, cpp, seam, max_step, offset)
    if beams is not None:
        b += b"".join(struct.pack("<h", v // 6) for v in beams)
    if init_id is not None:
        b += struct.pack("<IB", init_id, 0)
    if sn is not None:
        b += struct.pack("<IHB", sn & 0xFFFFFFFF, sn >> 32, 0)
    return b + struct.pack("<H", frame)


def ouster_op(op: int, room: int = -1, seed: int = 1, arg: int = 0) -> bytes:
    """One operation of fuzz_ouster.c: op byte (% 16: 0 raw, 1 NULL, 2 reset, else a well-formed payload; bit 4
    a new init id, bits 5-6 a move of the position, bit 7 invalid columns), room (-1: the most one payload gives),
    pixel seed, argument."""
    return struct.pack("<BBHH", op, 1 if room < 0 else (room << 1) & 0xFE, seed, arg)


def ouster_seeds() -> dict:
    """Packet streams for fuzz_ouster: every profile over several frames, a seam inside the packets, fragments
    (a new init id and a seam crossing in one payload), columns straddling two frames (LEGACY), lost columns,
    jumps and steps back, invalid columns, a small room, raw, NULL and cut payloads, resets, a beam table, a
    configured init id and serial number, the FUSA header."""
    run = b"".join(ouster_op(3, seed=k) for k in range(8))
    seeds = {}
    for prof, name in enumerate(("legacy", "dual", "single", "lowdata")):
        seeds[f"{name}_frames"] = ouster_cfg(prof) + run
        seeds[f"{name}_seam_small_room"] = ouster_cfg(prof, cpp=4, cpf=16, seam=5) + b"".join(
            ouster_op(3, room=(7 * k) % 64, seed=k) for k in range(12))
        seeds[f"{name}_restart_fragment"] = ouster_cfg(prof, seam=8) + ouster_op(3) + ouster_op(3) + \
            ouster_op(3 | 16) + ouster_op(3) + ouster_op(3 | 16, seed=9) + ouster_op(3)
        seeds[f"{name}_moves"] = ouster_cfg(prof, max_step=4) + ouster_op(3) + ouster_op(3 | 32, arg=3) + \
            ouster_op(3 | 32, arg=9) + ouster_op(3 | 64, arg=2) + ouster_op(3) + ouster_op(3 | 96, arg=1) + \
            ouster_op(3 | 128, arg=0x5A) + ouster_op(3)
    for f in (1, 2, 3):
        seeds[f"dual_filter{f}"] = ouster_cfg(1, filt=f, ppc=16) + run
    seeds["legacy_straddle"] = ouster_cfg(0, cpf=16) + ouster_op(3 | 32, arg=8) + run
    seeds["fusa_configured"] = ouster_cfg(2, fusa=True, init_id=0x123456, sn=0x0102030405, frame=65530) + run + \
        ouster_op(3 | 16)
    seeds["beam_table"] = ouster_cfg(2, ppc=4, beams=[4200, -4200, 1500, -179994]) + run
    seeds["raw_null_reset"] = ouster_cfg(2) + ouster_op(0, arg=600) + bytes(range(40)) + ouster_op(1) + \
        ouster_op(3) + ouster_op(2) + ouster_op(3) + ouster_op(0, arg=10) + bytes(40) + ouster_op(3)
    seeds["odd_columns"] = ouster_cfg(0, cpf=100, cpp=8, seam=37, max_step=60) + run + ouster_op(3 | 32, arg=50) + run
    seeds["jump_then_seam"] = ouster_cfg(0, cpp=8, max_step=4) + ouster_op(3) + ouster_op(3) + \
        ouster_op(3 | 32, arg=5) + run
    seeds["serial_only"] = ouster_cfg(2, sn=0x0A0B0C0D0E) + ouster_op(3) + ouster_op(3 | 16) + ouster_op(3)
    seeds["back_a_frame_and_restart"] = ouster_cfg(0, cpp=8) + ouster_op(3) + ouster_op(3) + \
        ouster_op(3 | 64, arg=20) + ouster_op(3) + ouster_op(3)
    seeds["restart_back"] = ouster_cfg(2, cpp=8) + ouster_op(3) + ouster_op(3) + ouster_op(3 | 16 | 64, arg=40) + \
        ouster_op(3) + ouster_op(3 | 64, arg=20) + ouster_op(3)
    seeds["bad_config"] = ouster_cfg(2, cpp=17) + run
    return seeds


def write_ouster_corpus() -> None:
    d = OUT / "ouster"
    d.mkdir(exist_ok=True)
    for name, b in ouster_seeds().items():
        (d / f"{name}.bin").write_bytes(b)


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
    # the range-only pixel (min_points byte's top bit: 0x88, min_points 5) and 9 ground sectors (byte 8): an odd count
    # turns stream_sectors on (fuzz_detector_q.c), the ground stage streamed sector by sector
    head, body = scan_parts_q("vlp16", True, True, 4, 1, seed=len("vlp16_table_rings"))
    k = bytes([KNOBS_Q[0] | 1, KNOBS_Q[1], 0x88, 8]) + KNOBS_Q[4:]
    (d / "vlp16_stream_sectors.bin").write_bytes(head + k + body)
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
    write_track_corpora()
    write_ouster_corpus()
    for p in sorted(OUT.rglob("*.bin")):
        print(p.relative_to(ROOT), p.stat().st_size)


if __name__ == "__main__":
    main()
