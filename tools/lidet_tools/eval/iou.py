# SPDX-License-Identifier: MIT
"""Overlaps used by the evaluators, vectorized over pairs (numpy, float64).

Boxes are given in one generic layout, ``(N, 7)`` = ``[u, v, zc, l, w, h, theta]``:
(u, v) the footprint centre in a right-handed ground plane, zc the centre along the vertical
axis, l along the heading, w across it, h vertical, theta the heading angle in the (u, v) plane.

* lidet sensor frame: ``[x, y, z, l, w, h, yaw]`` as is (see :func:`boxes_from_sensor`).
* KITTI rectified camera frame: ``u = tx, v = tz, zc = ty - h/2, theta = -ry`` (see
  :func:`boxes_from_camera`). The footprint corners are then exactly those of the official devkit
  (``evaluate_object_3d_offline.cpp``: offsets (l/2, w/2) rotated by [[cos ry, sin ry], [-sin ry, cos ry]]
  in the camera x-z plane), and the vertical extent is [ty - h, ty] as there.

Rotated IoU is exact up to rounding: the BEV intersection of the two rectangles is computed by
Sutherland-Hodgman clipping of one rectangle by the four edges of the other (both convex), vectorized
over all pairs; the 3D intersection is that area times the vertical overlap.
"""
from __future__ import annotations

import numpy as np

__all__ = [
    "boxes_from_sensor", "boxes_from_camera", "bev_corners", "convex_intersection_area",
    "iou_bev_pairs", "iou_3d_pairs", "iou_bev", "iou_3d", "iou_2d", "iou_2d_pairs",
]


def boxes_from_sensor(arr) -> np.ndarray:
    """(N, 7) sensor-frame boxes [x, y, z, l, w, h, yaw] -> generic layout (a float64 copy)."""
    return np.array(arr, dtype=np.float64).reshape(-1, 7)


def boxes_from_camera(dims_hwl, loc, ry) -> np.ndarray:
    """KITTI label_2 fields -> generic layout. dims_hwl: (N, 3) h, w, l as in the file; loc: (N, 3)
    bottom centre (tx, ty, tz) in the rectified camera frame; ry: (N,)."""
    d = np.asarray(dims_hwl, dtype=np.float64).reshape(-1, 3)
    t = np.asarray(loc, dtype=np.float64).reshape(-1, 3)
    r = np.asarray(ry, dtype=np.float64).reshape(-1)
    h, w, l = d[:, 0], d[:, 1], d[:, 2]
    return np.stack([t[:, 0], t[:, 2], t[:, 1] - h / 2.0, l, w, h, -r], axis=1)


def bev_corners(boxes) -> np.ndarray:
    """(N, 7) generic boxes -> (N, 4, 2) footprint corners, counter-clockwise."""
    b = np.asarray(boxes, dtype=np.float64).reshape(-1, 7)
    c, s = np.cos(b[:, 6]), np.sin(b[:, 6])
    dx = np.array([0.5, -0.5, -0.5, 0.5])[None, :] * b[:, 3:4]
    dy = np.array([0.5, 0.5, -0.5, -0.5])[None, :] * b[:, 4:5]
    u = b[:, 0:1] + c[:, None] * dx - s[:, None] * dy
    v = b[:, 1:2] + s[:, None] * dx + c[:, None] * dy
    return np.stack([u, v], axis=2)


def _polygon_area(poly, n):
    """Shoelace area of (P, K, 2) polygons whose first n[p] vertices are valid (counter-clockwise)."""
    P, K = poly.shape[:2]
    if K == 0:
        return np.zeros(P)
    idx = np.arange(K)[None, :]
    nxt = np.where(idx + 1 < n[:, None], idx + 1, 0)
    q = np.take_along_axis(poly, nxt[:, :, None], axis=1)
    cross = poly[:, :, 0] * q[:, :, 1] - poly[:, :, 1] * q[:, :, 0]
    cross = np.where(idx < n[:, None], cross, 0.0)
    return 0.5 * cross.sum(axis=1)


def convex_intersection_area(subject, clip) -> np.ndarray:
    """Area of the intersection of pairs of convex polygons, both counter-clockwise:
    subject (P, Ks, 2), clip (P, Kc, 2) (all vertices valid). Returns (P,) float64, >= 0.

    Sutherland-Hodgman: the subject is clipped by each edge of the clip polygon in turn. Polygons are
    kept in (P, K, 2) arrays with a per-row vertex count; after each edge the surviving vertices are
    compacted to the front and K shrinks to the largest count, so nothing is ever truncated.
    """
    poly = np.array(subject, dtype=np.float64)
    clip = np.asarray(clip, dtype=np.float64)
    P = poly.shape[0]
    n = np.full(P, poly.shape[1], dtype=np.int64)
    for e in range(clip.shape[1]):
        if poly.shape[1] == 0:
            break
        a = clip[:, e, :]
        b = clip[:, (e + 1) % clip.shape[1], :]
        ex, ey = (b - a)[:, 0:1], (b - a)[:, 1:2]
        K = poly.shape[1]
        idx = np.arange(K)[None, :]
        valid = idx < n[:, None]
        # signed distance (times edge length): >= 0 is the inside (left of a counter-clockwise edge)
        d = ex * (poly[:, :, 1] - a[:, 1:2]) - ey * (poly[:, :, 0] - a[:, 0:1])
        nxt = np.where(idx + 1 < n[:, None], idx + 1, 0)
        q = np.take_along_axis(poly, nxt[:, :, None], axis=1)
        dq = np.take_along_axis(d, nxt, axis=1)
        inside = d >= 0
        inside_q = dq >= 0
        cross = valid & (inside != inside_q)
        denom = np.where(cross, d - dq, 1.0)
        t = np.where(cross, d / denom, 0.0)
        x = poly + t[:, :, None] * (q - poly)
        # output slots: 2 per input vertex (the vertex if inside, then the crossing if any)
        out = np.stack([poly, x], axis=2).reshape(P, 2 * K, 2)
        keep = np.stack([valid & inside, cross], axis=2).reshape(P, 2 * K)
        n = keep.sum(axis=1)
        Kn = int(n.max()) if P else 0
        order = np.argsort(~keep, axis=1, kind="stable")[:, :Kn]
        poly = np.take_along_axis(out, order[:, :, None], axis=1)
    return np.maximum(_polygon_area(poly, n), 0.0)


