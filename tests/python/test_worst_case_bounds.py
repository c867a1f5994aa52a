# SPDX-License-Identifier: MIT
"""The caps that bound the worst-case time per stage (issue 19, docs/ROBUSTNESS.md): the clustering's rescue
budget (max_fragment_pixels) and occluder bridging budget (max_bridge_steps), both mirrored by the numpy
reference, and the detector's box budget (max_boxes), in the float and the integer detector."""
import json
import subprocess

import numpy as np
import pytest

from lidet_tools import native
from lidet_tools.sensors import get_sensor
from test_bindings_cluster import _check_against_ref


def _random_range_window(sensor, cols, seed=0):
    """One point per pixel of the first `cols` columns right of straight ahead, each at its own random range
    (5-40 m): the clustering's worst case, nearly every pixel a fragment."""
    s = get_sensor(sensor)
    elev = np.asarray(s.elev_sorted_desc, np.float64)
    r, c = np.meshgrid(np.arange(len(elev)), s.cols // 2 + np.arange(cols), indexing="ij")
    az = np.pi * (1.0 - 2.0 * (c + 0.5) / s.cols)
    rng = np.random.default_rng(seed).uniform(5, 40, r.shape)
    el = elev[r]
    xyz = np.stack([rng * np.cos(el) * np.cos(az), rng * np.cos(el) * np.sin(az), rng * np.sin(el)], -1)
    pts = np.zeros((xyz.size // 3, 4), np.float32)
    pts[:, :3] = xyz.reshape(-1, 3)
    return pts


def test_rescue_budget_matches_reference():
    pts = _random_range_window("vlp16", 240)
    ground = np.zeros(len(pts), bool)
    stats = {}
    for budget in (0, 150):
        cfg = {k: v for k, v in native.cluster_defaults("vlp16").items() if k != "mount_height_m"}
        cfg["max_fragment_pixels"] = budget
        c = _check_against_ref(pts, ground, cfg, "vlp16", exact=True)
        stats[budget] = c.stats
    assert stats[0]["n_fragment_pixels"] > 150 and stats[0]["n_dropped_fragment_budget"] == 0
    assert 0 < stats[150]["n_fragment_pixels"] <= 150 and stats[150]["n_dropped_fragment_budget"] > 0
    assert stats[150]["n_fragments"] < stats[0]["n_fragments"]


def test_bridge_budget_matches_reference():
    pts = _random_range_window("vlp16", 240, seed=1)
    ground = np.zeros(len(pts), bool)
    stats = {}
    for per_pixel in (0.0, 0.25):
        cfg = {k: v for k, v in native.cluster_defaults("vlp16").items() if k != "mount_height_m"}
        cfg.update(bridge_occluders=1, max_bridge_per_pixel=per_pixel)
        stats[per_pixel] = _check_against_ref(pts, ground, cfg, "vlp16", exact=True).stats
    budget = int(np.float32(0.25) * np.float32(stats[0.25]["n_candidates"]))
    assert stats[0.0]["n_bridge_steps"] > 2 * budget
    # the budget is checked per pixel: the last pixel that bridges may pass it by its own few steps
    assert budget <= stats[0.25]["n_bridge_steps"] < budget + 4 * 16


def test_rescue_budget_default_leaves_real_sized_scans_alone(root):
    """the defaults (4096 / 2048 pixels) are well above what the simulated samples hand to the rescue"""
    from lidet_tools import kitti
    for sensor in ("hdl64", "vlp16"):
        pts = kitti.read_bin(root / f"tests/data/sim_{sensor}/velodyne/000000.bin")
        c = native.cluster(pts, sensor)
        assert c.stats["n_dropped_fragment_budget"] == 0
        # no ground mask here: the most bridging a scan does; still below the default budget
        assert c.stats["n_bridge_steps"] < native.cluster_defaults(sensor)["max_bridge_per_pixel"] * c.stats[
            "n_candidates"] * 0.75
        assert 0 < c.stats["n_fragment_pixels"] <= native.cluster_defaults(sensor)["max_fragment_pixels"] // 2


@pytest.mark.parametrize("fixed", [False, True], ids=["float", "integer"])
def test_box_budget(cli, root, fixed):
    scan = root / "tests/data/sim_hdl64/velodyne/000000.bin"

    def run(*extra):
        r = subprocess.run([str(cli), "detect", str(scan), "--sensor", "hdl64", "--json", *extra,
                            *(["--fixed"] if fixed else [])], check=True, capture_output=True, text=True)
        return json.loads(r.stdout)

    full = run()
    assert full["box_budget"] == 48 and full["over_box_budget"] == 0 and full["boxed"] >= 4
    capped = run("--set", "max_boxes=2")
    assert capped["boxed"] == 2 and capped["over_box_budget"] == full["boxed"] - 2
    assert capped["status"] == 1  # LIDET_TRUNCATED
    assert capped["detections"] <= 2
    # the boxed ones are the first gate-1 passes in nearest-first order: their detections are unchanged
    kept = {b["cluster"] for b in capped["boxes"]}
    assert kept <= {b["cluster"] for b in full["boxes"]}
