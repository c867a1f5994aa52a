# SPDX-License-Identifier: MIT
"""The integer projection (lib/src/proj/lidet_proj_q.c) and the integer sensor presets (lib/src/proj/lidet_sensor_q.c):
C equals the numpy reference (codegen/lidet_ref/proj_q.py) bit for bit on random, simulated and real
scans, C presets equal tools/lidet_tools/sensors.py, and the integer image agrees with the float projection
(docs/FIXED_POINT.md, "Projection")."""
import numpy as np
import pytest

from lidet_ref import proj_q as ref
from lidet_ref import qmath
from lidet_tools import kitti, native, sensors
from lidet_tools.sim import simulate_scan

KEYS = ("point_pixel", "point_idx", "x_4mm", "y_4mm", "z_4mm", "range_4mm", "row_elev_bam")


@pytest.fixture(scope="module")
def nq(need_lib):
    from lidet_tools import native
    return native


def _mm(pts):
    return np.round(np.asarray(pts, dtype=np.float64)[:, :3] * 1000.0).astype(np.int32)


def _check_bit_exact(nq, mm, sensor, ring=None, **cfg):
    s = sensors.get_sensor(sensor) if isinstance(sensor, str) else sensor
    c = nq.project_q(mm, s, ring=ring, **cfg)
    margin = cfg.pop("fov_margin_urad", 87266)
    tab = ref.init(s.beam_elev_urad, s.cols, fov_margin_urad=margin, fov_urad=s.fov_urad)
    r = ref.project(mm, tab, ring=ring, max_points=native.capacity()["max_points"], **cfg)
    for k in KEYS:
        np.testing.assert_array_equal(np.asarray(c[k], dtype=np.int64), np.asarray(r[k], dtype=np.int64), err_msg=k)
    assert c["stats"] == r["stats"]
    return c


def _agreement(nq, pts, sensor, ring=None):
    """(same pixel share, same winner share) of the integer projection of round(1000 x) against the float
    projection of the same points (x = mm / 1000)."""
    mm = _mm(pts)
    c = nq.project_q(mm, sensor, ring=ring)
    f = native.project((mm / 1000.0).astype(np.float32), sensor, ring=ring)
    return (f.point_pixel == c["point_pixel"]).mean(), (f.point_idx.ravel() == c["point_idx"]).mean()


def test_integer_presets_match_python_and_float(nq):
    cq = nq.sensors_q()
    cf = native.c_sensors()
    assert list(cq) == list(sensors.SENSORS)
    for name, s in sensors.SENSORS.items():
        q = cq[name]
        assert (q["rows"], q["cols"]) == (s.rows, s.cols), name
        np.testing.assert_array_equal(q["elev_urad"], s.beam_elev_urad, err_msg=name)
        assert q["fov_urad"] == s.fov_urad, name
        assert (q["mount_height_mm"], q["max_range_mm"]) == (s.mount_height_mm, s.max_range_mm), name
        # the float presets rounded (the float table is float32: at most one microradian apart)
        assert np.max(np.abs(q["elev_urad"] - cf[name][2].astype(np.float64) * 1e6)) <= 1.0, name
        assert q["mount_height_mm"] == round(cf[name][3] * 1000), name


def test_isqrt32_exact(nq):
    rng = np.random.default_rng(32)
    k = np.arange(1, 65536, dtype=np.int64)
    v = np.concatenate([[0, 1, 2, 3, 4, 2**32 - 1, 2**32 - 2, 2**30, 2**30 - 1], k * k, k * k - 1,
                        rng.integers(0, 2**32, 200_000)])
    np.testing.assert_array_equal(nq.isqrt32(v), qmath.isqrt(v))


