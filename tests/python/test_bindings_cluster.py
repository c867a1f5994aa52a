# SPDX-License-Identifier: MIT
"""Clustering + proposals through the bindings against the numpy reference (codegen/lidet_ref/cluster.py)."""
import numpy as np
import pytest

from lidet_ref import cluster as ref
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
    rng = np.random.default_rng(3)
    for n_src, n_out, seed in [(1, 64, 0), (5, 8, 0x5EED1234), (10, 64, 7), (64, 64, 3), (65, 64, 3),
                               (1000, 128, 8), (123457, 64, 0xFFFFFFFF), (0x9E3779B9 % 100000 + 1, 16, 0x9E3779B9)]:
        pixels = np.sort(rng.choice(1 << 20, n_src, replace=False)).astype(np.uint32)
        c = native.proposal_indices(n_src, n_out, seed, pixels)
        r = ref.proposal_indices(n_src, n_out, seed, pixels)
        np.testing.assert_array_equal(c, r, err_msg=f"{n_src} {n_out} {seed}")
        if n_src <= n_out:  # the pixels are not read
            np.testing.assert_array_equal(native.proposal_indices(n_src, n_out, seed), r)
        else:
            with pytest.raises(native.LidetError):
                native.proposal_indices(n_src, n_out, seed)
            with pytest.raises(ValueError):
                ref.proposal_indices(n_src, n_out, seed)


