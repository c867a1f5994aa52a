# SPDX-License-Identifier: MIT
"""Box geometry shared by the real-data readers (sensor frame: x forward, y left, z up, metres).

* :func:`points_in_box` - which points lie inside a :class:`~lidet_tools.kitti.Box3D` (centre, l along yaw).
* :func:`box_from_corners` - a box from its 8 corners given in any order, possibly tilted (KITTI-360 json): sizes
  from the three edges at one corner, yaw from the long horizontal edge.
* :func:`fit_box_to_points` - an amodal box from the visible points of one object (SemanticKITTI, SqueezeSeg):
  yaw by search-based L-shape fitting (closeness criterion, Zhang et al., IV 2017, 1 degree steps), then every
  dimension shorter than the class prior (:data:`CLASS_PRIORS`) is completed: *away from the sensor* along the
  viewing ray (the visible face stays where the points are), symmetrically across it (the points there span the
  silhouette); z from the points' min (ground contact) to max.
* :func:`connected_components` - Euclidean clustering (grid candidates + union-find), for sources without
  instance ids (SqueezeSeg).
* :func:`estimate_ground_z` - the road height below the sensor from the points (z histogram mode near the sensor).

Checked with BEV pictures (``python -m lidet_tools.real.show --all``) of every source's frames.
"""
from __future__ import annotations

import numpy as np

from ..kitti import Box3D

#: amodal size priors (l, w, h) in metres: l and w complete boxes fitted to partly visible objects, h is the
#: lowest fitted height (grown upwards from the lowest point) so a box of a few points is not flat
CLASS_PRIORS: dict[str, tuple[float, float, float]] = {
    "Car": (3.9, 1.6, 1.4),
    "Van": (3.9, 1.6, 1.4),
    "Pedestrian": (0.6, 0.6, 1.0),
    "Cyclist": (1.7, 0.6, 1.2),
    "Other": (0.6, 0.6, 0.5),
}


def wrap_angle(a):
    """Wrap an angle (or array) to [-pi, pi)."""
    return (np.asarray(a) + np.pi) % (2.0 * np.pi) - np.pi


def points_in_box(xyz: np.ndarray, b: Box3D, margin: float = 0.0) -> np.ndarray:
    """Boolean mask of the (N, >=3) points inside the box enlarged by margin on every side."""
    d = np.asarray(xyz, dtype=np.float64)[:, :3] - np.array([b.x, b.y, b.z])
    c, s = np.cos(b.yaw), np.sin(b.yaw)
    u = c * d[:, 0] + s * d[:, 1]
    v = -s * d[:, 0] + c * d[:, 1]
    return ((np.abs(u) <= b.l / 2 + margin) & (np.abs(v) <= b.w / 2 + margin)
            & (np.abs(d[:, 2]) <= b.h / 2 + margin))


def box_point_share(points: np.ndarray, b: Box3D, margin_m: float = 0.25,
                    ground_clear_m: float = 0.2) -> tuple[int, int]:
    """(points inside the box, points near it) where "near" is within margin_m of the box horizontally, and
    both count only points between the box bottom + ground_clear_m and its top + margin_m (the road under a box
    would otherwise dominate). inside / near close to 1 means the box sits on its object's points."""
    p = np.asarray(points, dtype=np.float64)[:, :3]
    zb = b.z - b.h / 2
    z_ok = (p[:, 2] >= zb + ground_clear_m) & (p[:, 2] <= zb + b.h + margin_m)
    big = Box3D(b.cls, b.x, b.y, b.z, b.l + 2 * margin_m, b.w + 2 * margin_m, 1e9, b.yaw)
    near = z_ok & points_in_box(p, big)
    inside = near & points_in_box(p, b)
    return int(inside.sum()), int(near.sum())


def normalize_lw(b: Box3D) -> Box3D:
    """Same rectangle with l >= w (yaw turned by 90 degrees where l and w are exchanged), yaw in [-pi, pi)."""
    if b.w > b.l:
        return Box3D(b.cls, b.x, b.y, b.z, b.w, b.l, b.h, float(wrap_angle(b.yaw + np.pi / 2)), b.score)
    return Box3D(b.cls, b.x, b.y, b.z, b.l, b.w, b.h, float(wrap_angle(b.yaw)), b.score)