def _bev_inter_pairs(a, b):
    """Intersection areas of paired generic boxes a[i], b[i]; pairs whose circumscribed circles do
    not meet are skipped (area 0)."""
    P = a.shape[0]
    out = np.zeros(P)
    if P == 0:
        return out
    ra = 0.5 * np.hypot(a[:, 3], a[:, 4])
    rb = 0.5 * np.hypot(b[:, 3], b[:, 4])
    near = np.hypot(a[:, 0] - b[:, 0], a[:, 1] - b[:, 1]) < ra + rb
    if near.any():
        out[near] = convex_intersection_area(bev_corners(a[near]), bev_corners(b[near]))
    return out


def _safe_div(num, den):
    return np.where(den > 0, num / np.where(den > 0, den, 1.0), 0.0)


def iou_bev_pairs(a, b) -> np.ndarray:
    """BEV IoU of paired generic boxes (P, 7), (P, 7) -> (P,)."""
    a = np.asarray(a, dtype=np.float64).reshape(-1, 7)
    b = np.asarray(b, dtype=np.float64).reshape(-1, 7)
    inter = _bev_inter_pairs(a, b)
    return _safe_div(inter, a[:, 3] * a[:, 4] + b[:, 3] * b[:, 4] - inter)


def iou_3d_pairs(a, b) -> np.ndarray:
    """3D IoU of paired generic boxes: BEV intersection times vertical overlap over the union volume."""
    a = np.asarray(a, dtype=np.float64).reshape(-1, 7)
    b = np.asarray(b, dtype=np.float64).reshape(-1, 7)
    top = np.minimum(a[:, 2] + a[:, 5] / 2, b[:, 2] + b[:, 5] / 2)
    bot = np.maximum(a[:, 2] - a[:, 5] / 2, b[:, 2] - b[:, 5] / 2)
    vov = np.maximum(top - bot, 0.0)
    inter = np.zeros(a.shape[0])
    m = vov > 0
    if m.any():
        inter[m] = _bev_inter_pairs(a[m], b[m]) * vov[m]
    va = a[:, 3] * a[:, 4] * a[:, 5]
    vb = b[:, 3] * b[:, 4] * b[:, 5]
    return _safe_div(inter, va + vb - inter)


def _all_pairs(a, b):
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    n, m = len(a), len(b)
    return np.repeat(a, m, axis=0), np.tile(b, (n, 1)), (n, m)


def iou_bev(a, b) -> np.ndarray:
    """(N, 7) x (M, 7) generic boxes -> (N, M) BEV IoU."""
    aa, bb, shape = _all_pairs(np.reshape(a, (-1, 7)), np.reshape(b, (-1, 7)))
    return iou_bev_pairs(aa, bb).reshape(shape)


def iou_3d(a, b) -> np.ndarray:
    """(N, 7) x (M, 7) generic boxes -> (N, M) 3D IoU."""
    aa, bb, shape = _all_pairs(np.reshape(a, (-1, 7)), np.reshape(b, (-1, 7)))
    return iou_3d_pairs(aa, bb).reshape(shape)


def iou_2d_pairs(a, b, criterion: int = -1) -> np.ndarray:
    """Image boxes [x1, y1, x2, y2], paired. criterion -1: IoU; 0: intersection over the area of a
    (the devkit's DontCare test); 1: over the area of b. Areas without the +1 pixel, as the devkit."""
    a = np.asarray(a, dtype=np.float64).reshape(-1, 4)
    b = np.asarray(b, dtype=np.float64).reshape(-1, 4)
    w = np.minimum(a[:, 2], b[:, 2]) - np.maximum(a[:, 0], b[:, 0])
    h = np.minimum(a[:, 3], b[:, 3]) - np.maximum(a[:, 1], b[:, 1])
    inter = np.where((w > 0) & (h > 0), w * h, 0.0)
    aa = (a[:, 2] - a[:, 0]) * (a[:, 3] - a[:, 1])
    ab = (b[:, 2] - b[:, 0]) * (b[:, 3] - b[:, 1])
    if criterion == -1:
        den = aa + ab - inter
    elif criterion == 0:
        den = aa
    elif criterion == 1:
        den = ab
    else:
        raise ValueError(f"criterion must be -1, 0 or 1, got {criterion}")
    return _safe_div(inter, den)


def iou_2d(a, b, criterion: int = -1) -> np.ndarray:
    """(N, 4) x (M, 4) image boxes -> (N, M); see :func:`iou_2d_pairs`."""
    aa, bb, shape = _all_pairs(np.reshape(a, (-1, 4)), np.reshape(b, (-1, 4)))
    return iou_2d_pairs(aa, bb, criterion).reshape(shape)
