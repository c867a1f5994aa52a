# SPDX-License-Identifier: MIT
"""Rotated IoU: analytic cases and an independent polygon implementation (shapely)."""
import numpy as np
import pytest

from lidet_tools import kitti
from lidet_tools.eval import iou


def B(x=0.0, y=0.0, z=0.0, l=4.0, w=2.0, h=1.5, yaw=0.0):
    return np.array([[x, y, z, l, w, h, yaw]])


def both(a, b):
    return float(iou.iou_bev(a, b)[0, 0]), float(iou.iou_3d(a, b)[0, 0])


@pytest.mark.parametrize("yaw", [0.0, 0.3, np.pi / 2, np.pi, -2.5])
def test_identical(yaw):
    assert both(B(yaw=yaw), B(yaw=yaw)) == pytest.approx((1.0, 1.0), abs=1e-12)


def test_heading_flipped_by_pi_is_identical_footprint():
    assert both(B(yaw=0.4), B(yaw=0.4 + np.pi)) == pytest.approx((1.0, 1.0), abs=1e-12)


def test_shifted_along_length_by_half():
    # overlap 2 x 2 of two 4 x 2 boxes: 4 / (8 + 8 - 4) = 1/3
    assert both(B(), B(x=2.0)) == pytest.approx((1 / 3, 1 / 3), abs=1e-12)


def test_shifted_vertically():
    bev, d3 = both(B(h=2.0), B(z=0.5, h=2.0))
    assert bev == pytest.approx(1.0) and d3 == pytest.approx(1.5 / 2.5, abs=1e-12)


def test_rotated_by_90_degrees():
    # 4 x 2 box and the same box turned by 90 degrees: a 2 x 2 cross, 4 / (8 + 8 - 4)
    assert both(B(), B(yaw=np.pi / 2)) == pytest.approx((1 / 3, 1 / 3), abs=1e-12)


def test_square_rotated_45_inside_circle_of_other():
    # unit square vs the same square rotated 45 deg: intersection is a regular octagon of area 2(sqrt2-1)
    a, b = B(l=1, w=1, h=1), B(l=1, w=1, h=1, yaw=np.pi / 4)
    inter = 2 * (np.sqrt(2) - 1)
    assert both(a, b)[0] == pytest.approx(inter / (2 - inter), abs=1e-12)


def test_disjoint():
    assert both(B(), B(x=10.0)) == (0.0, 0.0)
    assert both(B(), B(x=4.0)) == (0.0, 0.0)       # touching edges
    assert both(B(h=1.0), B(z=5.0, h=1.0)) == (pytest.approx(1.0), 0.0)  # stacked, BEV identical


def test_partial_overlap_both_axes():
    # shifted by (1, 0.5): intersection 3 x 1.5 = 4.5, union 16 - 4.5
    assert both(B(), B(x=1.0, y=0.5))[0] == pytest.approx(4.5 / 11.5, abs=1e-12)
    assert both(B(), B(x=1.0, y=0.5, z=0.75))[1] == pytest.approx(4.5 * 0.75 / (24 - 4.5 * 0.75), abs=1e-12)


def test_one_inside_another():
    big, small = B(l=6, w=4, h=3), B(x=0.5, y=-0.3, l=2, w=1, h=1, yaw=0.7)
    bev, d3 = both(big, small)
    assert bev == pytest.approx(2 / 24, abs=1e-12) and d3 == pytest.approx(2 / 72, abs=1e-12)


def test_2d_iou_and_ioa():
    a = np.array([[0, 0, 10, 10]])
    b = np.array([[5, 0, 15, 10], [0, 0, 10, 10], [20, 20, 30, 30], [2, 2, 4, 4]])
    assert iou.iou_2d(a, b)[0] == pytest.approx([50 / 150, 1.0, 0.0, 4 / 100])
    assert iou.iou_2d(b[3:], a, criterion=0)[0, 0] == pytest.approx(1.0)   # inside: IoA 1
    assert iou.iou_2d(a, b[3:], criterion=1)[0, 0] == pytest.approx(1.0)


