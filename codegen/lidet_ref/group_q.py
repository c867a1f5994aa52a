# SPDX-License-Identifier: MIT
"""The integer detector's group split, bit for bit as lib/src/cluster/lidet_group_q.c (the rule:
lib/src/internal/lidet_group_common.h): the shape test on a cluster's member pixels, the one-dimensional k-means cut
along its principal horizontal axis, and a part's proposal. Lengths in 4 mm steps, the axis in Q30, divisions
rounded half away from zero (qmath.div_round), the bounds halved with a floor shift."""
from __future__ import annotations

import numpy as np

from lidet_ref import qmath as qm
from lidet_ref.cluster import proposal_indices

MAX_PARTS = 4
MIN_POINTS = 20
MIN_PART = 8
ITERS = 8
Z_LO2, Z_HI2 = 62500, 302500      # (1.0 m)^2, (2.2 m)^2 in 4 mm steps
S_LO2, S_HI2 = 50625, 765625      # (0.9 m)^2, (3.5 m)^2


def _i(v) -> int:
    return int(np.asarray(v).item())


def _div_round(n: int, d: int) -> int:
    return _i(qm.div_round(n, d))


class Group:
    """One cluster's state (lidet_group_q_t): mean, axis (c, s Q30), spread, cuts to try, and the last cut's
    bounds, counts and part means."""

    def __init__(self, mean, c: int, s: int, spread: int, k_min: int, k_max: int):
        self.mean = [int(v) for v in mean]
        self.c, self.s, self.spread, self.k_min, self.k_max = c, s, spread, k_min, k_max
        self.k = 0
        self.bound: list[int] = []
        self.n: list[int] = []
        self.part_mean: list[list[int]] = []

    def offsets(self, d: np.ndarray) -> np.ndarray:
        """round((dx c + dy s) / 2^30) per member offset row of d (int64)."""
        return (d[:, 0] * self.c + d[:, 1] * self.s + (1 << 29)) >> 30

    def parts(self, t: np.ndarray) -> np.ndarray:
        """The part of each offset: the number of bounds <= t."""
        return np.searchsorted(np.asarray(self.bound, np.int64), t, side="right") if self.bound else \
            np.zeros(len(t), np.int64)


def _member_d(rec, members, X, Y, Z, mean) -> np.ndarray:
    pix = np.asarray(members, np.int64)[rec.first_member: rec.first_member + rec.n_points]
    return np.stack([X[pix] - mean[0], Y[pix] - mean[1], Z[pix] - mean[2]], 1).astype(np.int64)


def shape(rec, members, X, Y, Z, max_range_mm: int) -> Group | None:
    """lidet__group_q_shape: the cluster's Group when it is shaped like people side by side, else None.
    X, Y, Z: the image's pixels (flattened, 4 mm steps)."""
    n = int(rec.n_points)
    mx, my = int(rec.mean[0]), int(rec.mean[1])
    if n < MIN_POINTS or 16 * (mx * mx + my * my) > int(max_range_mm) ** 2:
        return None
    d = _member_d(rec, members, X, Y, Z, rec.mean)
    sxx, syy = int((d[:, 0] * d[:, 0]).sum()), int((d[:, 1] * d[:, 1]).sum())
    sxy, szz = int((d[:, 0] * d[:, 1]).sum()), int((d[:, 2] * d[:, 2]).sum())
    if 12 * szz < Z_LO2 * n or 12 * szz > Z_HI2 * n:
        return None
    ay, ax, sh = 2 * sxy, sxx - syy, 0
    while (abs(ay) >> sh) >= (1 << 30) or (abs(ax) >> sh) >= (1 << 30):
        sh += 1
    half = _i(qm.atan2(ay >> sh, ax >> sh)) >> 1
    g = Group(rec.mean, _i(qm.cos(half & 0xFFFFFFFF)), _i(qm.sin(half & 0xFFFFFFFF)), 0, 0, 0)
    t = g.offsets(d)
    stt = int((t * t).sum())
    if 12 * stt < S_LO2 * n or 12 * stt > S_HI2 * n:
        return None
    g.spread = _i(qm.isqrt((12 * stt) // n))
    g.k_max = min((2 * g.spread + 125) // 250, MAX_PARTS)
    g.k_min = max((2 * g.spread + 175) // 350, 2)
    return g if g.k_min <= g.k_max else None


def cut(rec, members, X, Y, Z, g: Group, k: int) -> bool:
    """lidet__group_q_cut: the k-part cut into g; True when every part holds MIN_PART members."""
    g.k = k
    d = _member_d(rec, members, X, Y, Z, g.mean)
    t = g.offsets(d)
    centre = [_div_round((2 * j + 1 - k) * g.spread, 2 * k) for j in range(k)]
    g.part_mean = [[0, 0, 0] for _ in range(k)]
    for _ in range(ITERS):
        g.bound = [(centre[j] + centre[j + 1]) >> 1 for j in range(k - 1)]
        q = g.parts(t)
        g.n = [int((q == j).sum()) for j in range(k)]
        moved = False
        for j in range(k):
            if g.n[j] == 0:
                continue
            sel = q == j
            m = _div_round(int(t[sel].sum()), g.n[j])
            moved |= m != centre[j]
            centre[j] = m
            g.part_mean[j] = [g.mean[a] + _div_round(int(d[sel, a].sum()), g.n[j]) for a in range(3)]
        if not moved:
            break
    return all(v >= MIN_PART for v in g.n)


def _sat16(v: int) -> int:
    return -32768 if v < -32768 else (32767 if v > 32767 else v)


def _bin(v: int, b: int) -> int:
    return _sat16(v // b)


def proposal(rec, members, X, Y, Z, g: Group, part: int, cfg: dict):
    """lidet__group_q_proposal: part `part` of g's last cut as (xyz (n_points, 3) int16, mean (3,) int32, voxel
    (3,) int16), the cluster proposals' resampling rule over the part's members in member order."""
    d = _member_d(rec, members, X, Y, Z, g.mean)
    sel = np.flatnonzero(g.parts(g.offsets(d)) == part)
    n_src = len(sel)
    mx, my, mz = g.part_mean[part]
    zo = int(rec.mean[2]) - int(rec.height) if int(cfg.get("z_origin", 0)) == 1 else mz
    pix = np.asarray(members, np.int64)[rec.first_member + sel]
    idx = proposal_indices(n_src, int(cfg["n_points"]), int(cfg["seed"]), pix)
    rows = d[sel[idx]] + np.array(g.mean, np.int64)
    xyz = np.array([[_sat16(int(r[0]) - mx), _sat16(int(r[1]) - my), _sat16(int(r[2]) - zo)] for r in rows],
                   np.int16)
    rxy2 = mx * mx + my * my
    vox = np.array([_bin(_i(qm.atan2(my, mx)), int(cfg["azimuth_bin_bam"])),
                    _bin(_i(qm.atan2(mz, _i(qm.sqrt_round(rxy2)))), int(cfg["elevation_bin_bam"])),
                    _bin(_i(qm.sqrt_round(rxy2 + mz * mz)), int(cfg["range_bin_4mm"]))], np.int16)
    return xyz, np.array([mx, my, zo], np.int32), vox, n_src
