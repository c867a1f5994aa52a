# SPDX-License-Identifier: MIT
"""numpy reference of the ground stage (lib/src/ground/lidet_ground_filter.c, lidet_ground_ransac.c).

Same algorithm, same order, same random draws (ref/rng.py mirrors the C xorshift32):

* `sample_mask`: the Sobel-inspired filter in float32, operation for operation as the C code, so the
  sample mask is bit-identical;
* `gather_samples`: samples grouped by sector on the step grid, in the C order;
* `ransac_sector`: hypotheses and their scores in float32 (identical draws and counts), the
  least-squares refinement in float64 with numpy's eigh (the C code uses float sums and Jacobi
  rotations: planes agree to ~1e-5, so a few pixels at the p_th boundary may flip);
* `fit_sectors` (per cell: near / far part of each sector, with the fallback), `label_pixels`, and
  `veto_vertical`, and `ground` chaining them.

Configuration: a dict with the field names of lidet_ground_cfg_t (native.ground_defaults gives the
C defaults).
"""
from __future__ import annotations

import numpy as np

from .rng import XorShift32, cell

F = np.float32
FITTED, NEIGHBOUR, MOUNT, NEAR = 0, 1, 2, 3


def sector_col(s: int, n_sectors: int, cols: int) -> int:
    """First column of sector s (sector of column c = c * n_sectors // cols)."""
    return (s * cols + n_sectors - 1) // n_sectors


def sample_mask(R: np.ndarray, Z: np.ndarray, cfg: dict) -> np.ndarray:
    """(rows, cols) uint8 sample mask from the R (horizontal range) and Z images (float32, empty = 0)."""
    R = np.asarray(R, F)
    Z = np.asarray(Z, F)
    rows, cols = R.shape
    step = int(cfg["sample_step"])
    fy, fx_max = F(cfg["fy_max"]), F(cfg["fx_max_m"])
    dr_min = F(0.0) if cfg["require_descending"] else F(-3.0e38)
    mount = F(cfg["mount_height_m"])
    if cfg["height_gate"]:
        z_lo, z_hi = -mount - F(cfg["gate_below_m"]), -mount + F(cfg["gate_above_m"])
    else:
        z_lo, z_hi = F(-3.0e38), F(3.0e38)
    out = np.zeros((rows, cols), np.uint8)
    two = F(2.0)
    for r in range(0, rows - 1, step):
        R0, R1, Z0, Z1 = R[r], R[r + 1], Z[r], Z[r + 1]
        F0 = Z0 if cfg["fx_on_z"] else R0
        nxt = lambda a, k: np.roll(a, -k)  # a[c + k] with wrap-around
        dr = (two * R0 + nxt(R0, 1)) - (two * R1 + nxt(R1, 1))
        dz = (two * Z0 + nxt(Z0, 1)) - (two * Z1 + nxt(Z1, 1))
        fx = (np.roll(F0, 1) + two * F0) - (two * nxt(F0, 1) + nxt(F0, 2))
        rmin = np.minimum.reduce([np.roll(R0, 1), R0, nxt(R0, 1), nxt(R0, 2), R1, nxt(R1, 1)])
        ok = ((rmin > 0) & (np.abs(dz) <= fy * np.abs(dr)) & (np.abs(fx) <= fx_max) & (dr > dr_min)
              & (Z0 >= z_lo) & (Z0 <= z_hi))
        out[r] = ok
    return out


def gather_samples(sample: np.ndarray, X, Y, Z, cfg: dict, R=None):
    """Samples per cell as (N, 3) float32 arrays: cells 0..ns-1 are the near parts of the sectors
    (horizontal range < ring_split_m, or everything when it is 0), cells ns..2ns-1 the far parts.
    Near samples in raster order, far samples in reverse raster order (as the C buffer fills)."""
    rows, cols = sample.shape
    ns, step, cstep = int(cfg["n_sectors"]), int(cfg["sample_step"]), int(cfg.get("sample_col_step", 1))
    split = F(cfg.get("ring_split_m", 0.0))
    R = np.zeros_like(np.asarray(X, F)) if R is None else np.asarray(R, F)
    near, far = [], []
    rr = np.arange(0, rows - 1, step)
    for s in range(ns):
        c0, c1 = sector_col(s, ns, cols), sector_col(s + 1, ns, cols)
        cc = np.arange(c0 + (cstep - c0 % cstep) % cstep, c1, cstep)
        m = sample[np.ix_(rr, cc)].astype(bool)
        pts = np.stack([np.asarray(A, F)[np.ix_(rr, cc)][m] for A in (X, Y, Z)], 1).reshape(-1, 3)
        is_far = (R[np.ix_(rr, cc)][m] >= split) if split > 0 else np.zeros(len(pts), bool)
        near.append(pts[~is_far])
        far.append(pts[is_far][::-1])
    return near + far


