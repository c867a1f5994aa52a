# SPDX-License-Identifier: MIT
"""KITTI protocol: devkit rules on crafted frames, GT-as-prediction, recall cap, CLI, and the whole
evaluator against the literal devkit restatement (_devkit_ref) on synthetic frames."""
import json

import numpy as np
import pytest

import _devkit_ref as ref
from lidet_tools.eval import cli, iou, kitti_ap, synth


def line(t, x=0.0, z=20.0, ry=0.0, bbox=(100, 100, 200, 160), occ=0, trunc=0.0, h=1.5, w=1.6, l=3.9,
         score=None):
    s = (f"{t} {trunc:.2f} {occ} 0.0 {bbox[0]} {bbox[1]} {bbox[2]} {bbox[3]} {h} {w} {l} "
         f"{x} 1.6 {z} {ry}")
    return s + (f" {score}" if score is not None else "")


def evaluate(tmp_path, gt_frames, dt_frames, reps=50, **kw):
    """Crafted frames are repeated `reps` times: the devkit samples precision at one score threshold
    per recall step of 1/40, so AP can reach 100 only with more than 40 valid objects."""
    g = synth.write_frames(tmp_path / "gt", gt_frames * reps)
    synth.write_frames(tmp_path / "dt", dt_frames * reps)
    res = kitti_ap.evaluate_dirs(tmp_path / "gt", tmp_path / "dt", frame_ids=g, warn=False, **kw)
    return res["ap"]


@pytest.mark.parametrize("overlap,flavour", [("strict", "kitti"), ("loose", "openpcdet")])
def test_ground_truth_as_prediction_is_100(tmp_path, overlap, flavour):
    gt, _ = synth.synth_kitti(1000, seed=1)   # > 40 valid objects per class and difficulty
    ap = evaluate(tmp_path, gt, gt, reps=1, overlap=overlap, flavour=flavour)
    for cls in ("Car", "Pedestrian", "Cyclist"):
        for m in ("3d", "bev", "2d"):
            for r in ("R11", "R40"):
                for d in ("easy", "moderate", "hard"):
                    assert ap[cls][m][r][d] == pytest.approx(100.0), (cls, m, r, d)


def test_half_of_the_detections_caps_recall(tmp_path):
    gt = [[line("Car", x=-20 + 10 * k, z=30.0) for k in range(5)] for _ in range(20)]  # 100 easy cars
    dt = [[line("Car", x=-20 + 10 * k, z=30.0, score=round(1 - 0.01 * (5 * f + k), 3))
           for k in range(5) if (5 * f + k) % 2 == 0] for f in range(20)]
    ap = evaluate(tmp_path, gt, dt, reps=1)
    for m in ("3d", "bev", "2d"):
        for d in ("easy", "moderate", "hard"):
            # precision 1 up to recall 0.5 (samples 0..20), 0 beyond
            assert ap["Car"][m]["R40"][d] == pytest.approx(50.0)
            assert ap["Car"][m]["R11"][d] == pytest.approx(6 / 11 * 100)


def test_neighbouring_classes(tmp_path):
    gt = [[line("Car", x=-5), line("Van", x=5)]]
    # a Car detection on the Van: neither TP nor FP, even with the highest score
    assert evaluate(tmp_path / "a", gt, [[line("Car", x=-5, score=0.8), line("Car", x=5, score=0.9)]]
                    )["Car"]["3d"]["R40"]["easy"] == pytest.approx(100.0)
    # the same object labelled Truck is no neighbour of Car: the detection is a false positive
    gt2 = [[line("Car", x=-5), line("Truck", x=5)]]
    assert evaluate(tmp_path / "b", gt2, [[line("Car", x=-5, score=0.8), line("Car", x=5, score=0.9)]]
                    )["Car"]["3d"]["R40"]["easy"] == pytest.approx(50.0)
    # a Van detection on a Car is no hit for Car
    assert evaluate(tmp_path / "c", gt, [[line("Van", x=-5, score=0.9)]])["Car"]["3d"]["R40"]["easy"] == 0.0
    # Person_sitting is ignored for Pedestrian
    gp = [[line("Pedestrian", x=-3, h=1.7, w=0.6, l=0.8), line("Person_sitting", x=3, h=1.2, w=0.6, l=0.8)]]
    dp = [[line("Pedestrian", x=-3, h=1.7, w=0.6, l=0.8, score=0.5),
           line("Pedestrian", x=3, h=1.2, w=0.6, l=0.8, score=0.9)]]
    ap = evaluate(tmp_path / "d", gp, dp)
    assert ap["Pedestrian"]["3d"]["R40"]["easy"] == pytest.approx(100.0)
    assert ap["Car"]["3d"]["R40"]["easy"] is None   # no Car ground truth: no AP


