# SPDX-License-Identifier: MIT
"""The presets benchmark's points per object (tools/bench/bench_presets.py, `object_points`): on a hand-made set the
points inside each labelled box (+ 0.1 m, the box turned by its yaw, z its centre) are counted, medians taken per
class and band, and boxes of other classes or beyond 40 m left out."""
import pathlib

import numpy as np


def _write(d: pathlib.Path, frame: str, boxes: list, pts: np.ndarray):
    (d / "boxes").mkdir(parents=True, exist_ok=True)
    (d / "velodyne").mkdir(parents=True, exist_ok=True)
    (d / "boxes" / f"{frame}.txt").write_text(
        "".join(f"{c} {x} {y} {z} {ln} {w} {h} {yaw} 1.0\n" for c, x, y, z, ln, w, h, yaw in boxes))
    np.hstack([pts, np.zeros((len(pts), 1))]).astype(np.float32).tofile(d / "velodyne" / f"{frame}.bin")


def test_points_per_object_by_class_and_band(tmp_path, bench_mod):
    m = bench_mod("presets")
    yaw = np.pi / 2  # a car 4 m long along y
    # car at (10, 0): 5 points inside (one 0.05 m beyond its side, within the margin), 2 outside (0.3 m beyond
    # its length, which lies along y after the turn; 0.25 m above its top)
    car = [(10.0, 1.9, -0.5), (10.0, -1.9, -0.5), (10.9, 0.0, 0.0), (9.1, 0.5, -1.0), (10.95, 0.0, 0.0),
           (10.0, 2.3, 0.0), (10.0, 0.0, 0.75)]
    # person at (25, 0): 3 points; a second person at (30, 0) with 1; a pedestrian at 45 m (out of every band)
    # and a Misc box at (10, 0) (not a road user) take none
    ped = [(25.0, 0.1, -0.5), (25.2, -0.1, 0.0), (24.8, 0.0, 0.3), (30.0, 0.0, 0.0), (45.0, 0.0, 0.0)]
    boxes = [("Car", 10.0, 0.0, -0.25, 4.0, 1.8, 1.5, yaw), ("Pedestrian", 25.0, 0.0, -0.1, 0.6, 0.6, 1.7, 0.0),
             ("Pedestrian", 30.0, 0.0, -0.1, 0.6, 0.6, 1.7, 0.3), ("Pedestrian", 45.0, 0.0, -0.1, 0.6, 0.6, 1.7, 0.0),
             ("Misc", 10.0, 0.0, -0.25, 4.0, 1.8, 1.5, yaw)]
    _write(tmp_path, "000000", boxes, np.asarray(car + ped, np.float64))
    # a second frame: another car at 15 m with 2 points
    _write(tmp_path, "000001", [("Car", 0.0, 15.0, -0.25, 4.0, 1.8, 1.5, 0.0)],
           np.asarray([(0.0, 15.0, 0.0), (1.9, 15.8, -0.9), (0.0, 18.0, 0.0)], np.float64))
    got = m.object_points(tmp_path)
    assert got[("Car", "0-20")] == (3.5, 2)  # median of 5 and 2
    assert got[("Pedestrian", "20-40")] == (2.0, 2)  # median of 3 and 1
    assert ("Pedestrian", "0-20") not in got and ("Car", "20-40") not in got
    assert set(got) == {("Car", "0-20"), ("Pedestrian", "20-40")}