def fit_plane_lsq(pts: np.ndarray):
    """Least-squares plane (float64): (nx, ny, nz, d) with nz >= 0, and eigenvalues ascending; None if
    the points are (nearly) collinear."""
    p = np.asarray(pts, np.float64)
    if len(p) < 3:
        return None
    c = p.mean(0)
    q = p - c
    cov = q.T @ q / len(p)
    w, v = np.linalg.eigh(cov)
    if not (w[1] > 1e-7 * w[2] and w[2] > 0):
        return None
    n = v[:, 0] / np.linalg.norm(v[:, 0])
    if n[2] < 0:
        n = -n
    return np.array([n[0], n[1], n[2], -n @ c]), w


def ransac_sector(pts: np.ndarray, rng: XorShift32, cfg: dict, near=None, at=None):
    """One sector's plane (float64 array nx, ny, nz, d) or None, and the number of hypotheses scored.
    near, at: a far cell's test with far_max_step_m (its sector's near plane, the split point x, y)."""
    n = len(pts)
    xs, ys, zs = (pts[:, k].astype(F) for k in range(3))
    cos_t = F(np.cos(F(cfg["max_tilt_rad"])))
    cos2 = cos_t * cos_t
    stride = (n + int(cfg["eval_samples"]) - 1) // int(cfg["eval_samples"])
    n_eval = (n + stride - 1) // stride
    thr = F(cfg["inlier_m"])
    conf = F(cfg["confidence"])
    best, best_cnt, hyps = None, 0, 0
    for it in range(int(cfg["ransac_iters"])):
        i0, i1, i2 = rng.below(n), rng.below(n), rng.below(n)
        if i0 == i1 or i0 == i2 or i1 == i2:
            continue
        ux, uy, uz = xs[i1] - xs[i0], ys[i1] - ys[i0], zs[i1] - zs[i0]
        vx, vy, vz = xs[i2] - xs[i0], ys[i2] - ys[i0], zs[i2] - zs[i0]
        cx, cy, cz = uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx
        len2 = cx * cx + cy * cy + cz * cz
        if not (len2 > F(1e-8)) or not (cz * cz >= cos2 * len2):
            continue
        inv = F(1.0) / np.sqrt(len2)
        if cz < 0:
            inv = -inv
        p = (cx * inv, cy * inv, cz * inv)
        d = -(p[0] * xs[i0] + p[1] * ys[i0] + p[2] * zs[i0])
        hyps += 1
        h = p[0] * xs[::stride] + p[1] * ys[::stride] + p[2] * zs[::stride] + d
        cnt = int(np.count_nonzero(np.abs(h) <= thr))
        if best is None or cnt > best_cnt:
            best, best_cnt = np.array([p[0], p[1], p[2], d], np.float64), cnt
            if conf > 0:
                w = F(cnt) / F(n_eval)
                q = F(1.0) - w * w * w
                miss = F(1.0)
                for _ in range(it + 1):
                    miss = F(miss * q)
                if miss <= F(1.0) - conf:
                    break
    if best is None or best_cnt < int(cfg["min_inliers"]):
        return None, hyps
    p64 = pts.astype(np.float64)
    for _ in range(int(cfg["refine_iters"])):
        inl = np.abs(p64 @ best[:3] + best[3]) <= float(thr)
        fit = fit_plane_lsq(p64[inl])
        if fit is None or not (fit[0][2] ** 2 >= float(cos2)):
            break
        best = fit[0]
    if not (best[2] >= float(cos_t)):
        return None, hyps
    if near is not None:
        hn = -(near[0] * at[0] + near[1] * at[1] + near[3]) / near[2]
        hf = -(best[0] * at[0] + best[1] * at[1] + best[3]) / best[2]
        if not (abs(hf - hn) <= cfg["far_max_step_m"]):
            return None, hyps
    elif not (abs(best[3] - cfg["mount_height_m"]) <= cfg["max_height_dev_m"]):
        return None, hyps
    return best, hyps


def split_point(s: int, ns: int, split: float) -> tuple[float, float]:
    """The split circle at the middle azimuth of sector s, pi (1 - (2 s + 1) / ns) (float32, as lidet_ground_ransac.c)."""
    az = F(F(np.pi) * (F(1.0) - (F(2.0) * F(s) + F(1.0)) / F(ns)))
    return float(F(split) * F(np.cos(az))), float(F(split) * F(np.sin(az)))


