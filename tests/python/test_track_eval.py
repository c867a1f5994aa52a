# SPDX-License-Identifier: MIT
"""Tracking evaluation (lidet_tools.track.eval, `lidet-eval track`) on hand-made cases whose answers follow from
CLEAR MOT's definitions; the AB3DMOT-style peer (track/peer.py); the runner (track/run.py) end to end on two tiny
simulated sequences, with the peer and a stand-in for lidet's tracker defined here."""
import json

import numpy as np
import pytest

from lidet_tools.eval.cli import main as eval_main
from lidet_tools.sim import sequence as sq
from lidet_tools.track import eval as tev
from lidet_tools.track import run as trun
from lidet_tools.track.peer import KITTI, OUT_COASTING, TRACK_DTYPE, PeerTracker, associate, giou_3d


def _f(*rows, npts=50):
    """A frame from (id, cls, x, y[, vx, vy]) rows."""
    out = []
    for r in rows:
        i, c, x, y = r[:4]
        vx, vy = (r[4], r[5]) if len(r) > 4 else (0.0, 0.0)
        out.append(dict(id=i, cls=c, x=x, y=y, vx=vx, vy=vy, npts=npts))
    return out


def _car(res):
    return res["classes"]["Car"]


# ------------------------------------------------------------------------------------------------
# evaluation: hand-made cases


def test_perfect_tracking():
    gt = [_f((1, "Car", 10.0 + k, 0.0), (2, "Pedestrian", 5.0, 3.0 + 0.1 * k)) for k in range(5)]
    r = tev.evaluate((gt, gt))
    for c in ("Car", "Pedestrian"):
        m = r["classes"][c]
        assert m["mota"] == 1.0 and m["motp"] == 0.0 and m["idf1"] == 1.0
        assert m["num_switches"] == m["num_false_positives"] == m["num_misses"] == m["num_fragmentations"] == 0
        assert m["mostly_tracked"] == 1 and m["num_objects"] == 5
    assert r["classes"]["Cyclist"]["num_objects"] == 0 and r["overall"]["mota"] == 1.0


def test_one_id_switch():
    # one object seen 4 times; the prediction's id changes from 7 to 8 at the third scan
    gt = [_f((1, "Car", 10.0 + k, 0.0)) for k in range(4)]
    pred = [_f((7 if k < 2 else 8, "Car", 10.0 + k, 0.3)) for k in range(4)]
    m = _car(tev.evaluate((gt, pred)))
    assert m["num_switches"] == 1 and m["num_misses"] == 0 and m["num_false_positives"] == 0
    assert m["mota"] == pytest.approx(1 - 1 / 4)
    assert m["motp"] == pytest.approx(0.3)
    # IDF1: the best one-to-one id map keeps 2 of 4 (2 IDTP / (4 + 4) * 2)
    assert m["idf1"] == pytest.approx(0.5)
    assert m["ids_per_100"] == pytest.approx(100.0)


def test_one_false_positive_and_a_missed_frame():
    gt = [_f((1, "Car", 10.0 + k, 0.0), (2, "Car", 10.0 + k, 6.0)) for k in range(5)]
    pred = []
    for k in range(5):
        rows = [(7, "Car", 10.0 + k, 0.5)]
        if k != 2:                                  # object 2 missed in scan 2
            rows.append((8, "Car", 10.0 + k, 6.0))
        if k == 1:                                  # a false positive 20 m away from everything
            rows.append((9, "Car", -10.0, -10.0))
        pred.append(_f(*rows))
    m = _car(tev.evaluate((gt, pred)))
    assert m["num_false_positives"] == 1 and m["num_misses"] == 1 and m["num_switches"] == 0
    assert m["num_fragmentations"] == 1                  # object 2: tracked, lost, tracked again
    assert m["mota"] == pytest.approx(1 - 2 / 10)
    assert m["mostly_tracked"] == 2                      # 4 / 5 = 80 % is still mostly tracked
    assert m["motp"] == pytest.approx(0.5 * 5 / 9)       # 5 matches at 0.5 m, 4 at 0 m


