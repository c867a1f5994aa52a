# SPDX-License-Identifier: MIT
"""The proposal refinement (lib/src/cluster/lidet_refine.c, cfg split_people and join_cars) against its numpy reference
(codegen/lidet_ref/cluster.py: refine_ref): the C's labels without the refinement, refined in
numpy, equal the C's labels with it, on simulated crowd scans (issue 15) of both sensor kinds; and the
crowd scenes of lidet-sim (close people; the default scenes unchanged)."""
import inspect

import numpy as np
import pytest

from lidet_ref import cluster as ref
from lidet_tools import cluster_eval as ce
from lidet_tools import native
from lidet_tools.sim.simulate import simulate_scan


def _refine_defaults(sensor):
    """the sensor's C defaults of the settings refine_ref takes (16-beam profiles have values of their own)"""
    names = inspect.signature(ref.refine_ref).parameters
    return {k: v for k, v in native.cluster_defaults(sensor).items() if k in names}


@pytest.mark.parametrize("sensor,index", [("hdl64", 0), ("hdl64", 3), ("vlp16", 1), ("vlp16", 3)])
def test_refine_matches_reference(sensor, index):
    r = simulate_scan(sensor, seed=15, index=index, crowd=True)
    g = ce.ground_mask(r.sem.astype(np.uint32))
    plain = native.cluster(r.points, sensor, ground=g, split_people=0, join_cars=0, with_image=True)
    refined = native.cluster(r.points, sensor, ground=g)
    xyz = np.stack([plain.image.x, plain.image.y, plain.image.z], -1)
    cfg = _refine_defaults(sensor)
    assert cfg["person_min_points"] == (9 if sensor == "vlp16" else 10) and "join_gap_m" in cfg
    want = ref.refine_ref(plain.pixel_labels, xyz, **cfg)
    assert refined.stats["n_split"] > 0          # the scene has groups to cut (else the test shows nothing)
    np.testing.assert_array_equal(refined.pixel_labels, want)
    assert len(refined) == len(plain) + refined.stats["n_split_parts"] - refined.stats["n_joined"]


@pytest.mark.parametrize("split,join", [(1, 0), (0, 1)])
def test_each_rule_alone_matches_reference(split, join):
    r = simulate_scan("hdl64", seed=15, index=3, crowd=True)
    g = ce.ground_mask(r.sem.astype(np.uint32))
    plain = native.cluster(r.points, "hdl64", ground=g, split_people=0, join_cars=0, with_image=True)
    one = native.cluster(r.points, "hdl64", ground=g, split_people=split, join_cars=join)
    assert one.stats["n_split" if split else "n_joined"] > 0 and one.stats["n_joined" if split else "n_split"] == 0
    xyz = np.stack([plain.image.x, plain.image.y, plain.image.z], -1)
    np.testing.assert_array_equal(one.pixel_labels,
                                  ref.refine_ref(plain.pixel_labels, xyz, **{**_refine_defaults("hdl64"),
                                                 "split_people": bool(split), "join_cars": bool(join)}))


@pytest.mark.parametrize("cap", [3, 12])
def test_join_budget_matches_reference(cap):
    """max_join_pieces: only the first `cap` car pieces (slot order) join; the C and the reference agree, the
    budget binds (pieces were skipped) and costs joins against no budget."""
    r = simulate_scan("hdl64", seed=15, index=3, crowd=True)
    g = ce.ground_mask(r.sem.astype(np.uint32))
    plain = native.cluster(r.points, "hdl64", ground=g, split_people=0, join_cars=0, with_image=True)
    free = native.cluster(r.points, "hdl64", ground=g, split_people=0, max_join_pieces=0)
    capped = native.cluster(r.points, "hdl64", ground=g, split_people=0, max_join_pieces=cap)
    assert capped.stats["n_join_skipped"] > 0 and free.stats["n_join_skipped"] == 0
    assert capped.stats["n_joined"] < free.stats["n_joined"]
    xyz = np.stack([plain.image.x, plain.image.y, plain.image.z], -1)
    np.testing.assert_array_equal(capped.pixel_labels, ref.refine_ref(plain.pixel_labels, xyz, split_people=False,
                                                                       max_join_pieces=cap))
    np.testing.assert_array_equal(free.pixel_labels, ref.refine_ref(plain.pixel_labels, xyz, split_people=False,
                                                                     max_join_pieces=0))


