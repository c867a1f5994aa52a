# SPDX-License-Identifier: MIT
"""The integer tracker (docs/TRACKING.md, "Integer build"): numpy int64 mirror of lib/src/track/lidet_track_q.c,
bit for bit.

Every product and sum stays far inside int64 for the configuration ranges init accepts and positions within
2^20 mm (the C source's top comment gives the bounds), so numpy's int64 arithmetic equals the C's; divisions
round half away from zero (qmath.div_round = lidet__q_div_round), shifts half up (qmath.rshift_round), and
sin / cos / atan2 / isqrt are qmath's, the integer path's own.

Detections are int rows (cls, cx_mm, cy_mm, cz_mm, l_mm, w_mm, h_mm, yaw_bam, score_q15) of an (n, 9) array;
`quantise_dets` makes them from float rows (cls, x, y, z, l, w, h, yaw, score) in metres and radians, as the
detector's integer path has them (millimetres and Q15 rounded half away from zero, BAM32). Tracks come out as
int rows of TRACK_Q_FIELDS (lidet_track_q_t's fields).
"""
from __future__ import annotations

import math

import numpy as np

from lidet_ref import qmath as Q

COORD_MAX_MM = 1 << 20          # LIDET_TRACK_Q_COORD_MAX_MM
SIZE_MAX_MM = 100000            # LIDET_TRACK_Q_SIZE_MAX_MM
VMAX_MMPS = 100000              # LIDET_TRACK_Q_VMAX_MMPS
P_MAX = 2**31 - 1               # LIDET_TRACK_Q_P_MAX
DT_MAX_MS = 10000               # LIDET_TRACK_Q_DT_MAX_MS
COORD_MAX_Q8 = COORD_MAX_MM * 256
VMAX_Q8 = VMAX_MMPS * 256
G_CAP_Q8 = 1 << 25
H_CAP_Q8 = 1 << 24
VOTE_HALVE = 1 << 30
ONE_Q16 = 65536
HUNGARIAN_INF = (2**63 - 1) // 4
U32_MAX = 2**32 - 1
QUARTER, HALF = 1 << 30, 1 << 31

TENTATIVE, CONFIRMED, COASTING = 0, 1, 2
OUT_COASTING, OUT_TENTATIVE = 1, 2
ASSIGN_OPTIMAL, ASSIGN_GREEDY = 0, 1
OK, TRUNCATED, ERR_ARG, ERR_CONFIG, ERR_STATE = 0, 1, -1, -2, -5

#: lidet_tracker_q_cfg_t's fields in order, with their lengths (the bindings' flat config array)
CFG_FIELDS = (("meas_sigma_mm", 3), ("accel_sigma_mmps2", 3), ("init_vel_sigma_mmps", 3), ("gate_max_mm", 3),
              ("gate_chi2_q16", 1), ("class_penalty_q16", 1), ("assign", 1), ("confirm_hits", 1), ("max_misses", 1),
              ("birth_min_score_q15", 1), ("yaw_alpha_q15", 1), ("size_alpha_q15", 1), ("heading_speed_mmps", 1),
              ("heading_from_velocity", 1), ("report_misses", 3))
CFG_LEN = sum(n for _, n in CFG_FIELDS)

#: one output track (lidet_track_q_t), the bindings' flat rows
TRACK_Q_FIELDS = ("id", "cls", "state", "cx_mm", "cy_mm", "cz_mm", "l_mm", "w_mm", "h_mm", "yaw_bam", "vx_mmps",
                  "vy_mmps", "p_pp", "p_pv", "p_vv", "score_q15", "hits", "misses", "age", "det")

