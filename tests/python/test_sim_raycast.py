# SPDX-License-Identifier: MIT
"""Ray casting of the simulator against known geometry."""
import numpy as np

from lidet_tools.sensors import custom_sensor
from lidet_tools.sim import raycast as rc
from lidet_tools.sim.sensor_model import SensorModel


def _cast(plist, dirs):
    prims = plist.freeze()
    ray = np.repeat(np.arange(len(dirs)), len(prims))
    pidx = np.tile(np.arange(len(prims)), len(dirs))
    t, _ = rc.intersect_pairs(prims, dirs, ray, pidx)
    return t.reshape(len(dirs), len(prims)).min(1)


def _unit(v):
    v = np.asarray(v, float)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def test_ray_hits_box_cylinder_ellipsoid_at_right_range():
    pl = rc.PrimitiveList()
    pl.add(rc.BOX, [10.0, 0.0, 0.0], [1.0, 2.0, 0.5])                       # front face at x = 9
    pl.add(rc.CYLINDER, [0.0, 5.0, 0.0], [0.5, 0.5, 2.0])                   # surface at y = 4.5
    pl.add(rc.ELLIPSOID, [0.0, -7.0, 0.0], [1.0, 1.0, 1.0])                 # sphere, surface at 6
    pl.add(rc.BOX, [-8.0, 0.0, 0.0], [1.0, 1.0, 1.0], rc.rot_z(np.pi / 4))   # diamond: corner at 8 - sqrt 2
    pl.add(rc.CYLINDER, [0.0, 0.0, 12.0], [3.0, 3.0, 1.0])                  # bottom cap at z = 11
    dirs = _unit([[1, 0, 0], [0, 1, 0], [0, -1, 0], [-1, 0, 0], [0, 0, 1], [1, 0, 0.3], [0, 0, -1]])
    t = _cast(pl, dirs)
    assert abs(t[0] - 9.0) < 1e-5
    assert abs(t[1] - 4.5) < 1e-5
    assert abs(t[2] - 6.0) < 1e-5
    assert abs(t[3] - (8.0 - np.sqrt(2.0))) < 1e-5
    assert abs(t[4] - 11.0) < 1e-5
    # slanted ray into the box front face: x = 9 reached at t = 9 / cos, z = 2.7 > 0.5 -> miss
    assert np.isinf(t[5])
    assert np.isinf(t[6])


def test_ray_hits_ground_plane_and_heightfield_step():
    n = 401
    z = np.full((n, n), -2.0)
    code = np.zeros((n, n), np.int8)
    hf = rc.HeightField(-50.0, -50.0, 0.25, z, code)
    el = np.radians([-30.0, -10.0, -3.0, 5.0])
    dirs = np.stack([np.cos(el), np.zeros(4), np.sin(el)], 1)
    t = rc.intersect_ground(hf, dirs, 100.0)
    assert np.allclose(t[:3], 2.0 / np.sin(-el[:3]), atol=2e-3)
    assert np.isinf(t[3])
    # a 15 cm curb at x >= 37: the -3 deg ray (flat hit at 38.2 m, z = -1.94 at x = 37) stops at its face
    z2 = z.copy()
    z2[:, (np.arange(n) * 0.25 - 50.0) >= 37.0] = -1.85
    hf2 = rc.HeightField(-50.0, -50.0, 0.25, z2, code)
    t2 = rc.intersect_ground(hf2, dirs[2:3], 100.0)
    x = t2[0] * np.cos(el[2])
    assert 36.7 < x < 37.05


def test_culling_matches_brute_force():
    rng = np.random.default_rng(3)
    pl = rc.PrimitiveList()
    for _ in range(60):
        kind = int(rng.integers(0, 3))
        c = np.r_[rng.uniform(-30, 30, 2), rng.uniform(-2, 3)]
        half = rng.uniform(0.1, 4.0, 3)
        R = rc.rot_z(rng.uniform(-3, 3)) @ rc.rot_y(rng.uniform(-1, 1))
        pl.add(kind, c, half, R)
    prims = pl.freeze()
    sensor = custom_sensor("t", 360, fov_up_deg=15, fov_down_deg=-25, rows=24)
    grid, _ = SensorModel(sensor, 1.0, 0.004, -0.003).ray_grid()
    ray, pidx = rc.cull_pairs(prims, grid)
    t, _ = rc.intersect_pairs(prims, grid.dirs, ray, pidx)
    best = np.full(len(grid.dirs), np.inf)
    np.minimum.at(best, ray, t)
    ref = _cast(pl, grid.dirs)
    assert np.isfinite(ref).sum() > 500
    assert np.array_equal(np.isfinite(best), np.isfinite(ref))
    assert np.allclose(best[np.isfinite(ref)], ref[np.isfinite(ref)])


def test_ground_search_band_keeps_hits():
    """The per-row radial band must not drop ground hits that a dense search finds (hills, rising rays)."""
    from lidet_tools.sim.scene import make_scene
    from lidet_tools.sensors import get_sensor
    s = get_sensor("vlp16")
    sc = make_scene(np.random.default_rng(2), 0.5, s.max_range_m, robot=True)
    grid, _ = SensorModel(s, 0.5, 0.008, -0.006).ray_grid()
    fast = rc.intersect_ground(sc.ground, grid.dirs, 101.0, grid=grid)
    ref = rc.intersect_ground(sc.ground, grid.dirs, 101.0, n_samples=60, n_refine=14)
    assert np.isfinite(fast).sum() >= 0.99 * np.isfinite(ref).sum()
    both = np.isfinite(fast) & np.isfinite(ref)
    assert np.median(np.abs(fast[both] - ref[both])) < 0.01


def test_ground_search_band_low_field():
    """A field entirely below the sensor (zmax < 0) keeps all its hits with the radial band."""
    n = 301
    x = -45.0 + 0.3 * np.arange(n)
    z = -1.7 - 0.05 * np.abs(x)[None, :] * np.ones((n, 1))      # falls away from the sensor
    hf = rc.HeightField(-45.0, -45.0, 0.3, z, np.zeros((n, n), np.int8))
    from lidet_tools.sensors import get_sensor
    grid, _ = SensorModel(get_sensor("hdl64"), 1.7, 0.004, 0.003).ray_grid()
    fast = rc.intersect_ground(hf, grid.dirs, 121.0, grid=grid)
    ref = rc.intersect_ground(hf, grid.dirs, 121.0, n_samples=60, n_refine=14)
    assert np.isfinite(ref).sum() > 50000
    assert np.isfinite(fast).sum() >= 0.99 * np.isfinite(ref).sum()
