# SPDX-License-Identifier: MIT
"""The group split (lidet_detector_cfg_t.group_split, on for > 16 beams): people standing side by side in one
cluster, cut along the cluster's principal axis and kept when the classifier calls every part a pedestrian or a
cyclist (one at least a pedestrian); every part is boxed as a pedestrian. The
float detector through the bindings and the CLI on a simulated crowd scan where two labelled people share a
cluster, and on a real PandaSet frame when ../shared is there. The integer detector's split is checked bit for
bit against the numpy reference (codegen/lidet_ref/group_q.py) in test_detector_q.py (cases group, group_real)."""
from __future__ import annotations

import json
import subprocess

import numpy as np
import pytest

PED, GROUP = 2, 11  # lidet_class_t, LIDET_DET_OUT_GROUP


@pytest.fixture(scope="module")
def crowd():
    """A simulated HDL-64 crowd scan (lidet-sim --crowd, seed 9363) where the detector's clustering leaves two
    people walking side by side at 16 m in one cluster."""
    from lidet_tools.sim.simulate import simulate_scan
    return simulate_scan("hdl64", seed=9363, index=0, crowd=True)


def _bev(nd, a, b) -> float:
    from lidet_tools.eval import iou
    return float(iou.iou_bev_pairs(np.asarray(a, np.float64)[None], np.asarray(b, np.float64)[None])[0])


def test_group_split_finds_people_sharing_a_cluster(nd, crowd):
    on = nd.detect(crowd.points, "hdl64")  # the default for 64 beams
    off = nd.detect(crowd.points, "hdl64", group_split=False)
    groups = np.flatnonzero(on.outcome == GROUP) + 1
    assert len(groups) == on.stats["n_group_split"] >= 1
    assert off.stats["n_group_split"] == off.stats["n_group_classified"] == 0 and GROUP not in off.outcome
    peds = [b for b in crowd.boxes if b.cls == "Pedestrian"]
    for g in groups:
        parts = np.flatnonzero(on.cluster_id == g)
        assert 1 <= len(parts) <= 4 and np.all(on.cls[parts] == PED)
        # the cluster gave no detection of its own without the split
        assert g not in set(off.cluster_id.tolist())
        # every part lies on a labelled pedestrian, each on another one
        hit = [max(range(len(peds)), key=lambda i: _bev(nd, on.box[j], [peds[i].x, peds[i].y, peds[i].z, peds[i].l,
                                                                           peds[i].w, peds[i].h, peds[i].yaw]))
               for j in parts]
        assert len(set(hit)) == len(parts)
        for j, i in zip(parts, hit):
            assert np.hypot(on.box[j][0] - peds[i].x, on.box[j][1] - peds[i].y) < 0.5
    # the split adds its parts and changes nothing else
    rest = ~np.isin(on.cluster_id, groups)
    assert sorted(zip(on.cluster_id[rest].tolist(), on.cls[rest].tolist())) == \
        sorted(zip(off.cluster_id.tolist(), off.cls.tolist()))
    # its passes are counted apart from the clusters' and share the box budget
    assert on.stats["n_classified"] == off.stats["n_classified"]
    assert on.stats["n_group_classified"] >= 2 and 1 <= on.stats["n_group_boxed"] <= on.stats["n_group_classified"]


def test_group_split_off_for_16_beams_by_default(nd):
    from lidet_tools import kitti
    from pathlib import Path
    pts = kitti.read_bin(Path(__file__).resolve().parents[2] / "tests/data/sim_vlp16/velodyne/000000.bin")
    d = nd.detect(pts, "vlp16")
    assert d.stats["n_group_classified"] == 0


def test_cli_group_split(nd, crowd, tmp_path):
    from lidet_tools import kitti
    from lidet_tools.detect import find_cli
    scan = tmp_path / "crowd.bin"
    kitti.write_bin(scan, crowd.points)

    def run(*sets, fixed=False):
        cmd = [str(find_cli()), "detect", str(scan), "--sensor", "hdl64", "--json"] + (["--fixed"] if fixed else [])
        for s in sets:
            cmd += ["--set", s]
        return subprocess.run(cmd, capture_output=True, text=True)

    want = nd.detect(crowd.points, "hdl64")
    for sets, n_split in (((), want.stats["n_group_split"]), (("group_split=0",), 0),
                          (("group_max_range_m=10",), 0)):  # the group stands 16 m away
        r = run(*sets)
        assert r.returncode == 0, r.stderr
        js = json.loads(r.stdout)
        assert js["group_split"] == n_split, sets
    js = json.loads(run().stdout)
    assert [b["class"] for b in js["boxes"]] == [nd.CLASSES[int(c)] for c in want.cls]
    r = run("group_split=2")  # a flag: 0 or 1
    assert r.returncode != 0 and "group_split=2" in r.stderr
    r = run(fixed=True)  # the integer detector takes the switch too
    assert r.returncode == 0 and "group_split" in json.loads(r.stdout)
    assert json.loads(run("group_split=0", fixed=True).stdout)["group_classified"] == 0


def test_group_split_on_a_real_frame(nd, real_dir):
    """PandaSet 000000 (a training frame): people walking side by side in one cluster at 26 m, found by the
    split and by nothing else, and no one within 40 m lost."""
    from lidet_tools import real
    from lidet_tools.eval_real import _arr
    fr = real.load_frame(real_dir, "pandaset", "000000")
    on = nd.detect(fr.points, fr.sensor, mount_height_m=fr.mount_height_m)
    off = nd.detect(fr.points, fr.sensor, mount_height_m=fr.mount_height_m, group_split=False)
    # within 40 m (the evaluation's range): farther people can lose the box budget (48 box passes, reached on
    # this busy street) to the parts' passes
    peds = [_arr(b) for b in fr.boxes if b.cls == "Pedestrian" and np.hypot(b.x, b.y) <= 40.0]

    def found(d):
        return {i for i, g in enumerate(peds) for j in np.flatnonzero(d.cls == PED) if _bev(nd, d.box[j], g) >= 0.25}

    assert on.stats["n_group_split"] >= 1
    assert len(found(on) - found(off)) >= 1 and found(off) <= found(on)
