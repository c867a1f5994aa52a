# SPDX-License-Identifier: MIT
"""Reference spherical projection in float64 numpy (mirrors lib/src/proj/lidet_proj.c's contract:
nearest beam in angle, column = floor(0.5 * (1 - atan2(y, x)/pi) * cols) with wrap-around, the
closest point wins a pixel and ties keep the earlier point)."""
from __future__ import annotations

import numpy as np


def project_ref(points: np.ndarray, elev_ring_order: np.ndarray, cols: int, min_range_m: float = 0.1,
                max_range_m: float = 0.0, fov_margin_rad: float = np.radians(5.0), ring=None):
    """Returns (point_pixel (N,) int64 with -1 for dropped points, point_idx (rows*cols,) int64,
    row_elev (rows,) sorted top to bottom)."""
    p = np.asarray(points, dtype=np.float64)[:, :3]
    elev = np.asarray(elev_ring_order, dtype=np.float64)
    order = np.argsort(-elev, kind="stable")
    row_elev = elev[order]
    ring_to_row = np.empty(len(elev), np.int64)
    ring_to_row[order] = np.arange(len(elev))
    rows = len(elev)
    x, y, z = p.T
    with np.errstate(invalid="ignore", divide="ignore"):
        rxy = np.hypot(x, y)
        r = np.sqrt(rxy ** 2 + z ** 2)
        ok = np.isfinite(p).all(1) & (r > 0) & (r >= min_range_m)
        if max_range_m > 0:
            ok &= r <= max_range_m
        el = np.arctan2(z, rxy)
        if ring is None:
            ok &= (el <= row_elev[0] + fov_margin_rad) & (el >= row_elev[-1] - fov_margin_rad)
            mids = 0.5 * (row_elev[:-1] + row_elev[1:])
            # row = number of mid-angles strictly above el (ties go to the upper row)
            row = np.searchsorted(-mids, -el, side="left")
        else:
            ring = np.asarray(ring).astype(np.int64)
            ok &= ring < rows
            row = ring_to_row[np.clip(ring, 0, rows - 1)]
        az = np.arctan2(y, x)
        u = 0.5 * (1.0 - az / np.pi) * cols
        col = np.floor(np.nan_to_num(u)).astype(np.int64)
        col[col >= cols] -= cols
        col = np.clip(col, 0, cols - 1)
    pix = np.where(ok, row * cols + col, -1)
    point_idx = np.full(rows * cols, -1, np.int64)
    idx = np.nonzero(ok)[0]
    # closest wins, ties keep the earlier point: sort by (pixel, range, index), take the first
    o = np.lexsort((idx, r[idx], pix[idx]))
    sp = pix[idx][o]
    first = np.ones(len(sp), bool)
    first[1:] = sp[1:] != sp[:-1]
    point_idx[sp[first]] = idx[o][first]
    return pix, point_idx, row_elev
