# SPDX-License-Identifier: MIT
"""The C projection through the Python bindings, against the float64 numpy reference."""
import numpy as np
import pytest

from lidet_ref.proj import project_ref
from lidet_tools import kitti, native, sensors


pytestmark = pytest.mark.usefixtures("need_lib")


def test_python_and_c_sensor_tables_identical():
    cs = native.c_sensors()
    assert set(cs) == set(sensors.SENSORS)
    for name, s in sensors.SENSORS.items():
        rows, cols, elev, mh = cs[name]
        assert (rows, cols) == (s.rows, s.cols), name
        assert np.allclose(elev, s.beam_elev_rad, atol=2e-7), name
        assert mh == pytest.approx(s.mount_height_m), name


def _random_scan(sensor, n, rng):
    s = sensors.get_sensor(sensor)
    el = rng.uniform(s.beam_elev_rad.min() - 0.03, s.beam_elev_rad.max() + 0.03, n)
    az = rng.uniform(-np.pi, np.pi, n)
    r = rng.uniform(1.0, 80.0, n)
    pts = np.stack([r * np.cos(el) * np.cos(az), r * np.cos(el) * np.sin(az), r * np.sin(el),
                    rng.uniform(0, 1, n)], 1).astype(np.float32)
    return s, pts


@pytest.mark.parametrize("sensor", list(sensors.SENSORS))
def test_projection_matches_reference(sensor):
    rng = np.random.default_rng(7)
    s, pts = _random_scan(sensor, 20000, rng)
    out = native.project(pts, sensor)
    pix_ref, idx_ref, row_elev = project_ref(pts, s.beam_elev_rad, s.cols)
    assert np.allclose(out.row_elev, row_elev, atol=2e-7)
    agree = (out.point_pixel == pix_ref).mean()
    assert agree >= 0.999, f"{sensor}: only {agree:.5f} of points in the reference pixel"
    assert out.stats["n_points_in"] == len(pts)
    assert out.stats["n_projected"] == (out.point_pixel >= 0).sum()
    # valid pixels hold their winner's coordinates and range
    v = out.valid
    w = out.point_idx[v]
    assert np.allclose(out.x[v], pts[w, 0]) and np.allclose(out.z[v], pts[w, 2])
    assert np.allclose(out.range[v], np.linalg.norm(pts[w, :3], axis=1), rtol=1e-6)
    # every projected point's pixel is held by a point at least as close
    pp = out.point_pixel
    m = pp >= 0
    rngs = np.linalg.norm(pts[:, :3], axis=1)
    assert (out.range.ravel()[pp[m]] <= rngs[m] * (1 + 1e-6)).all()


def test_ring_path_and_errors():
    rng = np.random.default_rng(3)
    s, pts = _random_scan("vlp16", 1000, rng)
    ring = rng.integers(0, 17, len(pts)).astype(np.uint16)
    out = native.project(pts, "vlp16", ring=ring)
    pix_ref, _, _ = project_ref(pts, s.beam_elev_rad, s.cols, ring=ring)
    assert (out.point_pixel == pix_ref).mean() >= 0.999
    assert out.stats["n_bad_ring"] == (ring == 16).sum()
    with pytest.raises(ValueError):
        native.project(pts[:, :2], "vlp16")
    bad = sensors.custom_sensor("dup", 64, beam_elev_deg=[1.0, 1.0])
    with pytest.raises(native.LidetError, match="CONFIG"):
        native.project(pts, bad)


def test_real_kitti_every_point_projected(real_dir):
    for f in sorted((real_dir / "kitti" / "training" / "velodyne").glob("*.bin")):
        pts = kitti.read_bin(f)
        out = native.project(pts, "hdl64")
        assert out.stats["n_projected"] == len(pts)
        fill = out.valid.mean()
        assert 0.6 < fill < 0.95, fill


@pytest.mark.parametrize("sensor", ["hdl64", "vlp16"])
def test_sample_rings_agree_with_nearest_beam_rows(root, sensor):
    """The shipped simulated samples were made with the current beam tables: projecting by elevation
    and by the simulator's ring index gives the same pixels (guards against stale samples)."""
    d = root / "tests" / "data" / f"sim_{sensor}"
    pts = kitti.read_bin(d / "velodyne" / "000000.bin")
    ring = np.fromfile(d / "ring" / "000000.bin", np.uint16)
    by_elev = native.project(pts, sensor).point_pixel
    by_ring = native.project(pts, sensor, ring=ring).point_pixel
    assert (by_elev >= 0).all() and (by_ring >= 0).all()
    assert (by_elev == by_ring).mean() >= 0.99
