# SPDX-License-Identifier: MIT
"""`lidet_tools.eval_real` (make eval-real) and `lidet_tools.where_lost`: the split file, the operating-point
matching, and a whole run on a KITTI-format folder made from the simulator's shipped scan (always runs); the
real validation frames when ../shared/data/real is there."""
from __future__ import annotations

import json
import pathlib
import shutil

import numpy as np
import pytest

from lidet_tools import eval_real, kitti, native
from lidet_tools.where_lost import STAGES, points_in_box, where_lost

ROOT = pathlib.Path(__file__).resolve().parents[2]
REAL = ROOT.parent / "shared" / "data" / "real"
SIM = ROOT / "tests" / "data" / "sim_hdl64"


def _box(cls, x, y, l=4.0, w=1.8, yaw=0.0, score=1.0):
    return kitti.Box3D(cls, x, y, -0.9, l, w, 1.5, yaw, score)


def test_split_file_is_well_formed_and_disjoint():
    rows = eval_real.read_split()
    sides = {}
    for s, f, side in rows:
        sides.setdefault((s, f), set()).add(side)
    assert all(len(v) == 1 for v in sides.values())
    by = {}
    for s, _, side in rows:
        by.setdefault(s, set()).add(side)
    # every source has validation frames; the real-data training has frames of most sources
    assert all("val" in v for v in by.values())
    assert sum("train" in v for v in by.values()) >= 4


def test_split_errors(tmp_path):
    p = tmp_path / "s.txt"
    p.write_text("kitti 000000 val\nkitti 000000 train\n")
    with pytest.raises(ValueError, match="listed twice"):
        eval_real.read_split(p)
    p.write_text("kitti 000000 test\n")
    with pytest.raises(ValueError, match="train|val"):
        eval_real.read_split(p)


def test_match_counts_by_hand():
    gt = [_box("Car", 10, 0), _box("Car", 30, 5), _box("Car", 45, 0), _box("Pedestrian", 8, 3, 0.6, 0.6)]
    dets = [_box("Car", 10.3, 0.1, score=0.9),        # finds the first car
            _box("Car", 10.0, 0.0, score=0.5),        # a duplicate: a false positive
            _box("Car", 30, 9, score=0.8),            # 4 m off: a false positive
            _box("Car", 39.5, 0, score=0.7),          # overlaps nothing: a false positive
            _box("Pedestrian", 8.1, 3.0, 0.6, 0.6, score=0.6)]
    assert eval_real.match(gt, dets, "Car", 40.0, 0.5) == (2, 1, 4, 1)
    assert eval_real.match(gt, dets, "Car", 20.0, 0.5) == (1, 1, 2, 1)
    assert eval_real.match(gt, dets, "Pedestrian", 40.0, 0.25) == (1, 1, 1, 1)
    assert eval_real.match(gt, [], "Pedestrian", 40.0, 0.25) == (1, 0, 0, 0)
    # a detection of an object just beyond the range is neither right nor wrong
    assert eval_real.match([_box("Car", 40.5, 0)], [_box("Car", 39.9, 0)], "Car", 40.0, 0.5) == (0, 0, 0, 0)


def test_points_in_box_margin_and_yaw():
    b = np.array([5.0, 0.0, 0.0, 4.0, 2.0, 2.0, np.pi / 2])  # turned: 4 m along y
    p = np.array([[5.0, 1.9, 0.0], [5.0, 2.05, 0.0], [6.05, 0.0, 0.0], [6.5, 0.0, 0.0]])
    assert points_in_box(p, b, 0.1).tolist() == [True, True, True, False]
    assert points_in_box(p, b, 0.0).tolist() == [True, False, False, False]


def _sim_root(tmp_path):
    """A real-data folder in the KITTI layout, made by the simulator (3 HDL-64 scans, a fixed seed training never
    used), and a split naming two of them for validation."""
    import subprocess
    import sys
    sim = tmp_path / "sim"
    subprocess.run([sys.executable, "-m", "lidet_tools.sim.cli", "--sensor", "hdl64", "--scenes", "3", "--seed", "4242",
                    "--out", str(sim), "--no-progress"], check=True, capture_output=True)
    root = tmp_path / "real"
    for sub in ("velodyne", "calib", "label_2"):
        shutil.copytree(sim / sub, root / "kitti" / "training" / sub)
    split = tmp_path / "split.txt"
    split.write_text("kitti 000000 val\nkitti 000001 val\nkitti 000002 train\n")
    return root, split


