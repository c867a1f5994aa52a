# SPDX-License-Identifier: MIT
"""Simulator outputs: labels inside boxes, KITTI round trip, rings, ground classes, determinism."""
import hashlib

import numpy as np
import pytest

from lidet_tools import kitti
from lidet_tools.sensors import get_sensor
from lidet_tools.sim import SUBDIRS, read_ring, scan_paths, simulate_scan
from lidet_tools.sim.cli import main as sim_main
from lidet_tools.sim.sensor_model import SensorModel

SEM_OF = {"Car": 10, "Pedestrian": 30, "Cyclist": 31, "Van": 20, "Truck": 18, "Misc": 20}


@pytest.fixture(scope="module")
def scans():
    return [simulate_scan("hdl64", 0, 0), simulate_scan("vlp16", 0, 1), simulate_scan("vlp16", 5, 2)]


def _inside(points, b: kitti.Box3D, shrink=0.0):
    q = points[:, :3].astype(np.float64) - [b.x, b.y, b.z]
    c, s = np.cos(b.yaw), np.sin(b.yaw)
    lx = c * q[:, 0] + s * q[:, 1]
    ly = -s * q[:, 0] + c * q[:, 1]
    return ((np.abs(lx) < b.l / 2 - shrink) & (np.abs(ly) < b.w / 2 - shrink)
            & (np.abs(q[:, 2]) < b.h / 2 - shrink))


def test_points_in_box_carry_its_instance_and_class(scans):
    n_checked = 0
    for r in scans:
        assert len(r.boxes) > 0
        seen = set()
        for b in r.boxes:
            m = _inside(r.points, b)
            if not m.any():
                continue
            inst = np.unique(r.inst[m])
            assert len(inst) == 1 and inst[0] != 0, f"{b.cls} box holds instances {inst}"
            assert set(np.unique(r.sem[m])) == {SEM_OF[b.cls]}
            assert inst[0] not in seen
            seen.add(int(inst[0]))
            n_checked += 1
        # every instance id names one object of one class
        for i in np.unique(r.inst[r.inst > 0]):
            assert len(np.unique(r.sem[r.inst == i])) == 1
        # stuff has no instance id
        assert np.all(r.inst[np.isin(r.sem, [40, 44, 48, 49, 50, 51, 70, 71, 72, 80, 81, 99])] == 0)
    assert n_checked >= 5


def test_label2_calib_roundtrip_through_kitti_reader(tmp_path):
    assert sim_main(["--sensor", "hdl64", "--scenes", "2", "--seed", "3", "--out", str(tmp_path),
                     "--no-progress"]) == 0
    n = 0
    for name in ("000000", "000001"):
        p = scan_paths(tmp_path, name)
        calib = kitti.read_calib(p["calib"])
        boxes = kitti.read_boxes(p["boxes"])
        for o in kitti.read_label2(p["label_2"]):
            if o.type == "DontCare":
                continue
            assert o.type in SEM_OF
            assert o.occluded in (0, 1, 2) and 0.0 <= o.truncated <= 1.0
            assert 0 <= o.bbox[0] < o.bbox[2] <= calib.image_size[0] and 0 <= o.bbox[1] < o.bbox[3]
            b = kitti.kitti_to_box(o, calib)
            d = [np.abs([b.x - c.x, b.y - c.y, b.z - c.z]).max() for c in boxes]
            c = boxes[int(np.argmin(d))]
            assert min(d) < 1e-3, (o.to_line(), c)
            assert max(abs(b.l - c.l), abs(b.w - c.w), abs(b.h - c.h)) < 1e-3
            assert abs(np.angle(np.exp(1j * (b.yaw - c.yaw)))) < 1e-3
            assert b.cls == c.cls
            n += 1
    assert n >= 3