def test_class_thresholds_range_points_and_neighbours():
    # pedestrian 1.2 m off: beyond its 1 m -> a miss and a false positive; a car 1.2 m off matches (2 m)
    gt = [_f((1, "Pedestrian", 5.0, 0.0), (2, "Car", 15.0, 0.0))]
    pred = [_f((5, "Pedestrian", 6.2, 0.0), (6, "Car", 16.2, 0.0))]
    r = tev.evaluate((gt, pred))
    assert r["classes"]["Pedestrian"]["num_misses"] == 1 and r["classes"]["Pedestrian"]["num_false_positives"] == 1
    assert _car(r)["num_misses"] == 0 and _car(r)["num_matches"] == 1
    # a looser threshold matches the pedestrian
    r = tev.evaluate((gt, pred), match_dist={"Pedestrian": 1.5})
    assert r["classes"]["Pedestrian"]["num_matches"] == 1
    # ground truth out of range or with few points, and vans, are ignored: neither missed nor predictions on them
    # false; a lone prediction beyond range is dropped
    gt = [_f((1, "Car", 45.0, 0.0), (3, "Van", 8.0, 4.0)) + _f((2, "Car", 10.0, 0.0), npts=3)]
    pred = [_f((5, "Car", 45.3, 0.0), (6, "Car", 10.0, 0.2), (7, "Car", 8.0, 4.2), (8, "Car", 60.0, 0.0))]
    m = _car(tev.evaluate((gt, pred), max_range_m=40.0, min_points=10))
    assert m["num_objects"] == 0 and m["num_false_positives"] == 0 and m["num_misses"] == 0
    # counted again when the limits allow them
    m = _car(tev.evaluate((gt, pred), max_range_m=50.0, min_points=1))
    assert m["num_objects"] == 2 and m["num_matches"] == 2
    assert m["num_false_positives"] == 0          # 8 at 60 m is still beyond the range; the van still ignored
    m = _car(tev.evaluate((gt, pred), max_range_m=70.0, min_points=1))
    assert m["num_matches"] == 2 and m["num_false_positives"] == 1


def test_velocity_errors_and_tracker_output():
    # matches with velocity errors 0, 1, 2, 3 m/s; a tentative prediction (state 0) does not count
    gt = [_f((1, "Car", 10.0 + k, 0.0, 5.0, 0.0)) for k in range(5)]
    pred = np.zeros(5, dtype=[("id", "u4"), ("cls", "u1"), ("state", "u1"), ("x", "f4"), ("y", "f4"),
                              ("vx", "f4"), ("vy", "f4")])
    frames = []
    for k in range(5):
        p = np.zeros(1, pred.dtype)
        p["id"], p["cls"], p["x"], p["y"] = 3, 0, 10.0 + k, 0.0   # cls 0: lidet_class_t car
        p["vx"], p["vy"] = 5.0, [0.0, 1.0, 2.0, 3.0, 9.0][k]
        p["state"] = 0 if k == 4 else 1
        frames.append(p)
    m = _car(tev.evaluate((gt, frames)))
    assert m["num_matches"] == 5 and m["mota"] == 1.0
    v = m["vel_err"]
    assert v["n"] == 4 and v["median"] == pytest.approx(1.5) and v["p90"] == pytest.approx(2.7)


def test_two_sequences_keep_their_ids_apart():
    # the same ids in two sequences are different objects: no switch across them
    a = [_f((1, "Car", 10.0, 0.0)) for _ in range(3)]
    b = [_f((1, "Car", 20.0, 0.0)) for _ in range(3)]
    pa = [_f((4, "Car", 10.0, 0.0)) for _ in range(3)]
    pb = [_f((4, "Car", 20.0, 0.0)) for _ in range(3)]
    r = tev.evaluate([(a, pa), (b, pb)])
    m = _car(r)
    assert m["num_unique_objects"] == 2 and m["num_switches"] == 0 and m["mota"] == 1.0
    assert r["params"]["n_sequences"] == 2