def test_where_lost_on_the_simulated_scan():
    pts = kitti.read_bin(SIM / "velodyne" / "000000.bin")
    gts = [b for b in kitti.read_boxes(SIM / "boxes" / "000000.txt") if b.cls in eval_real.CLASSES]
    d = native.detect(pts, "hdl64")
    arr = np.array([[g.x, g.y, g.z, g.l, g.w, g.h, g.yaw] for g in gts])
    few = int(native.cluster_defaults("hdl64")["min_points"])
    st = where_lost(pts, arr, [g.cls for g in gts], d, few, lambda *a: True, native.CLASSES)
    assert len(st) == len(gts) and set(st) <= set(STAGES)
    # every object the detector boxed with its class is "detected" when any box counts, and no object is
    # detected twice: the detected ones are at most the detections of their class
    for c in eval_real.CLASSES:
        n_det = sum(native.CLASSES[int(k)] == c for k in d.cls)
        assert sum(s == "detected" and g.cls == c for s, g in zip(st, gts)) <= n_det
    assert "detected" in st
    # with a hit test that never passes, the same objects are "box off" instead
    st0 = where_lost(pts, arr, [g.cls for g in gts], d, few, lambda *a: False, native.CLASSES)
    assert [s if s != "detected" else "box off" for s in st] == st0
    # counted over the seen points only: none seen, every object has too few; all seen, as without the mask
    none = np.zeros(len(pts), dtype=bool)
    assert set(where_lost(pts, arr, [g.cls for g in gts], d, few, lambda *a: True, native.CLASSES, none)) == \
        {"too few points"}
    assert where_lost(pts, arr, [g.cls for g in gts], d, few, lambda *a: True, native.CLASSES,
                      np.ones(len(pts), dtype=bool)) == st
    # an object with no points is "too few points"
    far = np.array([[200.0, 0.0, 0.0, 4.0, 1.8, 1.5, 0.0]])
    assert where_lost(pts, far, ["Car"], d, few, lambda *a: True, native.CLASSES) == ["too few points"]


def test_where_lost_no_cluster_against_split():
    """An object most of whose non-ground points are in no kept cluster (its component dropped, a car chained to the
    kerb) is "no cluster", one whose points are mostly in clusters but none holding 70 % of them "split"; one
    cluster holding 70 % and mostly the object: on to the cluster's outcome."""
    from types import SimpleNamespace
    box = np.array([[10.0, 0.0, 0.0, 4.0, 2.0, 2.0, 0.0]])
    pts = np.zeros((30, 3))
    pts[:, 0] = np.linspace(8.5, 11.5, 30)

    def lost(point_cluster, outcome=(0, 0, 0)):
        det = SimpleNamespace(point_cluster=np.asarray(point_cluster), point_ground=np.zeros(30, np.uint8),
                              outcome=np.asarray(outcome), cluster_id=np.zeros(0, np.int64), cls=np.zeros(0),
                              box=np.zeros((0, 7)))
        return where_lost(pts, box, ["Car"], det, 8, lambda *a: True, native.CLASSES)[0]

    assert lost([0] * 30) == "no cluster"
    assert lost([0] * 25 + [1] * 5) == "no cluster"
    assert lost([0] * 15 + [1] * 15) == "no cluster"  # half in clusters
    assert lost([0] * 10 + [1] * 12 + [2] * 8) == "split"
    gate1 = next(k for k, v in native.OUTCOME.items() if v == "gate1")
    assert lost([0] * 5 + [1] * 25, (gate1, 0, 0)) == "gate 1"