# --------------------------------------------------------------------------------------------
# boxes from corners


def box_from_corners(corners: np.ndarray, cls: str, tol_m: float = 0.05) -> Box3D:
    """Box3D from the 8 corners (8, 3) of a cuboid given in any order, possibly tilted.

    The two corners nearest to corner 0 are its neighbours along the two shortest edges (any diagonal is
    longer), the third edge is the remaining corner direction orthogonal to both; the three edge vectors give
    the sizes exactly whatever the tilt: h is the edge closest to vertical, l the longer of the other two and
    yaw its direction in the xy plane (modulo pi, in [-pi/2, pi/2): corners carry no heading); the centre is
    the corners' mean. Raises ValueError when the corners are not finite (8, 3) or do
    not form a cuboid (edges not orthogonal, or a corner farther than tol_m from the cuboid they span)."""
    c = np.asarray(corners, dtype=np.float64)
    if c.shape != (8, 3) or not np.all(np.isfinite(c)):
        raise ValueError(f"expected 8 finite corners (8, 3), got shape {c.shape}")
    d = c[1:] - c[0]
    dn = np.linalg.norm(d, axis=1)
    if dn.min() <= 1e-9:
        raise ValueError("corners do not form a cuboid: repeated corner")
    o = np.argsort(dn)
    e1, e2 = d[o[0]], d[o[1]]
    rest = d[o[2:]] / dn[o[2:], None]
    e3 = d[o[2:]][np.argmin(np.abs(rest @ e1) / dn[o[0]] + np.abs(rest @ e2) / dn[o[1]])]
    edges = np.stack([e1, e2, e3])
    n = np.linalg.norm(edges, axis=1)
    model = c[0] + np.array([[i, j, k] for i in (0, 1) for j in (0, 1) for k in (0, 1)], float) @ edges
    err = np.linalg.norm(c[:, None, :] - model[None, :, :], axis=2).min(1).max()
    ortho = max(abs(edges[a] @ edges[b]) / (n[a] * n[b]) for a, b in ((0, 1), (0, 2), (1, 2)))
    if err > tol_m or ortho > 0.02:
        raise ValueError(f"corners do not form a cuboid (a corner off by {err:.2f} m, edge cosine {ortho:.3f})")
    kv = int(np.argmax(np.abs(edges[:, 2]) / n))
    hor = [i for i in range(3) if i != kv]
    kl, kw = (hor[0], hor[1]) if n[hor[0]] >= n[hor[1]] else (hor[1], hor[0])
    yaw = float((np.arctan2(edges[kl, 1], edges[kl, 0]) + np.pi / 2) % np.pi - np.pi / 2)
    m = c.mean(0)
    return Box3D(cls, float(m[0]), float(m[1]), float(m[2]), float(n[kl]), float(n[kw]), float(n[kv]), yaw)


# --------------------------------------------------------------------------------------------
# boxes from visible points


def _axes(a: float) -> tuple[np.ndarray, np.ndarray]:
    """Unit vectors along angle a and a + pi / 2."""
    return np.array([np.cos(a), np.sin(a)]), np.array([-np.sin(a), np.cos(a)])


def _extents(xy: np.ndarray, a: float):
    """(e1, e2, min, max) of (N, 2) points projected on the axes at angle a."""
    e1, e2 = _axes(a)
    p = np.stack([xy @ e1, xy @ e2], 1)
    return e1, e2, p.min(0), p.max(0)


