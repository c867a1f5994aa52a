# SPDX-License-Identifier: MIT
"""The integer path's post-processing, bit for bit as lib/src/detector/lidet_post_q.c (lidet_detector_q.h).

Boxes are tuples/arrays (cx_mm, cy_mm, cz_mm, l_mm, w_mm, h_mm, yaw_bam); Python integers throughout.
"""
from __future__ import annotations

from lidet_ref import qmath

SIZE_MIN_MM = ((2000, 1200, 900), (800, 200, 800), (200, 200, 700))
SIZE_MAX_MM = ((7500, 3000, 3200), (2600, 1500, 2400), (1600, 1600, 2400))
BOX_MAX_MM = 50000
MAX_CENTRE_MM = 1 << 20
MAX_VERTS = 16
#: the NMS bound between two parts of one group cut (lidet_group_common.h: LIDET_GROUP_NMS_IOU_Q15, 0.25)
GROUP_NMS_IOU_Q15 = 8192


def _div_round(n: int, d: int) -> int:
    return (n + d // 2) // d if n >= 0 else -((-n + d // 2) // d)


def _rshift_round(v: int, s: int) -> int:
    return (v + (1 << (s - 1))) >> s


def _valid(b) -> bool:
    return all(1 <= int(b[i]) <= BOX_MAX_MM for i in (3, 4, 5))


def size_ok(cls: int, b, lo=SIZE_MIN_MM, hi=SIZE_MAX_MM) -> bool:
    if not 0 <= cls < 3 or not _valid(b):
        return False
    return all(lo[cls][j] <= int(b[3 + j]) <= hi[cls][j] for j in range(3))


def _corners(b, ox: int, oy: int) -> list[list[int]]:
    yaw = int(b[6]) & 0xFFFFFFFF
    c, s = int(qmath.cos(yaw)), int(qmath.sin(yaw))
    cx, cy = 2 * (int(b[0]) - ox), 2 * (int(b[1]) - oy)
    l, w = int(b[3]), int(b[4])
    out = []
    for dl, dw in ((l, w), (-l, w), (-l, -w), (l, -w)):
        out.append([cx + _rshift_round(c * dl - s * dw, 30), cy + _rshift_round(s * dl + c * dw, 30)])
    return out


def _clip(p, a, b):
    out = []
    n = len(p)
    for i in range(n):
        if len(out) + 2 > MAX_VERTS:
            break
        u, v = p[i], p[(i + 1) % n]
        su = (b[0] - a[0]) * (u[1] - a[1]) - (b[1] - a[1]) * (u[0] - a[0])
        sv = (b[0] - a[0]) * (v[1] - a[1]) - (b[1] - a[1]) * (v[0] - a[0])
        if su >= 0:
            out.append([u[0], u[1]])
        if (su >= 0) != (sv >= 0):
            sign = 1 if su - sv > 0 else -1
            den = (su - sv) * sign
            out.append([u[0] + _div_round(su * sign * (v[0] - u[0]), den),
                        u[1] + _div_round(su * sign * (v[1] - u[1]), den)])
    return out


def bev_iou(a, b) -> int:
    """Rotated BEV IoU in Q15, as lidet_box_q_bev_iou."""
    if not _valid(a) or not _valid(b):
        return 0
    dx, dy = int(b[0]) - int(a[0]), int(b[1]) - int(a[1])
    if abs(dx) > MAX_CENTRE_MM or abs(dy) > MAX_CENTRE_MM:
        return 0
    rab = int(a[3]) + int(a[4]) + int(b[3]) + int(b[4])
    if 4 * (dx * dx + dy * dy) > rab * rab:
        return 0
    ox, oy = int(a[0]), int(a[1])
    poly = _corners(a, ox, oy)
    pb = _corners(b, ox, oy)
    for k in range(4):
        if not poly:
            break
        poly = _clip(poly, pb[k], pb[(k + 1) % 4])
    if len(poly) < 3:
        return 0
    inter2 = abs(sum(poly[k][0] * poly[(k + 1) % len(poly)][1] - poly[(k + 1) % len(poly)][0] * poly[k][1]
                     for k in range(len(poly))))
    union2 = 8 * (int(a[3]) * int(a[4]) + int(b[3]) * int(b[4])) - inter2
    if inter2 == 0 or union2 <= 0:
        return 0
    return (inter2 << 15) // union2


def nms(dets: list[dict], iou_q15: int) -> tuple[list[dict], list[int]]:
    """dets sorted best first (score_q15 desc, cluster_id asc); returns (kept, suppressed flags). Between two
    detections of one cluster id (the parts of one group cut) the bound is max(iou_q15, GROUP_NMS_IOU_Q15)."""
    own = max(iou_q15, GROUP_NMS_IOU_Q15)
    kept, flags = [], []
    for d in dets:
        drop = any(bev_iou(d["box"], k["box"]) > (iou_q15 if d["cluster_id"] != k["cluster_id"] else own)
                   for k in kept)
        flags.append(int(drop))
        if not drop:
            kept.append(d)
    return kept, flags


def sort_key(d: dict):
    """The order lidet_detections_q_insert keeps."""
    return (-int(d["score_q15"]), int(d["cluster_id"]))