def test_eval_real_on_a_simulated_folder(tmp_path):
    root, split = _sim_root(tmp_path)
    out = tmp_path / "out"
    assert eval_real.main(["--root", str(root), "--split", str(split), "--out", str(out)]) == 0
    rep = json.loads((out / "report.json").read_text())
    s = rep["summary"]["kitti"]
    assert s["frames"] == 2
    # the objects counted are the label_2 road users in the camera's view with >= 10 points
    from lidet_tools import real
    want = dict.fromkeys(eval_real.CLASSES, 0)
    for fid in ("000000", "000001"):
        fr = real.load_frame(root, "kitti", fid)
        for b in fr.boxes:
            if b.cls in want and np.hypot(b.x, b.y) <= 40 and eval_real._in_fov(b.x, b.y, fr.fov_half_rad) and \
                    points_in_box(fr.points, eval_real._arr(b)).sum() >= 10:
                want[b.cls] += 1
    assert {c: s["classes"][c]["40"]["objects"] for c in eval_real.CLASSES} == want
    assert sum(want.values()) >= 3
    # the detector finds most of the simulator's road users (88 / 71 / 87 AP on its benchmark)
    found = sum(s["classes"][c]["40"]["found"] for c in eval_real.CLASSES)
    assert found >= 0.6 * sum(want.values())
    lost = s["where_lost"]
    assert sum(sum(v.values()) for v in lost.values()) == sum(want.values())
    assert (out / "pictures" / "kitti_000000.png").stat().st_size > 10_000
    md = (out / "report.md").read_text()
    assert "| kitti | 2 | <= 40 m |" in md and "KITTI's protocol" in md
    # the integer detector on the same folder
    assert eval_real.main(["--root", str(root), "--split", str(split), "--out", str(out / "q"), "--fixed",
                           "--no-pictures"]) == 0
    q = json.loads((out / "q" / "report.json").read_text())["summary"]["kitti"]
    assert sum(q["classes"][c]["40"]["found"] for c in eval_real.CLASSES) >= 0.6 * sum(want.values())
    # ... where each object was lost, from the integer run's own per-point labels
    assert sum(sum(v.values()) for v in q["where_lost"].values()) == sum(want.values())
    assert sum(q["where_lost"][c]["detected"] for c in eval_real.CLASSES) >= 0.5 * sum(want.values())
    assert "`lidet_tools.where_lost`; the integer (int8) detector" in (out / "q" / "report.md").read_text()
    # each frame's tallies add up to the summary, and two runs compare frame by frame (lidet_tools.real.paired)
    for rng in ("20", "40"):
        for k, c in enumerate(eval_real.CLASSES):
            tot = np.sum([f["counts"][rng][c] for f in rep["frames"]], axis=0)
            v = s["classes"][c][rng]
            assert list(tot[:3]) == [v["objects"], v["found"], v["detections"]]
    from lidet_tools.real import paired
    res = paired.compare(paired.load(out / "report.json"), paired.load(out / "q" / "report.json"), boot=200)
    for c in eval_real.CLASSES:
        r = res["classes"][c]
        assert r["objects"] == s["classes"][c]["40"]["objects"]
        assert (r["found_base"], r["found_new"]) == (s["classes"][c]["40"]["found"], q["classes"][c]["40"]["found"])
        assert r["interval90"][0] <= r["diff"] <= r["interval90"][1] or r["frames_changed"] > 0


def test_eval_real_round_mm(tmp_path, monkeypatch):
    """--round-mm: the detector sees each scan in whole millimetres (the integer detector's input)."""
    root, split = _sim_root(tmp_path)
    seen = []
    real_eval = eval_real.evaluate_frame

    def spy(fr, *a, **k):
        seen.append(fr.points[:, :3].astype(np.float64))
        return real_eval(fr, *a, **k)
    monkeypatch.setattr(eval_real, "evaluate_frame", spy)
    out = tmp_path / "mm"
    assert eval_real.main(["--root", str(root), "--split", str(split), "--out", str(out), "--no-pictures",
                           "--round-mm"]) == 0
    assert len(seen) == 2
    for p in seen:
        mm = p * 1000.0
        assert np.abs(mm - np.round(mm)).max() < 0.01  # float32 holds the millimetres to within its precision
    rep = json.loads((out / "report.json").read_text())
    assert "--round-mm" in rep["meta"]["command"] and "millimetres" in rep["meta"]["detector"]


