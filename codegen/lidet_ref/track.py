# SPDX-License-Identifier: MIT
"""The tracker (docs/TRACKING.md), float build: numpy mirror of lib/src/track/lidet_track.c.

Every value is float32 and every expression is evaluated in the C source's order, one rounding per operation (the
library is built with -ffp-contract=off; numpy's float32 +, -, *, / and fmod round as C's do, element by element),
so the reference and the C agree to the last bit. The exceptions are the three libm calls: the reference takes
sin, cos and atan2 in float64 rounded to float32 (the correctly rounded values), where the C's sinf / cosf / atan2f
may be one unit in the last place off. sin and cos only run with an ego motion and enter the state there; atan2
only makes the reported yaw. Hence the parity test's tolerance (tests/python/test_track.py): ids, states, classes,
counters and detection indices identical; without ego motion every float bit for bit but the reported yaw (within
2e-6 rad); with ego motion every float within 1e-4 + 1e-5 |x| (a one-ulp sin or cos moves a 30 m position by
2e-6 m, and the Kalman gains carry that into the velocity). Measured on 80 random sequences with glibc: bit for
bit everywhere, the reported yaw at most 1 ulp (2.4e-7 rad) off.

Detections are rows (cls, x, y, z, l, w, h, yaw, score) of an (n, 9) array; a class that is not 0, 1 or 2 is an
invalid detection (the bindings pass it to C as class 255).
"""
from __future__ import annotations

import math

import numpy as np

F = np.float32
PI = F(3.14159265)        # LIDET_PI_F
HALF_PI = F(1.57079633)   # LIDET_HALF_PI_F
TWO_PI = F(6.28318531)
HUNG_INF = F(1.0e30)
MAX_DT_S = F(10.0)
MAX_EGO_M = F(1000.0)
MAX_CENTRE_M = F(10000.0)
MAX_SIZE_M = F(100.0)

TENTATIVE, CONFIRMED, COASTING = 0, 1, 2
OUT_COASTING, OUT_TENTATIVE = 1, 2
ASSIGN_OPTIMAL, ASSIGN_GREEDY = 0, 1
OK, TRUNCATED, ERR_ARG, ERR_CONFIG, ERR_STATE = 0, 1, -1, -2, -5