def test_files_and_cli(tmp_path, capsys):
    gt_dir = tmp_path / "gt" / "0000"
    pred = [_f((7 if k < 2 else 8, "Car", 10.0 + k, 0.3, 1.0, 0.0)) for k in range(4)]
    for k in range(4):
        tr = [{"id": 1, "cls": "Car", "box": np.array([10.0 + k, 0.0, -0.9, 4.0, 1.8, 1.5, 0.0]),
               "v": np.array([1.0, 0.0]), "npts": 40}]
        sq.write_tracks(gt_dir / "tracks" / f"{k:06d}.txt", tr)
        p = {key: np.array([r[key] for r in pred[k]]) for key in ("id", "cls", "x", "y", "vx", "vy")}
        p.update(z=np.array([-0.9]), l=np.array([4.0]), w=np.array([1.8]), h=np.array([1.5]), yaw=np.array([0.0]))
        tev.write_tracks(tmp_path / "pred" / "0000" / "tracks" / f"{k:06d}.txt", p)
    r = tev.evaluate_dirs([gt_dir], tmp_path / "pred")
    assert _car(r)["num_switches"] == 1 and _car(r)["mota"] == pytest.approx(0.75)
    g = tev.read_tracks(gt_dir / "tracks" / "000002.txt")
    assert g["npts"].tolist() == [40] and g["box"][0].tolist() == [12.0, 0.0, -0.9, 4.0, 1.8, 1.5, 0.0]
    assert eval_main(["track", "--gt", str(gt_dir), "--pred", str(tmp_path / "pred"), "--json"]) == 0
    js = json.loads(capsys.readouterr().out)
    assert js["classes"]["Car"]["num_switches"] == 1 and js["overall"]["mota"] == pytest.approx(0.75)
    assert eval_main(["track", "--gt", str(gt_dir), "--pred", str(tmp_path / "pred")]) == 0
    assert "MOTA" in capsys.readouterr().out
    assert eval_main(["track", "--gt", str(tmp_path / "nope"), "--pred", str(tmp_path / "pred")]) == 2


# ------------------------------------------------------------------------------------------------
# the peer


def _det(cls, x, y, yaw=0.0, score=0.9, size=(4.0, 1.8, 1.5)):
    return [cls, x, y, -0.8, *size, yaw, score]


def test_giou_3d():
    a = np.array([[0.0, 0.0, 0.0, 4.0, 2.0, 1.5, 0.3]])
    assert giou_3d(a, a)[0, 0] == pytest.approx(1.0)
    # two unit cubes side by side, 1 m apart: IoU 0, hull 3 x 1, union 2 -> -1/3
    u = np.array([[0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 0.0]])
    v = np.array([[2.0, 0.0, 0.0, 1.0, 1.0, 1.0, 0.0]])
    assert giou_3d(u, v)[0, 0] == pytest.approx(-1 / 3)
    # half overlapping: IoU 1/3, hull 1.5 = union: GIoU = IoU
    w = np.array([[0.5, 0.0, 0.0, 1.0, 1.0, 1.0, 0.0]])
    assert giou_3d(u, w)[0, 0] == pytest.approx(1 / 3)
    assert giou_3d(np.vstack([u, v]), np.vstack([u, w, v])).shape == (2, 3)


def test_association_hungarian_and_greedy():
    aff = np.array([[0.9, 0.8], [0.85, -1.0]])
    assert associate(aff, 0.0, "hungar") == [(0, 1), (1, 0)]       # 0.8 + 0.85 beats 0.9 alone
    assert associate(aff, 0.0, "greedy") == [(0, 0)]                # greedy takes 0.9 first
    assert associate(aff, 0.95, "hungar") == []