def test_eval_real_seeds(tmp_path, capsys):
    """--seeds K: one run per draw of the proposals' points (the default seed, then 1 .. K - 1) in seed_<S>/, and
    seeds.md / seeds.json with each seed's headline figures, their mean and range."""
    root, split = _sim_root(tmp_path)
    base = ["--root", str(root), "--split", str(split), "--no-pictures"]
    assert eval_real.main(base + ["--out", str(tmp_path / "one")]) == 0
    one = json.loads((tmp_path / "one" / "report.json").read_text())["summary"]
    out = tmp_path / "seeds"
    assert eval_real.main(base + ["--out", str(out), "--seeds", "3", "--set", "nms_iou=0.1"]) == 0
    seeds = eval_real.seed_list(3)
    assert seeds == [0x5EED1234, 1, 2]
    js = json.loads((out / "seeds.json").read_text())
    assert js["seeds"] == seeds
    for sd in seeds:
        rep = json.loads((out / f"seed_{sd}" / "report.json").read_text())
        assert f"proposal.seed={sd}" in rep["meta"]["command"] and "nms_iou=0.1" in rep["meta"]["command"]
        assert js["per_seed"][str(sd)] == eval_real._headline(rep["summary"])
    # the default seed's draw is the plain run's (the CLI and the bindings run the same float detector)
    assert js["per_seed"][str(seeds[0])] == eval_real._headline(one)
    for k, st in js["stats"].items():
        v = [js["per_seed"][str(sd)][k] for sd in seeds if js["per_seed"][str(sd)][k] is not None]
        if st is not None:
            assert st["min"] == min(v) and st["max"] == max(v) and st["mean"] == pytest.approx(np.mean(v))
    md = (out / "seeds.md").read_text()
    assert "| figure | default | seed 1 | seed 2 | mean | min - max |" in md and "--seeds 3" in md
    assert "| Car found 40 m (of " in md
    # errors: a seed count out of range, a seed set by hand beside --seeds
    for bad in (["--seeds", "0"], ["--seeds", "2", "--set", "proposal.seed=5"]):
        with pytest.raises(SystemExit):
            eval_real.main(base + ["--out", str(tmp_path / "bad")] + bad)
    capsys.readouterr()


@pytest.mark.parametrize("vary", ["ground", "both"])
def test_eval_real_seeds_vary(tmp_path, capsys, vary):
    """--seeds K --vary ground|both: each run draws the ground stage's RANSAC hypotheses anew (its default seed
    first), with the proposals' draw too for both; the first run is the defaults' (the plain run's figures)"""
    root, split = _sim_root(tmp_path)
    base = ["--root", str(root), "--split", str(split), "--no-pictures"]
    assert eval_real.main(base + ["--out", str(tmp_path / "one")]) == 0
    one = json.loads((tmp_path / "one" / "report.json").read_text())["summary"]
    out = tmp_path / vary
    assert eval_real.main(base + ["--out", str(out), "--seeds", "3", "--vary", vary]) == 0
    js = json.loads((out / "seeds.json").read_text())
    first = eval_real.DEFAULT_GROUND_SEED if vary == "ground" else eval_real.DEFAULT_PROPOSAL_SEED
    assert js["seeds"] == [first, 1, 2]
    for j, sd in enumerate(js["seeds"]):
        cmd = json.loads((out / f"seed_{sd}" / "report.json").read_text())["meta"]["command"]
        assert f"stages.ground.seed={12345 if j == 0 else j}" in cmd
        assert ("proposal.seed=" in cmd) == (vary == "both")
    assert js["per_seed"][str(first)] == eval_real._headline(one)
    md = (out / "seeds.md").read_text()
    assert "RANSAC" in md and f"--seeds 3 --vary {vary}" in md and "| figure | default | seed 1 | seed 2 |" in md
    for bad in (["--vary", "ground"], ["--seeds", "2", "--vary", "ground", "--set", "stages.ground.seed=5"]):
        with pytest.raises(SystemExit):
            eval_real.main(base + ["--out", str(tmp_path / "bad")] + bad)
    capsys.readouterr()