def _edge_scan(sensor, n, rng):
    s = sensors.get_sensor(sensor)
    el = rng.uniform(s.beam_elev_rad.min() - 0.12, s.beam_elev_rad.max() + 0.12, n)
    az = rng.uniform(-np.pi, np.pi, n)
    r = rng.uniform(0.0, 140.0, n)
    pts = np.stack([r * np.cos(el) * np.cos(az), r * np.cos(el) * np.sin(az), r * np.sin(el)], 1)
    mm = np.round(pts * 1000).astype(np.int64)
    lim = 2**31 - 1
    special = np.array([[0, 0, 0], [0, 0, 5000], [0, 0, -5000], [1, 0, 0], [0, -1, 0], [131000, 0, 0],
                        [131001, 0, 0], [-131000, -131000, 0], [lim, 0, 0], [-lim - 1, 5, 5], [0, -lim - 1, 0],
                        [5, 5, -lim - 1], [-3000, 0, 10], [-3000, -1, 10], [-3000, 1, 10], [60, 50, 0],
                        [100, 0, 0], [99, 0, 0], [70, 71, 0], [92000, 92000, 0], [92000, 93000, 0]], np.int64)
    # points exactly on column edges of the axes and diagonals, and on the horizon
    diag = np.array([[k, k, 0] for k in (1, 7, 1000)] + [[-k, k, 3] for k in (1, 7, 1000)] +
                    [[k, -k, -3] for k in (1, 7, 1000)] + [[-k, -k, 0] for k in (1, 7, 1000)], np.int64)
    return np.concatenate([mm, special, diag]).astype(np.int64)


@pytest.mark.parametrize("sensor", list(sensors.SENSORS))
def test_bit_exact_random_and_limits(nq, sensor):
    rng = np.random.default_rng(16)
    mm = _edge_scan(sensor, 30000, rng)
    c = _check_bit_exact(nq, mm.astype(np.int32), sensor)
    st = c["stats"]
    assert st["n_too_far"] >= 7 and st["n_too_close"] >= 1 and st["n_out_of_fov"] > 0
    assert st["n_projected"] == (c["point_pixel"] >= 0).sum()
    assert st["n_pixels_filled"] == (c["point_idx"] >= 0).sum() == (c["range_4mm"] > 0).sum()
    assert st["n_too_far"] + st["n_too_close"] + st["n_out_of_fov"] + st["n_projected"] == len(mm)
    # valid pixels hold their winner, rounded to 4 mm; every projected point is at least as far as its winner
    v = c["point_idx"] >= 0
    w = c["point_idx"][v]
    np.testing.assert_array_equal(c["x_4mm"][v], (mm[w, 0] + 2) >> 2)
    r2 = (mm[:, :3] ** 2).sum(1)
    pp = c["point_pixel"]
    m = pp >= 0
    assert (r2[c["point_idx"][pp[m]]] <= r2[m]).all()
    # with config variants: no minimum range, a maximum range, no margin, stride 5
    _check_bit_exact(nq, mm.astype(np.int32), sensor, min_range_mm=0, max_range_mm=50000, fov_margin_urad=0)
    wide = np.concatenate([mm, rng.integers(-9, 9, (len(mm), 2))], 1).astype(np.int32)
    _check_bit_exact(nq, wide, sensor, min_range_mm=2500)


def test_ring_path_bit_exact_and_bad_rings(nq):
    rng = np.random.default_rng(5)
    mm = _edge_scan("vlp16", 5000, rng).astype(np.int32)
    ring = rng.integers(0, 18, len(mm)).astype(np.uint16)
    c = _check_bit_exact(nq, mm, "vlp16", ring=ring)
    assert c["stats"]["n_bad_ring"] > 0 and c["stats"]["n_out_of_fov"] == 0


def test_row_elevations_are_the_microradians_in_bam(nq):
    for name, s in sensors.SENSORS.items():
        c = nq.project_q(np.zeros((0, 3), np.int32), name)
        np.testing.assert_array_equal(c["row_elev_bam"], qmath.urad_to_bam(np.sort(s.beam_elev_urad)[::-1]))
        f = native.project(np.zeros((0, 3), np.float32), name)
        # within one BAM32 step per float32 ulp of the float projection's own conversion
        assert np.max(np.abs(c["row_elev_bam"] * (2 * np.pi / 2**32) - f.row_elev)) < 1.5e-6, name


