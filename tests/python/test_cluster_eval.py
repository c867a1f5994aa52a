# SPDX-License-Identifier: MIT
"""lidet_tools.cluster_eval: outcomes on crafted labellings, bands, CLI on the real scans."""
import subprocess
import sys

import numpy as np

from lidet_tools import cluster_eval as ce


def _lab(sem, inst):
    return (np.asarray(inst, np.uint32) << 16) | np.asarray(sem, np.uint32)


def test_outcomes():
    n = 100
    pts = np.zeros((6 * n, 3))
    pts[:, 0] = np.repeat([5.0, 15.0, 25.0, 35.0, 45.0, 10.0], n)  # centroid distances
    sem = np.repeat([10, 10, 30, 252, 31, 40], n)
    inst = np.repeat([1, 2, 3, 4, 5, 0], n)
    pred = np.zeros(6 * n, np.int64)
    pred[0:n] = 1                              # car 1: recovered
    pred[n:n + 50] = 2                         # car 2: split in two -> over
    pred[n + 50:2 * n] = 3
    pred[2 * n:3 * n] = 4                      # person merged with the ground -> under
    pred[5 * n:6 * n] = 4
    pred[3 * n:3 * n + 60] = 5                 # moving car: 60 % in one cluster, rest none -> partial
    res = {(r.cls, r.instance): r for r in ce.evaluate_scan(pred, _lab(sem, inst), pts)}
    assert res[("car", 1)].outcome == "recovered" and res[("car", 1)].precision == 1.0
    assert res[("car", 2)].outcome == "over" and res[("car", 2)].n_clusters == 2
    assert res[("person", 3)].outcome == "under" and abs(res[("person", 3)].precision - 0.5) < 1e-9
    assert res[("car", 4)].outcome == "partial" and abs(res[("car", 4)].recall - 0.6) < 1e-9
    assert res[("bicyclist", 5)].outcome == "missed"
    s = ce.summarize(list(res.values()))
    assert s["car"]["0-20"]["n"] == 2 and s["car"]["0-20"]["recovered"] == 0.5
    assert s["car"]["20-40"]["n"] == 1 and s["car"]["0-40"]["n"] == 3
    assert s["bicyclist"]["40+"]["missed"] == 1.0
    assert "| car | 0-20 | 2 | 50% |" in ce.markdown(s)


def test_small_objects_and_unlabelled_instances_skipped():
    pts = np.zeros((15, 3))
    lab = _lab([10] * 5 + [30] * 10, [1] * 5 + [0] * 10)
    assert ce.evaluate_scan(np.zeros(15), lab, pts) == []


def test_cli_on_real_scans(real_dir):
    r = subprocess.run([sys.executable, "-m", "lidet_tools.cluster_eval", str(real_dir / "semantickitti")],
                       capture_output=True, text=True, check=True)
    assert "| car | 0-40 |" in r.stdout


def test_kitti_box_labels():
    """Objects from label_2 boxes: inside the box grown by the margin, above its bottom + the floor, not ground;
    classes mapped (Van -> car, Person_sitting -> person), DontCare and Misc unscored, first box wins."""
    from lidet_tools import kitti
    calib = kitti.Calib()
    # a car box 10 m ahead in the sensor frame, yaw 0, 4 x 2 x 1.5 m, bottom at z = -1.73
    car = kitti.box_to_kitti(kitti.Box3D("Car", 10.0, 0.0, -1.73 + 0.75, 4.0, 2.0, 1.5, 0.0, 1.0), calib)
    ped = kitti.box_to_kitti(kitti.Box3D("Pedestrian", 10.0, 5.0, -1.73 + 0.9, 0.8, 0.6, 1.8, 0.0, 1.0), calib)
    van = kitti.box_to_kitti(kitti.Box3D("Car", 10.5, 0.0, -1.73 + 0.75, 4.0, 2.0, 1.5, 0.0, 1.0), calib)
    misc = kitti.box_to_kitti(kitti.Box3D("Car", 20.0, 0.0, -1.73 + 0.75, 4.0, 2.0, 1.5, 0.0, 1.0), calib)
    car.type, ped.type, van.type, misc.type = "Car", "Person_sitting", "Van", "Misc"
    pts = np.array([[10.0, 0.0, -1.0, 0],     # car, inside
                    [12.05, 0.0, -1.0, 0],    # car, inside the 0.1 m margin along its length
                    [12.2, 0.0, -1.0, 0],     # beyond the margin: in the second (van) box only
                    [10.0, 1.2, -1.0, 0],     # beyond the margin across: nothing
                    [10.0, 0.0, -1.68, 0],    # below bottom + floor: nothing
                    [10.0, 0.5, -1.0, 0],     # inside, but ground by the mask: ground
                    [10.0, 0.0, -0.17, 0],    # 0.06 m above the top: inside the margin
                    [10.0, 5.0, -1.0, 0],     # the sitting person
                    [20.0, 0.0, -1.0, 0]],    # Misc: unscored
                   np.float32)
    ground = np.array([0, 0, 0, 0, 0, 1, 0, 0, 0], bool)
    lab = ce.kitti_box_labels(pts, [car, ped, van, misc], calib, ground)
    sem, inst = lab & 0xFFFF, lab >> 16
    np.testing.assert_array_equal(sem, [10, 10, 10, 0, 0, 40, 10, 30, 0])
    np.testing.assert_array_equal(inst, [1, 1, 3, 0, 0, 0, 1, 2, 0])
    import pytest
    with pytest.raises(ValueError):
        ce.kitti_box_labels(pts, [car], calib, ground[:3])


def test_kitti_scans_on_real_frames(real_dir):
    """The real KITTI object frames: the pedestrian of 000000 and the car of 000002 are scored objects, none of
    their points ground."""
    got = {stem: lab for stem, pts, lab in ce.kitti_scans(real_dir / "kitti" / "training")}
    # every labelled frame of the folder (9 today; the first three were there first)
    assert {"000000", "000001", "000002"} <= set(got)
    assert set(got) == {p.stem for p in (real_dir / "kitti" / "training" / "label_2").glob("*.txt")}
    for stem, cls in (("000000", 30), ("000002", 10)):
        sem = got[stem] & 0xFFFF
        assert (sem == cls).sum() >= 10 and (sem == 40).sum() > 10000