#: the output rows: one record per track (the layout lidet_tools.track.Tracker also returns)
TRACK_DTYPE = np.dtype([
    ("id", "<u4"), ("cls", "u1"), ("state", "u1"),
    ("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("l", "<f4"), ("w", "<f4"), ("h", "<f4"), ("yaw", "<f4"),
    ("vx", "<f4"), ("vy", "<f4"), ("p_pp", "<f4"), ("p_pv", "<f4"), ("p_vv", "<f4"), ("score", "<f4"),
    ("hits", "<u4"), ("misses", "<u4"), ("age", "<u4"), ("det", "<i4")])

STATS = ("n_tracks", "n_confirmed", "n_births", "n_births_dropped", "n_deaths", "n_matched", "n_feasible_pairs",
         "n_dets_dropped", "n_bad_dets")


def cfg_default() -> dict:
    """lidet_tracker_cfg_default (the C field names)."""
    return {
        "meas_sigma_m": [0.30, 0.25, 0.20],
        "accel_sigma_mps2": [2.0, 2.5, 1.5],
        "init_vel_sigma_mps": [10.0, 6.0, 3.0],
        "gate_max_m": [4.0, 3.0, 2.0],
        "gate_chi2": 9.21,
        "class_penalty": 2.0,
        "assign": ASSIGN_OPTIMAL,
        "confirm_hits": 2,
        "max_misses": 12,
        "report_misses": [1, 1, 0],
        "birth_min_score": 0.0,
        "yaw_alpha": 0.5,
        "size_alpha": 0.3,
        "heading_speed_mps": 1.0,
        "heading_from_velocity": (1 << 2) | (1 << 1),
    }


def cfg_ok(c: dict) -> bool:
    """lidet_tracker_init's checks (cfg_ok)."""
    def rng(v, lo, hi):
        return bool(F(v) >= F(lo)) and bool(F(v) <= F(hi))

    for k in range(3):
        if not (rng(c["meas_sigma_m"][k], 0.001, 100.0) and rng(c["accel_sigma_mps2"][k], 0.0, 100.0)
                and rng(c["init_vel_sigma_mps"][k], 0.0, 100.0) and F(c["gate_max_m"][k]) > 0
                and F(c["gate_max_m"][k]) <= F(1000.0)):
            return False
    if not (F(c["gate_chi2"]) > 0 and F(c["gate_chi2"]) <= F(1000.0) and rng(c["class_penalty"], 0.0, 1000.0)):
        return False
    if int(c["assign"]) not in (ASSIGN_OPTIMAL, ASSIGN_GREEDY):
        return False
    if not (1 <= int(c["confirm_hits"]) <= 1000 and 0 <= int(c["max_misses"]) <= 1000):
        return False
    if not all(0 <= int(v) <= 1000 for v in c["report_misses"]):
        return False
    if not (rng(c["birth_min_score"], 0, 1) and rng(c["yaw_alpha"], 0, 1) and rng(c["size_alpha"], 0, 1)
            and rng(c["heading_speed_mps"], 0, 100)):
        return False
    return 0 <= int(c["heading_from_velocity"]) < (1 << 3)


def wrap_pi(a):
    """wrap_pi: float32 angles into (-pi, pi] (fmod first beyond two turns, then single steps)."""
    a = np.array(a, dtype=F, copy=True)
    scalar = a.ndim == 0
    a = np.atleast_1d(a)
    bad = ~np.isfinite(a)
    a[bad] = a[bad] - a[bad]
    big = (a > TWO_PI) | (a < -TWO_PI)
    a[big] = np.fmod(a[big], TWO_PI)
    while np.any(a > PI):
        a = np.where(a > PI, a - TWO_PI, a)
    while np.any(a <= -PI):
        a = np.where(a <= -PI, a + TWO_PI, a)
    return a[0] if scalar else a


def det_ok(d: np.ndarray) -> np.ndarray:
    """det_ok per row of an (n, 9) float32 array: class 0-2, finite yaw and score, centre within 10 km, size in
    (0, 100] m."""
    d = np.asarray(d, dtype=F).reshape(-1, 9)
    with np.errstate(invalid="ignore"):
        ok = np.isin(d[:, 0], (0.0, 1.0, 2.0)) & np.isfinite(d[:, 7]) & np.isfinite(d[:, 8])
        for c in (1, 2, 3):
            ok &= (d[:, c] >= -MAX_CENTRE_M) & (d[:, c] <= MAX_CENTRE_M)
        for c in (4, 5, 6):
            ok &= (d[:, c] > 0) & (d[:, c] <= MAX_SIZE_M)
    return ok


def hungarian(a: np.ndarray) -> np.ndarray:
    """hungarian: minimum-cost assignment of the square float32 matrix a (n x n) by shortest augmenting paths
    with potentials, exactly as the C (rows added in order, ties to the lower column). Returns p: p[j] = the
    1-based row of column j (1-based), p[0] unused."""
    a = np.asarray(a, dtype=F)
    n = a.shape[0]
    u = np.zeros(n + 1, F)
    v = np.zeros(n + 1, F)
    p = np.zeros(n + 1, np.int64)
    way = np.zeros(n + 1, np.int64)
    for i in range(1, n + 1):
        p[0] = i
        j0 = 0
        minv = np.full(n + 1, HUNG_INF, F)
        used = np.zeros(n + 1, bool)
        for _ in range(n + 1):
            used[j0] = True
            i0 = p[j0]
            free = ~used[1:]
            cur = (a[i0 - 1, :] - u[i0]) - v[1:]
            upd = free & (cur < minv[1:])
            minv[1:][upd] = cur[upd]
            way[1:][upd] = j0
            cand = np.where(free, minv[1:], np.inf).astype(F)
            j1 = int(np.argmin(cand)) + 1
            delta = cand[j1 - 1]
            if not delta < HUNG_INF:  # never with finite costs
                break
            pu = p[used]
            u[pu] = u[pu] + delta
            v[used] = v[used] - delta
            minv[~used] = minv[~used] - delta
            j0 = j1
            if p[j0] == 0:
                break
        while j0 != 0:
            j1 = way[j0]
            p[j0] = p[j1]
            j0 = j1
    return p


def greedy(cost: np.ndarray, big) -> np.ndarray:
    """greedy: row -> column (-1: none), the cheapest feasible pair first; ties: lower row, then lower column."""
    c = np.array(cost, dtype=F, copy=True)
    nt, nd = c.shape
    row_col = np.full(nt, -1, np.int64)
    while c.size:
        k = int(np.argmin(c))
        if not c.flat[k] < big:
            break
        r, j = divmod(k, nd)
        row_col[r] = j
        c[r, :] = big
        c[:, j] = big
    return row_col


class Tracker:
    """lidet_tracker_t: init (cfg overrides by C field name), update, tracks, stats, reset."""

    def __init__(self, max_tracks: int = 64, max_dets: int = 64, **cfg):
        c = cfg_default()
        for k, v in cfg.items():
            if k not in c:
                raise TypeError(f"unknown tracker field {k!r}")
            c[k] = {"optimal": ASSIGN_OPTIMAL, "greedy": ASSIGN_GREEDY}.get(v, v) if k == "assign" else v
        if not cfg_ok(c):
            raise ValueError("LIDET_ERR_CONFIG")
        self.cfg = c
        self.max_tracks = int(max_tracks)
        self.max_dets = int(max_dets)
        self.meas = np.array(c["meas_sigma_m"], F)
        self.accel = np.array(c["accel_sigma_mps2"], F)
        self.vel0 = np.array(c["init_vel_sigma_mps"], F)
        self.gmax = np.array(c["gate_max_m"], F)
        self.chi2 = F(c["gate_chi2"])
        self.pen = F(c["class_penalty"])
        self.birth_min = F(c["birth_min_score"])
        self.yaw_alpha = F(c["yaw_alpha"])
        self.size_alpha = F(c["size_alpha"])
        self.hs = F(c["heading_speed_mps"])
        self.reset()

    def reset(self) -> None:
        T = self.max_tracks
        self.used = np.zeros(T, bool)
        self.id = np.zeros(T, np.int64)
        self.state = np.zeros(T, np.int64)
        self.cls = np.zeros(T, np.int64)
        for f in ("x", "y", "vx", "vy", "p_pp", "p_pv", "p_vv", "z", "l", "w", "h", "yaw", "score"):
            setattr(self, f, np.zeros(T, F))
        self.votes = np.zeros((T, 3), F)
        self.hits = np.zeros(T, np.int64)
        self.misses = np.zeros(T, np.int64)
        self.age = np.zeros(T, np.int64)
        self.det = np.full(T, -1, np.int64)
        self.next_id = 1
        self.stats = dict.fromkeys(STATS, 0)

    # ---- one scan ------------------------------------------------------------------------------------------
    def update(self, dets, dt_s: float, ego=None) -> int:
        """lidet_tracker_update; returns the status (ERR_ARG leaves everything unchanged)."""
        dets = np.asarray(dets, dtype=F).reshape(-1, 9)
        dt = F(dt_s)
        if not (dt > 0 and dt <= MAX_DT_S):
            return ERR_ARG
        if ego is not None:
            e = np.asarray(ego, dtype=F)
            ok = (e[0] >= -MAX_EGO_M) and (e[0] <= MAX_EGO_M) and (e[1] >= -MAX_EGO_M) and (e[1] <= MAX_EGO_M) \
                and (e[2] >= -PI) and (e[2] <= PI)
            if not ok:
                return ERR_ARG
        st = dict.fromkeys(STATS, 0)
        n_use = min(len(dets), self.max_dets)
        st["n_dets_dropped"] = len(dets) - n_use
        ok = det_ok(dets[:n_use])
        st["n_bad_dets"] = int((~ok).sum())
        cols = np.flatnonzero(ok)                     # col_det
        D = dets[cols]
        dcls = D[:, 0].astype(np.int64)
        if ego is not None:
            self._ego(e)
        self._predict(dt)
        rows = np.flatnonzero(self.used)              # row_slot
        nt, nd = len(rows), len(cols)
        big = (self.chi2 + self.pen) + F(1.0)
        cost = self._costs(rows, D, dcls, big)
        st["n_feasible_pairs"] = int((cost < big).sum())
        row_col = np.full(nt, -1, np.int64)
        if nt > 0 and nd > 0 and st["n_feasible_pairs"] > 0:
            if int(self.cfg["assign"]) == ASSIGN_GREEDY:
                row_col = greedy(cost, big)
            else:
                n = max(nt, nd)
                a = np.full((n, n), big, F)
                a[:nt, :nd] = cost
                p = hungarian(a)
                for j in range(1, n + 1):
                    r = p[j]
                    if 1 <= r <= nt and j <= nd and cost[r - 1, j - 1] < big:
                        row_col[r - 1] = j - 1
        taken = np.zeros(nd, bool)
        taken[row_col[row_col >= 0]] = True
        # updates and misses
        for r in range(nt):
            s = rows[r]
            if row_col[r] >= 0:
                self._update_track(s, D[row_col[r]], int(cols[row_col[r]]))
                st["n_matched"] += 1
                continue
            self.misses[s] += 1
            self.det[s] = -1
            if self.state[s] == TENTATIVE or self.misses[s] > int(self.cfg["max_misses"]):
                self.used[s] = False
                st["n_deaths"] += 1
            else:
                self.state[s] = COASTING
        # births
        for c in range(nd):
            if taken[c] or not (D[c, 8] >= self.birth_min):
                continue
            free = np.flatnonzero(~self.used)
            if len(free) == 0:
                st["n_births_dropped"] += 1
                continue
            self._birth(int(free[0]), D[c], int(cols[c]))
            self.next_id = 1 if self.next_id == 0xFFFFFFFF else self.next_id + 1
            st["n_births"] += 1
        # confirmation
        conf = self.used & (self.state == TENTATIVE) & (self.hits >= int(self.cfg["confirm_hits"]))
        self.state[conf] = CONFIRMED
        st["n_tracks"] = int(self.used.sum())
        st["n_confirmed"] = int((self.used & (self.state != TENTATIVE)).sum())
        self.stats = st
        return TRUNCATED if st["n_dets_dropped"] > 0 or st["n_births_dropped"] > 0 else OK

    def _ego(self, e) -> None:
        s_ = np.flatnonzero(self.used)
        c, s = F(math.cos(float(e[2]))), F(math.sin(float(e[2])))
        px = self.x[s_] - e[0]
        py = self.y[s_] - e[1]
        vx, vy = self.vx[s_], self.vy[s_]
        self.x[s_] = c * px + s * py
        self.y[s_] = c * py - s * px
        self.vx[s_] = c * vx + s * vy
        self.vy[s_] = c * vy - s * vx
        self.yaw[s_] = wrap_pi(self.yaw[s_] - e[2])

    def _predict(self, dt) -> None:
        dt2 = dt * dt
        dt3 = dt2 * dt
        dt4 = dt2 * dt2
        two_dt = F(2.0) * dt
        q = self.accel * self.accel
        q_pp = (dt4 * q) * F(0.25)
        q_pv = (dt3 * q) * F(0.5)
        q_vv = dt2 * q
        s = np.flatnonzero(self.used)
        k = self.cls[s]
        self.x[s] = self.x[s] + self.vx[s] * dt
        self.y[s] = self.y[s] + self.vy[s] * dt
        pp = ((self.p_pp[s] + two_dt * self.p_pv[s]) + dt2 * self.p_vv[s]) + q_pp[k]
        pv = (self.p_pv[s] + dt * self.p_vv[s]) + q_pv[k]
        vv = self.p_vv[s] + q_vv[k]
        self.p_pp[s], self.p_pv[s], self.p_vv[s] = pp, pv, vv
        self.age[s] += 1

    def _costs(self, rows, D, dcls, big) -> np.ndarray:
        tk = self.cls[rows]
        gm2 = self.gmax[tk] * self.gmax[tk]
        ms = self.meas[dcls]
        ex = D[None, :, 1] - self.x[rows][:, None]
        ey = D[None, :, 2] - self.y[rows][:, None]
        d2 = ex * ex + ey * ey
        m = d2 / (self.p_pp[rows][:, None] + (ms * ms)[None, :])
        feas = (m <= self.chi2) & (d2 <= gm2[:, None])
        cost = np.where(dcls[None, :] != tk[:, None], m + self.pen, m)
        return np.where(feas, cost, big).astype(F)

    def _update_track(self, s: int, d: np.ndarray, index: int) -> None:
        k = int(d[0])
        ms = self.meas[k]
        S = self.p_pp[s] + ms * ms
        kp = self.p_pp[s] / S
        kv = self.p_pv[s] / S
        ex = d[1] - self.x[s]
        ey = d[2] - self.y[s]
        self.x[s] = self.x[s] + kp * ex
        self.y[s] = self.y[s] + kp * ey
        self.vx[s] = self.vx[s] + kv * ex
        self.vy[s] = self.vy[s] + kv * ey
        vv = self.p_vv[s] - kv * self.p_pv[s]
        self.p_vv[s] = vv if vv > 0 else F(0.0)
        self.p_pp[s] = (F(1.0) - kp) * self.p_pp[s]
        self.p_pv[s] = (F(1.0) - kp) * self.p_pv[s]
        pp, pv, vv = self.p_pp[s], self.p_pv[s], self.p_vv[s]
        if pv * pv > pp * vv:  # |p_pv| <= sqrt(p_pp p_vv) (rounding with r << p_pp and a nearly singular prior)
            lim = np.sqrt(pp * vv)
            self.p_pv[s] = -lim if pv < 0 else lim
        dyaw = wrap_pi(d[7] - self.yaw[s])
        if dyaw > HALF_PI:
            dyaw = dyaw - PI
        elif dyaw < -HALF_PI:
            dyaw = dyaw + PI
        self.yaw[s] = wrap_pi(self.yaw[s] + self.yaw_alpha * dyaw)
        a = self.size_alpha
        self.z[s] = self.z[s] + a * (d[3] - self.z[s])
        self.l[s] = self.l[s] + a * (d[4] - self.l[s])
        self.w[s] = self.w[s] + a * (d[5] - self.w[s])
        self.h[s] = self.h[s] + a * (d[6] - self.h[s])
        self.votes[s, k] = self.votes[s, k] + d[8]
        self.cls[s] = int(np.argmax(self.votes[s]))   # first on ties
        self.score[s] = d[8]
        self.hits[s] += 1
        self.misses[s] = 0
        self.det[s] = index
        if self.state[s] == COASTING:
            self.state[s] = CONFIRMED

    def _birth(self, s: int, d: np.ndarray, index: int) -> None:
        k = int(d[0])
        self.used[s] = True
        self.id[s] = self.next_id
        self.state[s] = TENTATIVE
        self.cls[s] = k
        self.x[s], self.y[s] = d[1], d[2]
        self.vx[s] = self.vy[s] = F(0.0)
        self.p_pp[s] = self.meas[k] * self.meas[k]
        self.p_pv[s] = F(0.0)
        self.p_vv[s] = self.vel0[k] * self.vel0[k]
        self.z[s], self.l[s], self.w[s], self.h[s] = d[3], d[4], d[5], d[6]
        self.yaw[s] = wrap_pi(d[7])
        self.votes[s] = 0
        self.votes[s, k] = d[8]
        self.score[s] = d[8]
        self.hits[s] = 1
        self.misses[s] = 0
        self.age[s] = 0
        self.det[s] = index

    # ---- output ----------------------------------------------------------------------------------------------
    def _reported_yaw(self, s: int):
        vx, vy, yaw = self.vx[s], self.vy[s], self.yaw[s]
        sp2 = vx * vx + vy * vy
        if not (sp2 > 0 and sp2 >= self.hs * self.hs and sp2 >= F(4.0) * self.p_vv[s]):
            return yaw
        hd = wrap_pi(F(math.atan2(float(vy), float(vx))))
        if (int(self.cfg["heading_from_velocity"]) >> int(self.cls[s])) & 1:
            return hd
        dd = wrap_pi(hd - yaw)
        return wrap_pi(yaw + PI) if (dd > HALF_PI or dd < -HALF_PI) else yaw

    def tracks(self, flags: int = 0) -> np.ndarray:
        """lidet_tracker_tracks: the tracks in id order (TRACK_DTYPE)."""
        keep = self.used.copy()
        if not flags & OUT_COASTING:
            rep = np.asarray(self.cfg["report_misses"], np.int64)[np.minimum(self.cls, 2).astype(np.int64)]
            keep &= (self.state != COASTING) | (self.misses.astype(np.int64) <= rep)
        if not flags & OUT_TENTATIVE:
            keep &= self.state != TENTATIVE
        s = np.flatnonzero(keep)
        s = s[np.argsort(self.id[s], kind="stable")]
        out = np.zeros(len(s), TRACK_DTYPE)
        for f in ("id", "cls", "state", "x", "y", "z", "l", "w", "h", "vx", "vy", "p_pp", "p_pv", "p_vv", "score",
                  "hits", "misses", "age", "det"):
            out[f] = getattr(self, f)[s]
        out["yaw"] = [self._reported_yaw(int(k)) for k in s]
        return out