def test_rings_and_layout(scans, tmp_path):
    for r, name in zip(scans, ("hdl64", "vlp16", "vlp16")):
        s = get_sensor(name)
        assert r.points.dtype == np.float32 and r.points.shape[1] == 4
        assert len(r.ring) == len(r.points) == len(r.sem) == len(r.inst)
        assert r.ring.max() < s.rows
        # ring by ring
        assert np.all(np.diff(r.ring.astype(int)) >= 0)
        # each point's elevation is that of its ring's beam (up to the small mount tilt)
        xyz = r.points[:, :3].astype(np.float64)
        el = np.arcsin(xyz[:, 2] / np.linalg.norm(xyz, axis=1))
        assert np.abs(el - s.beam_elev_rad[r.ring]).max() < np.radians(0.1)
        assert 0.0 <= r.points[:, 3].min() and r.points[:, 3].max() <= 1.0
    sim_main(["--sensor", "vlp16", "--scenes", "1", "--out", str(tmp_path), "--no-progress"])
    for sub in SUBDIRS:
        assert (tmp_path / sub).is_dir()
    p = scan_paths(tmp_path, "000000")
    pts = kitti.read_bin(p["velodyne"])
    sem, _ = kitti.read_label(p["labels"], len(pts))
    assert len(read_ring(p["ring"])) == len(pts)


def test_ground_points_carry_ground_classes():
    r = simulate_scan("hdl64", 1, 0, pitch_deg=0.0, roll_deg=0.0, keep_scene=True)
    hf = r.scene.ground
    xyz = r.points[:, :3].astype(np.float64)
    dz = xyz[:, 2] - hf.height(xyz[:, 0], xyz[:, 1])
    ground = np.isin(r.sem, kitti.GROUND_IDS)
    assert ground.mean() > 0.25
    # ground labels lie on the heightfield (up to noise; hits on a curb face may be one cell off)
    assert np.percentile(np.abs(dz[ground]), 99.5) < 0.05 and np.abs(dz[ground]).max() < 0.2
    near = np.abs(dz) < 0.02
    assert ground[near].mean() > 0.95                # and what lies on it is ground
    # several ground classes occur
    assert len(set(np.unique(r.sem[ground])) & {40, 44, 48, 49, 72}) >= 3


def _hashes(d):
    return {p.relative_to(d).as_posix(): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(d.rglob("*")) if p.is_file()}


def test_same_seed_same_bytes_other_seed_other_scene(tmp_path):
    args = ["--sensor", "vlp16", "--scenes", "2", "--no-progress"]
    sim_main(args + ["--seed", "7", "--out", str(tmp_path / "a")])
    sim_main(args + ["--seed", "7", "--out", str(tmp_path / "b")])
    sim_main(args + ["--seed", "8", "--out", str(tmp_path / "c")])
    ha, hb, hc = _hashes(tmp_path / "a"), _hashes(tmp_path / "b"), _hashes(tmp_path / "c")
    assert len(ha) == 12 and ha == hb
    assert ha["velodyne/000000.bin"] != hc["velodyne/000000.bin"]
    assert ha["boxes/000000.txt"] != hc["boxes/000000.txt"] or ha["labels/000000.label"] != hc["labels/000000.label"]
    # --start continues a run: scan 1 alone equals scan 1 of the full run
    sim_main(args[:2] + ["--scenes", "1", "--start", "1", "--seed", "7", "--out", str(tmp_path / "d"),
                         "--no-progress"])
    hd = _hashes(tmp_path / "d")
    assert hd["velodyne/000001.bin"] == ha["velodyne/000001.bin"]
    # worker processes write the same bytes
    sim_main(args + ["--seed", "7", "--jobs", "2", "--out", str(tmp_path / "e")])
    assert _hashes(tmp_path / "e") == ha


def test_mount_height_and_sensor_model():
    r = simulate_scan("vlp16", 0, 3, mount_height_m=0.3, pitch_deg=0.0, roll_deg=0.0)
    g = np.isin(r.sem, kitti.GROUND_IDS)
    assert abs(np.median(r.points[g, 2][np.hypot(r.points[g, 0], r.points[g, 1]) < 4]) + 0.3) < 0.1
    sm = SensorModel(get_sensor("hdl64"), 1.73)
    grid, order = sm.ray_grid()
    assert grid.dirs.shape == (64 * 2048, 3)
    assert np.all(np.diff(grid.elev_rows) <= 0)