def lshape_yaw(xy: np.ndarray, step_deg: float = 1.0, d0: float = 0.01) -> float:
    """Orientation in [0, pi/2) of the rectangle best fitting (N, 2) BEV points: search-based L-shape fitting
    with the closeness criterion (Zhang et al. 2017): every point scores 1 / max(distance to the nearest of
    the rectangle's two nearest edges, d0)."""
    xy = np.asarray(xy, dtype=np.float64).reshape(-1, 2)
    if len(xy) < 3:
        return 0.0
    xy = xy - xy.mean(0)
    ang = np.deg2rad(np.arange(0.0, 90.0, step_deg))
    c1 = xy @ np.stack([np.cos(ang), np.sin(ang)])          # (N, A) along e1
    c2 = xy @ np.stack([-np.sin(ang), np.cos(ang)])         # (N, A) along e2
    d1 = np.minimum(c1.max(0) - c1, c1 - c1.min(0))
    d2 = np.minimum(c2.max(0) - c2, c2 - c2.min(0))
    score = (1.0 / np.maximum(np.minimum(d1, d2), d0)).sum(0)
    return float(ang[int(np.argmax(score))])


def fit_box_to_points(xyz: np.ndarray, cls: str, prior: tuple[float, float, float] | None = None) -> Box3D:
    """Amodal box of one object from its visible points (N, >=3), sensor frame.

    1. yaw from :func:`lshape_yaw` of the BEV points, visible extents along the two axes;
    2. the length axis: the longer extent when it exceeds 1.25 x the prior width, else (a short view: the far
       side is hidden) the axis closer to the viewing ray through the points' centre;
    3. a dimension shorter than its prior is completed: along the axis closer to the viewing ray the far face is
       hidden, so the box grows away from the sensor (the visible near face stays at the points; both sides
       grow when the sensor lies within the extent); across the ray the points span the object's silhouette,
       so both sides grow equally;
    4. z: points' min (ground contact) to max, at least the prior height (grown upwards).
    l >= w is not forced (a fitted l follows the prior's length axis); yaw in [-pi/2, pi/2) (no heading).
    """
    p = np.asarray(xyz, dtype=np.float64)[:, :3]
    if len(p) == 0:
        raise ValueError("fit_box_to_points: no points")
    pl, pw, ph = prior if prior is not None else CLASS_PRIORS.get(cls, CLASS_PRIORS["Other"])
    a = lshape_yaw(p[:, :2])
    e1, e2, lo, hi = _extents(p[:, :2], a)
    ext = hi - lo
    along = int(np.argmax(np.abs((lo + hi) / 2)))   # the axis closer to the viewing ray through the centre
    k = int(np.argmax(ext)) if max(ext) > 1.25 * pw else along   # the length axis
    want = np.empty(2)
    want[k], want[1 - k] = pl, pw
    for i in range(2):
        if ext[i] >= want[i]:
            continue
        # along the ray the far face is hidden: the near face (the sensor, at 0, lies outside [lo, hi]) stays;
        # across the ray the points span the object's silhouette: grow both sides equally
        if i == along and lo[i] >= 0.0:
            hi[i] = lo[i] + want[i]
        elif i == along and hi[i] <= 0.0:
            lo[i] = hi[i] - want[i]
        else:
            g = (want[i] - ext[i]) / 2
            lo[i] -= g
            hi[i] += g
    mid = (lo + hi) / 2
    cxy = mid[0] * e1 + mid[1] * e2
    d = hi - lo
    yaw = a if k == 0 else a + np.pi / 2
    yaw = float((yaw + np.pi / 2) % np.pi - np.pi / 2)
    z0 = float(p[:, 2].min())
    z1 = max(float(p[:, 2].max()), z0 + ph)
    return Box3D(cls, float(cxy[0]), float(cxy[1]), (z0 + z1) / 2, float(d[k]), float(d[1 - k]), z1 - z0, yaw)


