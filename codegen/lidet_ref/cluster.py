# SPDX-License-Identifier: MIT
"""Reference of the clustering stage and of the proposals (mirrors lib/src/cluster/lidet_cluster.c,
lidet_cluster_grow.c, lidet_cluster_rescue.c and lidet_proposal.c; the contract is written in
lib/include/lidet/lidet_cluster.h).

- `proposal_indices` / `make_proposal` reproduce the C resampling *exactly* (integer xorshift32 and pixel keys):
  training uses them, or the bindings (`lidet_tools.native.proposals`), and both give the same points.
- `cluster_ref` is a plain-Python BFS with the same rules (4- or 8-neighbourhood, hole bridging over
  non-candidates up to max_steps, optionally over nearer occluders, column wrap, the angle criterion in
  tangent form, the gap bound, filters, capacity, the fragment rescue, canonical ids). It is slow
  (seconds per 64 x 2048 image) and meant for tests.
"""
from __future__ import annotations

from collections import deque

import numpy as np

_M32 = 0xFFFFFFFF


def xorshift32(x: int) -> int:
    """One step of the (13, 17, 5) xorshift32 generator (uint32 arithmetic)."""
    x ^= (x << 13) & _M32
    x ^= x >> 17
    x ^= (x << 5) & _M32
    return x & _M32


def proposal_key(seed: int, pixels) -> np.ndarray:
    """The keys of member pixels in the draw seeded with seed (lidet__proposal_key): MurmurHash3's 32-bit
    finaliser of seed ^ (p * 0x9E3779B9), uint32 arithmetic; a bijection of p."""
    p = np.asarray(pixels, np.int64).astype(np.uint64)
    h = (np.uint64(seed & _M32) ^ ((p * np.uint64(0x9E3779B9)) & np.uint64(_M32)))
    h ^= h >> np.uint64(16)
    h = (h * np.uint64(0x85EBCA6B)) & np.uint64(_M32)
    h ^= h >> np.uint64(13)
    h = (h * np.uint64(0xC2B2AE35)) & np.uint64(_M32)
    h ^= h >> np.uint64(16)
    return h.astype(np.uint32)


def proposal_indices(n_src: int, n_out: int, seed: int = 0x5EED1234, pixels=None) -> np.ndarray:
    """Member indices a proposal takes (lidet_proposal_indices): every member once then draws with
    replacement when n_src <= n_out; otherwise from each of n_out equal strata of the member list the member
    whose pixel (pixels: the n_src member pixels in member order, required then) has the smallest key."""
    if n_src <= 0 or n_out <= 0:
        raise ValueError("n_src and n_out must be positive")
    out = np.empty(n_out, np.int64)
    if n_src <= n_out:
        s = (seed ^ ((n_src * 0x9E3779B9) & _M32)) & _M32
        if s == 0:
            s = 0x6C646574
        out[:n_src] = np.arange(n_src)
        for i in range(n_src, n_out):
            s = xorshift32(s)
            out[i] = s % n_src
        return out
    if pixels is None or len(pixels) != n_src:
        raise ValueError(f"a cluster of {n_src} > {n_out} members needs its {n_src} member pixels")
    key = proposal_key(seed, pixels)
    for i in range(n_out):
        b0 = (i * n_src) // n_out
        b1 = ((i + 1) * n_src) // n_out
        out[i] = b0 + int(np.argmin(key[b0:b1]))  # keys never tie: the first minimum is the only one
    return out


def voxel_of(mean, azimuth_bin_rad=np.float32(np.radians(10.0)), elevation_bin_rad=np.float32(np.radians(10.0)),
             range_bin_m=1.0) -> np.ndarray:
    """PVLE voxel of a cluster mean: floor(azimuth / bin), floor(elevation / bin), floor(range / bin),
    azimuth = atan2(y, x), elevation = atan2(z, hypot(x, y)); int16, saturating. (float64 here, float32
    in C: the two can differ only for a mean within float rounding of a bin edge.)"""
    m = np.asarray(mean, np.float64)
    x, y, z = m[..., 0], m[..., 1], m[..., 2]
    rxy = np.hypot(x, y)
    v = np.stack([np.floor(np.arctan2(y, x) / float(azimuth_bin_rad)),
                  np.floor(np.arctan2(z, rxy) / float(elevation_bin_rad)),
                  np.floor(np.sqrt(rxy ** 2 + z ** 2) / float(range_bin_m))], -1)
    return np.clip(v, -32768, 32767).astype(np.int16)


