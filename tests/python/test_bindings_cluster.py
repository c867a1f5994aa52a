# SPDX-License-Identifier: MIT
"""Clustering + proposals through the bindings against the numpy reference (codegen ref/cluster.py)."""
import numpy as np
import pytest

from lidet_codegen.ref import cluster as ref
from lidet_tools import native

GROUND = [40, 44, 48, 49, 60, 72]


def _face(rng, centre, width, height, n):
    """n points on a vertical rectangle facing the sensor (a surface, as a LiDAR sees an object)."""
    c = np.asarray(centre, np.float64)
    t = np.array([-c[1], c[0], 0.0]) / np.hypot(c[0], c[1])
    u = rng.uniform(-0.5, 0.5, (n, 1)) * width
    v = rng.uniform(-0.5, 0.5, (n, 1)) * height
    return (c + u * t + v * np.array([0.0, 0.0, 1.0])).astype(np.float32)


def _synthetic():
    """Flat ground plus a car-sized box at 10 m and a pedestrian-sized one at 8 m, 4 m apart."""
    rng = np.random.default_rng(1)
    g = np.c_[rng.uniform(-30, 30, 40000), rng.uniform(-30, 30, 40000), np.full(40000, -1.73)].astype(np.float32)
    car = _face(rng, (10, 0, -0.9), 1.8, 1.5, 6000)
    ped = _face(rng, (8, 4, -0.85), 0.5, 1.7, 1500)
    pts = np.r_[g, car, ped]
    pts = np.c_[pts, np.zeros(len(pts), np.float32)]
    ground = np.r_[np.ones(len(g), bool), np.zeros(len(car) + len(ped), bool)]
    return pts, ground, len(g), len(car)


def test_proposal_indices_match_reference():
    for n_src, n_out, seed in [(1, 64, 0), (5, 8, 0x5EED1234), (10, 64, 7), (64, 64, 3), (65, 64, 3),
                               (1000, 128, 8), (123457, 64, 0xFFFFFFFF), (0x9E3779B9 % 100000 + 1, 16, 0x9E3779B9)]:
        c = native.proposal_indices(n_src, n_out, seed)
        r = ref.proposal_indices(n_src, n_out, seed)
        np.testing.assert_array_equal(c, r, err_msg=f"{n_src} {n_out} {seed}")


def test_synthetic_objects_are_separate_clusters():
    pts, ground, ng, ncar = _synthetic()
    c = native.cluster(pts, "hdl64", ground=ground, with_image=True)
    img = c.image
    car_ids = np.unique(c.point_labels[ng:ng + ncar])
    ped_ids = np.unique(c.point_labels[ng + ncar:])
    assert len(car_ids) == 1 and car_ids[0] > 0
    assert len(ped_ids) == 1 and ped_ids[0] > 0 and ped_ids[0] != car_ids[0]
    # ground pixels are never clustered (ground points hidden behind an object share its pixel: its id)
    win = img.point_idx[img.valid]
    assert np.all(c.pixel_labels[img.valid][ground[win]] == 0)
    assert c.stats["n_kept"] == 2 and c.stats["n_queue_overflow"] == 0
    # canonical ids: 1..K in raster order of the seed pixel
    assert np.all(np.diff(c.seed_pixel.astype(np.int64)) > 0)
    # per-pixel and per-point labels agree; the means are the members' means
    pp = img.point_pixel
    ok = pp >= 0
    np.testing.assert_array_equal(c.point_labels[ok], c.pixel_labels.ravel()[pp[ok]])
    np.testing.assert_array_equal(c.point_labels[~ok], 0)
    xyz = np.stack([img.x, img.y, img.z], -1).reshape(-1, 3)
    for i in range(len(c)):
        m = c.members[c.first_member[i]:c.first_member[i] + c.n_points[i]]
        np.testing.assert_allclose(xyz[m].mean(0), c.mean[i], atol=1e-4)
        assert np.all(np.diff(m) > 0)