def test_headline_has_the_kitti_protocol_rows():
    """The seeds' headline figures carry the KITTI frames' AP3D moderate by KITTI's protocol when they are among
    the sources, and leave it out otherwise."""
    cls = {c: {r: {"found": 1} for r in ("20", "40")} for c in eval_real.CLASSES}
    ap = {c: {"3d": {"20 m": 1.0, "40 m": 2.0}, "bev": {"20 m": 3.0, "40 m": 4.0}} for c in eval_real.CLASSES}
    one = {"classes": cls, "fp_per_frame": {"20": 0.5, "40": 1.5}, "ap": {"kitti": ap, "loose": ap}}
    ko = {c: {"3d": {"easy": 1.0, "moderate": m, "hard": 3.0}, "bev": {}} for c, m in
          (("Car", 25.5), ("Pedestrian", 40.0), ("Cyclist", 7.0))}
    h = eval_real._headline({"kitti": dict(one, kitti_official=ko), "pandaset": one, "all": one})
    assert h["KITTI frames: car AP3D moderate"] == 25.5 and h["KITTI frames: ped AP3D moderate"] == 40.0
    assert h["car AP3D 40 m"] == 2.0 and h["FP/frame 40 m"] == 1.5
    assert not any(k.startswith("KITTI") for k in eval_real._headline({"pandaset": one, "all": one}))
    assert not any(k.startswith("KITTI") for k in eval_real._headline({"kitti": dict(one, kitti_official=ko)}))


def test_eval_real_missing_root(tmp_path, capsys):
    assert eval_real.main(["--root", str(tmp_path / "nope"), "--out", str(tmp_path / "o")]) == 2
    assert "not found" in capsys.readouterr().err


@pytest.mark.skipif(not REAL.is_dir(), reason="../shared/data/real is not there")
def test_every_split_frame_exists_and_loads():
    from lidet_tools import real
    for s, f, _ in eval_real.read_split():
        fr = real.load_frame(REAL, s, f)
        assert len(fr.points) > 1000, (s, f)


def test_compare_rows_and_table():
    """lidet_tools.real.compare on two simulated scans: every road user within 45 m has a row whose points and
    spans are those of its box, and the table reads them per class and band."""
    from lidet_tools.real import compare
    rows = compare.sim_rows(2, 4242)
    assert rows and {r["cls"] for r in rows} <= set(compare.CLASSES)
    for r in rows:
        assert r["range"] < 45 and r["n"] >= 0 and r["stage"] in STAGES
        if r["n"] >= 5:
            assert 0 <= r["span"][2] <= 2.6  # no road user is taller
            # the lowest seen points lie inside the box (0.1 m margin), at most its height above the bottom
            assert -0.11 <= r["low"] <= 2.6
    cars = [r for r in rows if r["cls"] == "Car" and r["n"] >= 100]
    # a car seen near by is seen down to its sills: its low 5 % within 0.5 m of the box bottom
    assert np.median([r["low"] for r in cars]) < 0.5
    assert cars and all(1.0 <= r["span"][0] <= 5.5 for r in cars)
    t = compare.table(rows, rows)
    assert "| Car | 0-15 |" in t or "| Car | 15-30 |" in t
    assert t.count(" / ") >= 9


def test_thin_keeps_the_target_beams():
    """Points on every HDL-64 beam: thinned to a VLP-16 only the 9 beams it shares with the HDL-64 (-15 to +1 deg)
    stay, each within 0.25 deg of a VLP-16 beam; to a VLP-32C 26 of its 32."""
    from lidet_tools.real import thin
    from lidet_tools.sensors import get_sensor
    el = np.asarray(get_sensor("hdl64").beam_elev_rad)
    az = np.linspace(-3, 3, 50)
    pts = np.array([[10 * np.cos(a) * np.cos(e), 10 * np.sin(a) * np.cos(e), 10 * np.sin(e), 0.5]
                    for e in el for a in az], np.float32)
    t = thin.thin(pts, "hdl64", "vlp16")
    kept = np.unique(np.round(np.degrees(np.arctan2(t[:, 2], np.hypot(t[:, 0], t[:, 1]))), 1))
    assert len(t) == 9 * len(az) and len(kept) == 9
    vlp = np.degrees(np.asarray(get_sensor("vlp16").beam_elev_rad))
    assert all(np.min(np.abs(vlp - k)) <= 0.3 for k in kept)
    assert len(thin.beam_map("hdl64", "vlp32c")) == 26


