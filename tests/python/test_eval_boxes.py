# SPDX-License-Identifier: MIT
"""Sensor-frame protocol (lidet box lines, distance bands) on synthetic scenes made here."""
import json

import numpy as np
import pytest

from lidet_tools import kitti
from lidet_tools.eval import boxes_ap, cli

SIZES = {"Car": (4.0, 1.7, 1.5), "Pedestrian": (0.8, 0.6, 1.75), "Cyclist": (1.8, 0.6, 1.7)}


def scene(rng, n_per_class=(4, 3, 2)):
    """Non-overlapping random boxes around the sensor (grid cells of 6 m), on flat ground at -1.7 m."""
    cells = rng.permutation([(x, y) for x in range(-9, 10) for y in range(-9, 10) if (x, y) != (0, 0)])
    out, k = [], 0
    for cls, n in zip(SIZES, n_per_class):
        for _ in range(n):
            cx, cy = cells[k] * 6.0 + rng.uniform(-1, 1, 2)
            k += 1
            l, w, h = np.asarray(SIZES[cls]) * rng.normal(1, 0.05, 3)
            out.append(kitti.Box3D(cls, cx, cy, -1.7 + h / 2, l, w, h, rng.uniform(-np.pi, np.pi), 1.0))
    return out


def perturb(rng, boxes, sigma_m=0.03, sigma_yaw=0.02):
    return [kitti.Box3D(b.cls, b.x + rng.normal(0, sigma_m), b.y + rng.normal(0, sigma_m), b.z,
                        b.l, b.w, b.h, b.yaw + rng.normal(0, sigma_yaw), float(rng.uniform(0.3, 1.0)))
            for b in boxes]


def shifted(boxes, d):
    return [kitti.Box3D(b.cls, b.x + d, b.y, b.z, b.l, b.w, b.h, b.yaw, b.score) for b in boxes]


@pytest.fixture(scope="module")
def scenes():
    rng = np.random.default_rng(0)
    gt = [scene(rng) for _ in range(300)]
    return gt, [perturb(rng, f) for f in gt]


def band_of(b):
    r = np.hypot(b.x, b.y)
    return "0-20" if r < 20 else ("20-40" if r < 40 else "40+")


def test_perturbed_predictions_score_100_in_every_band(scenes):
    gt, dt = scenes
    res = boxes_ap.evaluate(boxes_ap.boxset_from_frames(gt), boxes_ap.boxset_from_frames(dt))
    for cls in ("Car", "Pedestrian", "Cyclist"):
        for m in ("3d", "bev"):
            for band in ("0-20", "20-40", "40+", "all"):
                assert res["ap"][cls][m]["R40"][band] == pytest.approx(100.0), (cls, m, band)
                assert res["curves"][cls][m][band]["n_gt"] > 40


def test_missing_band_and_out_of_band_detections(scenes):
    gt, dt = scenes
    # drop every detection of the 20-40 m band: that band scores 0, the others are untouched
    dt2 = [[b for b in f if band_of(b) != "20-40"] for f in dt]
    ap = boxes_ap.evaluate(boxes_ap.boxset_from_frames(gt), boxes_ap.boxset_from_frames(dt2))["ap"]
    assert ap["Car"]["3d"]["R40"]["20-40"] == 0.0
    assert ap["Car"]["3d"]["R40"]["0-20"] == pytest.approx(100.0)
    assert ap["Car"]["3d"]["R40"]["40+"] == pytest.approx(100.0)
    # detections far from any ground truth are false positives in their own band only
    fp = [f + [kitti.Box3D("Car", 10.0, 0.5, -1.0, 4, 1.7, 1.5, 0.0, 0.99)] for f in dt]
    ap = boxes_ap.evaluate(boxes_ap.boxset_from_frames(gt), boxes_ap.boxset_from_frames(fp))["ap"]
    assert ap["Car"]["3d"]["R40"]["0-20"] < 60.0
    assert ap["Car"]["3d"]["R40"]["20-40"] == pytest.approx(100.0)


def test_iou_sets_kitti_and_025(scenes):
    gt, dt = scenes
    # shifted 1 m along x: a car (4 x 1.7 m) keeps IoU < 0.7 but > 0.25 for most headings
    ds = [shifted(f, 1.0) for f in dt]
    G, D = boxes_ap.boxset_from_frames(gt), boxes_ap.boxset_from_frames(ds)
    strict = boxes_ap.evaluate(G, D, classes=["Car"])["ap"]["Car"]["bev"]["R40"]["all"]
    loose = boxes_ap.evaluate(G, D, classes=["Car"], overlap="0.25")["ap"]["Car"]["bev"]["R40"]["all"]
    assert strict < 10.0 and loose > 60.0
    # wrong class is no hit
    wrong = [[kitti.Box3D("Pedestrian" if b.cls == "Car" else b.cls, b.x, b.y, b.z, b.l, b.w, b.h,
                          b.yaw, b.score) for b in f] for f in dt]
    ap = boxes_ap.evaluate(G, boxes_ap.boxset_from_frames(wrong))["ap"]
    assert ap["Car"]["3d"]["R40"]["all"] == 0.0


def test_band_edge_detection_is_ignored_not_false():
    # a car at 19.9 m detected at 20.1 m: in band 0-20 the ground truth is absorbed by an ignored
    # detection (no false negative; as in the devkit it still counts in the number of valid objects
    # from which the recall steps are sampled, so AP is capped at the other half); in band 20-40 the
    # detection is absorbed by ignored ground truth (no false positive)
    gt = [[kitti.Box3D("Car", 19.9, 0.0, -1.0, 4.0, 1.7, 1.5, 0.0)],
          [kitti.Box3D("Car", 10.0, 0.0, -1.0, 4.0, 1.7, 1.5, 0.0)]] * 30
    dt = [[kitti.Box3D("Car", 20.1, 0.0, -1.0, 4.0, 1.7, 1.5, 0.0, 0.9)],
          [kitti.Box3D("Car", 10.0, 0.0, -1.0, 4.0, 1.7, 1.5, 0.0, 0.8)]] * 30
    res = boxes_ap.evaluate(boxes_ap.boxset_from_frames(gt), boxes_ap.boxset_from_frames(dt))
    assert res["curves"]["Car"]["3d"]["0-20"]["n_gt"] == 60
    assert res["ap"]["Car"]["3d"]["R40"]["0-20"] == pytest.approx(50.0)  # recall capped at 1/2
    assert res["ap"]["Car"]["3d"]["R40"]["20-40"] is None           # no ground truth there
    assert res["curves"]["Car"]["3d"]["20-40"]["fp"].sum() == 0


def test_cli_boxes_json(tmp_path, scenes, capsys):
    gt, dt = scenes
    for i, (g, d) in enumerate(zip(gt[:50], dt[:50])):
        kitti.write_boxes(tmp_path / "gt" / f"{i:06d}.txt", g)
        kitti.write_boxes(tmp_path / "dt" / f"{i:06d}.txt", d)
    assert cli.main(["boxes", "--gt", str(tmp_path / "gt"), "--pred", str(tmp_path / "dt"),
                     "--json", "--overlap", "0.25"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert set(out) == {"Car", "Pedestrian", "Cyclist"}
    assert set(out["Car"]) == {"3d", "bev"}
    assert set(out["Car"]["3d"]["R11"]) == {"0-20", "20-40", "40+", "all"}
    assert out["Car"]["3d"]["R40"]["all"] == pytest.approx(100.0)