#: the same tracks in SI units: the layout of codegen/lidet_ref/track.py's TRACK_DTYPE
TRACK_DTYPE = np.dtype([
    ("id", "<u4"), ("cls", "u1"), ("state", "u1"),
    ("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("l", "<f4"), ("w", "<f4"), ("h", "<f4"), ("yaw", "<f4"),
    ("vx", "<f4"), ("vy", "<f4"), ("p_pp", "<f4"), ("p_pv", "<f4"), ("p_vv", "<f4"), ("score", "<f4"),
    ("hits", "<u4"), ("misses", "<u4"), ("age", "<u4"), ("det", "<i4")])

STATS = ("n_tracks", "n_confirmed", "n_births", "n_births_dropped", "n_deaths", "n_matched", "n_feasible_pairs",
         "n_dets_dropped", "n_bad_dets")

BAM_PER_RAD = 2.0**32 / (2.0 * math.pi)


def _rha(v):
    """round half away from zero (float64 arrays -> float64 integers)."""
    v = np.asarray(v, dtype=np.float64)
    return np.sign(v) * np.floor(np.abs(v) + 0.5)


def wrap_bam(a):
    """int64 -> signed BAM32 (two's complement of the low 32 bits)."""
    a = np.asarray(a, dtype=np.int64)
    return ((a + HALF) & U32_MAX) - HALF


# ---- conversions ----------------------------------------------------------------------------------------------

def quantise_dets(dets) -> np.ndarray:
    """Float detections (n, 9): cls, x, y, z, l, w, h (m), yaw (rad), score -> int64 (n, 9) as the detector's
    integer path has them: lengths in mm rounded half away from zero (saturated to int32), yaw in BAM32
    (round half away from zero of yaw 2^32 / 2 pi, wrapped), score in Q15 (rounded, clipped to [0, 32768]).
    A row with a non-finite field or a class other than 0, 1, 2 gets class 255 (the tracker skips and counts it)."""
    d = np.asarray(dets, dtype=np.float64).reshape(-1, 9)
    out = np.zeros(d.shape, np.int64)
    finite = np.isfinite(d).all(axis=1)
    good = finite & np.isin(d[:, 0], (0.0, 1.0, 2.0))
    dd = np.where(finite[:, None], d, 0.0)
    out[:, 0] = np.where(good, dd[:, 0], 255).astype(np.int64)
    lim = float(2**31 - 1)
    out[:, 1:7] = np.clip(_rha(dd[:, 1:7] * 1000.0), -lim, lim).astype(np.int64)
    turn = np.remainder(dd[:, 7], 2.0 * math.pi)  # [0, 2 pi): keeps the product small
    out[:, 7] = wrap_bam(_rha(turn * BAM_PER_RAD).astype(np.int64))
    out[:, 8] = np.clip(_rha(dd[:, 8] * 32768.0), 0, 32768).astype(np.int64)
    return out


def quantise_ego(ego):
    """(dx, dy, dyaw) in metres and radians -> (dx_mm, dy_mm, dyaw_bam) ints, as quantise_dets rounds."""
    if ego is None:
        return None
    e = np.asarray(ego, dtype=np.float64).reshape(3)
    if not np.isfinite(e).all():
        raise ValueError("ego motion not finite")
    lim = float(2**31 - 1)
    dx, dy = (int(np.clip(_rha(v * 1000.0), -lim, lim)) for v in e[:2])
    dyaw = int(wrap_bam(int(_rha(np.remainder(e[2], 2.0 * math.pi) * BAM_PER_RAD))))
    return dx, dy, dyaw


def quantise_dt(dt_s: float) -> int:
    """seconds -> ms, rounded half away from zero (0 stays 0: the tracker refuses it)."""
    return int(_rha(float(dt_s) * 1000.0))


def cfg_default() -> dict:
    """lidet_tracker_q_cfg_default (the C field names)."""
    return {
        "meas_sigma_mm": [300, 250, 200],
        "accel_sigma_mmps2": [2000, 2500, 1500],
        "init_vel_sigma_mmps": [10000, 6000, 3000],
        "gate_max_mm": [4000, 3000, 2000],
        "gate_chi2_q16": 603587,
        "class_penalty_q16": 2 * ONE_Q16,
        "assign": ASSIGN_OPTIMAL,
        "confirm_hits": 2,
        "max_misses": 12,
        "report_misses": [1, 1, 0],
        "birth_min_score_q15": 0,
        "yaw_alpha_q15": 16384,
        "size_alpha_q15": 9830,
        "heading_speed_mmps": 1000,
        "heading_from_velocity": (1 << 2) | (1 << 1),
    }


#: float field (lidet_tracker_cfg_t, ref/track.py) -> (integer field, scale)
FLOAT_FIELDS = {
    "meas_sigma_m": ("meas_sigma_mm", 1000.0), "accel_sigma_mps2": ("accel_sigma_mmps2", 1000.0),
    "init_vel_sigma_mps": ("init_vel_sigma_mmps", 1000.0), "gate_max_m": ("gate_max_mm", 1000.0),
    "gate_chi2": ("gate_chi2_q16", 65536.0), "class_penalty": ("class_penalty_q16", 65536.0),
    "birth_min_score": ("birth_min_score_q15", 32768.0), "yaw_alpha": ("yaw_alpha_q15", 32768.0),
    "size_alpha": ("size_alpha_q15", 32768.0), "heading_speed_mps": ("heading_speed_mmps", 1000.0),
}


#: docs/TRACKING.md's names (as lidet_tools.track.Tracker takes them) -> the float field names
ALIASES = {"meas_sigma": "meas_sigma_m", "accel_sigma": "accel_sigma_mps2", "init_vel_sigma": "init_vel_sigma_mps",
           "gate_max": "gate_max_m", "heading_speed": "heading_speed_mps"}
CLASSES = ("car", "cyclist", "pedestrian")


def cfg_from(**overrides) -> dict:
    """The defaults with overrides given by integer field name (meas_sigma_mm=...), by the float tracker's field
    name in SI units (meas_sigma_m=..., gate_chi2=...) or docs/TRACKING.md's name (meas_sigma=..., converted,
    rounded half away from zero); assign (0, 1, "optimal", "greedy"), confirm_hits, max_misses and
    heading_from_velocity (a bit mask, or class names / indices) are shared. A per-class field takes a scalar
    (every class) or 3 values. Unknown names raise TypeError."""
    c = cfg_default()
    for key, v in overrides.items():
        k = ALIASES.get(key, key)
        if k == "assign" and isinstance(v, str):
            if v not in ("optimal", "greedy"):
                raise ValueError(f"assign: {v!r} is not 'optimal' or 'greedy'")
            v = ASSIGN_OPTIMAL if v == "optimal" else ASSIGN_GREEDY
        if k == "heading_from_velocity" and not np.isscalar(v):
            v = sum(1 << (CLASSES.index(x) if isinstance(x, str) else int(x)) for x in v)
        if k in c:
            name, scale = k, None
        elif k in FLOAT_FIELDS:
            name, scale = FLOAT_FIELDS[k]
        else:
            raise TypeError(f"unknown tracker field {key!r}")
        if isinstance(c[name], list):
            vals = np.broadcast_to(np.asarray(v, dtype=np.float64), (3,))
        else:
            vals = np.asarray([v], dtype=np.float64)
        if scale is not None:
            vals = _rha(vals * scale)
        elif not np.all(vals == np.floor(vals)):
            raise ValueError(f"{key}: expected integers, got {v!r}")
        ints = [int(x) for x in vals]
        c[name] = ints if isinstance(c[name], list) else ints[0]
    return c


def cfg_to_array(c: dict) -> np.ndarray:
    """The flat int64 array of CFG_FIELDS (what ports/python/lidet_py_track_q.c reads)."""
    vals = []
    for name, n in CFG_FIELDS:
        v = c[name]
        vals += [int(x) for x in v] if n > 1 else [int(v)]
    return np.asarray([min(max(x, -2**63), 2**63 - 1) for x in vals], np.int64)  # init refuses what saturates


def cfg_ok(c: dict) -> bool:
    """lidet_tracker_q_init's checks (cfg_ok)."""
    def rng(v, lo, hi):
        return lo <= int(v) <= hi

    for k in range(3):
        if not (rng(c["meas_sigma_mm"][k], 1, 10000) and rng(c["accel_sigma_mmps2"][k], 0, 100000)
                and rng(c["init_vel_sigma_mmps"][k], 0, 46340) and rng(c["gate_max_mm"][k], 1, 1000000)):
            return False
    return (rng(c["gate_chi2_q16"], 1, 1000 * ONE_Q16) and rng(c["class_penalty_q16"], 0, 1000 * ONE_Q16)
            and int(c["assign"]) in (ASSIGN_OPTIMAL, ASSIGN_GREEDY) and rng(c["confirm_hits"], 1, 1000)
            and rng(c["max_misses"], 0, 1000) and rng(c["birth_min_score_q15"], 0, 32768)
            and rng(c["yaw_alpha_q15"], 0, 32768) and rng(c["size_alpha_q15"], 0, 32768)
            and rng(c["heading_speed_mmps"], 0, VMAX_MMPS) and rng(c["heading_from_velocity"], 0, 7)
            and all(rng(v, 0, 1000) for v in c["report_misses"]))


def tracks_to_si(rows) -> np.ndarray:
    """Integer track rows (TRACK_Q_FIELDS) -> TRACK_DTYPE records in metres, radians, m/s, m^2, m^2/s, m^2/s^2."""
    r = np.asarray(rows, dtype=np.int64).reshape(-1, len(TRACK_Q_FIELDS))
    out = np.zeros(len(r), TRACK_DTYPE)
    f = {name: r[:, i] for i, name in enumerate(TRACK_Q_FIELDS)}
    for a, b in (("id", "id"), ("cls", "cls"), ("state", "state"), ("hits", "hits"), ("misses", "misses"),
                 ("age", "age"), ("det", "det")):
        out[a] = f[b]
    for a, b in (("x", "cx_mm"), ("y", "cy_mm"), ("z", "cz_mm"), ("l", "l_mm"), ("w", "w_mm"), ("h", "h_mm"),
                 ("vx", "vx_mmps"), ("vy", "vy_mmps")):
        out[a] = f[b] / 1000.0
    out["yaw"] = f["yaw_bam"] / BAM_PER_RAD
    out["p_pp"] = f["p_pp"] / 1e6
    out["p_pv"] = f["p_pv"] / 1e6
    out["p_vv"] = f["p_vv"] / 1e6
    out["score"] = f["score_q15"] / 32768.0
    return out


# ---- the covariance guard and the assignment --------------------------------------------------------------

def cov_guard(pp, pv, vv):
    """cov_guard: p_pp, p_vv into [1, P_MAX], |p_pv| <= P_MAX, then p_pv^2 < p_pp p_vv (floor(sqrt(p_pp p_vv - 1)))."""
    pp = np.clip(np.asarray(pp, np.int64), 1, P_MAX)
    vv = np.clip(np.asarray(vv, np.int64), 1, P_MAX)
    pv = np.clip(np.asarray(pv, np.int64), -P_MAX, P_MAX)
    bad = pv * pv >= pp * vv
    m = pp * vv - 1
    lim = np.where(m > 0, Q.isqrt(np.maximum(m, 1)), 0)
    pv = np.where(bad, np.where(pv < 0, -lim, lim), pv)
    return pp, pv, vv


def hungarian(cost, big: int) -> np.ndarray:
    """hungarian: the minimum-cost assignment of the nr x nc int costs padded to n = max(nr, nc) with big, by
    shortest augmenting paths with potentials, rows added in order, columns scanned in order, ties to the lower
    column (the C's strict <). Returns row -> column (-1: none, or only at cost big)."""
    cost = np.asarray(cost, dtype=np.int64)
    nr, nc = cost.shape
    n = max(nr, nc)
    a = np.full((n + 1, n + 1), int(big), np.int64)
    a[1:nr + 1, 1:nc + 1] = cost
    u = np.zeros(n + 1, np.int64)
    v = np.zeros(n + 1, np.int64)
    p = np.zeros(n + 1, np.int64)
    way = np.zeros(n + 1, np.int64)
    for i in range(1, n + 1):
        p[0] = i
        j0 = 0
        minv = np.full(n + 1, HUNGARIAN_INF, np.int64)
        used = np.zeros(n + 1, bool)
        while True:
            used[j0] = True
            i0 = p[j0]
            free = np.flatnonzero(~used[1:]) + 1
            cur = a[i0, free] - u[i0] - v[free]
            upd = cur < minv[free]
            minv[free[upd]] = cur[upd]
            way[free[upd]] = j0
            j1 = int(free[int(np.argmin(minv[free]))])  # the first minimum: the C's strict <
            delta = minv[j1]
            uj = np.flatnonzero(used)
            u[p[uj]] += delta
            v[uj] -= delta
            minv[~used] -= delta
            j0 = j1
            if p[j0] == 0:
                break
        while True:
            j1 = way[j0]
            p[j0] = p[j1]
            j0 = j1
            if j0 == 0:
                break
    row_col = np.full(nr, -1, np.int64)
    for j in range(1, n + 1):
        i = p[j]
        if 1 <= i <= nr and j <= nc and cost[i - 1, j - 1] < big:
            row_col[i - 1] = j - 1
    return row_col


def greedy(cost, big: int) -> np.ndarray:
    """greedy: row -> column (-1: none), the cheapest pair below big first; ties: lower row, then lower column."""
    c = np.array(cost, dtype=np.int64, copy=True)
    nr, nc = c.shape
    row_col = np.full(nr, -1, np.int64)
    while c.size:
        k = int(np.argmin(c))
        if c.flat[k] >= big:
            break
        r, j = divmod(k, nc)
        row_col[r] = j
        c[r, :] = big
        c[:, j] = big
    return row_col


def assign(cost, big: int, mode: int) -> np.ndarray:
    """lidet__track_q_assign: row -> column (-1: none)."""
    return greedy(cost, big) if int(mode) == ASSIGN_GREEDY else hungarian(cost, big)


# ---- the tracker ------------------------------------------------------------------------------------------------

class TrackerQ:
    """lidet_tracker_q_t: init (overrides as cfg_from), update, tracks, stats, reset. Capacities as the C build's
    LIDET_TRACK_MAX_TRACKS / LIDET_TRACK_MAX_DETS."""

    def __init__(self, max_tracks: int = 64, max_dets: int = 64, **cfg):
        c = cfg_from(**cfg)
        if not cfg_ok(c):
            raise ValueError("LIDET_ERR_CONFIG")
        self.cfg = c
        self.max_tracks = int(max_tracks)
        self.max_dets = int(max_dets)
        self.r = np.array(c["meas_sigma_mm"], np.int64) ** 2
        self.accel = np.array(c["accel_sigma_mmps2"], np.int64)
        self.vv0 = np.array(c["init_vel_sigma_mmps"], np.int64) ** 2
        self.gmax = np.array(c["gate_max_mm"], np.int64)
        self.chi2 = int(c["gate_chi2_q16"])
        self.pen = int(c["class_penalty_q16"])
        self.big = self.chi2 + self.pen + ONE_Q16
        self.reset()

    def reset(self) -> None:
        T = self.max_tracks
        self.active = np.zeros(T, bool)
        for f in ("x", "y", "vx", "vy", "pp", "pv", "vv", "cz", "l", "w", "h", "yaw", "id", "score", "hits",
                  "misses", "age", "state", "cls"):
            setattr(self, f, np.zeros(T, np.int64))
        self.det = np.full(T, -1, np.int64)
        self.votes = np.zeros((T, 3), np.int64)
        self.next_id = 1
        self.stats = dict.fromkeys(STATS, 0)

    @staticmethod
    def det_ok(d: np.ndarray) -> np.ndarray:
        """det_ok per int row: class 0-2, l, w, h in [1, SIZE_MAX_MM], score in [0, 32768], |centre| <= 2^20."""
        d = np.asarray(d, np.int64).reshape(-1, 9)
        ok = (d[:, 0] >= 0) & (d[:, 0] < 3) & (d[:, 8] >= 0) & (d[:, 8] <= 32768)
        for c in (1, 2, 3):
            ok &= np.abs(d[:, c]) <= COORD_MAX_MM
        for c in (4, 5, 6):
            ok &= (d[:, c] >= 1) & (d[:, c] <= SIZE_MAX_MM)
        return ok

    def update(self, dets, dt_ms: int, ego=None) -> int:
        """lidet_tracker_q_update on int rows (n, 9); ego (dx_mm, dy_mm, dyaw_bam) or None. Returns the status
        (ERR_ARG leaves everything unchanged)."""
        dets = np.asarray(dets, dtype=np.int64).reshape(-1, 9)
        dt_ms = int(dt_ms)
        if not 1 <= dt_ms <= DT_MAX_MS:
            return ERR_ARG
        if ego is not None:
            ego = tuple(int(e) for e in ego)
            if abs(ego[0]) > COORD_MAX_MM or abs(ego[1]) > COORD_MAX_MM:
                return ERR_ARG
        st = dict.fromkeys(STATS, 0)
        n_use = min(len(dets), self.max_dets)
        st["n_dets_dropped"] = len(dets) - n_use
        ok = self.det_ok(dets[:n_use])
        st["n_bad_dets"] = int((~ok).sum())
        cols = np.flatnonzero(ok)
        D = dets[cols]
        dcls = D[:, 0]
        self._ego_predict(dt_ms, ego, st)
        rows = np.flatnonzero(self.active)
        nr, nc = len(rows), len(cols)
        cost = self._costs(rows, D, dcls)
        st["n_feasible_pairs"] = int((cost < self.big).sum())
        row_col = np.full(nr, -1, np.int64)
        if nr > 0 and nc > 0 and st["n_feasible_pairs"] > 0:
            row_col = assign(cost, self.big, self.cfg["assign"])
        taken = np.zeros(nc, bool)
        taken[row_col[row_col >= 0]] = True
        m = row_col >= 0
        if m.any():
            self._update(rows[m], D[row_col[m]], cols[row_col[m]])
            st["n_matched"] = int(m.sum())
        for s in rows[~m]:
            self.misses[s] = min(self.misses[s] + 1, U32_MAX)
            if self.state[s] == TENTATIVE or self.misses[s] > int(self.cfg["max_misses"]):
                self.active[s] = False
                st["n_deaths"] += 1
            else:
                self.state[s] = COASTING
        for c in range(nc):
            if taken[c] or D[c, 8] < int(self.cfg["birth_min_score_q15"]):
                continue
            free = np.flatnonzero(~self.active)
            if len(free) == 0:
                st["n_births_dropped"] += 1
                continue
            self._birth(int(free[0]), D[c], int(cols[c]))
            self.next_id = 1 if self.next_id == U32_MAX else self.next_id + 1
            st["n_births"] += 1
        conf = self.active & (self.state == TENTATIVE) & (self.hits >= int(self.cfg["confirm_hits"]))
        self.state[conf] = CONFIRMED
        st["n_tracks"] = int(self.active.sum())
        st["n_confirmed"] = int((self.active & (self.state != TENTATIVE)).sum())
        self.stats = st
        return TRUNCATED if st["n_dets_dropped"] > 0 or st["n_births_dropped"] > 0 else OK

    def _ego_predict(self, dt_ms: int, ego, st) -> None:
        """_ego_predict (ego_predict): age + 1, the ego motion, the prediction; tracks leaving the range die."""
        s = np.flatnonzero(self.active)
        self.age[s] = np.minimum(self.age[s] + 1, U32_MAX)
        self.det[s] = -1
        x, y, vx, vy = self.x[s], self.y[s], self.vx[s], self.vy[s]
        if ego is not None:
            c, sn = int(Q.cos(ego[2] & U32_MAX)), int(Q.sin(ego[2] & U32_MAX))
            px = x - ego[0] * 256
            py = y - ego[1] * 256
            x = Q.rshift_round(c * px + sn * py, 30)
            y = Q.rshift_round(c * py - sn * px, 30)
            vx, vy = (np.clip(Q.rshift_round(c * vx + sn * vy, 30), -VMAX_Q8, VMAX_Q8),
                      np.clip(Q.rshift_round(c * vy - sn * vx, 30), -VMAX_Q8, VMAX_Q8))
            self.yaw[s] = wrap_bam(self.yaw[s] - ego[2])
        T = dt_ms
        x = x + Q.div_round(vx * T, 1000)
        y = y + Q.div_round(vy * T, 1000)
        self.vx[s], self.vy[s] = vx, vy
        alive = (np.abs(x) <= COORD_MAX_Q8) & (np.abs(y) <= COORD_MAX_Q8)
        dead = s[~alive]
        self.active[dead] = False
        st["n_deaths"] += len(dead)
        s, x, y = s[alive], x[alive], y[alive]
        self.x[s], self.y[s] = x, y
        a = self.accel[self.cls[s]]
        g = np.minimum(Q.div_round(T * T * a * 256, 1000000), G_CAP_Q8)
        h = np.minimum(Q.div_round(T * a * 256, 1000), H_CAP_Q8)
        pp, pv, vv = self.pp[s], self.pv[s], self.vv[s]
        self.pp[s], self.pv[s], self.vv[s] = cov_guard(
            pp + Q.div_round(2000 * T * pv + T * T * vv, 1000000) + Q.rshift_round(g * g, 18),
            pv + Q.div_round(T * vv, 1000) + Q.rshift_round(g * h, 17),
            vv + Q.rshift_round(h * h, 16))

    def _costs(self, rows, D, dcls) -> np.ndarray:
        """_costs: Q16 costs, big where infeasible."""
        gm = (self.gmax[self.cls[rows]] * 256)[:, None]
        dx = D[None, :, 1] * 256 - self.x[rows][:, None]
        dy = D[None, :, 2] * 256 - self.y[rows][:, None]
        near = (np.abs(dx) <= gm) & (np.abs(dy) <= gm)
        d2 = np.where(near, dx * dx + dy * dy, 0)
        S = self.pp[rows][:, None] + self.r[dcls][None, :]
        feas = near & (d2 <= gm * gm) & (d2 <= self.chi2 * S)
        cost = Q.div_round(d2, S) + np.where(dcls[None, :] != self.cls[rows][:, None], self.pen, 0)
        return np.where(feas, cost, self.big).astype(np.int64)

    def _update(self, s, D, index) -> None:
        """_update (update_track) of the tracks s with their detections D (rows), vectorised (s distinct)."""
        k = D[:, 0]
        r = self.r[k]
        pp, pv, vv = self.pp[s], self.pv[s], self.vv[s]
        S = pp + r
        ex = D[:, 1] * 256 - self.x[s]
        ey = D[:, 2] * 256 - self.y[s]
        self.x[s] = self.x[s] + Q.div_round(pp * ex, S)
        self.y[s] = self.y[s] + Q.div_round(pp * ey, S)
        self.vx[s] = np.clip(self.vx[s] + Q.div_round(pv * ex, S), -VMAX_Q8, VMAX_Q8)
        self.vy[s] = np.clip(self.vy[s] + Q.div_round(pv * ey, S), -VMAX_Q8, VMAX_Q8)
        self.pp[s], self.pv[s], self.vv[s] = cov_guard(Q.div_round(pp * r, S), Q.div_round(pv * r, S),
                                                       vv - Q.div_round(pv * pv, S))
        dyaw = wrap_bam(D[:, 7] - self.yaw[s])
        flip = (dyaw > QUARTER) | (dyaw < -QUARTER)
        dyaw = np.where(flip, wrap_bam(dyaw + HALF), dyaw)
        self.yaw[s] = wrap_bam(self.yaw[s] + Q.rshift_round(int(self.cfg["yaw_alpha_q15"]) * dyaw, 15))
        sa = int(self.cfg["size_alpha_q15"])
        for f, c in (("cz", 3), ("l", 4), ("w", 5), ("h", 6)):
            cur = getattr(self, f)
            cur[s] = cur[s] + Q.rshift_round(sa * (D[:, c] - cur[s]), 15)
        votes = self.votes[s]
        votes[np.arange(len(s)), k] += D[:, 8]
        halve = votes[np.arange(len(s)), k] >= VOTE_HALVE
        votes[halve] >>= 1
        self.votes[s] = votes
        self.cls[s] = np.argmax(votes, axis=1)  # first on ties
        self.hits[s] = np.minimum(self.hits[s] + 1, U32_MAX)
        self.misses[s] = 0
        self.score[s] = D[:, 8]
        self.det[s] = index
        st = self.state[s]
        self.state[s] = np.where(st == COASTING, CONFIRMED, st)

    def _birth(self, s: int, d, index: int) -> None:
        k = int(d[0])
        self.active[s] = True
        self.x[s], self.y[s] = int(d[1]) * 256, int(d[2]) * 256
        self.vx[s] = self.vy[s] = 0
        self.pp[s], self.pv[s], self.vv[s] = (int(v) for v in cov_guard(self.r[k], 0, self.vv0[k]))
        self.cz[s], self.l[s], self.w[s], self.h[s], self.yaw[s] = (int(d[i]) for i in (3, 4, 5, 6, 7))
        self.votes[s] = 0
        self.votes[s, k] = int(d[8])
        self.cls[s] = k
        self.id[s] = self.next_id
        self.score[s] = int(d[8])
        self.hits[s] = 1
        self.misses[s] = 0
        self.age[s] = 0
        self.det[s] = index
        self.state[s] = TENTATIVE

    # ---- output ----------------------------------------------------------------------------------------------
    def _report_yaw(self, s: int) -> int:
        """_report (report): the reported heading."""
        vx, vy, yaw = int(self.vx[s]), int(self.vy[s]), int(self.yaw[s])
        v2 = vx * vx + vy * vy
        hs = int(self.cfg["heading_speed_mmps"]) * 256
        if not (v2 > 0 and v2 >= hs * hs and v2 >= 4 * int(self.vv[s]) * 65536):
            return yaw
        mot = int(Q.atan2(vy, vx))
        if (int(self.cfg["heading_from_velocity"]) >> int(self.cls[s])) & 1:
            return mot
        dd = int(wrap_bam(yaw - mot))
        return int(wrap_bam(yaw + HALF)) if (dd > QUARTER or dd < -QUARTER) else yaw

    def tracks(self, flags: int = 0, cap: int | None = None) -> np.ndarray:
        """lidet_tracker_q_tracks: int64 rows of TRACK_Q_FIELDS in id order (the lowest cap ids)."""
        rep = np.asarray(self.cfg["report_misses"], np.int64)[np.minimum(self.cls, 2).astype(np.int64)]
        coast = bool(flags & OUT_COASTING) | (self.misses.astype(np.int64) <= rep)
        keep = self.active & ((self.state == CONFIRMED) | ((self.state == COASTING) & coast)
                              | ((self.state == TENTATIVE) & bool(flags & OUT_TENTATIVE)))
        s = np.flatnonzero(keep)
        s = s[np.argsort(self.id[s], kind="stable")]
        if cap is not None:
            s = s[:cap]
        out = np.zeros((len(s), len(TRACK_Q_FIELDS)), np.int64)
        for n, k in enumerate(s):
            out[n] = (self.id[k], self.cls[k], self.state[k], Q.rshift_round(self.x[k], 8),
                      Q.rshift_round(self.y[k], 8), self.cz[k], self.l[k], self.w[k], self.h[k], self._report_yaw(k),
                      Q.rshift_round(self.vx[k], 8), Q.rshift_round(self.vy[k], 8), self.pp[k], self.pv[k],
                      self.vv[k], self.score[k], self.hits[k], self.misses[k], self.age[k], self.det[k])
        return out