def test_dontcare(tmp_path):
    gt = [[line("Car", x=-5, bbox=(100, 100, 200, 160)),
           "DontCare -1 -1 -10 500.0 100.0 700.0 200.0 -1 -1 -1 -1000 -1000 -1000 -10"]]
    # a false positive whose image box is inside the DontCare region, scored above the true positive
    dt = [[line("Car", x=-5, bbox=(100, 100, 200, 160), score=0.8),
           line("Car", x=8, z=40, bbox=(550, 120, 650, 170), score=0.9)]]
    ap = evaluate(tmp_path / "a", gt, dt)
    assert ap["Car"]["2d"]["R40"]["easy"] == pytest.approx(100.0)   # suppressed in 2D (devkit)
    assert ap["Car"]["3d"]["R40"]["easy"] == pytest.approx(50.0)    # devkit: BEV/3D do not suppress
    assert ap["Car"]["bev"]["R40"]["easy"] == pytest.approx(50.0)
    ap = evaluate(tmp_path / "b", gt, dt, dontcare_all_metrics=True)
    assert ap["Car"]["3d"]["R40"]["easy"] == pytest.approx(100.0)
    # DontCare is no ground truth: nothing to miss, and a DontCare region alone gives no AP
    ap = evaluate(tmp_path / "c", [[gt[0][1]]], [[dt[0][1]]])
    assert ap["Car"]["2d"]["R40"]["easy"] is None
    # only partly inside (intersection over the detection's area 0.5 < 0.7): a false positive again
    dt2 = [[dt[0][0], line("Car", x=8, z=40, bbox=(650, 120, 750, 170), score=0.9)]]
    assert evaluate(tmp_path / "d", gt, dt2)["Car"]["2d"]["R40"]["easy"] == pytest.approx(50.0)


def test_minimum_detection_height(tmp_path):
    gt = [[line("Car", x=-5)]]
    small = [[line("Car", x=-5, score=0.5), line("Car", x=6, bbox=(300, 100, 340, 120), score=0.9)]]
    ap = evaluate(tmp_path / "a", gt, small)   # 20 px high: ignored at every difficulty
    assert [ap["Car"]["3d"]["R40"][d] for d in ("easy", "moderate", "hard")] == pytest.approx([100] * 3)
    mid = [[line("Car", x=-5, score=0.5), line("Car", x=6, bbox=(300, 100, 340, 130.5), score=0.9)]]
    ap = evaluate(tmp_path / "b", gt, mid)     # 30.5 px: ignored for easy (40), counted for moderate (25)
    assert [ap["Car"]["3d"]["R40"][d] for d in ("easy", "moderate", "hard")] == pytest.approx([100, 50, 50])


def test_difficulty_from_occlusion_truncation_height(tmp_path):
    gt = [[line("Car", x=-8), line("Car", x=0, occ=1), line("Car", x=8, trunc=0.4),
           line("Car", x=16, bbox=(700, 100, 760, 135))]]   # 35 px: moderate
    dt = [[line("Car", x=-8, score=0.9)]]
    ap = evaluate(tmp_path, gt, dt)["Car"]["3d"]["R40"]
    # easy: only the first is valid; moderate: + occluded + 35 px; hard: all four.
    # Precision is 1 at every sampled threshold; recall is capped at 1/2, 1/3, 1/4.
    assert ap["easy"] == pytest.approx(100.0)
    for d, n_valid in (("moderate", 3), ("hard", 4)):
        n_samples = len(ref.get_thresholds([0.9] * 50, 50 * n_valid))
        assert n_samples in (int(40 / n_valid) + 1, int(40 / n_valid) + 2)
        assert ap[d] == pytest.approx(100 * (n_samples - 1) / 40)


def test_iou_threshold_sets(tmp_path):
    gt = [[line("Car", x=0)]]
    dt = [[line("Car", x=1.2, score=0.9)]]   # shifted 1.2 m along its length (camera x, ry = 0)
    g = iou.boxes_from_camera([[1.5, 1.6, 3.9]], [[0, 1.6, 20]], [0.0])
    d = iou.boxes_from_camera([[1.5, 1.6, 3.9]], [[1.2, 1.6, 20]], [0.0])
    assert iou.iou_3d(g, d)[0, 0] == pytest.approx(2.7 / 5.1)   # between 0.5 and 0.7
    assert evaluate(tmp_path / "a", gt, dt)["Car"]["3d"]["R40"]["easy"] == 0.0
    ap = evaluate(tmp_path / "b", gt, dt, overlap="loose")
    assert ap["Car"]["3d"]["R40"]["easy"] == pytest.approx(100.0)
    assert ap["Car"]["2d"]["R40"]["easy"] == pytest.approx(100.0)   # same image box


def test_few_objects_devkit_quirk(tmp_path):
    """One object, found: the devkit samples one threshold, so AP|R11 = 1/11 and AP|R40 = 0
    (the well-known 9.09 of single-frame KITTI evaluations)."""
    ap = evaluate(tmp_path, [[line("Car")]], [[line("Car", score=0.9)]], reps=1)
    assert ap["Car"]["3d"]["R11"]["easy"] == pytest.approx(100 / 11)
    assert ap["Car"]["3d"]["R40"]["easy"] == 0.0


