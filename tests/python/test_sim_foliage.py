# SPDX-License-Identifier: MIT
"""lidet-sim --foliage (simulate.cast_scene foliage_m): rays return from inside vegetation, not its surface; and
foliage_report's roughness measure."""
import numpy as np

from lidet_tools.sim import cli as sim_cli
from lidet_tools.sim import foliage_report as FR
from lidet_tools.sim.simulate import FOLIAGE_CAP, S_VEGETATION, simulate_scan

SUBURB = dict(scene_kind="suburban")  # hedges, bushes and trees along the street


def test_zero_foliage_is_the_default_scan():
    """The option at 0 draws nothing: the same points and boxes as without it."""
    a = simulate_scan("vlp16", 5, 1, **SUBURB)
    b = simulate_scan("vlp16", 5, 1, foliage_m=0.0, **SUBURB)
    np.testing.assert_array_equal(a.points, b.points)
    np.testing.assert_array_equal(a.sem, b.sem)
    assert [(x.cls, x.x, x.y) for x in a.boxes] == [(x.cls, x.x, x.y) for x in b.boxes]


def test_foliage_moves_vegetation_returns_deeper_and_rougher():
    """With foliage the vegetation's returns lie farther along their rays than without (the same rays: the points
    of one ring and column, matched by direction), by at most the cap plus the range noise, and their neighbours
    scatter about a plane several times more; the other classes' surfaces stay as rough as before."""
    a = simulate_scan("hdl64", 11, 0, **SUBURB)
    b = simulate_scan("hdl64", 11, 0, foliage_m=0.2, **SUBURB)
    assert [(x.cls, x.x, x.y) for x in a.boxes] == [(x.cls, x.x, x.y) for x in b.boxes]

    def dirs(r):
        xyz = r.points[:, :3].astype(np.float64)
        d = np.linalg.norm(xyz, axis=1)
        return xyz / d[:, None], d

    ua, da = dirs(a)
    ub, db = dirs(b)
    from scipy.spatial import cKDTree
    dist, j = cKDTree(ua).query(ub)
    same = dist < 1e-4  # the same ray (directions are exact per ray)
    vb = same & (b.sem == S_VEGETATION) & (a.sem[j] == S_VEGETATION)
    assert vb.sum() > 500
    deeper = db[vb] - da[j[vb]]
    assert np.median(deeper) > 0.08                                    # exponential, mean 0.2, capped: median ~0.14
    assert deeper.max() < FOLIAGE_CAP * 0.2 + 0.2                     # the cap, plus both scans' range noise
    rv0 = np.median(FR.band_medians(*FR.plane_rms(a.points[:, :3], a.sem == S_VEGETATION))[:1])
    rv1 = np.median(FR.band_medians(*FR.plane_rms(b.points[:, :3], b.sem == S_VEGETATION))[:1])
    assert rv1 > 2.0 * rv0, (rv0, rv1)
    rb0 = FR.band_medians(*FR.plane_rms(a.points[:, :3], a.sem == 50))
    rb1 = FR.band_medians(*FR.plane_rms(b.points[:, :3], b.sem == 50))
    for x, y in zip(rb0, rb1):
        if x is not None and y is not None:
            assert abs(y - x) < 0.3 * x, (rb0, rb1)


def test_plane_rms_of_hand_made_surfaces():
    """A flat grid has no spread about its plane; the same grid with N(0, s) offsets along its normal spreads by
    about s (the 12-point plane fit absorbs a little of it)."""
    g = np.stack(np.meshgrid(np.arange(40) * 0.05, np.arange(40) * 0.05), -1).reshape(-1, 2)
    flat = np.column_stack([np.full(len(g), 10.0), g[:, 0] - 1.0, g[:, 1]])
    r, d = FR.plane_rms(flat, np.ones(len(flat), bool))
    assert r.max() < 1e-6 and np.allclose(d, np.hypot(flat[:, 0], flat[:, 1]))
    rough = flat.copy()
    rough[:, 0] += np.random.default_rng(0).normal(0.0, 0.03, len(rough))
    r, _ = FR.plane_rms(rough, np.ones(len(rough), bool))
    assert 0.015 < np.median(r) < 0.035
    assert FR.band_medians(r, d) == [float(np.median(r)), None]  # all at 10.0-12.0 m: the 5-15 m band
    assert FR.plane_rms(flat, np.zeros(len(flat), bool))[0].size == 0


def test_cli_rejects_bad_foliage(tmp_path, capsys):
    assert sim_cli.main(["--sensor", "vlp16", "--scenes", "1", "--out", str(tmp_path), "--foliage", "-0.1"]) == 2
    assert "--foliage must be in [0, 2] m" in capsys.readouterr().err
    assert sim_cli.main(["--sensor", "vlp16", "--scenes", "1", "--out", str(tmp_path), "--foliage", "0.2",
                         "--sequence", "2"]) == 2
    assert "not to --sequence" in capsys.readouterr().err


def test_report_runs_on_simulated_scans_alone(tmp_path, capsys):
    assert FR.main(["--real", str(tmp_path), "--scans", "1", "--foliage", "0,0.2"]) == 0
    out = capsys.readouterr().out
    assert "simulated, --foliage 0.2" in out and "real" not in out.split("|---")[1]