def test_eval_real_as_vlp16(tmp_path):
    root, split = _sim_root(tmp_path)
    out = tmp_path / "o16"
    assert eval_real.main(["--root", str(root), "--split", str(split), "--out", str(out), "--as-sensor", "vlp16",
                           "--no-pictures"]) == 0
    rep = json.loads((out / "report.json").read_text())
    assert "thinned to vlp16" in rep["meta"]["detector"] and rep["summary"]["kitti"]["frames"] == 2
    with pytest.raises(SystemExit):
        eval_real.main(["--root", str(root), "--split", str(split), "--out", str(out), "--as-sensor", "hdl64"])


def test_fp_kinds_by_point_labels():
    """A car detection on a bush, one on a wall, one on a labelled car (matched: not wrong) and one on nothing."""
    pts, sem = [], []
    for x, y, c in ((10, 0, 70), (20, 5, 50), (15, -5, 10)):
        p = np.random.default_rng(c).uniform(-0.5, 0.5, (50, 3)) + [x, y, -0.8]
        pts.append(p)
        sem += [c] * 50
    pts = np.vstack(pts)
    gt = [_box("Car", 15, -5)]
    dets = [_box("Car", 10, 0), _box("Car", 20, 5), _box("Car", 15.1, -5), _box("Car", 30, 10), _box("Car", 45, 0)]
    kinds = eval_real.fp_kinds(pts, np.array(sem), gt, dets)
    assert kinds == ["vegetation, terrain", "building, fence, structure", "empty"]


def test_dontcare_regions_of_kitti_frames():
    """A detection whose projected 2D box lies in a DontCare region is not scored; elsewhere, or behind the camera,
    it is; a frame without DontCare lines has no test."""
    calib = kitti.read_calib(SIM / "calib" / "000000.txt")
    car = _box("Car", 15, 1)
    bb = kitti.box_to_kitti(car, calib).bbox
    dc = kitti.KittiObject("DontCare", -1, -1, -10, np.array([bb[0] - 5, bb[1] - 5, bb[2] + 5, bb[3] + 5]),
                           -1, -1, -1, np.array([-1000.0, -1000, -1000]), -10)
    test = eval_real.dontcare_test(calib, [dc])
    assert test(car) and not test(_box("Car", 15, -8)) and not test(_box("Car", -15, 1))
    assert eval_real.dontcare_test(calib, []) is None


def test_integer_run_through_the_bindings_is_the_clis(tmp_path):
    """eval_real --fixed runs the integer detector through the bindings (native.detect_q, with the per-point labels
    where_lost reads); with --set it goes through `lidet detect --fixed`. Both give the same boxes (the CLI's JSON
    rounds them to 0.1 mm and 1e-5 rad), and the labels are the run's: a detection's cluster holds its points."""
    from lidet_tools import native, real
    root, _ = _sim_root(tmp_path)
    fr = real.load_frame(root, "kitti", "000000")
    a, run, _ = eval_real._run_fixed(fr, None)
    b, none, _ = eval_real._run_cli(fr, True, None)
    assert none is None and len(a) == len(b) > 0
    for x, y in zip(a, b):
        assert x.cls == y.cls
        np.testing.assert_allclose([x.x, x.y, x.z, x.l, x.w, x.h], [y.x, y.y, y.z, y.l, y.w, y.h], atol=6e-5)
        assert abs(x.yaw - y.yaw) < 1e-4 and abs(x.score - y.score) < 1e-4
    assert len(run.outcome) == run.point_cluster.max() == run.stats["n_clusters"]
    for cid, bx in zip(run.cluster_id, run.box):
        inside = points_in_box(fr.points, bx.astype(np.float64), margin=0.3)
        assert np.mean(run.point_cluster[inside] == cid) > 0.2
    assert 0.3 < run.point_ground.mean() < 0.9
    d = native.detect_q(native.to_mm(fr.points), fr.sensor, point_labels=True)
    np.testing.assert_array_equal(d["point_cluster"], run.point_cluster)
    with pytest.raises(ValueError, match="mount_height_m"):
        native.detect_q(native.to_mm(fr.points), fr.sensor, mount_height_m=11.0)
