# SPDX-License-Identifier: MIT
"""A peer for lidet's tracker: an AB3DMOT-style 3D Kalman tracker (Weng et al., "3D Multi-Object Tracking: A
Baseline and New Evaluation Metrics", IROS 2020, and the settings of its later releases), written from the
published description for comparisons (tools/lidet_tools/track/run.py, docs/TRACKING.md).

* One constant-velocity Kalman filter per track (filterpy) over AB3DMOT's state (x, y, z, yaw, l, w, h, vx, vy,
  vz), measuring (x, y, z, yaw, l, w, h). AB3DMOT's covariances, which it states per frame: P0 = 10 I with 10^4
  on the velocities, Q = I with 10^-2 on the velocities, R = I; here velocities are in m/s, so their entries are
  divided by dt^2 (P0 with the first scan's dt).
* One tracker per class with AB3DMOT's KITTI settings (`KITTI`): Car: GIoU 3D >= -0.2, Hungarian, min_hits 3,
  max_age 2; Pedestrian: GIoU 3D >= -0.4, greedy, min_hits 1, max_age 4; Cyclist: centre distance <= 2 m
  (affinity -distance >= -2), Hungarian, min_hits 3, max_age 4. The Hungarian assignment is
  scipy.optimize.linear_sum_assignment on the negated affinities; pairs below the threshold are dropped.
* The heading flip: when a matched detection's yaw is more than pi/2 from the track's, the track's yaw is
  turned by pi before the update, and the measured yaw is taken within pi of it.
* Births: every unmatched detection (score >= min_score); a track is reported once it has min_hits hits (or in
  the first min_hits scans, as AB3DMOT), and dies after max_age scans without a detection.
* Ego motion, which AB3DMOT takes from the vehicle's poses, as lidet's tracker takes it: (dx, dy, dyaw), the
  sensor's motion since the previous scan in the previous scan's frame; every state moves into the new frame
  (position, velocity and yaw, the covariance turned with them).

Same input and output as lidet_tools.track.native.Tracker: update(dets (n, 9) cls x y z l w h yaw score, dt_s,
ego, flags) -> structured array (TRACK_DTYPE: id, cls, state, box, vx, vy, p_pp, p_pv, p_vv, score, hits, misses,
age, det), in id order; flags OUT_COASTING | OUT_TENTATIVE add the tracks that missed this scan / that are not
reported yet.
"""
from __future__ import annotations

import numpy as np

from ..eval import iou as _iou