def test_whole_evaluator_matches_literal_devkit():
    gt_l, dt_l = synth.synth_kitti(80, seed=7, fp_per_frame=3.0)
    parse = kitti_ap._parse_label2_text
    from lidet_tools import kitti
    gt_objs = [[kitti.KittiObject(p[0], float(p[1]), int(float(p[2])), float(p[3]),
                                  np.array(p[4:8], float), float(p[8]), float(p[9]), float(p[10]),
                                  np.array(p[11:14], float), float(p[14]),
                                  float(p[15]) if len(p) == 16 else None)
                for p in parse("\n".join(f), "")] for f in gt_l]
    dt_objs = [[kitti.KittiObject(p[0], float(p[1]), int(float(p[2])), float(p[3]),
                                  np.array(p[4:8], float), float(p[8]), float(p[9]), float(p[10]),
                                  np.array(p[11:14], float), float(p[14]), float(p[15]))
                for p in parse("\n".join(f), "")] for f in dt_l]
    gt, dt = kitti_ap.labelset_from_objects(gt_objs), kitti_ap.labelset_from_objects(dt_objs)
    for overlap in ("strict", "loose"):
        res = kitti_ap.evaluate(gt, dt, overlap=overlap)
        for cls in ("Car", "Pedestrian", "Cyclist"):
            for m in ("3d", "bev", "2d"):
                thr = kitti_ap.MIN_OVERLAP[overlap][m][cls.lower()]
                for d, dn in enumerate(kitti_ap.DIFFICULTIES):
                    ign_gt, ign_dt = kitti_ap.ignore_flags(gt, dt, cls, d)
                    frames = []
                    for f in range(gt.n_frames):
                        gi = np.nonzero(gt.frame == f)[0]
                        di = np.nonzero(dt.frame == f)[0]
                        dci = gi[gt.name[gi] == "dontcare"]
                        if m == "2d":
                            ov = iou.iou_2d(dt.bbox[di], gt.bbox[gi])
                        else:
                            ov = getattr(iou, f"iou_{m}")(dt.boxes[di], gt.boxes[gi])
                        ov[:, gt.name[gi] == "dontcare"] = 0.0
                        ioa = iou.iou_2d(dt.bbox[di], gt.bbox[dci], 0)
                        dc = (ioa > thr).any(1) if (m == "2d" and len(dci)) else np.zeros(len(di), bool)
                        frames.append(dict(ov=ov, ign_gt=list(ign_gt[gi]), ign_dt=list(ign_dt[di]),
                                           scores=list(dt.score[di]), dc_hit=list(dc)))
                    r11, r40, _ = ref.eval_class(frames, thr)
                    got = res["ap"][cls][m]
                    if got["R40"][dn] is None:
                        assert r40 == 0.0
                        continue
                    assert got["R11"][dn] == pytest.approx(r11, abs=1e-9), (overlap, cls, m, dn)
                    assert got["R40"][dn] == pytest.approx(r40, abs=1e-9), (overlap, cls, m, dn)


def test_cli_json_shape_and_table(tmp_path, capsys):
    gt, dt = synth.synth_kitti(40, seed=3)
    synth.write_frames(tmp_path / "gt", gt)
    ids = synth.write_frames(tmp_path / "dt", dt)
    (tmp_path / "dt" / f"{ids[-1]}.txt").unlink()   # a frame without detections
    assert cli.main(["kitti", "--gt", str(tmp_path / "gt"), "--pred", str(tmp_path / "dt"), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert set(out) == {"Car", "Pedestrian", "Cyclist"}
    for cls in out.values():
        assert set(cls) == {"3d", "bev", "2d"}
        for m in cls.values():
            assert set(m) == {"R11", "R40"}
            for r in m.values():
                assert set(r) == {"easy", "moderate", "hard"}
                assert all(v is None or 0 <= v <= 100 for v in r.values())
    assert cli.main(["kitti", "--gt", str(tmp_path / "gt"), "--pred", str(tmp_path / "dt"),
                     "--classes", "Car", "--overlap", "loose"]) == 0
    cap = capsys.readouterr()
    assert "Car" in cap.out and "moderate" in cap.out and "1 of 40 frames" in cap.err
    (tmp_path / "ids.txt").write_text("\n".join(ids[:10]) + "\n")
    assert cli.main(["kitti", "--gt", str(tmp_path / "gt"), "--pred", str(tmp_path / "dt"),
                     "--frames", str(tmp_path / "ids.txt"), "--metrics", "bev"]) == 0
    assert "10 frames" in capsys.readouterr().out
    assert cli.main(["kitti", "--gt", str(tmp_path / "nope"), "--pred", str(tmp_path / "dt")]) == 2
    assert cli.main(["kitti", "--gt", str(tmp_path / "gt"), "--pred", str(tmp_path / "dt"),
                     "--classes", "Bus"]) == 2
