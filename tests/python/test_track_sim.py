# SPDX-License-Identifier: MIT
"""Simulated sequences (lidet_tools.sim.sequence, `lidet-sim --sequence`): determinism, ids and motion consistent
with the reported velocities, ego deltas consistent with the poses, label_02 through the KITTI reader, nothing
overlapping, the CLI. Small VLP-16 sequences (a few frames) keep it fast."""
import hashlib
import json

import numpy as np
import pytest

from lidet_tools import kitti
from lidet_tools.eval import iou
from lidet_tools.sim import sequence as sq
from lidet_tools.sim.cli import main as sim_main
from lidet_tools.track import eval as tev

OPTS = sq.SeqOptions(frames=6, ego_speed=1.2, pitch_deg=0.0, roll_deg=0.0)


def _hashes(d):
    return {p.relative_to(d).as_posix(): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(d.rglob("*")) if p.is_file()}


@pytest.fixture(scope="module")
def seq_dir(tmp_path_factory):
    """Sequence 0 of run 5 (VLP-16 robot, 6 scans at 10 Hz, driving 1.2 m/s, level mount), written once."""
    d = tmp_path_factory.mktemp("seq")
    sq.write_sequence(d, "vlp16", 5, 0, OPTS)
    return d / "0000"


@pytest.fixture(scope="module")
def car_frames():
    """A street seen from a car-mounted HDL-64 driving at 8 m/s (in memory), frames and plan."""
    o = sq.SeqOptions(frames=7, ego_speed=8.0, pitch_deg=0.0, roll_deg=0.0, scene_kind="street")
    plan = sq.plan_sequence("hdl64", 2, 1, o)
    return list(sq.simulate_sequence("hdl64", 2, 1, o, plan)), plan


def test_layout_and_meta(seq_dir):
    for sub in ("velodyne", "ring", "labels", "boxes", "tracks"):
        assert len(list((seq_dir / sub).iterdir())) == OPTS.frames, sub
    assert (seq_dir / "label_02" / "0000.txt").exists() and (seq_dir / "calib" / "0000.txt").exists()
    meta = json.loads((seq_dir / "meta.json").read_text())
    assert meta["sensor"] == "vlp16" and meta["rate_hz"] == 10.0 and meta["dt_s"] == pytest.approx(0.1)
    assert meta["seed"] == 5 and meta["index"] == 0 and meta["frames"] == OPTS.frames
    poses = sq.read_poses(seq_dir / "poses.txt")
    assert poses.shape == (OPTS.frames, 8)
    np.testing.assert_allclose(poses[:, 1], np.arange(OPTS.frames) * 0.1, atol=1e-6)
    # the sensor drove ~1.2 m/s along its way
    np.testing.assert_allclose(np.hypot(poses[1:, 5], poses[1:, 6]), 0.12, atol=2e-3)


def test_same_seed_same_bytes_other_seed_other_scene(tmp_path, seq_dir):
    sq.write_sequence(tmp_path / "a", "vlp16", 5, 0, OPTS)
    assert _hashes(tmp_path / "a" / "0000") == _hashes(seq_dir)
    sq.write_sequence(tmp_path / "b", "vlp16", 6, 0, OPTS)
    hb = _hashes(tmp_path / "b" / "0000")
    assert hb["velodyne/000000.bin"] != _hashes(seq_dir)["velodyne/000000.bin"]
    # the CLI writes the same bytes (one process: --jobs 1)
    rc = sim_main(["--sequence", str(OPTS.frames), "--sensor", "vlp16", "--scenes", "1", "--seed", "5",
                   "--out", str(tmp_path / "c"), "--ego-speed", "1.2", "--pitch-deg", "0", "--roll-deg", "0",
                   "--no-progress"])
    assert rc == 0
    assert _hashes(tmp_path / "c" / "0000") == _hashes(seq_dir)


def test_single_scan_options_refused_without_sequence(tmp_path, capsys):
    assert sim_main(["--scenes", "1", "--out", str(tmp_path), "--ego-speed", "3", "--no-progress"]) == 2
    assert sim_main(["--sequence", "3", "--sensor", "hdl64", "--rate", "20", "--scenes", "1",
                     "--out", str(tmp_path), "--no-progress"]) == 2
    assert "hdl64 scans at 10 Hz" in capsys.readouterr().err


def test_rate_20hz(tmp_path):
    o = sq.SeqOptions(frames=3, rate_hz=20.0)
    meta = sq.write_sequence(tmp_path, "vlp16", 1, 2, o)
    assert meta["dt_s"] == pytest.approx(0.05)
    poses = sq.read_poses(tmp_path / "0002" / "poses.txt")
    np.testing.assert_allclose(poses[:, 1], [0.0, 0.05, 0.1], atol=1e-6)
    with pytest.raises(ValueError):
        sq.plan_sequence("hdl64", 0, 0, o)


def _to_first(pose, xy):
    x, y, yaw = pose
    c, s = np.cos(yaw), np.sin(yaw)
    return np.array([x + c * xy[0] - s * xy[1], y + s * xy[0] + c * xy[1]])