def test_camera_frame_matches_sensor_frame():
    """IoU of two boxes is the same computed in the sensor frame or from their label_2 form."""
    c = kitti.Calib()
    rng = np.random.default_rng(5)
    for _ in range(30):
        p = [kitti.Box3D("Car", rng.uniform(5, 20), rng.uniform(-3, 3), -1.0, 4.0, 1.7, 1.5,
                         rng.uniform(-np.pi, np.pi)) for _ in range(2)]
        p[1].x, p[1].y = p[0].x + rng.uniform(-2, 2), p[0].y + rng.uniform(-1, 1)
        s = [iou.boxes_from_sensor([[b.x, b.y, b.z, b.l, b.w, b.h, b.yaw]]) for b in p]
        o = [kitti.box_to_kitti(b, c) for b in p]
        k = [iou.boxes_from_camera([[x.h, x.w, x.l]], [x.loc], [x.ry]) for x in o]
        assert iou.iou_3d(*s)[0, 0] == pytest.approx(iou.iou_3d(*k)[0, 0], abs=1e-9)
        assert iou.iou_bev(*s)[0, 0] == pytest.approx(iou.iou_bev(*k)[0, 0], abs=1e-9)


def test_camera_footprint_is_devkit_rotation():
    """Footprint of a camera-frame box: offsets (l/2, w/2) rotated by [[cos ry, sin ry], [-sin ry, cos ry]]."""
    ry, l, w = 0.6, 4.0, 2.0
    g = iou.boxes_from_camera([[1.5, w, l]], [[3.0, 1.0, 20.0]], [ry])
    cs = iou.bev_corners(g)[0]
    R = np.array([[np.cos(ry), np.sin(ry)], [-np.sin(ry), np.cos(ry)]])
    off = np.array([[l / 2, w / 2], [-l / 2, w / 2], [-l / 2, -w / 2], [l / 2, -w / 2]])
    want = off @ R.T + [3.0, 20.0]
    assert sorted(map(tuple, np.round(cs, 9))) == sorted(map(tuple, np.round(want, 9)))


def test_against_shapely_10000_random_pairs():
    shapely = pytest.importorskip("shapely")
    from shapely.geometry import Polygon
    rng = np.random.default_rng(42)
    N = 10000
    a = np.column_stack([rng.uniform(-2, 2, N), rng.uniform(-2, 2, N), rng.uniform(-1, 1, N),
                         rng.uniform(0.2, 5, N), rng.uniform(0.2, 3, N), rng.uniform(0.3, 2, N),
                         rng.uniform(-4, 4, N)])
    b = np.column_stack([rng.uniform(-2, 2, N), rng.uniform(-2, 2, N), rng.uniform(-1, 1, N),
                         rng.uniform(0.2, 5, N), rng.uniform(0.2, 3, N), rng.uniform(0.3, 2, N),
                         rng.uniform(-4, 4, N)])
    # a tenth of the pairs share a centre, edge directions or a side (degenerate clipping)
    b[:500, :2] = a[:500, :2]
    b[500:1000, 6] = a[500:1000, 6] + np.pi / 2 * rng.integers(0, 4, 500)
    got_bev, got_3d = iou.iou_bev_pairs(a, b), iou.iou_3d_pairs(a, b)
    ca, cb = iou.bev_corners(a), iou.bev_corners(b)
    pa = shapely.polygons(ca)
    pb = shapely.polygons(cb)
    inter = shapely.area(shapely.intersection(pa, pb))
    want_bev = inter / (a[:, 3] * a[:, 4] + b[:, 3] * b[:, 4] - inter)
    vov = np.clip(np.minimum(a[:, 2] + a[:, 5] / 2, b[:, 2] + b[:, 5] / 2)
                  - np.maximum(a[:, 2] - a[:, 5] / 2, b[:, 2] - b[:, 5] / 2), 0, None)
    iv = inter * vov
    want_3d = iv / (a[:, 3:6].prod(1) + b[:, 3:6].prod(1) - iv)
    assert (want_bev > 0).sum() > 3000
    np.testing.assert_allclose(got_bev, want_bev, rtol=0, atol=1e-6)
    np.testing.assert_allclose(got_3d, want_3d, rtol=0, atol=1e-6)
    assert isinstance(Polygon(ca[0]).area, float)