def test_defaults_and_options():
    d = native.cluster_defaults("hdl64")
    assert d["min_points"] == 10 and d["max_steps"] == 5 and d["theta_rad"] == 0.18 and d["diagonals"] == 1
    assert d["max_gap_m"] == 0.7 and d["max_gap_per_m"] == 0.025 and d["bridge_occluders"] == 1
    v = native.cluster_defaults("vlp16")
    assert v["theta_rad"] == 0.12 and v["max_steps"] == 4 and v["bridge_occluders"] == 0 and v["max_gap_per_m"] == 0.04
    pts, ground, _, _ = _synthetic()
    a = native.cluster(pts, "hdl64", ground=ground, min_points=100000)
    assert a.stats["n_kept"] == 0 and a.stats["n_dropped_small"] == a.stats["n_found"]
    with pytest.raises(TypeError):
        native.cluster(pts, "hdl64", theta=0.3)
    with pytest.raises(native.LidetError):
        native.cluster(pts, "hdl64", theta_rad=0.0)


def _real(real_dir, k=0):
    f = real_dir / "semantickitti" / "velodyne" / f"00_{k:06d}.bin"
    pts = np.fromfile(f, np.float32).reshape(-1, 4)
    lab = np.fromfile(real_dir / "semantickitti" / "labels" / f"00_{k:06d}.label", np.uint32)
    return pts, np.isin(lab & 0xFFFF, GROUND)


def test_real_scan_matches_reference(real_dir):
    """The C labels equal the plain-Python BFS reference on a real SemanticKITTI scan."""
    pts, ground = _real(real_dir)
    for cfg in (dict(theta_rad=0.40, max_steps=5, bridge_occluders=True, diagonals=True, min_points=10,
                     max_extent_m=6.0, max_mean_height_m=2.5, max_gap_m=0.0, max_gap_per_m=0.0),
                dict(theta_rad=0.2, max_steps=9, bridge_occluders=False, diagonals=False, min_points=10,
                     max_extent_m=6.0, max_mean_height_m=2.5, max_gap_m=0.0, max_gap_per_m=0.0),
                {k: v for k, v in native.cluster_defaults("hdl64").items() if k != "mount_height_m"}):
        _check_against_ref(pts, ground, cfg)


def _check_against_ref(pts, ground, cfg):
    c = native.cluster(pts, "hdl64", ground=ground, with_image=True, **cfg)
    img = c.image
    cand = img.valid.copy()
    w = img.point_idx[img.valid]
    cand[img.valid] = ~ground[w]
    xyz = np.stack([img.x, img.y, img.z], -1)
    labels, members = ref.cluster_ref(img.range, cand, img.row_elev, xyz, mount_height_m=1.73, **cfg)
    agree = np.mean(labels == c.pixel_labels)
    assert agree > 0.999, agree
    assert abs(len(members) - len(c)) <= 1


def test_proposals_match_reference(real_dir):
    pts, ground = _real(real_dir, 1)
    c = native.cluster(pts, "hdl64", ground=ground, with_image=True)
    assert len(c) > 20
    for n_points in (16, 64):
        p = native.proposals(n_clusters=len(c), n_points=n_points)
        p2 = native.proposals(n_clusters=len(c), n_points=n_points)
        np.testing.assert_array_equal(p.xyz, p2.xyz)
        xyz = np.stack([c.image.x, c.image.y, c.image.z], -1).reshape(-1, 3)
        edge = 0
        for i in range(len(c)):
            m = c.members[c.first_member[i]:c.first_member[i] + c.n_points[i]]
            rx, rmean, rvox = ref.make_proposal(xyz[m], c.mean[i], n_points=n_points)
            np.testing.assert_array_equal(p.xyz[i], rx)  # bit-exact: same indices, same float32 subtraction
            np.testing.assert_array_equal(p.mean[i], rmean)
            assert p.n_src[i] == len(m)
            edge += int(np.any(p.voxel[i] != rvox))
        assert edge <= 1  # only a mean within float rounding of a bin edge may differ
        # centred: with every member taken at least once the mean of the proposal is near 0
        small = c.n_points <= n_points
        if small.any():
            j = int(np.nonzero(small)[0][0])
            assert np.all(np.abs(p.xyz[j, :c.n_points[j]].mean(0)) < 1e-3)
