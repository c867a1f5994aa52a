# SPDX-License-Identifier: MIT
"""tools/bench/ablate_q.py (the int8 accuracy ablations of issue 16): the detectors' candidate proposals
(lidet_tools.native.candidates_float / candidates_q) and the script's post-processing reproduce the float and
the integer detector, so that the mixed combinations (float geometry + int8 nets, integer geometry + float nets)
differ from them only in what they swap."""
import importlib.util
import math
import pathlib

import numpy as np
import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
SAMPLES = {"hdl64": (ROOT / "tests/data/sim_hdl64/velodyne/000000.bin", 48),
           "vlp16": (ROOT / "tests/data/sim_vlp16/velodyne/000000.bin", 24)}


@pytest.fixture(scope="module")
def ab(need_lib):
    spec = importlib.util.spec_from_file_location("ablate_q", ROOT / "tools/bench/ablate_q.py")
    m = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(m)
    return m


@pytest.mark.parametrize("fam", sorted(SAMPLES))
@pytest.mark.parametrize("crop", [False, True])
def test_pure_combinations_reproduce_the_detectors(ab, fam, crop):
    from lidet_tools import kitti, native
    path, max_boxes = SAMPLES[fam]
    pts = kitti.read_bin(path)
    # integer geometry + int8 nets = the integer detector, bit for bit (classes, Q15 scores, mm boxes)
    cq = native.candidates_q(native.to_mm(pts), fam, crop_half_bam=(1 << 29) if crop else 0)
    # (the detectors' post-processing that ablate_q leaves out off: the flat-surface test, the car boxes' ground,
    # and the group split, whose parts are proposals of their own that the candidates do not hold)
    dq = native.detect_q(native.to_mm(pts), fam, crop_half_bam=(1 << 29) if crop else 0, car_min_z_spread_mm=0,
                         car_ground_mm=0, group_split=False)
    assert len(cq["xyz"]) == dq["stats"]["n_classified"] > 0
    got = ab.nets_int8(fam, cq["xyz"], cq["mean"], cq["voxel"], cq["cluster_id"], cq["n_points"])
    assert len(got) == len(dq["cls"]) > 0
    np.testing.assert_array_equal([g[0] for g in got], dq["cls"])
    np.testing.assert_array_equal(np.rint([g[1] * 32768 for g in got]), dq["score_q15"])
    np.testing.assert_allclose([g[2][:6] for g in got], dq["boxes"][:, :6] / 1000.0, atol=1e-9)
    # float geometry + float nets = the float detector without refinement (same float32 values)
    cf = native.candidates_float(pts, fam, crop_half_rad=math.pi / 4 if crop else 0.0)
    df = native.detect(pts, fam, crop_half_rad=math.pi / 4 if crop else 0.0, refine=False, car_min_z_spread_m=0,
                       car_ground_m=0, group_split=False)
    assert len(cf["xyz"]) == df.stats["n_classified"]
    got = ab.nets_float(fam, cf["xyz"], cf["mean"], cf["voxel"], cf["cluster_id"], max_boxes, cf["n_points"])
    assert len(got) == len(df.cls) > 0
    np.testing.assert_array_equal([g[0] for g in got], df.cls)
    np.testing.assert_allclose([g[1] for g in got], df.score, rtol=1e-6)
    np.testing.assert_allclose([g[2] for g in got], df.box, atol=1e-6)


def test_candidates_follow_the_detectors_order(need_lib):
    """Nearest first (squared horizontal range of the mean), each a proposal of the models' 64 points."""
    from lidet_tools import kitti, native
    pts = kitti.read_bin(SAMPLES["vlp16"][0])
    cq = native.candidates_q(native.to_mm(pts), "vlp16")
    r2 = (cq["mean"][:, :2].astype(np.int64) ** 2).sum(1)
    assert np.all(np.diff(r2) >= 0) and cq["xyz"].shape[1:] == (64, 3)
    cf = native.candidates_float(pts, "vlp16")
    r2 = (cf["mean"][:, :2].astype(np.float64) ** 2).sum(1)
    assert np.all(np.diff(r2) >= -1e-6) and len(np.unique(cf["cluster_id"])) == len(cf["cluster_id"])
    # the cluster sizes the score reads: those of the detections of the same run
    d = native.detect_q(native.to_mm(pts), "vlp16")
    size = dict(zip(cq["cluster_id"].tolist(), cq["n_points"].tolist()))
    assert len(d["cluster_id"]) > 0 and all(size[int(c)] == int(n) for c, n in zip(d["cluster_id"], d["n_points"]))