def make_proposal(member_xyz: np.ndarray, mean=None, n_points: int = 64, seed: int = 0x5EED1234,
                  azimuth_bin_rad=np.float32(np.radians(10.0)), elevation_bin_rad=np.float32(np.radians(10.0)),
                  range_bin_m: float = 1.0, height_m=None, pixels=None):
    """A proposal from a cluster's member points (n_src, 3) in member order (raster order of their
    pixels, as lidet_cluster_members lists them); pixels: their pixel indices (needed when n_src > n_points). mean: the cluster mean (default: the float64 mean of
    the members). height_m: None for LIDET_PROPOSAL_Z_MEAN; else the record's height above its ground plane
    (lidet_cluster_rec_t height_m) and z is measured from the ground under the mean (LIDET_PROPOSAL_Z_GROUND),
    which is the returned mean's z. Returns (xyz (n_points, 3) float32 centred on the mean, mean float32 (3,),
    voxel int16 (3,): the voxel of the cluster mean either way)."""
    pts = np.asarray(member_xyz, np.float32)
    mean32 = (pts.astype(np.float64).mean(0) if mean is None else np.asarray(mean, np.float64)).astype(np.float32)
    origin = mean32.copy()
    if height_m is not None:
        origin[2] = mean32[2] - np.float32(height_m)  # float32 - float32, as in C
    idx = proposal_indices(len(pts), n_points, seed, pixels)
    xyz = pts[idx] - origin  # float32 - float32, as in C
    return xyz, origin, voxel_of(mean32, azimuth_bin_rad, elevation_bin_rad, range_bin_m)