def test_proposal_indices_follow_the_pixels_not_the_count():
    """A cluster that gains or loses a pixel (the float and integer projections of one scan) takes the same member
    pixels in every stratum the change leaves alone; the pick in a stratum is uniform over its members."""
    rng = np.random.default_rng(5)
    same = []
    for trial in range(40):
        n = int(rng.integers(200, 3000))
        pixels = np.sort(rng.choice(200_000, n + 1, replace=False))
        a = pixels[:-1] if trial % 2 else np.delete(pixels, int(rng.integers(0, n + 1)))
        b = pixels
        pa = a[native.proposal_indices(len(a), 64, 0x5EED1234, a)]
        pb = b[native.proposal_indices(len(b), 64, 0x5EED1234, b)]
        same.append(len(np.intersect1d(pa, pb)) / 64)
    assert np.mean(same) > 0.9, np.mean(same)
    # the position of the pick within its stratum: uniform (chi-square over 8 bins of the relative position)
    pos = []
    for seed in range(300):
        pixels = np.arange(64 * 40) * 3 + seed
        idx = native.proposal_indices(len(pixels), 64, seed, pixels)
        pos.append(idx - np.arange(64) * 40)
    h = np.bincount(np.concatenate(pos) * 8 // 40, minlength=8)
    e = h.sum() / 8
    assert ((h - e) ** 2 / e).sum() < 30, h  # chi-square, 7 degrees of freedom: 24.3 at p = 0.001


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
    f = np.float32  # the defaults come from C: float32 values
    d = native.cluster_defaults("hdl64")
    assert d["min_points"] == 8 and d["max_steps"] == 5 and d["theta_rad"] == f(0.18) and d["diagonals"] == 1
    assert d["max_gap_m"] == f(0.7) and d["max_gap_per_m"] == f(0.025) and d["bridge_occluders"] == 1
    assert d["rescue_gap_m"] == f(0.8) and d["rescue_gap_per_m"] == f(0.03) and d["rescue_rows"] == 2
    assert d["rescue_cols"] == 6 and d["mount_height_m"] == f(1.73)
    v = native.cluster_defaults("vlp16")
    assert v["theta_rad"] == f(0.12) and v["max_steps"] == 5 and v["bridge_occluders"] == 0
    assert v["max_gap_per_m"] == f(0.04)
    assert v["rescue_rows"] == 1
    # issue 15: the 16-beam values of their own (simulated VLP-16 crowd scenes); the dense ones unchanged
    assert v["min_points"] == 8 and v["person_min_points"] == 9 and d["person_min_points"] == 10
    assert v["rescue_gap_m"] == f(1.0) and v["join_gap_m"] == f(0.8)
    assert v["split_min_width_m"] == f(0.7)
    assert d["join_gap_m"] == f(0.5) and d["split_min_width_m"] == f(0.7) and d["person_min_cols"] == 2
    pts, ground, _, _ = _synthetic()
    a = native.cluster(pts, "hdl64", ground=ground, min_points=100000, rescue_gap_m=0.0)
    assert a.stats["n_kept"] == 0 and a.stats["n_dropped_small"] == a.stats["n_found"]
    assert a.stats["n_fragments"] == 0 and a.stats["n_rescue_pixels"] == 0
    # with the rescue every component is a fragment (or too high); the rescue groups are all small
    b = native.cluster(pts, "hdl64", ground=ground, min_points=100000)
    assert b.stats["n_kept"] == 0 and b.stats["n_fragments"] + b.stats["n_dropped_height"] == b.stats["n_found"]
    assert 1 <= b.stats["n_dropped_small"] <= b.stats["n_fragments"]
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
    defaults = {k: v for k, v in native.cluster_defaults("hdl64").items() if k != "mount_height_m"}
    for cfg in (dict(theta_rad=0.40, max_steps=5, bridge_occluders=True, diagonals=True, min_points=10,
                     max_extent_m=6.0, max_mean_height_m=2.5, max_gap_m=0.0, max_gap_per_m=0.0, rescue_gap_m=0.0,
                     split_people=0, join_cars=0, regrow_gap_m=0.0),
                dict(theta_rad=0.2, max_steps=9, bridge_occluders=False, diagonals=False, min_points=10,
                     max_extent_m=6.0, max_mean_height_m=2.5, max_gap_m=0.0, max_gap_per_m=0.0, rescue_gap_m=0.0,
                     split_people=0, join_cars=0, regrow_gap_m=0.0),
                defaults,
                {**defaults, "rescue_gap_m": 1.0, "rescue_gap_per_m": 0.05, "rescue_rows": 3, "rescue_cols": 9,
                 "min_points": 20},
                {**defaults, "max_extent_m": 3.0, "regrow_max_pixels": 0}):  # many components regrown
        _check_against_ref(pts, ground, cfg)


def test_rescue_matches_reference_on_sample(root):
    """The fragment rescue (on by default) in C and in the reference, on the shipped simulated VLP-16
    sample (16 beams: where the rescue matters most); and it really rescues pixels there."""
    d = root / "tests" / "data" / "sim_vlp16"
    pts = np.fromfile(d / "velodyne" / "000000.bin", np.float32).reshape(-1, 4)
    lab = np.fromfile(d / "labels" / "000000.label", np.uint32)
    defaults = {k: v for k, v in native.cluster_defaults("vlp16").items() if k != "mount_height_m"}
    c = _check_against_ref(pts, np.isin(lab & 0xFFFF, GROUND), defaults, "vlp16", exact=True)
    assert c.stats["n_fragments"] > 0 and c.stats["n_rescue_joined"] > 0 and c.stats["n_rescue_pixels"] > 0
    assert c.n_rescued.sum() == c.stats["n_rescue_pixels"] and np.all(c.n_rescued <= c.n_points)
    # the records of clusters that took in fragments describe all their members
    xyz = np.stack([c.image.x, c.image.y, c.image.z], -1).reshape(-1, 3)
    for i in np.nonzero(c.n_rescued)[0]:
        m = c.members[c.first_member[i]:c.first_member[i] + c.n_points[i]]
        assert c.seed_pixel[i] == m[0]
        np.testing.assert_allclose(xyz[m].mean(0), c.mean[i], atol=1e-4)
        np.testing.assert_array_equal(xyz[m].min(0), c.min[i])
        np.testing.assert_array_equal(xyz[m].max(0), c.max[i])
    assert np.all(np.diff(c.seed_pixel.astype(np.int64)) > 0)


def test_regrow_cut_matches_reference(root):
    """regrow_cut_m (off by default): the regrowth leaves out the pixels less than the cut above the ground, in C and
    in the reference, on the shipped simulated HDL-64 sample with a small extent limit that sends many components
    through the regrowth; the cut changes the clusters."""
    d = root / "tests" / "data" / "sim_hdl64"
    pts = np.fromfile(d / "velodyne" / "000000.bin", np.float32).reshape(-1, 4)
    lab = np.fromfile(d / "labels" / "000000.label", np.uint32)
    ground = np.isin(lab & 0xFFFF, GROUND)
    defaults = {k: v for k, v in native.cluster_defaults("hdl64").items() if k != "mount_height_m"}
    assert defaults["regrow_cut_m"] == 0.0
    kw = dict(defaults, max_extent_m=3.0, regrow_max_pixels=0)
    uncut = _check_against_ref(pts, ground, kw, exact=True)
    cut = _check_against_ref(pts, ground, dict(kw, regrow_cut_m=1.0), exact=True)
    assert cut.stats["n_regrown"] == uncut.stats["n_regrown"] > 5
    assert not np.array_equal(cut.pixel_labels, uncut.pixel_labels)
    with pytest.raises(native.LidetError):
        native.cluster(pts, "hdl64", regrow_cut_m=2.5)


@pytest.mark.parametrize("sensor,half", [("vlp16", 0.8), ("hdl64", 1.3090)])
def test_azimuth_window_matches_reference(root, sensor, half):
    """azimuth_half_rad (what the detector's crop sets): only the columns within it are candidates, in C and in
    the reference; the clusters inside it are those of the whole image, the pixels outside it unlabelled."""
    d = root / "tests" / "data" / f"sim_{sensor}"
    pts = np.fromfile(d / "velodyne" / "000000.bin", np.float32).reshape(-1, 4)
    lab = np.fromfile(d / "labels" / "000000.label", np.uint32)
    ground = np.isin(lab & 0xFFFF, GROUND)
    defaults = {k: v for k, v in native.cluster_defaults(sensor).items() if k != "mount_height_m"}
    win = _check_against_ref(pts, ground, dict(defaults, azimuth_half_rad=half), sensor, exact=True)
    full = native.cluster(pts, sensor, ground=ground, with_image=True)
    assert 0 < win.stats["n_candidates"] < full.stats["n_candidates"]
    cols = win.pixel_labels.shape[1]
    az = np.pi * (1.0 - 2.0 * (np.arange(cols) + 0.5) / cols)  # column centres
    assert not win.pixel_labels[:, np.abs(az) > half + 4 * np.pi / cols].any()
    # a cluster of the whole image with every pixel well inside the window is there, the same pixels
    inside = np.abs(az) < half - np.radians(20)
    for k in range(1, int(full.pixel_labels.max()) + 1):
        m = full.pixel_labels == k
        if inside[np.nonzero(m)[1]].all():
            ids = np.unique(win.pixel_labels[m])
            assert len(ids) == 1 and ids[0] > 0 and (win.pixel_labels == ids[0]).sum() == m.sum()


@pytest.mark.parametrize("sensor,half,seed", [("vlp16", 1.0, 0.6), ("hdl64", 1.3090, 0.7)])
def test_seed_window_matches_reference(root, sensor, half, seed):
    """seed_half_rad (the detector's crop: seeds in the crop, growth over the crop + 15 deg) in C and in the
    reference; no component lies wholly outside the seed columns, some reach past them, and the components with a
    pixel well inside the seed columns are those of the window alone."""
    d = root / "tests" / "data" / f"sim_{sensor}"
    pts = np.fromfile(d / "velodyne" / "000000.bin", np.float32).reshape(-1, 4)
    lab = np.fromfile(d / "labels" / "000000.label", np.uint32)
    ground = np.isin(lab & 0xFFFF, GROUND)
    defaults = {k: v for k, v in native.cluster_defaults(sensor).items() if k != "mount_height_m"}
    sw = _check_against_ref(pts, ground, dict(defaults, azimuth_half_rad=half, seed_half_rad=seed), sensor,
                            exact=True)
    win = native.cluster(pts, sensor, ground=ground, with_image=True, **dict(defaults, azimuth_half_rad=half))
    assert sw.stats["n_candidates"] == win.stats["n_candidates"]
    cols = sw.pixel_labels.shape[1]
    az = np.pi * (1.0 - 2.0 * (np.arange(cols) + 0.5) / cols)  # column centres
    past = 0
    for k in range(1, int(sw.pixel_labels.max()) + 1):
        c = np.nonzero(sw.pixel_labels == k)[1]
        assert (np.abs(az[c]) <= seed + 4 * np.pi / cols).any()  # every cluster starts in the seed columns
        past += bool((np.abs(az[c]) > seed + 4 * np.pi / cols).any())
    assert past > 0  # and some grow past them
    # fewer clusters than the window alone (those wholly in its margin are not formed); a cluster of the window
    # alone that lies well inside the seed columns is there, the same pixels
    assert 0 < sw.pixel_labels.max() < win.pixel_labels.max()
    inner = np.abs(az) < seed - np.radians(15)
    same = 0
    for k in range(1, int(win.pixel_labels.max()) + 1):
        m = win.pixel_labels == k
        if inner[np.nonzero(m)[1]].all():
            ids = np.unique(sw.pixel_labels[m])
            same += len(ids) == 1 and ids[0] > 0 and (sw.pixel_labels == ids[0]).sum() == m.sum()
            assert len(ids) == 1 and ids[0] > 0, "a cluster in the seed columns lost"
    assert same > 0


def _check_against_ref(pts, ground, cfg, sensor="hdl64", exact=False):
    c = native.cluster(pts, sensor, ground=ground, with_image=True, **cfg)
    img = c.image
    cand = img.valid.copy()
    w = img.point_idx[img.valid]
    cand[img.valid] = ~ground[w]
    xyz = np.stack([img.x, img.y, img.z], -1)
    labels, members = ref.cluster_ref(img.range, cand, img.row_elev, xyz,
                                      mount_height_m=native.cluster_defaults(sensor)["mount_height_m"], **cfg)
    if exact:  # no mean within float rounding of a filter's edge here
        np.testing.assert_array_equal(labels, c.pixel_labels)
    agree = np.mean(labels == c.pixel_labels)
    assert agree > 0.999, agree
    assert abs(len(members) - len(c)) <= 1
    return c


def test_proposals_match_reference(real_dir):
    pts, ground = _real(real_dir, 1)
    c = native.cluster(pts, "hdl64", ground=ground, with_image=True)
    assert len(c) > 20
    for n_points in (16, 64):
        p = native.proposals(c, n_points=n_points)
        p2 = native.proposals(c, n_points=n_points)
        np.testing.assert_array_equal(p.xyz, p2.xyz)
        xyz = np.stack([c.image.x, c.image.y, c.image.z], -1).reshape(-1, 3)
        edge = 0
        for i in range(len(c)):
            m = c.members[c.first_member[i]:c.first_member[i] + c.n_points[i]]
            rx, rmean, rvox = ref.make_proposal(xyz[m], c.mean[i], n_points=n_points, pixels=m)
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


def test_proposals_from_the_ground_match_reference(need_lib):
    """z_origin LIDET_PROPOSAL_Z_GROUND: z measured from the ground under the cluster mean (the mean's z minus its
    height above the plane), bit for bit as lidet_ref.cluster.make_proposal; x, y and the voxel as the mean's origin."""
    from lidet_tools.sim import simulate_scan
    pts = simulate_scan("hdl64", 16, 0).points
    gr = native.ground(pts, "hdl64")
    c = native.cluster(pts, "hdl64", ground=gr.mask_point, planes=gr.planes, with_image=True)
    assert len(c) > 10
    a = native.proposals(c, n_points=64)
    b = native.proposals(c, n_points=64, z_origin=1)
    xyz = np.stack([c.image.x, c.image.y, c.image.z], -1).reshape(-1, 3)
    for i in range(len(c)):
        m = c.members[c.first_member[i]:c.first_member[i] + c.n_points[i]]
        rx, rmean, rvox = ref.make_proposal(xyz[m], c.mean[i], n_points=64, height_m=c.height[i], pixels=m)
        np.testing.assert_array_equal(b.xyz[i], rx)
        np.testing.assert_array_equal(b.mean[i], rmean)
    np.testing.assert_array_equal(a.voxel, b.voxel)
    np.testing.assert_array_equal(a.xyz[..., :2], b.xyz[..., :2])
    np.testing.assert_allclose(b.mean[:, 2], c.mean[:, 2] - c.height, atol=1e-6)
    # upright objects standing on the road start near z = 0 in the ground frame
    assert np.median(b.xyz[:, :, 2].min(1)) < 0.5
    with pytest.raises(native.LidetError):
        native.proposals(c, n_points=64, z_origin=2)
