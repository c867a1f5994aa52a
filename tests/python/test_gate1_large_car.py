# SPDX-License-Identifier: MIT
"""gate1_large_car_margin (lidet_detector_cfg_t, lidet_detector_q_cfg_t _q16): gate 1 widened for a car proposal
whose cluster holds >= LIDET_DET_FLAT_MIN_POINTS (100) member pixels (docs/DETECTOR.md, "Operating points"). The
integer detector's bit-exactness with its reference, the margin included: test_detector_q.py ("large_car")."""
from __future__ import annotations

import json
import pathlib
import subprocess

import numpy as np
import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
SAMPLE = ROOT / "tests/data/sim_hdl64/velodyne/000000.bin"


def test_margin_lets_through_only_large_car_clusters(nd):
    """Against the margin off, a wide margin adds detections and every added one is a car the classifier placed
    above the car gamma, from a cluster of >= 100 points; the detections without it all stay (the stages after
    gate 1 opened, so that what passes it shows: gate 2, the operating point and the flat-surface test off)."""
    pts = np.fromfile(SAMPLE, np.float32).reshape(-1, 4)
    later_off = dict(gate2=False, min_score=[0.0, 0.0, 0.0], car_min_z_spread_m=0.0)
    off = nd.detect(pts, "hdl64", gate1_large_car_margin=0.0, **later_off)
    wide = nd.detect(pts, "hdl64", gate1_large_car_margin=6.0, **later_off)
    gamma_car = float(nd.pn_models()["cls_hdl64"].gamma[0])
    assert wide.stats["n_gate1_rejected"] < off.stats["n_gate1_rejected"]
    added = np.setdiff1d(wide.cluster_id, off.cluster_id)
    assert len(added) >= 1 and set(off.cluster_id.tolist()) <= set(wide.cluster_id.tolist())
    for cid in added:
        k = int(np.flatnonzero(wide.cluster_id == cid)[0])
        assert wide.cls[k] == 0 and wide.energy_cls[k] >= gamma_car
        assert int((wide.point_cluster == cid).sum()) >= 100
    with pytest.raises(ValueError, match="gate1_large_car_margin"):
        nd.detect(pts, "hdl64", gate1_large_car_margin=-0.5)


def test_cli_takes_the_margin_in_both_detectors(nd):
    """`lidet detect --set gate1_large_car_margin=M`: 1 is the > 16-beam default (the same boxes), 0 turns it off
    (no more detections than the default), a wide one adds detections once the stages after gate 1 are opened, out
    of [0, 20] it is refused; with --fixed too."""
    from lidet_tools.detect import find_cli

    def run(*args):
        return subprocess.run([str(find_cli()), "detect", str(SAMPLE), "--sensor", "hdl64", "--json", *args],
                              capture_output=True, text=True)

    for fixed in ((), ("--fixed",)):
        base = json.loads(run(*fixed).stdout)
        same = run(*fixed, "--set", "gate1_large_car_margin=1")
        assert same.returncode == 0 and json.loads(same.stdout)["boxes"] == base["boxes"]
        off = json.loads(run(*fixed, "--set", "gate1_large_car_margin=0").stdout)
        assert len(off["boxes"]) <= len(base["boxes"])
        opened = (*fixed, "--set", "gate2=0", "--set", "min_score.car=0", "--set", "car_min_z_spread_m=0")
        n_off = len(json.loads(run(*opened, "--set", "gate1_large_car_margin=0").stdout)["boxes"])
        wide = json.loads(run(*opened, "--set", "gate1_large_car_margin=6").stdout)
        assert len(wide["boxes"]) > n_off
        for bad in ("-0.5", "20.5"):
            assert run(*fixed, "--set", f"gate1_large_car_margin={bad}").returncode != 0
