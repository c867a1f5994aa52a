# SPDX-License-Identifier: MIT
"""The integer ground stage (lib/src/ground/*_q.c) through the bindings: bit for bit against its numpy
reference (codegen/lidet_ref/ground_q.py) on the simulated samples, freshly simulated scans and the real scans, its
defaults against the float ones, and its agreement with the float ground stage on the same compact images
(issue 16: ground labels equal for >= 99.5 % of points) and against the per-point labels."""
import glob
import math
import pathlib

import numpy as np
import pytest

from lidet_ref import ground_q as gq
from lidet_tools import ground_eval, kitti, native

ROOT = pathlib.Path(__file__).resolve().parents[2]
pytestmark = pytest.mark.usefixtures("need_lib")


def _sample_scans():
    """(sensor, points, semantic labels or None) of the committed simulated samples."""
    out = []
    for sensor in ("hdl64", "vlp16"):
        d = ROOT / "tests" / "data" / f"sim_{sensor}"
        for f in sorted(glob.glob(str(d / "velodyne" / "*.bin"))):
            lab = d / "labels" / (pathlib.Path(f).stem + ".label")
            pts = kitti.read_bin(f)
            sem = kitti.read_label(lab, len(pts))[0] if lab.exists() else None
            out.append((sensor, pts, sem))
    return out


def _fresh_scans():
    """A few scans simulated here with fixed seeds (lidet_tools.sim)."""
    from lidet_tools.sim.simulate import simulate_scan
    out = []
    for sensor in ("hdl64", "vlp16"):
        for i in range(2):
            r = simulate_scan(sensor, seed=1616, index=i)
            out.append((sensor, r.points, r.sem))
    return out


def _real_scans(real_dir):
    pairs, _ = ground_eval.find_scans([real_dir / "semantickitti"])
    if not pairs:
        pytest.skip("no labeled SemanticKITTI scans")
    return [("hdl64", kitti.read_bin(v), kitti.read_label(lab)[0]) for v, lab in pairs]


def _bit_exact(sensor, pts, **over):
    img = native.project_compact(pts, sensor)
    res = native.ground_q(img, sensor, **over)
    cfg = native.ground_q_defaults(sensor)
    cfg.update(over)
    mask, smp, planes, d, src, stats = gq.ground(img.x, img.y, img.z, cfg)
    assert np.array_equal(smp, res.sample), "sample masks differ"
    assert np.array_equal(src, res.source), "plane sources differ"
    assert np.array_equal(planes, res.planes), "planes differ"
    assert np.array_equal(d, res.plane_d), "plane offsets differ"
    assert np.array_equal(mask, res.mask), "labels differ"
    assert stats == res.stats
    assert res.stats["n_ground"] > 0
    return res


def test_pixel_r_is_the_exact_rounded_root():
    """R = round(256 sqrt(x^2 + y^2)) of the integer stage (Newton's iteration and the fraction test on cores with a
    divide, digit by digit below 2^12 and on ARMv6-M) against Python's exact integer root: every value below 2^16,
    every square of a root up to 46340 and its neighbours (where the floor and the rounding turn), random values up
    to 2^31 and the ends."""
    s = np.arange(1, 46341, dtype=np.int64)
    near = [s * s + d for d in (-1, 0, 1, 2)] + [s * s + s + d for d in (-1, 0, 1)] + [s * s + 2 * s]
    rnd = np.random.default_rng(16).integers(0, 1 << 31, 100_000)
    v = np.unique(np.concatenate([np.arange(1 << 16)] + near + [rnd, [4095, 4096, (1 << 31) - 1]]))
    v = v[(v >= 0) & (v < (1 << 31))]

    def exact(x):
        w = int(x) << 16
        r = math.isqrt(w)
        return r + (w - r * r > r)

    want = np.fromiter((exact(x) for x in v), np.int64, len(v))
    np.testing.assert_array_equal(native.qmath("ground_r", v), want)


def test_defaults_are_the_float_defaults_rounded():
    for sensor in ("hdl64", "vlp16", "os1-64", "vlp32c"):
        f = native.ground_defaults(sensor)
        q = native.ground_q_defaults(sensor)
        assert q["fy_max_q16"] == round(f["fy_max"] * 65536)
        assert q["confidence_q16"] == round(f["confidence"] * 65536)
        assert q["below_factor_q16"] == round(f["below_factor"] * 65536)
        assert q["veto_slope_q16"] == round(f["veto_slope"] * 65536)
        assert q["ground_per_m_q16"] == round(f["ground_m_per_m"] * 65536)
        assert q["max_tilt_urad"] == round(f["max_tilt_rad"] * 1e6)
        for k in ("fx_max", "gate_above", "gate_below", "mount_height", "inlier", "max_height_dev", "ring_split",
                  "far_max_step", "far2_split", "ground", "veto_min_dz"):
            assert q[k + "_mm"] == round(f[k + "_m"] * 1000), k
        for k in ("fx_on_z", "require_descending", "height_gate", "refine_iters", "n_sectors", "ransac_iters",
                  "sample_step", "sample_col_step", "eval_samples", "min_samples", "min_inliers", "fallback_sectors",
                  "seed", "seed_per_cell"):
            assert q[k] == f[k], k


def test_bad_config_refused():
    img = native.project_compact(_sample_scans()[0][1], "hdl64")
    for k, v in (("fx_max_mm", 0), ("inlier_mm", 0), ("max_tilt_urad", 1570797), ("confidence_q16", 65536),
                 ("fallback_sectors", 33), ("ground_per_m_q16", 6555), ("gate_above_mm", -5001),
                 ("far_max_step_mm", 5001), ("far2_split_mm", 500001)):
        with pytest.raises(native.LidetError):
            native.ground_q(img, "hdl64", **{k: v})