def test_peer_constant_velocity_and_ego_motion():
    # a car at 10 m/s along x seen by a sensor driving 5 m/s along x: in the sensor frame it moves 5 m/s,
    # the ego motion adds 5 m/s back: the velocity over the ground converges to 10 m/s
    t = PeerTracker()
    dt = 0.1
    for k in range(30):
        x = 20.0 + 10.0 * dt * k - 5.0 * dt * k
        out = t.update(np.array([_det(0, x, 3.0)]), dt, None if k == 0 else (0.5, 0.0, 0.0))
    assert len(out) == 1 and out["id"][0] == 1 and out["state"][0] == 1
    assert out["vx"][0] == pytest.approx(10.0, abs=0.3) and abs(out["vy"][0]) < 0.2
    # the sensor turns: a parked car keeps its place over the ground and gets no velocity
    t = PeerTracker()
    pose = np.zeros(3)
    world = np.array([15.0, 4.0])
    for k in range(25):
        dyaw = 0.05
        if k:
            c, s = np.cos(pose[2]), np.sin(pose[2])
            pose = pose + np.array([c * 0.8, s * 0.8, dyaw])
        c, s = np.cos(pose[2]), np.sin(pose[2])
        rel = np.array([[c, s], [-s, c]]) @ (world - pose[:2])
        out = t.update(np.array([_det(0, rel[0], rel[1], yaw=-pose[2])]), 0.1, None if k == 0 else (0.8, 0.0, dyaw))
    assert len(out) == 1 and out["id"][0] == 1
    assert np.hypot(out["vx"][0], out["vy"][0]) < 0.3
    assert out["x"][0] == pytest.approx(rel[0], abs=0.2) and out["y"][0] == pytest.approx(rel[1], abs=0.2)


def test_peer_heading_flip_min_hits_and_max_age():
    t = PeerTracker()
    dt = 0.1
    outs = [t.update(np.array([_det(0, 10.0 + k, 0.0, yaw=(np.pi if k == 3 else 0.0) + 0.01)]), dt) for k in range(6)]
    # the flipped detection turns the track by pi (AB3DMOT follows the detection's heading) instead of averaging
    # 0 and pi into a box across the road; the next one turns it back
    assert [abs(float(np.sin(o["yaw"][0]))) < 0.05 for o in outs] == [True] * 6
    assert [abs(float(np.cos(o["yaw"][0])) - (-1 if k == 3 else 1)) < 0.05 for k, o in enumerate(outs)] == [True] * 6
    assert [len(o) for o in outs] == [1] * 6 and set(int(o["id"][0]) for o in outs) == {1}
    # a car born after the first min_hits scans is reported from its 3rd hit (min_hits 3)
    t = PeerTracker()
    t.update(np.zeros((0, 9)), dt)
    t.update(np.zeros((0, 9)), dt)
    t.update(np.zeros((0, 9)), dt)
    shown = [len(t.update(np.array([_det(0, 10.0 + k, 0.0)]), dt)) for k in range(4)]
    assert shown == [0, 0, 1, 1]
    # max_age 2: one missed scan is survived (coasting with OUT_COASTING), two are not
    assert len(t.update(np.zeros((0, 9)), dt)) == 0
    assert len(t.tracks_out(OUT_COASTING)) == 1 and t.tracks_out(OUT_COASTING)["state"][0] == 2
    out = t.update(np.array([_det(0, 16.0, 0.0)]), dt)
    assert out["id"].tolist() == [1]
    t.update(np.zeros((0, 9)), dt)
    t.update(np.zeros((0, 9)), dt)
    assert len(t.tracks) == 0
    out = t.update(np.array([_det(0, 19.0, 0.0)]), dt)
    assert len(t.tracks) == 1 and t.tracks[0].id == 2
    assert KITTI[2]["min_hits"] == 1 and out.dtype == TRACK_DTYPE


# ------------------------------------------------------------------------------------------------
# the runner