def test_refine_off_is_the_plain_clustering():
    r = simulate_scan("hdl64", seed=15, index=0, crowd=True)
    g = ce.ground_mask(r.sem.astype(np.uint32))
    a = native.cluster(r.points, "hdl64", ground=g, split_people=0, join_cars=0, with_image=True)
    xyz = np.stack([a.image.x, a.image.y, a.image.z], -1)
    off = ref.refine_ref(a.pixel_labels, xyz, split_people=False, join_cars=False)
    np.testing.assert_array_equal(off, a.pixel_labels)
    assert a.stats["n_split"] == 0


def test_crowd_scene_has_close_people():
    """lidet-sim --crowd puts people within 1.2 m (centre to centre: 0.2-0.7 m body to body) of each other."""
    r = simulate_scan("hdl64", seed=15, index=1, crowd=True)
    person = (r.sem == 30) & (r.inst > 0)
    ids = np.unique(r.inst[person])
    cent = np.array([r.points[person & (r.inst == i), :2].mean(0) for i in ids])
    d = np.hypot(*(cent[:, None] - cent[None]).transpose(2, 0, 1)) + np.eye(len(cent)) * 1e9
    assert (d.min(1) < 1.2).sum() >= 4


@pytest.mark.parametrize("sensor", ["hdl64", "vlp16"])
def test_default_scenes_unchanged(sensor):
    """Scenes without --crowd are the bytes of before it existed: the committed test scans (tests/data,
    seed 0) come out again."""
    import pathlib
    d = pathlib.Path(__file__).resolve().parents[1] / "data" / f"sim_{sensor}"
    r = simulate_scan(sensor, seed=0, index=0)
    assert r.points.tobytes() == (d / "velodyne" / "000000.bin").read_bytes()
    lab = (r.inst.astype(np.uint32) << 16) | r.sem.astype(np.uint32)
    assert lab.tobytes() == (d / "labels" / "000000.label").read_bytes()


def test_cli_switches_the_rules(cli, tmp_path):
    """`lidet cluster --set split_people=0 / join_cars=0` and `lidet detect --set stages.cluster.KEY` switch the
    rules (the JSON counts follow); an unknown clustering key is refused."""
    import json
    import subprocess
    r = simulate_scan("hdl64", seed=15, index=3, crowd=True)
    scan = tmp_path / "scan.bin"
    r.points.tofile(scan)

    def run(*args):
        p = subprocess.run([str(cli), *args], capture_output=True, text=True)
        return p.returncode, (json.loads(p.stdout) if p.returncode == 0 else p.stderr)

    _, on = run("cluster", str(scan), "--sensor", "hdl64", "--json")
    _, off = run("cluster", str(scan), "--sensor", "hdl64", "--json", "--set", "split_people=0", "--set", "join_cars=0")
    assert on["split"] > 0 and on["joined"] > 0 and off["split"] == 0 and off["joined"] == 0
    assert on["clusters"] == off["clusters"] + on["split_parts"] - on["joined"]
    _, d_on = run("detect", str(scan), "--sensor", "hdl64", "--json")
    _, d_off = run("detect", str(scan), "--sensor", "hdl64", "--json", "--set", "stages.cluster.split_people=0",
                   "--set", "stages.cluster.join_cars=0")
    assert d_on["clusters"] != d_off["clusters"]  # its own ground stage and image: other counts, but they move
    rc, err = run("detect", str(scan), "--sensor", "hdl64", "--set", "stages.cluster.nope=1")
    assert rc != 0 and "bad --set" in err


def test_realism_rows_measures():
    """crowd_report's measures on hand-made points: fragments of a car's points and the gap between people."""
    from lidet_tools.sim.crowd_report import fragments, person_gaps
    line = np.stack([np.linspace(0, 4, 40), np.zeros(40), np.zeros(40)], 1)
    assert fragments(line) == 1
    two = np.concatenate([line[:10], line[-10:]])          # 0-0.9 m and 3.1-4 m: 2.2 m apart
    assert fragments(two) == 2
    assert fragments(np.concatenate([two, [[10.0, 0, 0]]])) == 2  # a stray point is no fragment
    pts = np.array([[10, 0, 0], [10, 0.3, 0], [10, 0.9, 0], [60, 0, 0], [60, 5, 0]], np.float32)
    sem = np.array([30, 30, 30, 30, 30])
    inst = np.array([1, 1, 2, 3, 4])
    np.testing.assert_allclose(sorted(person_gaps(pts, sem, inst)), [0.6, 0.6], atol=1e-6)  # 3, 4 beyond 40 m