def connected_components(xyz: np.ndarray, link_m: float) -> np.ndarray:
    """(N,) int64 component ids (0..K-1, numbered by first point) of Euclidean clustering: points closer than
    link_m (3D) are one object. Points share a grid cell of side link_m / sqrt(3) (so any two in a cell are
    closer than link_m); two cells up to 2 apart are joined (union-find over cells) when their closest pair of
    points is closer than link_m."""
    p = np.asarray(xyz, dtype=np.float64)[:, :3]
    n = len(p)
    if n == 0:
        return np.zeros(0, dtype=np.int64)
    cell = np.floor(p / (link_m / np.sqrt(3.0) * (1 - 1e-9))).astype(np.int64)
    uniq, inv = np.unique(cell, axis=0, return_inverse=True)
    inv = inv.reshape(-1)
    order = np.argsort(inv, kind="stable")
    groups = np.split(order, np.flatnonzero(np.diff(inv[order])) + 1)
    index = {tuple(c): k for k, c in enumerate(uniq.tolist())}
    parent = list(range(len(uniq)))

    def find(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    r = range(-2, 3)
    offs = [(dx, dy, dz) for dx in r for dy in r for dz in r if (dx, dy, dz) > (0, 0, 0)]
    lim = link_m * link_m
    for k, key in enumerate(uniq.tolist()):
        a = p[groups[k]]
        for dx, dy, dz in offs:
            j = index.get((key[0] + dx, key[1] + dy, key[2] + dz))
            if j is None:
                continue
            rk, rj = find(k), find(j)
            if rk == rj:
                continue
            b = p[groups[j]]
            if ((a[:, None, :] - b[None, :, :]) ** 2).sum(-1).min() < lim:
                parent[max(rk, rj)] = min(rk, rj)
    roots = np.array([find(k) for k in range(len(uniq))])[inv]
    _, first, lab = np.unique(roots, return_index=True, return_inverse=True)
    rank = np.argsort(np.argsort(first))  # renumber by first appearance
    return rank[lab.reshape(-1)].astype(np.int64)


# --------------------------------------------------------------------------------------------
# ground


def estimate_ground_z(points: np.ndarray, r_min_m: float = 3.0, r_max_m: float = 20.0,
                      bin_m: float = 0.05, prominence: float = 0.3) -> float:
    """Road height (z, metres, negative below the sensor) from a scan: the lowest prominent mode of a z
    histogram (bin_m bins, 5-bin smoothing, z in [-4, 0]) of the points at horizontal range [r_min_m, r_max_m],
    refined as the median z within +-0.2 m of it. Prominent: a local maximum holding at least `prominence` of the
    largest bin. The road is the lowest large horizontal surface near the sensor (walls, hedges and car bodies
    can outnumber it in a narrow street, but lie above it); nan when no point qualifies.
    mount height = -estimate_ground_z(points)."""
    p = np.asarray(points, dtype=np.float64)
    r = np.hypot(p[:, 0], p[:, 1])
    z = p[(r >= r_min_m) & (r <= r_max_m) & (p[:, 2] >= -4.0) & (p[:, 2] <= 0.0), 2]
    if len(z) == 0:
        return float("nan")
    hist, edges = np.histogram(z, bins=np.arange(-4.0, 0.0 + bin_m, bin_m))
    sm = np.convolve(hist, np.ones(5) / 5.0, mode="same")
    pad = np.concatenate([[-1.0], sm, [-1.0]])
    peaks = np.flatnonzero((sm >= pad[:-2]) & (sm >= pad[2:]) & (sm >= prominence * sm.max()))
    k = int(peaks[0])
    m = (edges[k] + edges[k + 1]) / 2
    return float(np.median(z[np.abs(z - m) <= 0.2]))


def boxes_from_objects(points: np.ndarray, objects: list[tuple[str, np.ndarray]],
                       min_points: int = 5) -> tuple[list[Box3D], np.ndarray]:
    """(boxes, point_instance) from objects given as (class, indices of their points): one
    :func:`fit_box_to_points` box per object with at least min_points points, in the given order;
    point_instance (N,) int32 is the box index of each point (-1: none, or a dropped object)."""
    inst = np.full(len(points), -1, dtype=np.int32)
    boxes: list[Box3D] = []
    for cls, idx in objects:
        idx = np.asarray(idx, dtype=np.int64)
        if len(idx) < min_points:
            continue
        inst[idx] = len(boxes)
        boxes.append(fit_box_to_points(points[idx], cls))
    return boxes, inst