TRACK_DTYPE = np.dtype([
    ("id", "<u4"), ("cls", "u1"), ("state", "u1"),
    ("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("l", "<f4"), ("w", "<f4"), ("h", "<f4"), ("yaw", "<f4"),
    ("vx", "<f4"), ("vy", "<f4"), ("p_pp", "<f4"), ("p_pv", "<f4"), ("p_vv", "<f4"), ("score", "<f4"),
    ("hits", "<u4"), ("misses", "<u4"), ("age", "<u4"), ("det", "<i4")])
TENTATIVE, CONFIRMED, COASTING = 0, 1, 2
OUT_COASTING, OUT_TENTATIVE = 1, 2
#: AB3DMOT's KITTI settings per class (lidet_class_t: 0 car, 1 cyclist, 2 pedestrian)
KITTI = {0: dict(metric="giou_3d", thres=-0.2, algm="hungar", min_hits=3, max_age=2),
         1: dict(metric="dist_3d", thres=-2.0, algm="hungar", min_hits=3, max_age=4),
         2: dict(metric="giou_3d", thres=-0.4, algm="greedy", min_hits=1, max_age=4)}


def _wrap(a):
    return (a + np.pi) % (2.0 * np.pi) - np.pi


def giou_3d(a, b) -> np.ndarray:
    """Generalised 3D IoU of (m, 7) x (n, 7) boxes [x, y, z, l, w, h, yaw] (centre; eval.iou's generic layout):
    IoU - (C - U) / C with C the volume of the smallest enclosing shape: the convex hull of both footprints
    times the union of the vertical extents. (m, n) in [-1, 1]."""
    import shapely
    a = np.asarray(a, np.float64).reshape(-1, 7)
    b = np.asarray(b, np.float64).reshape(-1, 7)
    m, n = len(a), len(b)
    if m == 0 or n == 0:
        return np.zeros((m, n))
    iou3 = _iou.iou_3d(a, b)
    va = (a[:, 3] * a[:, 4] * a[:, 5])[:, None]
    vb = (b[:, 3] * b[:, 4] * b[:, 5])[None, :]
    inter = iou3 * (va + vb) / (1.0 + iou3)
    union = va + vb - inter
    ca, cb = _iou.bev_corners(a), _iou.bev_corners(b)
    pts = np.concatenate([np.repeat(ca, n, axis=0), np.tile(cb, (m, 1, 1))], axis=1).reshape(-1, 2)
    mp = shapely.multipoints(shapely.points(pts), indices=np.repeat(np.arange(m * n), 8))
    hull = shapely.area(shapely.convex_hull(mp)).reshape(m, n)
    top = np.maximum((a[:, 2] + a[:, 5] / 2)[:, None], (b[:, 2] + b[:, 5] / 2)[None, :])
    bot = np.minimum((a[:, 2] - a[:, 5] / 2)[:, None], (b[:, 2] - b[:, 5] / 2)[None, :])
    C = np.maximum(hull * (top - bot), 1e-12)
    return iou3 - (C - union) / C


def affinity(dets, trks, metric: str) -> np.ndarray:
    if metric == "giou_3d":
        return giou_3d(dets, trks)
    if metric == "iou_3d":
        return _iou.iou_3d(dets, trks)
    if metric == "dist_3d":
        d = np.asarray(dets, float).reshape(-1, 7)[:, None, :3] - np.asarray(trks, float).reshape(-1, 7)[None, :, :3]
        return -np.sqrt((d * d).sum(-1))
    raise ValueError(f"unknown metric {metric!r}")


def associate(aff: np.ndarray, thres: float, algm: str = "hungar"):
    """Pairs (det, trk) with affinity >= thres: Hungarian (linear_sum_assignment on -affinity) or greedy
    (highest affinity first)."""
    m, n = aff.shape
    if m == 0 or n == 0:
        return []
    if algm == "greedy":
        order = np.argsort(-aff, axis=None, kind="stable")
        used_d, used_t, out = set(), set(), []
        for k in order:
            i, j = divmod(int(k), n)
            if aff[i, j] < thres:
                break
            if i in used_d or j in used_t:
                continue
            used_d.add(i)
            used_t.add(j)
            out.append((i, j))
        return sorted(out)
    from scipy.optimize import linear_sum_assignment
    r, c = linear_sum_assignment(-aff)
    return [(int(i), int(j)) for i, j in zip(r, c) if aff[i, j] >= thres]


class _Track:
    def __init__(self, tid, cls, det, score, dt0, det_idx):
        from filterpy.kalman import KalmanFilter
        kf = KalmanFilter(dim_x=10, dim_z=7)
        kf.F = np.eye(10)
        kf.H = np.hstack([np.eye(7), np.zeros((7, 3))])
        kf.P = np.eye(10) * 10.0
        kf.P[7:, 7:] *= 1000.0 / (dt0 * dt0)       # AB3DMOT: 1e4 (m/frame)^2 -> (m/s)^2
        kf.R = np.eye(7)
        kf.x = np.zeros((10, 1))
        kf.x[:7, 0] = det[[0, 1, 2, 6, 3, 4, 5]]    # x y z yaw l w h
        kf.x[3, 0] = _wrap(kf.x[3, 0])
        self.kf = kf
        self.id, self.cls, self.score = tid, cls, score
        self.hits, self.hit_streak, self.tsu, self.age = 1, 1, 0, 0
        self.det = det_idx

    def box(self):
        x = self.kf.x[:, 0]
        return np.array([x[0], x[1], x[2], x[4], x[5], x[6], x[3]])


class PeerTracker:
    """AB3DMOT-style tracker; see the module doc. params: per-class overrides of KITTI (dicts by class index);
    min_score: detections below it start no track."""

    def __init__(self, params: dict | None = None, min_score: float = 0.0):
        self.params = {c: dict(KITTI[c], **((params or {}).get(c, {}))) for c in KITTI}
        self.min_score = float(min_score)
        self.reset()

    def reset(self):
        self.tracks: list[_Track] = []
        self.next_id = 1
        self.frame = 0
        self.dt0 = None

    def _ego(self, ego):
        dx, dy, dyaw = (float(v) for v in np.asarray(ego, float).reshape(3))
        c, s = np.cos(-dyaw), np.sin(-dyaw)
        R = np.array([[c, -s], [s, c]])
        J = np.eye(10)
        J[0:2, 0:2] = R
        J[7:9, 7:9] = R
        for t in self.tracks:
            x = t.kf.x[:, 0].copy()
            x[0:2] = R @ (x[0:2] - (dx, dy))
            x[7:9] = R @ x[7:9]
            x[3] = _wrap(x[3] - dyaw)
            t.kf.x = x[:, None]
            t.kf.P = J @ t.kf.P @ J.T

    def update(self, dets, dt_s: float, ego=None, flags: int = 0) -> np.ndarray:
        dt = float(dt_s)
        if not (0.0 < dt <= 10.0):
            raise ValueError(f"dt_s must be in (0, 10] s, got {dt_s!r}")
        if self.dt0 is None:
            self.dt0 = dt
        d = np.asarray(dets, np.float64).reshape(-1, 9) if np.size(dets) else np.zeros((0, 9))
        self.frame += 1
        # ego motion, then prediction (the same as predicting first: the motion is linear)
        if ego is not None and self.tracks:
            self._ego(ego)
        F = np.eye(10)
        F[0, 7] = F[1, 8] = F[2, 9] = dt
        Q = np.eye(10)
        Q[7:, 7:] *= 0.01 / (dt * dt)
        for t in self.tracks:
            t.kf.F, t.kf.Q = F, Q
            t.kf.predict()
            t.kf.x[3, 0] = _wrap(t.kf.x[3, 0])
            t.age += 1
            if t.tsu > 0:
                t.hit_streak = 0
            t.tsu += 1
            t.det = -1
        ok = np.isfinite(d).all(1) & (d[:, 4:7] > 0).all(1) & np.isin(d[:, 0], list(self.params))
        for c, prm in self.params.items():
            di = np.nonzero(ok & (d[:, 0] == c))[0]
            trks = [t for t in self.tracks if t.cls == c]
            tb = np.array([t.box() for t in trks]).reshape(-1, 7)
            pairs = associate(affinity(d[di, 1:8], tb, prm["metric"]), prm["thres"], prm["algm"])
            used = set()
            for i, j in pairs:
                self._correct(trks[j], d[di[i]], int(di[i]))
                used.add(i)
            for i in range(len(di)):
                if i not in used and d[di[i], 8] >= self.min_score:
                    self.tracks.append(_Track(self.next_id, c, d[di[i], 1:8], float(d[di[i], 8]), self.dt0,
                                              int(di[i])))
                    self.next_id = self.next_id + 1 if self.next_id < 0xFFFFFFFF else 1
        out = self.tracks_out(flags)
        self.tracks = [t for t in self.tracks if t.tsu < self.params[t.cls]["max_age"]]
        return out

    def _correct(self, t: _Track, det, idx):
        x = t.kf.x
        th_d = _wrap(det[7])
        if abs(_wrap(th_d - x[3, 0])) > np.pi / 2:
            x[3, 0] = _wrap(x[3, 0] + np.pi)          # heading flip: turn the track
        z = det[[1, 2, 3, 7, 4, 5, 6]].copy()
        z[3] = x[3, 0] + _wrap(th_d - x[3, 0])
        t.kf.update(z[:, None])
        t.kf.x[3, 0] = _wrap(t.kf.x[3, 0])
        t.hits += 1
        t.hit_streak += 1
        t.tsu = 0
        t.score = float(det[8])
        t.det = idx

    def tracks_out(self, flags: int = 0) -> np.ndarray:
        rows = []
        for t in sorted(self.tracks, key=lambda t: t.id):
            prm = self.params[t.cls]
            shown = t.hits >= prm["min_hits"] or self.frame <= prm["min_hits"]
            if t.tsu == 0 and shown:
                st = CONFIRMED
            elif t.tsu > 0 and t.hits >= prm["min_hits"] and (flags & OUT_COASTING) and t.tsu < prm["max_age"]:
                st = COASTING
            elif not shown and (flags & OUT_TENTATIVE) and t.tsu == 0:
                st = TENTATIVE
            else:
                continue
            x, P = t.kf.x[:, 0], t.kf.P
            rows.append((t.id, t.cls, st, x[0], x[1], x[2], x[4], x[5], x[6], x[3], x[7], x[8], P[0, 0], P[0, 7],
                         P[7, 7], t.score, t.hits, t.tsu, t.age, t.det))
        return np.array(rows, dtype=TRACK_DTYPE) if rows else np.zeros(0, TRACK_DTYPE)
