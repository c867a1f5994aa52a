# SPDX-License-Identifier: MIT
"""Reference of the integer clustering and proposals (lib/src/cluster/*_q.c: run, growth, rescue, refinement, proposals;
the contract is lib/include/lidet/lidet_cluster_q.h), bit for bit.

Plain Python integers over the compact image (4 mm steps), the angle tables from `ref.qmath` (the C integer
math mirrored), the flood fill with the C's exact search order and rules (hole and occluder bridging, column
wrap, diagonals), the filters, the capacity, the fragment rescue and the canonical ids; the proposals reuse
`ref.cluster.proposal_indices` (the shared resampling rule). Slow (seconds per 64 x 2048 image): for tests.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from lidet_ref import qmath as qm
from lidet_ref.cluster import grid_parts, proposal_indices

FREE, SMALL, PENDING, NONCAND = 0, 0xFFFD, 0xFFFE, 0xFFFF
STEPS = 16  # LIDET_CLUSTER_MAX_STEPS
M32 = 0xFFFFFFFF


def _i(v) -> int:
    return int(np.asarray(v).item())


def _div_round(n: int, d: int) -> int:
    """round(n / d), halves away from zero (lidet__q_div_round)."""
    return (n + d // 2) // d if n >= 0 else -((-n + d // 2) // d)


def _h_of(sin_half: int) -> int:
    """4 sin^2(alpha / 2), Q30, saturated (h_of)."""
    return min(_i(qm.rshift_round(sin_half * sin_half, 28)), M32)


def tables(row_elev_bam, cols: int, theta_urad: int):
    """The join test's tables (lidet__cluster_q_setup_geometry): sin(theta) Q16 and, per kind, S = sin(alpha +
    theta) Q16 (clamped at 0) and H = 4 sin^2(alpha / 2) Q30. Returns (sin_t, col_s, col_h, row_s, row_h,
    diag_s, diag_h) as lists (row tables indexed [r * STEPS + k - 1])."""
    e = [int(v) for v in row_elev_bam]
    rows = len(e)
    theta = _i(qm.urad_to_bam(theta_urad))
    sin_t = _i(qm.rshift_round(qm.sin(theta), 14))

    def tab(alpha):
        s = _i(qm.rshift_round(qm.sin(alpha + theta), 14))
        return max(s, 0), _h_of(_i(qm.sin(alpha >> 1)))

    col_s, col_h, a1 = [], [], 0
    for k in range(1, STEPS + 1):
        a = (((k % cols) << 32) + cols // 2) // cols
        a = (1 << 32) - a if a > (1 << 31) else a
        a1 = a if k == 1 else a1
        s, h = tab(a)
        col_s.append(s)
        col_h.append(h)
    row_s, row_h = [], []
    for r in range(rows):
        for k in range(1, STEPS + 1):
            s, h = tab(abs(e[r] - e[r + k]) & M32 if r + k < rows else 0)
            row_s.append(s)
            row_h.append(h)
    diag_s, diag_h = [0] * rows, [0] * rows
    hc = _h_of(_i(qm.sin(a1 >> 1)))
    for r in range(rows - 1):
        h1 = _h_of(_i(qm.sin((abs(e[r] - e[r + 1]) & M32) >> 1)))
        c12 = _i(qm.rshift_round(_i(qm.cos(e[r])) * _i(qm.cos(e[r + 1])), 30))
        hh = min(h1 + _i(qm.rshift_round(c12 * hc, 30)), M32)
        sh = min((_i(qm.isqrt(hh << 30)) + 1) >> 1, 1 << 30)
        ch = _i(qm.isqrt((1 << 60) - sh * sh))
        diag_s[r] = tab((_i(qm.atan2(sh, ch)) * 2) & M32)[0]
        diag_h[r] = hh
    return sin_t, col_s, col_h, row_s, row_h, diag_s, diag_h


@dataclass
class Rec:
    n_points: int
    first_member: int
    seed_pixel: int
    n_rescued: int
    mean: list
    min: list
    max: list
    height: int
    sums: list = field(default_factory=list)


STAT_KEYS = ["n_candidates", "n_found", "n_fragments", "n_rescue_joined", "n_rescue_pixels", "n_dropped_small",
             "n_dropped_extent", "n_dropped_height", "n_dropped_capacity", "n_kept", "n_pixels_kept",
             "n_queue_overflow",
             # the refinement (refine_q; lidet_refine_q.c)
             "n_split", "n_split_parts", "n_split_skipped", "n_joined", "n_join_skipped",
             # issue 19's bounds: the rescue budget (max_fragment_pixels) and the bridging budget
             # (max_bridge_per_pixel_q16)
             "n_fragment_pixels", "n_dropped_fragment_budget", "n_bridge_steps",
             # the regrowth of over-extent components (regrow_gap_mm)
             "n_regrown", "n_regrow_parts"]
REFINE_MAX_CELLS, REFINE_MAX_POINTS, REFINE_MAX_PARTS = 4096, 4096, 32  # lidet_opt.h defaults


def cluster_q_ref(x, y, z, rng, row_elev_bam, ground=None, planes_q=None, cfg: dict | None = None,
                  max_clusters: int = 1024):
    """Integer clustering of a compact image ((rows, cols) int16 x, y, z, uint16 range, (rows,) BAM32
    elevations; ground (rows, cols) uint8 or None; planes_q (S, 4) int or None). cfg: lidet_cluster_q_cfg_t
    fields (all required). Returns (labels (rows, cols) int64, members int64, list of Rec, stats dict)."""
    c = dict(cfg)
    rows, cols = np.asarray(rng).shape
    npix = rows * cols
    X = [int(v) for v in np.asarray(x).ravel()]
    Y = [int(v) for v in np.asarray(y).ravel()]
    Z = [int(v) for v in np.asarray(z).ravel()]
    R = [int(v) for v in np.asarray(rng).ravel()]
    G = [0] * npix if ground is None else [int(v) for v in np.asarray(ground).ravel()]
    PL = None if planes_q is None else [[int(v) for v in p] for p in np.asarray(planes_q).reshape(-1, 4)]
    sin_t, col_s, col_h, row_s, row_h, diag_s, diag_h = tables(row_elev_bam, cols, c["theta_urad"])
    ks = c["max_steps"]
    kc = min(ks, cols - 1)
    occl, diag = c["bridge_occluders"] != 0, c["diagonals"] != 0
    # the join test's gap bound: the first fill's, or the regrowth's (regrow_gap_mm) while it runs
    gp = {"on": c["max_gap_mm"] > 0, "gap": _div_round(c["max_gap_mm"], 4), "gpm": c["max_gap_per_m_q16"]}
    loose = dict(gp)
    tight = {"on": True, "gap": _div_round(c.get("regrow_gap_mm", 0), 4), "gpm": c.get("regrow_gap_per_m_q16", 0)}
    rgap, rgpm = _div_round(c["rescue_gap_mm"], 4), c["rescue_gap_per_m_q16"]
    wr, wc = c["rescue_rows"], min(c["rescue_cols"], (cols - 1) // 2)
    mount4 = _div_round(c["mount_height_mm"], 4)
    st = dict.fromkeys(STAT_KEYS, 0)

    lab = [FREE if (R[p] > 0 and G[p] == 0) else NONCAND for p in range(npix)]
    st["n_candidates"] = sum(1 for v in lab if v == FREE)
    bq = c["max_bridge_per_pixel_q16"]
    bridge_max = (bq * st["n_candidates"]) >> 16 if bq > 0 else M32
    mem: list = []
    recs: list = []

    def link(da, db, s, h):
        d1, d2 = (da, db) if da > db else (db, da)
        if not d2 * s > d1 * sin_t:
            return False
        if gp["on"]:
            gg = gp["gap"] + ((d2 * gp["gpm"] + 32768) >> 16)
            dd = d1 - d2
            if dd > gg:
                return False
            cross = ((((d1 * d2) * h) >> 29) + 1) >> 1
            return dd * dd + cross <= gg * gg
        return True

    def take(n):
        lab[n] = PENDING
        mem.append(n)

    def search(q, dq, step, nk, ta, tb, base, gs, occl):
        n = q
        if not occl:
            k = 0
            while True:
                n += step
                lv = lab[n]
                if lv != NONCAND:
                    break
                k += 1
                if k >= nk:
                    break
            if lv == FREE and link(dq, R[n], ta[base + k * gs], tb[base + k * gs]):
                take(n)
            return
        for k in range(nk):
            n += step
            lv = lab[n]
            if lv == NONCAND:
                continue
            dn = R[n]
            t = base + k * gs
            if lv == FREE:
                if link(dq, dn, ta[t], tb[t]):
                    take(n)
                    break
                if not dn < dq:
                    break
            elif not dn < dq or link(dq, dn, ta[t], tb[t]):
                break
            st["n_bridge_steps"] += 1

    def search_wrap(dq, rowbase, col, right, occl):
        for k in range(1, kc + 1):
            n = rowbase + ((col + k) % cols if right else (col - k) % cols)
            lv = lab[n]
            if lv == NONCAND:
                continue
            dn = R[n]
            ok = link(dq, dn, col_s[k - 1], col_h[k - 1])
            if lv == FREE and ok:
                take(n)
                break
            if not occl or not dn < dq or (lv != FREE and ok):
                break
            st["n_bridge_steps"] += 1

    def grow(start):
        head = start
        while head < len(mem):
            q = mem[head]
            head += 1
            r, col = divmod(q, cols)
            rowbase = r * cols
            dq = R[q]
            nd, nu = min(rows - 1 - r, ks), min(r, ks)
            oc = occl and st["n_bridge_steps"] < bridge_max  # the bridging budget, decided per pixel
            if col + kc < cols:
                search(q, dq, 1, kc, col_s, col_h, 0, 1, oc)
            else:
                search_wrap(dq, rowbase, col, True, oc)
            if col >= kc:
                search(q, dq, -1, kc, col_s, col_h, 0, 1, oc)
            else:
                search_wrap(dq, rowbase, col, False, oc)
            if nd > 0:
                search(q, dq, cols, nd, row_s, row_h, r * STEPS, 1, oc)
            if nu > 0:
                search(q, dq, -cols, nu, row_s, row_h, (r - 1) * STEPS, 1 - STEPS, oc)
            if diag:
                cl = col - 1 if col > 0 else cols - 1
                cr = col + 1 if col + 1 < cols else 0
                for rr, t in ((r + 1, r), (r - 1, r - 1)):
                    if 0 <= rr < rows:
                        for n in (rr * cols + cl, rr * cols + cr):
                            if lab[n] == FREE and link(dq, R[n], diag_s[t], diag_h[t]):
                                take(n)

    def stats_of(ms):
        out = []
        for P in (X, Y, Z):
            v = [P[m] for m in ms]
            out.append((sum(v), min(v), max(v)))
        return out

    split = int(c.get("plane_split_mm", 0))

    def height(seed, mean):
        if PL is not None:
            ns = len(PL) // 2 if split > 0 else len(PL)  # with a split: near planes, then far planes
            s = min((seed % cols) * ns // cols, ns - 1)
            if split > 0 and 16 * (mean[0] * mean[0] + mean[1] * mean[1]) >= split * split:
                s += ns  # its sector's far plane
            nx, ny, nz, d = PL[s]
            h = ((nx * mean[0] + ny * mean[1] + nz * mean[2] + (1 << 29)) >> 30) + d
        else:
            h = mean[2] + mount4
        return max(min(h, 0x7FFFFFFF), -0x7FFFFFFF)

    def claim(n, rescue):
        if len(recs) < max_clusters:
            recs.append(None)
            return len(recs) - 1
        m = 0
        for i in range(1, len(recs)):
            a, b = recs[i], recs[m]
            if a.n_points < b.n_points or (a.n_points == b.n_points and a.seed_pixel > b.seed_pixel):
                m = i
        st["n_dropped_capacity"] += 1
        if rescue or n <= recs[m].n_points:
            return None
        for i in range(recs[m].first_member, recs[m].first_member + recs[m].n_points):
            lab[mem[i]] = PENDING
        return m

    def finish(start, rescue, regrow=True):
        ms = mem[start:]
        n = len(ms)
        if not rescue:
            st["n_found"] += 1
        small = n < c["min_points"]
        if small and (rescue or c["rescue_gap_mm"] == 0):
            st["n_dropped_small"] += 1
            del mem[start:]
            return
        budget = c["max_fragment_pixels"]
        if small and budget != 0 and st["n_fragment_pixels"] + n > budget:
            st["n_dropped_fragment_budget"] += 1
            del mem[start:]
            return
        sx = stats_of(ms)
        lim = M32 if small else c["max_extent_mm"]
        if any((hi - lo) * 4 > lim for _, lo, hi in sx):
            mp = c.get("regrow_max_pixels", 0)
            if (regrow and not rescue and not small and c.get("regrow_gap_mm", 0) > 0 and (mp == 0 or n <= mp)
                    and 4 * (sx[2][2] - sx[2][1]) <= c["regrow_max_height_mm"]
                    and st["n_candidates"] <= npix and n <= npix - st["n_candidates"]):
                # grown again from its own pixels (in its order) with the tighter gap; each part is filtered
                del mem[start:]
                st["n_regrown"] += 1
                cut = c.get("regrow_cut_mm", 0)
                for m in ms:
                    # the pixels less than regrow_cut_mm above their ground plane are left out
                    lab[m] = NONCAND if cut > 0 and 4 * height(m, [X[m], Y[m], Z[m]]) < cut else FREE
                gp.update(tight)
                for m in ms:
                    if lab[m] != FREE:
                        continue
                    s0 = len(mem)
                    take(m)
                    grow(s0)
                    st["n_regrow_parts"] += 1
                    k = min(range(s0, len(mem)), key=lambda i: mem[i])  # the part's seed: its first pixel in raster
                    mem[s0], mem[k] = mem[k], mem[s0]                  # order, put first (as the C)
                    gp.update(loose)
                    finish(s0, False, False)
                    gp.update(tight)
                gp.update(loose)
                return
            st["n_dropped_extent"] += 1
            del mem[start:]
            return
        mean = [_div_round(s, n) for s, _, _ in sx]
        h = height(ms[0], mean)
        if h * 4 > c["max_mean_height_mm"]:
            st["n_dropped_height"] += 1
            del mem[start:]
            return
        if small:
            st["n_fragment_pixels"] += n
            st["n_fragments"] += 1
            for m in ms:
                lab[m] = SMALL
            del mem[start:]
            return
        slot = claim(n, rescue)
        if slot is None:
            del mem[start:]
            return
        recs[slot] = Rec(n, start, ms[0], n if rescue else 0, mean, [v[1] for v in sx], [v[2] for v in sx], h,
                         [v[0] for v in sx])
        if rescue:
            st["n_rescue_pixels"] += n
        for m in ms:
            lab[m] = slot + 1

    def join(slot, start):
        ms = mem[start:]
        n = len(ms)
        rec = recs[slot]
        sx = stats_of(ms)
        rec.n_points += n
        rec.n_rescued += n
        for a in range(3):
            rec.sums[a] += sx[a][0]
            rec.min[a] = min(rec.min[a], sx[a][1])
            rec.max[a] = max(rec.max[a], sx[a][2])
        rec.mean = [_div_round(s, rec.n_points) for s in rec.sums]
        for m in ms:
            lab[m] = slot + 1
        rec.seed_pixel = min(rec.seed_pixel, ms[0])
        rec.height = height(rec.seed_pixel, rec.mean)
        st["n_rescue_joined"] += 1
        st["n_rescue_pixels"] += n
        del mem[start:]

    for p in range(npix):
        if lab[p] != FREE:
            continue
        start = len(mem)
        take(p)
        grow(start)
        finish(start, False)

    if st["n_fragments"] > 0:
        for p in range(npix):
            if lab[p] != SMALL:
                continue
            start = len(mem)
            take(p)
            best, best_d2 = 0, M32
            head = start
            while head < len(mem):
                q = mem[head]
                head += 1
                r, col = divmod(q, cols)
                dq = R[q]
                c0 = col - wc if col >= wc else col + cols - wc
                for rr in range(max(r - wr, 0), min(r + wr, rows - 1) + 1):
                    for k in range(2 * wc + 1):
                        n = rr * cols + (c0 + k) % cols
                        lv = lab[n]
                        if lv >= PENDING or n == q:
                            continue
                        dn = R[n]
                        gg = rgap + ((min(dn, dq) * rgpm + 32768) >> 16)
                        dx, dy, dz = X[n] - X[q], Y[n] - Y[q], Z[n] - Z[q]
                        if abs(dn - dq) > gg or abs(dx) > gg or abs(dy) > gg or abs(dz) > gg:
                            continue
                        dd = dx * dx + dy * dy + dz * dz
                        if dd > gg * gg:
                            continue
                        if lv == SMALL:
                            take(n)
                        elif dd < best_d2:
                            best, best_d2 = lv, dd
            if best:
                join(best - 1, start)
            else:
                finish(start, True)

    labels, members, out_recs = _canonical(lab, recs, st)
    if c["split_people"] or c["join_cars"]:
        labels, members, out_recs = refine_q(labels, members, out_recs, X, Y, Z, cols, c, st, height, max_clusters)
    return labels.reshape(rows, cols), np.asarray(members, np.int64), out_recs, st


def _canonical(lab, recs, st: dict):
    """The canonical pass (canonicalise): records in seed order (stable), per-pixel slot labels (1..; 0 or >= SMALL:
    none) to ids, members regrouped in raster order. Returns (labels (npix,) int64, members list, records)."""
    order = sorted(range(len(recs)), key=lambda i: recs[i].seed_pixel)
    slot_id = {s + 1: i + 1 for i, s in enumerate(order)}
    labels = np.zeros(len(lab), np.int64)
    groups: list = [[] for _ in order]
    for p, lv in enumerate(lab):
        if 0 < lv < SMALL:
            labels[p] = slot_id[lv]
            groups[slot_id[lv] - 1].append(p)
    out_recs, members, first = [], [], 0
    for i, s in enumerate(order):
        rec = recs[s]
        rec.first_member = first
        first += rec.n_points
        members.extend(groups[i])
        out_recs.append(rec)
    st["n_pixels_kept"] = first
    st["n_kept"] = len(recs)
    return labels, members, out_recs


def _sat16(v: int) -> int:
    return max(-32768, min(32767, v))


def make_proposal_q(rec: Rec, members, x, y, z, cfg: dict):
    """lidet_proposal_q_make of one record (members: the canonical member array; x, y, z the image's int16
    planes; cfg: lidet_proposal_q_cfg_t fields). Returns (xyz (n_points, 3) int16, mean (3,) int32, voxel
    (3,) int16). cfg z_origin 1 (LIDET_PROPOSAL_Z_GROUND): z from the ground under the mean (mean z minus the
    record's height), which is then the returned mean's z."""
    X, Y, Z = (np.asarray(a).ravel() for a in (x, y, z))
    mx, my, mz = rec.mean
    zo = mz - rec.height if int(cfg.get("z_origin", 0)) == 1 else mz
    own = np.asarray(members)[rec.first_member: rec.first_member + rec.n_points]
    pix = own[proposal_indices(rec.n_points, cfg["n_points"], cfg["seed"], own)]
    xyz = np.array([[_sat16(int(P[p]) - m) for P, m in ((X, mx), (Y, my), (Z, zo))] for p in pix], np.int16)
    rxy2 = mx * mx + my * my

    def b(v, bin_):
        return _sat16(v // bin_)

    vox = np.array([b(_i(qm.atan2(my, mx)), cfg["azimuth_bin_bam"]),
                    b(_i(qm.atan2(mz, _i(qm.sqrt_round(rxy2)))), cfg["elevation_bin_bam"]),
                    b(_i(qm.sqrt_round(rxy2 + mz * mz)), cfg["range_bin_4mm"])], np.int16)
    return xyz, np.array([mx, my, zo], np.int32), vox


def _span_mm(lo: int, hi: int) -> int:
    return (hi - lo) * 4


def refine_q(labels, members, recs, X, Y, Z, cols: int, c: dict, st: dict, height, max_clusters: int):
    """The refinement of lib/src/cluster/lidet_refine_q.c (control flow: lib/src/internal/lidet_refine_body.h) on
    the canonical output (labels: per-pixel canonical ids; members; recs in id order), then the canonical pass
    again when it changed anything. Updates st; returns (labels, members, recs)."""
    lab = [int(v) for v in labels]
    mem = [int(v) for v in members]
    recs = list(recs)
    mp = c["min_points"]
    pmin = c["person_min_points"]  # a person-sized part needs this many pixels (lidet_cluster.h)
    order = [0] * len(recs)
    changed = False

    def rebuild(slot, src_first, src_n):
        ms = [p for p in mem[src_first:src_first + src_n] if lab[p] == slot + 1]
        n = len(ms)
        sums = [sum(P[p] for p in ms) for P in (X, Y, Z)]
        mean = [_div_round(v, n) for v in sums]
        r = Rec(n, src_first, ms[0], 0, mean, [min(P[p] for p in ms) for P in (X, Y, Z)],
                [max(P[p] for p in ms) for P in (X, Y, Z)], height(ms[0], mean), sums)
        if slot < len(recs):
            recs[slot] = r
        else:
            recs.append(r)
            order.append(0)
        return r

    # the cuts (split_people)
    k0 = len(recs)
    for k in range(k0 if c["split_people"] else 0):
        rec = recs[k]
        n0, f0 = rec.n_points, rec.first_member
        if n0 < pmin + min(pmin, mp) or n0 > REFINE_MAX_POINTS:
            continue
        ex, ey = _span_mm(rec.min[0], rec.max[0]), _span_mm(rec.min[1], rec.max[1])
        if not ((ex > c["split_min_width_mm"] or ey > c["split_min_width_mm"])
                and _span_mm(rec.min[2], rec.max[2]) >= c["person_min_height_mm"]):
            continue
        ax, ay = abs(rec.min[0] + rec.max[0]), abs(rec.min[1] + rec.max[1])
        r_mm = 2 * (ax + (ay >> 1) if ax > ay else ay + (ax >> 1))
        cs = c["split_cell_mm"] + ((c["split_cell_per_m_q16"] * r_mm + 32768) >> 16)
        inv = ((1 << 40) + cs - 1) // cs
        nx, ny = ex // cs + 1, ey // cs + 1
        if nx > REFINE_MAX_CELLS or ny > REFINE_MAX_CELLS // nx:
            st["n_split_skipped"] += 1
            continue
        ms = mem[f0:f0 + n0]
        cell = []
        for p in ms:
            ix = min((_span_mm(rec.min[0], X[p]) * inv) >> 40, nx - 1)
            iy = min((_span_mm(rec.min[1], Y[p]) * inv) >> 40, ny - 1)
            cell.append(iy * nx + ix)
        part = grid_parts(cell, nx, ny)
        n_parts = max(part) + 1
        if n_parts > REFINE_MAX_PARTS:  # label_parts gives up at the part past the cap
            st["n_split_skipped"] += 1
            continue
        if n_parts == 1:
            continue
        pn = [0] * n_parts
        bx = [[nx, -1, ny, -1] for _ in range(n_parts)]
        bz = [[None, None] for _ in range(n_parts)]
        bc = [[cols, -1] for _ in range(n_parts)]
        for p, cl, q in zip(ms, cell, part):
            pn[q] += 1
            cx, cy, col = cl % nx, cl // nx, p % cols
            b = bx[q]
            b[0], b[1], b[2], b[3] = min(b[0], cx), max(b[1], cx), min(b[2], cy), max(b[3], cy)
            z = Z[p]
            bz[q][0] = z if bz[q][0] is None else min(bz[q][0], z)
            bz[q][1] = z if bz[q][1] is None else max(bz[q][1], z)
            bc[q][0], bc[q][1] = min(bc[q][0], col), max(bc[q][1], col)
        person = []
        for q in range(n_parts):
            wx, wy = (bx[q][1] - bx[q][0] + 1) * cs, (bx[q][3] - bx[q][2] + 1) * cs
            wz = _span_mm(bz[q][0], bz[q][1])
            person.append(pn[q] >= pmin and wx <= c["person_max_width_mm"] and wy <= c["person_max_width_mm"]
                          and wz >= c["person_min_height_mm"] and (wz << 16) >= c["person_min_aspect_q16"] * max(wx, wy)
                          and bc[q][1] - bc[q][0] + 1 >= c["person_min_cols"])
        if not any(person):
            continue
        largest = 0
        largest_person = None
        for q in range(n_parts):
            if pn[q] > pn[largest]:
                largest = q
            if person[q] and (largest_person is None or pn[q] > pn[largest_person]):
                largest_person = q
        target = [1 if person[q] else 0 for q in range(n_parts)]
        if all(person[q] for q in range(n_parts) if pn[q] >= mp):
            target[largest] = 0
        if sum(pn[q] for q in range(n_parts) if target[q] == 0) < mp:
            target[largest_person] = 0
        n_new, n_slots = 0, len(recs)
        for q in range(n_parts):
            if target[q] == 0:
                target[q] = k
            elif n_slots < max_clusters:
                target[q] = n_slots
                n_slots += 1
                n_new += 1
            else:
                target[q] = k
        if n_new == 0:
            continue
        for p, q in zip(ms, part):
            lab[p] = target[q] + 1
        rk = rebuild(k, f0, n0)
        rk.n_rescued = min(rec.n_rescued, rk.n_points)
        for q in range(n_parts):
            if target[q] != k:
                rebuild(target[q], f0, n0).n_rescued = 0
        order[k] = 1
        for q in range(n_parts):
            order[target[q]] = 1
        st["n_split"] += 1
        st["n_split_parts"] += n_new
        changed = True

    # the joins (join_cars)
    def piece(r):
        wx, wy, wz = (_span_mm(r.min[d], r.max[d]) for d in range(3))
        upright = wx <= c["upright_max_width_mm"] and wy <= c["upright_max_width_mm"] and wz >= c["person_min_height_mm"]
        return (not upright and wz <= c["car_max_height_mm"] and max(wx, wy) <= c["car_max_length_mm"]
                and min(wx, wy) <= c["car_max_width_mm"])

    def joinable(a, b):
        gx = max(b.min[0] - a.max[0], a.min[0] - b.max[0], 0) * 4
        gy = max(b.min[1] - a.max[1], a.min[1] - b.max[1], 0) * 4
        if gx * gx + gy * gy > c["join_gap_mm"] ** 2:
            return False
        ux, uy, uz = (_span_mm(min(a.min[d], b.min[d]), max(a.max[d], b.max[d])) for d in range(3))
        return (uz <= c["car_max_height_mm"] and c["car_min_length_mm"] <= max(ux, uy) <= c["car_max_length_mm"]
                and min(ux, uy) <= c["car_max_width_mm"])

    def member_sums(r):
        ms = mem[r.first_member:r.first_member + r.n_points]
        return [sum(P[p] for p in ms) for P in (X, Y, Z)]

    n_joined = 0
    kk = len(recs)
    # the car pieces, decided once in slot order; past max_join_pieces (0 = no limit) they join nothing
    n_pieces = 0
    for i in range(kk if c["join_cars"] else 0):
        if order[i] == 0 and piece(recs[i]):
            if c.get("max_join_pieces", 0) and n_pieces >= c["max_join_pieces"]:
                st["n_join_skipped"] += 1
                continue
            order[i] = 4
            n_pieces += 1
    for i in range(kk if c["join_cars"] else 0):
        a = recs[i]
        if order[i] != 4:
            continue
        sums = None
        for j in range(i + 1, kk):
            b = recs[j]
            if order[j] != 4 or not joinable(a, b):
                continue
            if sums is None:
                sums = member_sums(a)
            sb = member_sums(b)
            n = a.n_points + b.n_points
            sums = [u + v for u, v in zip(sums, sb)]
            a.mean = [_div_round(v, n) for v in sums]
            a.min = [min(u, v) for u, v in zip(a.min, b.min)]
            a.max = [max(u, v) for u, v in zip(a.max, b.max)]
            for p in mem[b.first_member:b.first_member + b.n_points]:
                lab[p] = i + 1
            a.n_points = n
            a.n_rescued += b.n_rescued
            a.seed_pixel = min(a.seed_pixel, b.seed_pixel)
            a.height = height(a.seed_pixel, a.mean)
            b.n_points = 0
            b.seed_pixel = M32
            order[j] = 2
            n_joined += 1
    st["n_joined"] += n_joined
    changed = changed or n_joined > 0
    if not changed:
        return np.asarray(lab, np.int64), mem, recs
    # the canonical pass again (the emptied records, seed 0xFFFFFFFF, ordered last, then dropped)
    out, new_mem, new_recs = _canonical(lab, recs, st)
    new_recs = new_recs[:len(new_recs) - n_joined]
    st["n_kept"] = len(new_recs)
    return out, new_mem, new_recs