@pytest.mark.parametrize("i", range(len(_sample_scans())))
def test_c_matches_reference_on_samples(i):
    sensor, pts, _ = _sample_scans()[i]
    _bit_exact(sensor, pts)


@pytest.mark.parametrize("variant", [{"fx_on_z": 1, "height_gate": 1}, {"require_descending": 1, "eval_samples": 300},
                                     {"sample_step": 1, "sample_col_step": 1, "n_sectors": 16, "refine_iters": 0,
                                      "ring_split_mm": 0},
                                     {"ring_split_mm": 25000, "ground_per_m_q16": 197, "sample_step": 3,
                                      "sample_col_step": 2, "confidence_q16": 0, "refine_iters": 3},
                                     {"veto_slope_q16": 0, "max_tilt_urad": 350000, "n_sectors": 7},
                                     {"seed_per_cell": 1}, {"seed_per_cell": 1, "ring_split_mm": 25000}])
def test_c_matches_reference_variants(variant):
    sensor, pts, _ = _sample_scans()[0]
    _bit_exact(sensor, pts, **variant)


@pytest.mark.parametrize("step", [500, 0])
def test_c_matches_reference_on_a_climbing_road(step):
    """far_max_step_mm (the far planes' test at the split, lidet_ground_ransac_q.c far_meets; 0: the sensor-height test)
    on scan 155 of the simulated benchmark's seed, whose road climbs from 17 m ahead: bit for bit, and the step
    keeps far planes the height test refuses."""
    from lidet_tools.sim.simulate import simulate_scan
    pts = simulate_scan("hdl64", seed=7000, index=155).points
    res = _bit_exact("hdl64", pts, far_max_step_mm=step)
    assert (res.stats["n_far_fitted"] >= 14) == (step > 0)


@pytest.mark.parametrize("far2", [30000, 0])
def test_c_matches_reference_with_third_cells(far2):
    """far2_split_mm (the third cells, lidet__ground_far2_cells) on scan 37 of seed 7600, whose road bends a
    second time beyond 30 m: bit for bit, and they fit planes there."""
    from lidet_tools.sim.simulate import simulate_scan
    pts = simulate_scan("hdl64", seed=7600, index=37).points
    res = _bit_exact("hdl64", pts, far2_split_mm=far2)
    assert (res.stats["n_far2_fitted"] > 3) == (far2 > 0)
    assert len(res.source) == (3 if far2 else 2) * 32


def test_c_matches_reference_on_fresh_simulated_scans():
    for sensor, pts, _ in _fresh_scans():
        _bit_exact(sensor, pts)


def test_c_matches_reference_on_real_scans(real_dir):
    for sensor, pts, _ in _real_scans(real_dir):
        _bit_exact(sensor, pts)


def _agreement(scans, seed_per_cell=0):
    """(share of points with equal ground labels, float IoU, integer IoU) over all points of the scans."""
    same = total = 0
    conf_f = conf_q = 0
    for sensor, pts, sem in scans:
        fm, qm, _, _ = native.ground_pair(pts, sensor, seed_per_cell=seed_per_cell)
        same += int(np.count_nonzero(fm == qm))
        total += len(pts)
        if sem is not None:
            truth = ground_eval.ground_truth(sem)
            conf_f = conf_f + ground_eval.confusion(fm.astype(bool), truth)
            conf_q = conf_q + ground_eval.confusion(qm.astype(bool), truth)
    iou = lambda c: ground_eval.metrics(c)["iou"] if not np.isscalar(c) else math.nan  # noqa: E731
    return same / total, iou(conf_f), iou(conf_q)


@pytest.mark.parametrize("seed_per_cell", [0, 1])
def test_agreement_with_float_stage_simulated(seed_per_cell):
    agree, iou_f, iou_q = _agreement(_sample_scans() + _fresh_scans(), seed_per_cell)
    print(f"seed_per_cell {seed_per_cell}: labels agree on {agree:.5f}, IoU float {iou_f:.4f} integer {iou_q:.4f}")
    assert agree >= 0.995, agree
    assert abs(iou_q - iou_f) <= 0.005, (iou_f, iou_q)


def test_seed_per_cell_draws_other_samples():
    """The switch is live: a stream per cell gives other planes than one stream through the cells (the same
    samples, other RANSAC draws), and the integer stage refuses a value other than 0 or 1."""
    sensor, pts, _ = _sample_scans()[0]
    img = native.project_compact(pts, sensor)
    a, b = native.ground_q(img, sensor), native.ground_q(img, sensor, seed_per_cell=1)
    assert np.array_equal(a.sample, b.sample)
    assert not np.array_equal(a.plane_d, b.plane_d)
    with pytest.raises(native.LidetError):
        native.ground_q(img, sensor, seed_per_cell=2)


@pytest.mark.parametrize("seed_per_cell", [0, 1])
def test_agreement_with_float_stage_real(real_dir, seed_per_cell):
    agree, iou_f, iou_q = _agreement(_real_scans(real_dir), seed_per_cell)
    print(f"seed_per_cell {seed_per_cell}: labels agree on {agree:.5f}, IoU float {iou_f:.4f} integer {iou_q:.4f}")
    assert agree >= 0.995, agree
    assert iou_q > 0.89 and abs(iou_q - iou_f) <= 0.005, (iou_f, iou_q)