def fit_sectors(cells, cfg: dict):
    """(2 * n_sectors, 4) planes (near, then far) and sources, with the fallback applied."""
    ns = int(cfg["n_sectors"])
    n_cells = 2 * ns if cfg.get("ring_split_m", 0.0) > 0 else ns
    rng = XorShift32(int(cfg["seed"]))
    planes = np.zeros((2 * ns, 4))
    src = np.array([MOUNT] * ns + [NEAR] * ns, np.uint8)
    per_cell = bool(cfg.get("seed_per_cell", 0))
    step = float(cfg.get("far_max_step_m", 0.0))

    def fit(k):
        if len(cells[k]) < int(cfg["min_samples"]):
            return
        nonlocal rng
        if per_cell:  # a stream of its own per cell (lidet__rng_cell; never 0, so XorShift32 keeps it)
            rng = XorShift32(cell(int(cfg["seed"]), k))
        if k >= ns and step > 0:  # a far cell meets its sector's final near plane at the split
            p, _ = ransac_sector(cells[k], rng, cfg, planes[k - ns],
                                 split_point(k - ns, ns, cfg["ring_split_m"]))
        else:
            p, _ = ransac_sector(cells[k], rng, cfg)
        if p is not None:
            planes[k], src[k] = p, FITTED

    for k in range(min(n_cells, ns)):
        fit(k)
    mount = np.array([0.0, 0.0, 1.0, cfg["mount_height_m"]])
    fitted = src[:ns] == FITTED
    for s in range(ns):
        if fitted[s]:
            continue
        for k in range(1, int(cfg["fallback_sectors"]) + 1):
            left, right = (s - k) % ns, (s + k) % ns
            if fitted[left]:
                planes[s], src[s] = planes[left], NEIGHBOUR
                break
            if fitted[right]:
                planes[s], src[s] = planes[right], NEIGHBOUR
                break
        else:
            planes[s] = mount
    for k in range(ns, n_cells):  # far cells, after the near fallback (no random draw in it: same stream)
        fit(k)
    for s in range(ns):
        if src[ns + s] != FITTED:
            planes[ns + s], src[ns + s] = planes[s], NEAR
    if not far2_on(cfg):
        return planes, src
    # the third cells (lidet__ground_far2_cells, lidet_ground_internal.h): each far cell's samples at or beyond
    # far2_split_m, in their order, fitted after every other cell, judged against the far plane at far2_split_m
    s2 = F(cfg["far2_split_m"])
    planes = np.vstack([planes, planes[ns:2 * ns]])
    src = np.concatenate([src, np.full(ns, NEAR, np.uint8)])
    for s in range(ns):
        pts = np.asarray(cells[ns + s], F).reshape(-1, 3)
        sel = pts[(pts[:, 0] * pts[:, 0] + pts[:, 1] * pts[:, 1]) >= s2 * s2]
        if len(sel) < int(cfg["min_samples"]):
            continue
        if per_cell:
            rng = XorShift32(cell(int(cfg["seed"]), 2 * ns + s))
        if step > 0:
            p, _ = ransac_sector(sel, rng, cfg, planes[ns + s], split_point(s, ns, cfg["far2_split_m"]))
        else:
            p, _ = ransac_sector(sel, rng, cfg)
        if p is not None:
            planes[2 * ns + s], src[2 * ns + s] = p, FITTED
    return planes, src


def far2_on(cfg: dict) -> bool:
    """The third cells are on: a split, and far2_split_m beyond it."""
    split = float(cfg.get("ring_split_m", 0.0))
    return split > 0 and float(cfg.get("far2_split_m", 0.0)) > split


def label_pixels(X, Y, Z, R, valid, planes, cfg: dict) -> np.ndarray:
    """(rows, cols) uint8 ground mask: valid and -below < height above the pixel's cell plane < above."""
    rows, cols = np.shape(X)
    ns = int(cfg["n_sectors"])
    sec = (np.arange(cols) * ns) // cols
    R = np.asarray(R, F)
    split = F(cfg.get("ring_split_m", 0.0))
    above = F(cfg["ground_m"]) + F(cfg["ground_m_per_m"]) * R
    below = -F(cfg["below_factor"]) * above
    ok = np.zeros((rows, cols), bool)
    s2 = F(cfg["far2_split_m"]) if far2_on(cfg) else F(3.0e38)
    parts = [(0, R < split if split > 0 else np.ones_like(R, bool)),
             (1, ((R >= split) & (R < s2)) if split > 0 else np.zeros_like(R, bool))]
    if far2_on(cfg):
        parts.append((2, R >= s2))
    for part, sel in parts:
        pl = np.asarray(planes, F)[part * ns + sec]  # (cols, 4)
        h = pl[:, 0] * np.asarray(X, F) + pl[:, 1] * np.asarray(Y, F) + pl[:, 2] * np.asarray(Z, F) + pl[:, 3]
        ok |= sel & (h < above) & (h > below)
    return (np.asarray(valid, bool) & ok).astype(np.uint8)


def veto_vertical(mask, R, Z, cfg: dict) -> np.ndarray:
    """Drops ground pixels that form a steep surface with the pixel above (row - 1, same column)."""
    slope, min_dz = F(cfg.get("veto_slope", 0.0)), F(cfg.get("veto_min_dz_m", 0.0))
    if not slope > 0:
        return mask
    R = np.asarray(R, F)
    Z = np.asarray(Z, F)
    dz = np.abs(Z[:-1] - Z[1:])
    dr = np.abs(R[:-1] - R[1:])
    vert = (R[:-1] > 0) & (dz > slope * dr) & (dz > min_dz)
    out = mask.copy()
    out[1:] &= ~vert
    return out


def ground(X, Y, Z, R, valid, cfg: dict):
    """The whole stage on a range image: (mask, sample mask, planes (near then far), sources)."""
    smp = sample_mask(R, Z, cfg)
    planes, src = fit_sectors(gather_samples(smp, X, Y, Z, cfg, R), cfg)
    mask = veto_vertical(label_pixels(X, Y, Z, R, valid, planes, cfg), R, Z, cfg)
    return mask, smp, planes, src