def test_config_errors(nq):
    pts = np.array([[1000, 0, 0]], np.int32)
    with pytest.raises(native.LidetError, match="CONFIG"):
        nq.project_q(pts, sensors.custom_sensor("dup", 64, beam_elev_deg=[1.0, 1.0]))
    with pytest.raises(native.LidetError, match="CONFIG"):
        nq.project_q(pts, sensors.custom_sensor("steep", 64, beam_elev_deg=[70.0, 0.0]))
    for cfg in (dict(min_range_mm=-1), dict(min_range_mm=10001), dict(fov_margin_urad=500001),
                dict(max_range_mm=100, min_range_mm=100), dict(max_range_mm=-5)):
        with pytest.raises(native.LidetError, match="CONFIG"):
            nq.project_q(pts, "vlp16", **cfg)
    with pytest.raises(native.LidetError, match="CONFIG"):
        nq.project_q(pts, sensors.custom_sensor("few", 7, beam_elev_deg=[1.0, 0.0]))
    # a custom uniform sensor and a custom table go through, bit exact
    rng = np.random.default_rng(9)
    mm = _edge_scan("vlp16", 3000, rng).astype(np.int32)
    _check_bit_exact(nq, mm, sensors.custom_sensor("u", 900, fov_up_deg=10.0, fov_down_deg=-30.0, rows=40))
    _check_bit_exact(nq, mm, sensors.custom_sensor("t", 512, beam_elev_deg=[3.0, -1.0, 0.25, -9.0, 12.0]))


@pytest.mark.parametrize("sensor", ["hdl64", "vlp16"])
def test_samples_and_fresh_simulations(nq, root, sensor):
    d = root / "tests" / "data" / f"sim_{sensor}"
    scans = [(kitti.read_bin(d / "velodyne" / "000000.bin"), np.fromfile(d / "ring" / "000000.bin", np.uint16))]
    scans += [(r.points, r.ring) for r in (simulate_scan(sensor, seed, 0) for seed in (101, 202))]
    for pts, ring in scans:
        mm = _mm(pts)
        c = _check_bit_exact(nq, mm, sensor)
        assert c["stats"]["n_projected"] == len(mm)
        _check_bit_exact(nq, mm, sensor, ring=ring)
        for rg in (None, ring):
            same_pix, same_win = _agreement(nq, pts, sensor, ring=rg)
            assert same_pix >= 0.999 and same_win >= 0.999, (same_pix, same_win)


def test_real_scans(nq, real_dir):
    files = sorted(real_dir.rglob("velodyne/*.bin"))
    if not files:
        pytest.skip("no real scans")
    agree = []
    for f in files:
        pts = kitti.read_bin(f)
        _check_bit_exact(nq, _mm(pts), "hdl64")
        agree.append(_agreement(nq, pts, "hdl64"))
    agree = np.array(agree)
    assert agree.min() >= 0.995, agree.min(0)


def _check_returns(nq, sensor, rg, az, ri, **cfg):
    s = sensors.get_sensor(sensor)
    c = nq.project_q(None, s, returns=nq.as_returns(rg, az, ri), **cfg)
    tab = ref.init(s.beam_elev_urad, s.cols, fov_margin_urad=87266, fov_urad=s.fov_urad)
    r = ref.project_returns(rg, az, ri, tab, max_points=native.capacity()["max_points"], **cfg)
    for k in KEYS:
        np.testing.assert_array_equal(np.asarray(c[k], dtype=np.int64), np.asarray(r[k], dtype=np.int64), err_msg=k)
    assert c["stats"] == r["stats"]
    return c