def cluster_ref(range_m: np.ndarray, candidate: np.ndarray, row_elev_rad: np.ndarray, xyz: np.ndarray,
                theta_rad: float = 0.2, max_steps: int = 9, bridge_occluders: bool = True, diagonals: bool = True,
                max_gap_m: float = 0.0, max_gap_per_m: float = 0.0, min_points: int = 1, max_extent_m: float = 1e30,
                max_mean_height_m: float = 1e30, mount_height_m: float = 1.73, max_clusters: int = 1 << 30,
                rescue_gap_m: float = 0.0, rescue_gap_per_m: float = 0.0, rescue_rows: int = 0, rescue_cols: int = 0,
                max_fragment_pixels: int = 0, max_bridge_per_pixel: float = 0.0, split_people: bool = False,
                join_cars: bool = False, azimuth_half_rad: float = 0.0, regrow_gap_m: float = 0.0,
                regrow_gap_per_m: float = 0.0, regrow_max_pixels: int = 0, regrow_max_height_m: float = 1e30,
                regrow_cut_m: float = 0.0, plane_split_m: float = 0.0, seed_half_rad: float = 0.0, **refine):
    """Reference clustering of a (rows, cols) range image. candidate: (rows, cols) bool (holds a
    non-ground point); xyz: (rows, cols, 3). Returns (labels (rows, cols) int64 canonical ids, list of
    member-pixel arrays per kept cluster in raster order). Float32 tangent and distance tests like the
    C; the filters use float64 means (they can differ from the C's float32 only at a filter's edge).
    rescue_gap_m > 0 turns the fragment rescue on (lidet_cluster.h); max_fragment_pixels > 0 is its budget:
    fragments enter it in raster order while their pixels sum to at most that. max_bridge_per_pixel > 0
    sets the occluder bridging budget: a pixel's searches step over nearer candidates only while the run
    has stepped over fewer than max_bridge_per_pixel * (candidate pixels), in float32 as the C.
    split_people / join_cars turn the refinement on (refine_ref; lidet_cluster.h). regrow_gap_m > 0: a component
    past max_extent_m (at most regrow_max_pixels pixels, 0: any; z span at most regrow_max_height_m) is grown again
    from its own pixels, in its fill order, with the gap bound regrow_gap_m + regrow_gap_per_m * d2, and each part is
    filtered as a component of its own (lidet_cluster_run_body.h regrow), less its pixels below regrow_cut_m above
    the flat ground (z + mount_height_m, float32 as the C). plane_split_m: no planes here (flat
    ground), so it changes nothing. seed_half_rad in (0, pi): components start only at pixels of the columns within
    it (the window's column rule), in raster order, and still grow over every candidate; a component's seed (its
    canonical order) is then its first pixel in those columns."""
    rows, cols = range_m.shape
    rng = np.asarray(range_m, np.float32).ravel()
    cand = np.asarray(candidate, bool).ravel()
    def window_cols(w):
        # the columns within w of straight ahead, one more each side (lidet_math.h lidet__azimuth_window_cols)
        w = np.float32(w)
        if not np.float32(0.0) < w < np.float32(np.pi):
            return 0, cols
        half = np.float32(np.float32(w * np.float32(cols)) / np.float32(2.0 * np.float32(np.pi)))
        lo = np.float32(np.float32(np.float32(0.5) * np.float32(cols)) - half) - np.float32(1.0)
        hi = np.float32(np.float32(np.float32(0.5) * np.float32(cols)) + half) + np.float32(1.0)
        return (int(lo) if lo > 0 else 0), (int(hi) + 1 if hi < cols else cols)

    c_lo, c_hi = window_cols(azimuth_half_rad)
    if (c_lo, c_hi) != (0, cols):
        # the azimuth window (lidet_cluster.c window_out)
        keep = np.zeros(cols, bool)
        keep[c_lo:c_hi] = True
        cand = cand & np.tile(keep, rows)
    s_lo, s_hi = window_cols(seed_half_rad)
    s_lo, s_hi = max(s_lo, c_lo), min(s_hi, c_hi)  # the seed columns, within the window
    P = np.asarray(xyz, np.float64).reshape(-1, 3)
    tan_t = np.float32(np.tan(np.float32(theta_rad)))
    elev = np.asarray(row_elev_rad, np.float32)
    ks = np.arange(1, max_steps + 1)
    a_col = (2.0 * np.pi * (ks % cols) / cols).astype(np.float32)
    a_col = np.where(a_col > np.float32(np.pi), np.float32(2 * np.pi) - a_col, a_col)
    csin, ccos = np.sin(a_col).astype(np.float32), np.cos(a_col).astype(np.float32)

    def row_sc(r_top, k):
        a = np.float32(abs(np.float32(elev[r_top]) - np.float32(elev[r_top + k])))
        return np.float32(np.sin(a)), np.float32(np.cos(a))

    cd = np.float32(np.cos(np.float32(2.0 * np.pi / cols)))

    def diag_sc(r_top):
        e1, e2 = np.float32(elev[r_top]), np.float32(elev[r_top + 1])
        cs = np.float32(np.sin(e1) * np.sin(e2) + np.cos(e1) * np.cos(e2) * cd)
        cs = np.float32(min(max(cs, -1.0), 1.0))
        return np.float32(np.sqrt(np.float32(1.0) - cs * cs)), cs

    # the gap bound: the first fill's, or the regrowth's while it runs
    gp = {"gap": np.float32(max_gap_m), "gpm": np.float32(max_gap_per_m)}
    loose = dict(gp)
    tight = {"gap": np.float32(regrow_gap_m), "gpm": np.float32(regrow_gap_per_m)}

    def link(da, db, sn, cs):
        # angle test; with a gap bound also the distance of the two returns along their beams,
        # sqrt(u^2 + v^2) <= gap + gap_per_m * d2 (computed from the ranges, like the C)
        d1, d2 = (da, db) if da > db else (db, da)
        u, v = np.float32(d1 - np.float32(d2 * cs)), np.float32(d2 * sn)
        if not v > np.float32(tan_t * u):
            return False
        if gp["gap"] > 0:
            g = np.float32(gp["gap"] + np.float32(gp["gpm"] * d2))
            return bool(np.float32(np.float32(u * u) + np.float32(v * v)) <= np.float32(g * g))
        return True

    rescue = rescue_gap_m > 0
    ra, rb = np.float32(rescue_gap_m), np.float32(rescue_gap_per_m)
    rb1 = np.float32(np.float32(1.0) + rb)
    P32 = np.asarray(xyz, np.float32).reshape(-1, 3)
    wr, wc = int(rescue_rows), min(int(rescue_cols), (cols - 1) // 2)

    def _passes(m):
        pts = P[m]
        if np.any(pts.max(0) - pts.min(0) > max_extent_m):
            return False
        return pts[:, 2].mean() + mount_height_m <= max_mean_height_m

    def _rescue(state, owner, kept):
        # second fill over the fragments (state -3), seeds in raster order; window of wr rows and
        # wc columns around each member; a group joins the nearest kept pixel's cluster met within
        # the distance, else it is a cluster of its own when it passes the filters and a slot is free
        for seed in range(rows * cols):
            if state[seed] != -3:
                continue
            state[seed] = -1
            mem, head = [seed], 0
            best, best_d = -1, np.float32(3.0e38)
            while head < len(mem):
                q = mem[head]
                head += 1
                r, c = divmod(q, cols)
                dq = rng[q]
                hi = np.float32(np.float32(dq * rb1) + ra)
                lo = np.float32(np.float32(dq - ra) / rb1)
                for rr in range(max(r - wr, 0), min(r + wr, rows - 1) + 1):
                    for k in range(-wc, wc + 1):
                        n = rr * cols + (c + k) % cols
                        if n == q or not (state[n] == -3 or owner[n] >= 0):
                            continue
                        dn = rng[n]
                        if not (dn >= lo and dn <= hi):
                            continue
                        gg = np.float32(ra + np.float32(rb * min(dq, dn)))
                        d = P32[n] - P32[q]
                        dd = np.float32(np.float32(np.float32(d[0] * d[0]) + np.float32(d[1] * d[1])) + np.float32(d[2] * d[2]))
                        if not dd <= np.float32(gg * gg):
                            continue
                        if state[n] == -3:
                            state[n] = -1
                            mem.append(n)
                        elif dd < best_d:
                            best, best_d = owner[n], dd
            m = np.array(mem)
            if best >= 0:
                kept[best][0] += len(m)
                kept[best][1] = min(kept[best][1], seed)
                kept[best][2] = np.concatenate([kept[best][2], m])
                owner[m] = best
            elif len(m) >= min_points and _passes(m) and len(kept) < max_clusters:
                owner[m] = len(kept)
                kept.append([len(m), seed, m])

    state = np.where(cand, 0, -2).astype(np.int64)  # 0 free, -2 non-candidate, -1 visited, -3 fragment
    kc = min(max_steps, cols - 1)
    kept = []  # (n, seed, members)
    frag_px = 0  # fragment pixels handed to the rescue
    bridged = 0  # nearer candidates stepped over so far (occluder bridging)
    bridge_max = (int(np.float32(np.float32(max_bridge_per_pixel) * np.float32(int(cand.sum()))))
                  if max_bridge_per_pixel > 0 else 1 << 62)
    def fill(seed):
        # the flood fill of one component from a free seed (its members in fill order)
        nonlocal bridged
        state[seed] = -1
        mem = [seed]
        q = deque([seed])
        while q:
            p = q.popleft()
            r, c = divmod(p, cols)
            d = rng[p]
            occl = bridge_occluders and bridged < bridge_max  # decided per pixel, as the C
            dirs = []
            for k in range(1, kc + 1):
                dirs.append(("R", k, r * cols + (c + k) % cols))
            for k in range(1, kc + 1):
                dirs.append(("L", k, r * cols + (c - k) % cols))
            for k in range(1, max_steps + 1):
                if r + k < rows:
                    dirs.append(("D", k, p + k * cols))
            for k in range(1, max_steps + 1):
                if k <= r:
                    dirs.append(("U", k, p - k * cols))
            done = set()
            for name, k, n in dirs:
                if name in done or state[n] == -2:
                    continue
                if name in "RL":
                    sn, cs = csin[k - 1], ccos[k - 1]
                else:
                    sn, cs = row_sc(r if name == "D" else r - k, k)
                ok = link(d, rng[n], sn, cs)
                if ok:
                    done.add(name)
                    if state[n] == 0:
                        state[n] = -1
                        mem.append(n)
                        q.append(n)
                elif not (occl and rng[n] < d):
                    done.add(name)  # a surface behind it: stop; a nearer occluder is stepped over
                else:
                    bridged += 1
            if diagonals:  # direct diagonal neighbours: down-left, down-right, up-left, up-right
                for dr, dc in ((1, -1), (1, 1), (-1, -1), (-1, 1)):
                    rr = r + dr
                    if rr < 0 or rr >= rows:
                        continue
                    n = rr * cols + (c + dc) % cols
                    if state[n] != 0:
                        continue
                    sn, cs = diag_sc(r if dr > 0 else r - 1)
                    ok = link(d, rng[n], sn, cs)
                    if ok:
                        state[n] = -1
                        mem.append(n)
                        q.append(n)
        return mem

    n_cand = int(cand.sum())

    def component(mem, regrow):
        # the filters of one component (lidet_cluster_run_body.h finish_cluster)
        nonlocal frag_px
        m = np.array(mem)
        if len(m) < min_points:
            if rescue and max_fragment_pixels and frag_px + len(m) > max_fragment_pixels:
                return  # past the rescue budget: dropped
            if rescue and P[m][:, 2].mean() + mount_height_m <= max_mean_height_m:
                frag_px += len(m)
                state[m] = -3  # a fragment, for the rescue
            return
        pts = P[m]
        if np.any(pts.max(0) - pts.min(0) > max_extent_m):
            if (regrow and regrow_gap_m > 0 and (regrow_max_pixels == 0 or len(m) <= regrow_max_pixels)
                    and pts[:, 2].max() - pts[:, 2].min() <= regrow_max_height_m and len(m) <= rows * cols - n_cand):
                state[m] = 0
                if regrow_cut_m > 0:
                    low = (P[m][:, 2].astype(np.float32) + np.float32(mount_height_m)) < np.float32(regrow_cut_m)
                    state[m[low]] = -2  # left out: as a non-candidate
                gp.update(tight)
                for p in mem:
                    if state[p] == 0:
                        part = fill(p)
                        k = int(np.argmin(part))  # the part's seed: its first pixel in raster order, put first
                        part[0], part[k] = part[k], part[0]
                        gp.update(loose)
                        component(part, False)
                        gp.update(tight)
                gp.update(loose)
            return
        if pts[:, 2].mean() + mount_height_m > max_mean_height_m:
            return
        kept.append([len(m), int(m[0]), m])

    for seed in range(rows * cols):
        if state[seed] != 0 or not s_lo <= seed % cols < s_hi:
            continue
        component(fill(seed), True)
    if len(kept) > max_clusters:  # smallest dropped first, ties: the later seed
        order = sorted(range(len(kept)), key=lambda i: (-kept[i][0], kept[i][1]))[:max_clusters]
        kept = [kept[i] for i in sorted(order)]
    owner = np.full(rows * cols, -1, np.int64)  # index into kept, or -1
    for i, (_, _, m) in enumerate(kept):
        owner[m] = i
    if rescue:
        _rescue(state, owner, kept)
    labels = np.zeros(rows * cols, np.int64)
    kept.sort(key=lambda k: k[1])  # canonical ids: raster order of the first pixel
    out = []
    for i, (_, _, m) in enumerate(kept):
        m = np.sort(np.asarray(m))
        labels[m] = i + 1
        out.append(m)
    if split_people or join_cars:  # the refinement (refine_ref; its other settings in `refine`)
        labels = refine_ref(labels.reshape(rows, cols), xyz, min_points=min_points, max_clusters=max_clusters,
                            split_people=bool(split_people), join_cars=bool(join_cars), **refine).ravel()
        out = [np.nonzero(labels == i)[0] for i in range(1, int(labels.max(initial=0)) + 1)]
    return labels.reshape(rows, cols), out


def grid_parts(cells: list, nx: int, ny: int) -> list:
    """The part (8-connected component of the occupied cells of an nx x ny grid) of each member's cell, parts
    numbered in the order their first member is met (the refinement's label_parts, both stages)."""
    part_of: dict = {}
    occ = set(cells)
    pid = -1
    for c0 in cells:
        if c0 in part_of:
            continue
        pid += 1
        q = deque([c0])
        part_of[c0] = pid
        while q:
            cc = q.popleft()
            cx, cy = cc % nx, cc // nx
            for yy in range(max(cy - 1, 0), min(cy + 1, ny - 1) + 1):
                for xx in range(max(cx - 1, 0), min(cx + 1, nx - 1) + 1):
                    nb = yy * nx + xx
                    if nb in occ and nb not in part_of:
                        part_of[nb] = pid
                        q.append(nb)
    return [part_of[c] for c in cells]


def refine_ref(labels: np.ndarray, xyz: np.ndarray, min_points: int = 8, split_people: bool = True,
               split_min_width_m: float = 0.7, split_cell_m: float = 0.12, split_cell_per_m: float = 0.0,
               person_max_width_m: float = 1.0, person_min_height_m: float = 0.9, person_min_aspect: float = 1.8, person_min_cols: int = 2,
               person_min_points: int | None = None, max_clusters: int = 1 << 30, max_cells: int = 4096, max_parts: int = 32,
               max_points: int = 4096, join_cars: bool = True, join_gap_m: float = 0.5,
               car_max_length_m: float = 5.2, car_max_width_m: float = 2.2, car_max_height_m: float = 2.0,
               car_min_length_m: float = 2.5, upright_max_width_m: float = 1.3,
               max_join_pieces: int = 256) -> np.ndarray:
    """The refinement of lib/src/cluster/lidet_refine.c (split_people, join_cars; the rules in lidet_cluster.h) on
    canonical cluster labels (rows, cols) of the clustering without it, with the image's points xyz (rows, cols, 3)
    float32. Returns the canonical labels the C gives with it: the same float32 operations in the same
    order (cell size, truncated cell indices, spans), so the decisions match bit for bit."""
    f32 = np.float32
    pmin = 10 if person_min_points is None else person_min_points  # None: the C default of > 16 beams
    lab = np.asarray(labels).astype(np.int64).ravel().copy()
    P = np.asarray(xyz, np.float32).reshape(-1, 3)
    n_cols = np.shape(labels)[1]
    k0 = int(lab.max(initial=0))
    n_recs = k0
    cut = set()
    for k in range(1, k0 + 1 if split_people else 1):
        mem = np.nonzero(lab == k)[0]          # raster order, as the C's members
        if len(mem) == 0 or len(mem) > max_points:
            continue
        pts = P[mem]
        lo, hi = pts.min(0), pts.max(0)
        ex, ey = f32(hi[0] - lo[0]), f32(hi[1] - lo[1])
        if not (ex > f32(split_min_width_m)) and not (ey > f32(split_min_width_m)):
            continue
        ax = abs(f32(f32(0.5) * f32(lo[0] + hi[0])))
        ay = abs(f32(f32(0.5) * f32(lo[1] + hi[1])))
        r = f32(ax + f32(f32(0.5) * ay)) if ax > ay else f32(ay + f32(f32(0.5) * ax))
        cs = f32(f32(split_cell_m) + f32(f32(split_cell_per_m) * r))
        inv = f32(f32(1.0) / cs)
        nx, ny = int(f32(ex * inv)) + 1, int(f32(ey * inv)) + 1
        if nx > max_cells or ny > max_cells // nx:
            continue
        ix = np.minimum(((pts[:, 0] - lo[0]).astype(np.float32) * inv).astype(np.int64), nx - 1)
        iy = np.minimum(((pts[:, 1] - lo[1]).astype(np.float32) * inv).astype(np.int64), ny - 1)
        cell = iy * nx + ix
        part = np.array(grid_parts(cell.tolist(), nx, ny))
        n_parts = int(part.max()) + 1
        if n_parts > max_parts or n_parts == 1:
            continue
        n = np.bincount(part, minlength=n_parts)
        person = np.zeros(n_parts, bool)
        for p in range(n_parts):
            m = part == p
            wx = f32(f32(int(ix[m].max() - ix[m].min() + 1)) * cs)
            wy = f32(f32(int(iy[m].max() - iy[m].min() + 1)) * cs)
            wz = f32(pts[m, 2].max() - pts[m, 2].min())
            col = mem[m] % n_cols
            person[p] = (n[p] >= pmin and wx <= f32(person_max_width_m) and wy <= f32(person_max_width_m)
                         and wz >= f32(person_min_height_m) and wz >= f32(f32(person_min_aspect) * max(wx, wy))
                         and int(col.max() - col.min()) + 1 >= person_min_cols)
        if not person.any():
            continue
        leave = person.copy()
        big = n >= min_points
        if np.all(person[big]):
            leave[int(np.argmax(n))] = False
        if n[~leave].sum() < min_points:
            pers = np.nonzero(person)[0]
            leave[pers[int(np.argmax(n[pers]))]] = False
        target = np.full(n_parts, k)
        for p in range(n_parts):
            if leave[p] and n_recs < max_clusters:
                n_recs += 1
                target[p] = n_recs
        if not (target != k).any():
            continue
        lab[mem] = target[part]
        cut.update(target.tolist())
    if join_cars:
        lab = _join_ref(lab, P, n_recs, cut, f32(join_gap_m), f32(car_max_length_m), f32(car_max_width_m),
                        f32(car_max_height_m), f32(car_min_length_m), f32(upright_max_width_m),
                        f32(person_min_height_m), int(max_join_pieces))
    # canonical ids: raster order of each cluster's first pixel
    ids = np.unique(lab[lab > 0])
    first = np.array([np.argmax(lab == i) for i in ids])
    new = np.zeros(int(lab.max(initial=0)) + 1, np.int64)
    new[ids[np.argsort(first, kind="stable")]] = np.arange(1, len(ids) + 1)
    return new[lab].reshape(np.shape(labels))


def _join_ref(lab, P, n_recs, cut, gap, lmax, wmax, hmax, lmin, umax, pmin, max_pieces=0):
    """The joins of lidet_refine.c (join_cars) on slot labels 1..n_recs (slot order: canonical ids, then
    the cut-off parts); returns the labels with the joined slots renumbered (not yet canonical)."""
    f32 = np.float32
    lo = np.zeros((n_recs + 1, 3), np.float32)
    hi = np.zeros((n_recs + 1, 3), np.float32)
    for k in range(1, n_recs + 1):
        m = lab == k
        lo[k], hi[k] = P[m].min(0), P[m].max(0)

    def piece(k):
        wx, wy, wz = f32(hi[k, 0] - lo[k, 0]), f32(hi[k, 1] - lo[k, 1]), f32(hi[k, 2] - lo[k, 2])
        upright = wx <= umax and wy <= umax and wz >= pmin
        return not upright and wz <= hmax and max(wx, wy) <= lmax and min(wx, wy) <= wmax

    def joinable(a, b):
        gx = max(f32(lo[b, 0] - hi[a, 0]), f32(lo[a, 0] - hi[b, 0]), f32(0.0))
        gy = max(f32(lo[b, 1] - hi[a, 1]), f32(lo[a, 1] - hi[b, 1]), f32(0.0))
        if f32(f32(gx * gx) + f32(gy * gy)) > f32(gap * gap):
            return False
        u = [f32(max(hi[a, d], hi[b, d]) - min(lo[a, d], lo[b, d])) for d in range(3)]
        return u[2] <= hmax and lmin <= max(u[0], u[1]) <= lmax and min(u[0], u[1]) <= wmax

    # the car pieces, decided once in slot order; past max_pieces (0 = no limit) they join nothing
    pieces = [k for k in range(1, n_recs + 1) if k not in cut and piece(k)]
    if max_pieces:
        pieces = pieces[:max_pieces]
    is_piece = set(pieces)
    to = list(range(n_recs + 1))
    for i in range(1, n_recs + 1):
        if to[i] != i or i not in is_piece:
            continue
        for j in range(i + 1, n_recs + 1):
            if to[j] != j or j not in is_piece or not joinable(i, j):
                continue
            lo[i], hi[i] = np.minimum(lo[i], lo[j]), np.maximum(hi[i], hi[j])
            to[j] = i
    return np.asarray(to)[lab]
