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


def test_group_parts_touching_both_stand(nd, real_dir):
    """Four people side by side at 19 m on PandaSet 000000 (a training frame) share one cluster; the cut boxes
    each of them, and neighbouring part boxes touch (BEV IoU about 0.1). Parts of one cut suppress each other
    only past 0.25 (lidet_group_common.h): the float detector keeps its four parts even with nms_iou 0.05, and
    the integer one the pair whose IoU (0.103) passes the default 0.1, which the NMS of other clusters drops."""
    from lidet_tools import real
    fr = real.load_frame(real_dir, "pandaset", "000000")

    for nms in (0.1, 0.05):
        d = nd.detect(fr.points, fr.sensor, mount_height_m=fr.mount_height_m, nms_iou=nms)
        box = np.asarray(d.box)
        near = np.flatnonzero((np.hypot(box[:, 0] - 19.2, box[:, 1] + 14.0) < 1.5) &
                              (d.outcome[d.cluster_id - 1] == GROUP))
        assert len(near) == 4 and len(set(d.cluster_id[near].tolist())) == 1
        ious = [_bev(nd, box[i], box[j]) for i in near for j in near if i < j]
        assert 0.05 < max(ious) <= 0.25  # past 0.05: the NMS of other clusters would drop one
    q = nd.detect_q(nd.to_mm(fr.points), fr.sensor, model="hdl64", mount_height_m=fr.mount_height_m)
    b = q["boxes"].astype(np.float64) * 1e-3
    near = np.flatnonzero((np.hypot(b[:, 0] - 19.2, b[:, 1] + 14.0) < 1.5) &
                          (q["outcome"][q["cluster_id"] - 1] == GROUP))
    assert len(near) >= 3 and len(set(q["cluster_id"][near].tolist())) == 1
    iq = [int(nd.bev_iou_q(q["boxes"][[i]], q["boxes"][[j]])[0]) for i in near for j in near if i < j]
    assert 3277 < max(iq) <= 8192


def test_group_margin_judges_the_cut_not_the_parts(nd, real_dir):
    """group_gate1_margin (default 2 nats) widens gate 1 for the judgement of a cut only: on PandaSet 000000 a cut
    whose every part but one passes gate 1 now stands, and the people that pass it are found; a part that passes
    only within the margin gives no detection (every group detection passes gate 1 itself)."""
    from lidet_tools import real
    from lidet_tools.eval_real import _arr
    fr = real.load_frame(real_dir, "pandaset", "000000")
    wide = nd.detect(fr.points, fr.sensor, mount_height_m=fr.mount_height_m)  # the default, 2 nats
    strict = nd.detect(fr.points, fr.sensor, mount_height_m=fr.mount_height_m, group_gate1_margin=0.0)
    assert wide.stats["n_group_split"] > strict.stats["n_group_split"]
    # every part kept passes the plain gate 1 of its (pedestrian) class (margins 0 by default)
    gamma_ped = float(nd.pn_models()["cls_hdl64"].gamma[PED])
    groups = np.flatnonzero(wide.outcome == GROUP) + 1
    parts = np.flatnonzero(np.isin(wide.cluster_id, groups))
    assert len(parts) >= 1 and np.all(wide.cls[parts] == PED)
    # a part may be a person the classifier calls a rider (its own gamma, lower or higher): at most the larger one
    gamma_any = max(float(g) for g in nd.pn_models()["cls_hdl64"].gamma[1:])
    assert np.all(wide.energy_cls[parts] < gamma_any) and np.any(wide.energy_cls[parts] < gamma_ped)
    # and more labelled people within 40 m are found, none lost
    peds = [_arr(b) for b in fr.boxes if b.cls == "Pedestrian" and np.hypot(b.x, b.y) <= 40.0]

    def found(d):
        return {i for i, g in enumerate(peds) for j in np.flatnonzero(d.cls == PED) if _bev(nd, d.box[j], g) >= 0.25}

    assert found(strict) < found(wide)
    with pytest.raises(ValueError, match="group_gate1_margin"):
        nd.detect(fr.points, fr.sensor, group_gate1_margin=-1.0)


def test_cli_group_margin(nd, crowd, tmp_path):
    """`--set group_gate1_margin=M` reaches both detectors; out of [0, 20] it is refused."""
    from lidet_tools import kitti
    from lidet_tools.detect import find_cli
    scan = tmp_path / "crowd.bin"
    kitti.write_bin(scan, crowd.points)

    def run(*args):
        return subprocess.run([str(find_cli()), "detect", str(scan), "--sensor", "hdl64", "--json", *args],
                              capture_output=True, text=True)

    for fixed in ((), ("--fixed",)):
        base = json.loads(run(*fixed).stdout)
        same = run(*fixed, "--set", "group_gate1_margin=2")  # the default, said out loud
        assert same.returncode == 0 and json.loads(same.stdout)["boxes"] == base["boxes"]
        # a wider margin accepts every cut the default does (or an earlier one of the same cluster): no fewer
        # clusters split
        wide = json.loads(run(*fixed, "--set", "group_gate1_margin=20").stdout)
        assert wide["group_split"] >= base["group_split"] >= 1
        bad = run(*fixed, "--set", "group_gate1_margin=-0.5")
        assert bad.returncode != 0