@pytest.mark.parametrize("sensor", ["vlp16", "hdl64"])
def test_returns_bit_exact_limits_and_ties(nq, sensor):
    """lidet_proj_q_run_returns (the sensor's returns: range, azimuth, ring) equals ref.project_returns bit for bit:
    random returns with every limit (zero range, below min_range, at and past 131 000 mm and max_range, rings past
    the last row, the azimuth's wrap), several returns in one pixel (nearest wins, ties keep the earlier), and the
    x, y, z an image stores are the range-only image's decoding."""
    s = sensors.get_sensor(sensor)
    rng = np.random.default_rng(77)
    n = 20_000
    rg = rng.integers(0, 140_000, n)
    az = rng.integers(0, 65536, n)
    ri = rng.integers(0, s.rows + 3, n)
    rg[:12] = [0, 1, 99, 100, 101, 130_999, 131_000, 131_001, 2**32 - 1, 5000, 5000, 4999]
    az[:12] = [0, 0x8000, 0x7FFF, 0xFFFF, 1, 0x8001, 0, 0, 0, 1234, 1234, 1234]  # the last three: one pixel
    ri[:12] = [0, 1, 2, 0, 1, 2, 3, 0, 1, 2, 2, 2]
    c = _check_returns(nq, sensor, rg, az, ri)
    st = c["stats"]
    assert st["n_too_close"] >= 3 and st["n_too_far"] >= 2 and st["n_bad_ring"] > 0
    assert st["n_pixels_filled"] < st["n_projected"]  # pixels with several returns
    assert c["point_pixel"][9] == c["point_pixel"][10] == c["point_pixel"][11] >= 0
    assert c["point_idx"][c["point_pixel"][11]] == 11 and c["range_4mm"][c["point_pixel"][11]] == 1250
    tab = ref.init(s.beam_elev_urad, s.cols, fov_margin_urad=87266, fov_urad=s.fov_urad)
    x, y, z = qmath.decode_pixels(np.asarray(c["range_4mm"], np.int64).reshape(s.rows, s.cols), tab.row_elev_bam)
    np.testing.assert_array_equal(c["x_4mm"], x.ravel())
    np.testing.assert_array_equal(c["z_4mm"], z.ravel())
    _check_returns(nq, sensor, rg, az, ri, min_range_mm=0, max_range_mm=60_000)
    # 1 mm returns (round(1 / 4) = 0 -> 1) with a 1 mm range limit: every count accounted for
    rg1, ri1 = np.r_[rg, 1, 1, 2], np.r_[ri, 0, 0, 1]
    c = _check_returns(nq, sensor, rg1, np.r_[az, 7, 7, 9], ri1, min_range_mm=0, max_range_mm=1)
    st = c["stats"]
    assert st["n_projected"] == int(((rg1 == 1) & (ri1 < s.rows)).sum()) >= 2
    assert c["range_4mm"][c["point_pixel"][-2]] == 1 and c["point_pixel"][-1] == -1
    assert st["n_projected"] + st["n_too_close"] + st["n_too_far"] + st["n_bad_ring"] == st["n_points_in"]
    _check_returns(nq, sensor, rg[:0], az[:0], ri[:0])  # an empty scan


def test_returns_image_matches_the_points_image(nq, root):
    """The simulated VLP-16 sample as returns (ref.returns_of_points: range rounded to mm, azimuth to BAM16) fills
    the same pixels as its points with their rings, each range within one 4 mm step."""
    d = root / "tests/data/sim_vlp16"
    mm = _mm(kitti.read_bin(d / "velodyne/000000.bin"))
    ring = np.fromfile(d / "ring/000000.bin", np.uint16)
    p = nq.project_q(mm, "vlp16", ring=ring)
    c = _check_returns(nq, "vlp16", *ref.returns_of_points(mm, ring))
    filled_p, filled_c = p["range_4mm"] > 0, c["range_4mm"] > 0
    assert filled_p.sum() > 20_000 and (filled_p != filled_c).sum() <= filled_p.sum() // 1000
    both = filled_p & filled_c
    assert np.abs(p["range_4mm"][both].astype(np.int64) - c["range_4mm"][both]).max() <= 1


def test_returns_bad_arguments(nq):
    with pytest.raises(ValueError, match="azimuth"):
        nq.as_returns([1000], [70000], [0])
    with pytest.raises(ValueError, match="ring"):
        nq.as_returns([1000, 2000], [0, 1], [0])