def _check_motion(frames, dt, tol):
    """Ids unique per scan, class and size fixed per id, and central differences of the positions (in the first
    scan's frame, through the poses) equal to the reported velocity (turned the same way); returns the number of
    moving and standing checks."""
    size = {}
    for fr in frames:
        ids = [t["id"] for t in fr]
        assert len(ids) == len(set(ids))
        for t in fr:
            key = (t["cls"], *np.round(t["box"][3:6], 3))
            assert size.setdefault(t["id"], key) == key
    n_mov = n_still = 0
    for k in range(1, len(frames) - 1):
        a, b, c = ({t["id"]: t for t in f} for f in frames[k - 1:k + 2])
        for i in set(a) & set(b) & set(c):
            pa = _to_first(a[i]["pose"], a[i]["box"][:2])
            pc = _to_first(c[i]["pose"], c[i]["box"][:2])
            yaw = b[i]["pose"][2]
            R = np.array([[np.cos(yaw), -np.sin(yaw)], [np.sin(yaw), np.cos(yaw)]])
            v = R @ b[i]["v"]
            fd = (pc - pa) / (2 * dt)
            # braking starts between scans: allow half the change of velocity across the three scans
            kink = 0.5 * np.linalg.norm(R @ c[i]["v"] - R @ a[i]["v"])
            assert np.linalg.norm(fd - v) <= tol + kink, (i, fd, v)
            if np.linalg.norm(v) > 0.5:
                n_mov += 1
            elif np.linalg.norm(v) == 0:
                n_still += 1
                assert np.linalg.norm(pc - pa) < tol * dt
    return n_mov, n_still


def test_ids_persist_and_boxes_move_with_their_velocity(car_frames):
    frames, plan = car_frames
    fr = [[dict(t, pose=f.pose) for t in f.tracks] for f in frames]
    n_mov, n_still = _check_motion(fr, plan.meta["dt_s"], 1e-6)
    assert n_mov >= 5 and n_still >= 5            # the street has traffic and parked cars
    # the ids are the points' instance ids; npts counts them
    for f in frames:
        for t in f.tracks:
            assert int((f.scan.inst == t["id"]).sum()) == t["npts"]


def test_files_agree_with_velocities_and_poses(seq_dir):
    poses = sq.read_poses(seq_dir / "poses.txt")
    gt = tev.load_gt(seq_dir)
    frames = []
    for k, g in enumerate(gt):
        frames.append([{"id": int(g["id"][i]), "cls": g["cls"][i], "box": g["box"][i],
                        "v": np.array([g["vx"][i], g["vy"][i]]), "pose": poses[k, 2:5]} for i in range(len(g["id"]))])
    n_mov, n_still = _check_motion(frames, 0.1, 0.02)     # the files round to 0.1 mm, 1e-6 rad
    assert n_mov + n_still > 0


def test_ego_deltas_compose_to_the_poses(car_frames, seq_dir):
    frames, _ = car_frames
    for poses in (np.array([np.r_[f.pose, f.ego] for f in frames]), sq.read_poses(seq_dir / "poses.txt")[:, 2:]):
        np.testing.assert_array_equal(poses[0], 0.0)
        P = np.zeros(3)
        for k in range(1, len(poses)):
            dx, dy, dyaw = poses[k, 3:]
            # the delta is the motion since the previous scan in the previous scan's frame
            prev = poses[k - 1, :3]
            c, s = np.cos(prev[2]), np.sin(prev[2])
            np.testing.assert_allclose([prev[0] + c * dx - s * dy, prev[1] + s * dx + c * dy], poses[k, :2],
                                       atol=2e-5)
            c, s = np.cos(P[2]), np.sin(P[2])
            P = np.array([P[0] + c * dx - s * dy, P[1] + s * dx + c * dy, P[2] + dyaw])
        np.testing.assert_allclose(P, poses[-1, :3], atol=1e-4)
    assert np.hypot(*frames[-1].pose[:2]) == pytest.approx(8.0 * 0.6, rel=0.02)


def test_label02_round_trips_through_the_kitti_reader(seq_dir):
    rows = kitti.read_label02(seq_dir / "label_02" / "0000.txt")
    calib = kitti.read_calib(seq_dir / "calib" / "0000.txt")
    gt = tev.load_gt(seq_dir)
    assert rows, "the virtual camera sees someone"
    n = 0
    for frame, tid, o in rows:
        assert 0 <= frame < OPTS.frames and o.truncated in (0, 1, 2)
        if o.type == "DontCare":
            assert tid == -1
            continue
        g = gt[frame]
        i = int(np.nonzero(g["id"] == tid)[0][0])
        assert g["cls"][i] == o.type
        b = kitti.kitti_to_box(o, calib)
        np.testing.assert_allclose([b.x, b.y, b.z, b.l, b.w, b.h], g["box"][i][:6], atol=6e-3)
        assert abs(kitti._wrap(b.yaw - g["box"][i][6])) < 2e-3
        n += 1
    assert n > 0
    # writing what was read gives the same file
    out = seq_dir.parent / "rt.txt"
    kitti.write_label02(out, rows)
    assert out.read_text() == (seq_dir / "label_02" / "0000.txt").read_text()


def test_nothing_overlaps_nor_meets_the_sensor(car_frames):
    frames, _ = car_frames
    ego = np.array([[-0.6, 0.0, 0.0, 4.6, 1.9, 2.0, 0.0]])   # the driving car's footprint (sequence._Ego)
    for f in frames:
        b = np.array([t["box"] for t in f.tracks])
        m = iou.iou_bev(b, b)
        np.fill_diagonal(m, 0.0)
        assert m.max() == 0.0
        assert iou.iou_bev(b, ego).max() == 0.0


def test_profile_braking():
    p = sq.Profile.constant(10.0)
    b = p.brake_to(20.0, 4.0, 5.0)
    s, v = b.at(np.linspace(0, 5, 501))
    assert s.max() <= 20.0 + 1e-9 and v[-1] == 0.0 and np.all(np.diff(s) >= -1e-12)
    assert s.max() > 19.5                          # it brakes as late as it can
    assert sq.Profile.constant(10.0).brake_to(5.0, 4.0, 5.0) is None