class StandIn:
    """A stand-in for lidet's tracker (same interface): nearest previous track of the same class within 2 m,
    velocity from the last two positions, no ego motion."""

    def __init__(self):
        self.prev = np.zeros(0, TRACK_DTYPE)
        self.next_id = 1

    def update(self, dets, dt, ego=None, flags=0):
        d = np.asarray(dets, np.float64).reshape(-1, 9)
        out = np.zeros(len(d), TRACK_DTYPE)
        used = set()
        for j, r in enumerate(d):
            cand = [i for i in range(len(self.prev)) if i not in used and self.prev["cls"][i] == r[0]
                    and np.hypot(self.prev["x"][i] - r[1], self.prev["y"][i] - r[2]) < 2.0]
            if cand:
                i = min(cand, key=lambda i: np.hypot(self.prev["x"][i] - r[1], self.prev["y"][i] - r[2]))
                used.add(i)
                out["id"][j] = self.prev["id"][i]
                out["vx"][j] = (r[1] - self.prev["x"][i]) / dt
                out["vy"][j] = (r[2] - self.prev["y"][i]) / dt
            else:
                out["id"][j] = self.next_id
                self.next_id += 1
            out["cls"][j] = int(r[0])
            out["state"][j] = 1
            for k, n in enumerate(("x", "y", "z", "l", "w", "h", "yaw")):
                out[n][j] = r[1 + k]
            out["score"][j] = r[8]
        self.prev = out
        return out


@pytest.fixture(scope="module")
def tiny_seqs(tmp_path_factory):
    d = tmp_path_factory.mktemp("tseq")
    o = sq.SeqOptions(frames=12, ego_speed=1.0, scene_kind="street")
    for i in range(2):
        sq.write_sequence(d, "vlp16", 11, i, o)
    return [trun.load_sequence(d / f"{i:04d}") for i in range(2)]


def test_peer_on_noise_free_ground_truth(tiny_seqs):
    nz = trun.GtNoise(sigma_xy={0: 0.0, 1: 0.0, 2: 0.0}, sigma_z=0.0, sigma_size=0.0, sigma_yaw=0.0,
                      p_flip={0: 0.0, 1: 0.0, 2: 0.0}, p_drop=0.0, fp_rate=0.0, min_points=0)
    dets = [trun.gt_detections(s, nz, i) for i, s in enumerate(tiny_seqs)]
    res = trun.run(tiny_seqs, dets, {"peer": PeerTracker}, eval_kw={"min_points": 1, "max_range_m": 40.0})
    m = res["peer"]["overall"]
    assert m["num_objects"] > 20
    assert m["mota"] >= 0.99 and m["num_switches"] == 0 and m["num_false_positives"] == 0
    assert m["motp"] < 0.05                   # the filter lags moving objects a little


def test_runner_ground_truth_source_and_files(tiny_seqs, tmp_path):
    dets = [trun.gt_detections(s, trun.GtNoise(seed=3), i) for i, s in enumerate(tiny_seqs)]
    again = [trun.gt_detections(s, trun.GtNoise(seed=3), i) for i, s in enumerate(tiny_seqs)]
    assert all(np.array_equal(a, b) for x, y in zip(dets, again) for a, b in zip(x, y))
    res = trun.run(tiny_seqs, dets, {"standin": StandIn, "peer": PeerTracker}, out_dir=tmp_path)
    assert set(res) == {"standin", "peer"}
    for r in res.values():
        assert r["overall"]["num_objects"] > 0 and r["ms_per_scan"] > 0
    # the files written give the same numbers through lidet-eval track's reader
    again = tev.evaluate_dirs([s.path for s in tiny_seqs], tmp_path / "peer")
    assert again["overall"]["mota"] == pytest.approx(res["peer"]["overall"]["mota"], abs=1e-9)
    table = tev.compare_table(res)
    assert "ratio" in table and "[overall]" in table


def test_runner_with_the_detector(tiny_seqs, need_lib, capsys):
    dets = [trun.detect_sequence(s) for s in tiny_seqs]
    assert all(d.shape[1] == 9 for ds in dets for d in ds) and sum(len(d) for ds in dets for d in ds) > 0
    res = trun.run(tiny_seqs, dets, {"lidet": StandIn, "peer": PeerTracker})
    assert res["peer"]["overall"]["num_objects"] == res["lidet"]["overall"]["num_objects"] > 0
    # the CLI: the peer alone (and lidet's tracker when its bindings are built), both sources
    assert trun.main([str(s.path) for s in tiny_seqs] + ["--trackers", "peer"]) == 0
    out = capsys.readouterr().out
    assert "source 'detector'" in out and "source 'gt'" in out
