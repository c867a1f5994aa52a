# SPDX-License-Identifier: MIT
"""`lidet track` (host CLI, ports/host/cli_track.c): the detector and the tracker over a sequence of scans.

Its track lines are those of the Python pipeline on the same scans (lidet_tools.native.detect, then
lidet_tools.track.Tracker with the same dt and ego motion), its --fixed lines those of the integer detector
(native.detect_q) and the integer tracker (track.native_q.TrackerQ); a scene that moves at a known speed gets
that velocity; --out writes the same lines, lidet-eval track's prediction files and KITTI tracking labels; the
picture is deterministic; bad inputs are clear errors. Sequences: one scene moved by hand (the simulated HDL-64
scan as a sensor driving at 5 m/s, straight or turning) and, where the sequence simulator is there, a simulated
VLP-16 sequence with moving road users and a moving sensor (lidet_tools.sim.sequence)."""
import json
import pathlib
import shutil
import subprocess

import numpy as np
import pytest
from PIL import Image

from lidet_tools import kitti

ROOT = pathlib.Path(__file__).resolve().parents[2]
HDL64 = ROOT / "tests" / "data" / "sim_hdl64"
CLASSES = ("Car", "Cyclist", "Pedestrian")
SPEED, DT, N_SCANS = 5.0, 0.1, 8
FIELDS = ("x", "y", "z", "l", "w", "h", "yaw", "vx", "vy", "score")


def _run(cli, *args, ok=True):
    r = subprocess.run([str(cli), "track", *map(str, args)], capture_output=True, text=True)
    if ok:
        assert r.returncode == 0, r.stderr
    return r


def _lines(text):
    """Track lines `frame id class x y z l w h yaw vx vy score hits` (header and comment lines skipped)."""
    out = []
    for line in text.splitlines():
        if line.startswith("#") or not line.strip():
            continue
        p = line.split()
        assert len(p) == 14, line
        out.append((int(p[0]), int(p[1]), p[2], tuple(float(x) for x in p[3:13]), int(p[13])))
    return out


def _rot(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s], [s, c]])


def _drive(folder, yaw_rate, speed=SPEED, n=N_SCANS):
    """The simulated HDL-64 scan seen from a sensor that drives forward at `speed` m/s and turns at `yaw_rate`
    rad/s (the scene stands): velodyne/<frame>.bin, poses.txt in lidet-sim --sequence's 8 columns, a calib per
    scan. Without the ego motion every object moves at (-speed, 0) in the sensor frame when yaw_rate is 0."""
    pts = kitti.read_bin(HDL64 / "velodyne" / "000000.bin")
    (folder / "velodyne").mkdir(parents=True)
    (folder / "calib").mkdir()
    pos, yaw, rows = np.zeros(2), 0.0, []
    for k in range(n):
        if k:
            pos = pos + _rot(yaw) @ np.array([speed * DT, 0.0])
            yaw += yaw_rate * DT
        q = pts.copy()
        q[:, :2] = (pts[:, :2] - pos) @ _rot(yaw)  # R(-yaw) (p - pos), row vectors
        kitti.write_bin(folder / "velodyne" / f"{k:06d}.bin", q.astype(np.float32))
        shutil.copy(HDL64 / "calib" / "000000.txt", folder / "calib" / f"{k:06d}.txt")
        ego = (speed * DT, 0.0, yaw_rate * DT) if k else (0.0, 0.0, 0.0)
        rows.append(f"{k} {k * DT:.4f} {pos[0]:.5f} {pos[1]:.5f} {yaw:.6f} {ego[0]:.5f} {ego[1]:.5f} {ego[2]:.6f}")
    (folder / "poses.txt").write_text("# frame t x y yaw dx dy dyaw\n" + "\n".join(rows) + "\n")
    return folder


@pytest.fixture(scope="module")
def straight(tmp_path_factory):
    return _drive(tmp_path_factory.mktemp("straight"), 0.0)


@pytest.fixture(scope="module")
def turning(tmp_path_factory):
    return _drive(tmp_path_factory.mktemp("turning"), 0.2)


@pytest.fixture(scope="module")
def simseq(tmp_path_factory):
    """A simulated VLP-16 sequence (moving road users, the sensor driving at 4 m/s), or a skip."""
    try:
        from lidet_tools.sim.sequence import SeqOptions, write_sequence
    except ImportError as e:
        pytest.skip(f"the sequence simulator is not available: {e}")
    out = tmp_path_factory.mktemp("simseq")
    write_sequence(out, "vlp16", seed=1, index=0, opts=SeqOptions(frames=8, ego_speed=4.0))
    return out / "0000"


def _poses(seq):
    return np.loadtxt(seq / "poses.txt", comments="#", ndmin=2)


def _dt(P, k):
    return P[k, 1] - P[k - 1, 1] if k else P[1, 1] - P[0, 1]


def _python_float(seq, sensor, ego=True, flags=0):
    """The Python pipeline: native.detect per scan, then Tracker with poses.txt's dt and ego motion."""
    from lidet_tools import native
    from lidet_tools.track import Tracker
    P = _poses(seq)
    tr = Tracker()
    frames = []
    for k, scan in enumerate(sorted((seq / "velodyne").glob("*.bin"))):
        d = native.detect(kitti.read_bin(scan), sensor)
        dets = np.column_stack([d.cls, d.box, d.score]) if len(d.cls) else np.zeros((0, 9))
        frames.append(tr.update(dets, _dt(P, k), P[k, 5:8] if ego and k else None, flags))
    return frames


def _as_lines(frames):
    return [(k, int(t["id"]), CLASSES[t["cls"]], tuple(float(t[f]) for f in FIELDS), int(t["hits"]))
            for k, f in enumerate(frames) for t in f]


def _same(got, want, atol=1e-5):
    assert len(got) == len(want) > 0
    for g, w in zip(got, want):
        assert g[:3] == w[:3] and g[4] == w[4], (g, w)
        np.testing.assert_allclose(np.array(g[3]), np.array(w[3]), rtol=0, atol=atol, err_msg=str(g[:3]))


# ---- (a) the float pipeline ------------------------------------------------------------------------------------


@pytest.mark.parametrize("which", ["turning", "simseq"])
def test_lines_are_the_python_pipeline(cli, need_lib, request, which):
    seq = request.getfixturevalue(which)
    sensor = "hdl64" if which == "turning" else "vlp16"
    r = _run(cli, seq, "--sensor", sensor)
    want = _python_float(seq, sensor)
    _same(_lines(r.stdout), _as_lines(want))
    # one header line per scan
    assert sum(line.startswith("# frame ") for line in r.stdout.splitlines()) == N_SCANS
    # --json: every field, the covariance included, as the bindings return it (float32 written exactly)
    js = [json.loads(line) for line in _run(cli, seq, "--sensor", sensor, "--json").stdout.splitlines()]
    assert [j["frame"] for j in js] == list(range(N_SCANS))
    for j, f in zip(js, want):
        assert j["detect_ms"] >= 0 and j["track_ms"] >= 0 and j["tracker_status"] == 0
        assert set(j["stats"]) >= {"n_tracks", "n_confirmed", "n_births", "n_deaths", "n_matched"}
        assert [t["id"] for t in j["tracks"]] == [int(i) for i in f["id"]]
        for t, w in zip(j["tracks"], f):
            assert t["state"] == ("tentative", "confirmed", "coasting")[w["state"]] and t["hits"] == w["hits"]
            assert t["age"] == w["age"] and t["misses"] == w["misses"] and t["det"] == w["det"]
            for k in FIELDS + ("p_pp", "p_pv", "p_vv"):
                assert np.float32(t[k]) == w[k], (k, t[k], w[k])


def test_coasting_and_tentative_flags(cli, need_lib, simseq):
    from lidet_tools.track.native import OUT_COASTING, OUT_TENTATIVE
    flags = OUT_COASTING | OUT_TENTATIVE
    r = _run(cli, simseq, "--sensor", "vlp16", "--coasting", "--tentative")
    want = _python_float(simseq, "vlp16", flags=flags)
    _same(_lines(r.stdout), _as_lines(want))
    assert len(_lines(r.stdout)) > len(_lines(_run(cli, simseq, "--sensor", "vlp16").stdout))
    assert any(t["hits"] == 1 for t in want[0])  # the first scan's births are there, tentative


def test_ego_none_and_explicit_scans(cli, need_lib, turning):
    """DIR reads DIR/poses.txt; --ego none does not; the same scans given one by one read no poses.txt, and
    --ego FILE with 'dx dy dyaw' lines is the same as the poses file's columns 6-8."""
    scans = sorted((turning / "velodyne").glob("*.bin"))
    with_ego = _run(cli, turning).stdout
    no_ego = _lines(_run(cli, turning, "--ego", "none").stdout)
    _same(no_ego, _as_lines(_python_float(turning, "hdl64", ego=False)))
    _same(_lines(_run(cli, *scans).stdout), no_ego)
    ego3 = turning.parent / "ego3.txt"
    ego3.write_text("".join(f"{float(r[5])!r} {float(r[6])!r} {float(r[7])!r}\n" for r in _poses(turning)))
    assert _lines(_run(cli, *scans, "--ego", ego3).stdout) == _lines(with_ego)


def test_rate_and_dt_file(cli, need_lib, straight):
    """--rate HZ is dt = 1 / HZ on every scan; --dt-file gives each scan's; poses.txt's t column is the default."""
    scans = sorted((straight / "velodyne").glob("*.bin"))
    base = _lines(_run(cli, *scans).stdout)  # 10 Hz
    assert _lines(_run(cli, *scans, "--rate", "10").stdout) == base
    assert _lines(_run(cli, straight, "--ego", "none").stdout) == base  # t column: 0.1 s
    fast = _lines(_run(cli, *scans, "--rate", "20").stdout)
    dtf = straight.parent / "dt.txt"
    dtf.write_text("# dt per scan\n" + "0.05\n" * N_SCANS)
    assert _lines(_run(cli, *scans, "--dt-file", dtf).stdout) == fast
    # the same motion in half the time: twice the speed, on the tracks matched on every scan (a track born a few
    # scans ago has a velocity still on its way from the birth's zero, which takes another path at another dt)
    v_base = np.array([w[3][7] for w in base if w[0] == N_SCANS - 1 and w[4] == N_SCANS])
    v_fast = np.array([w[3][7] for w in fast if w[0] == N_SCANS - 1 and w[4] == N_SCANS])
    assert len(v_base) >= 3
    np.testing.assert_allclose(v_fast, 2 * v_base, rtol=0.05, atol=0.05)


# ---- (b) --fixed: the integer detector and tracker ---------------------------------------------------------------


def _tracker_q():
    try:
        from lidet_tools.track.native_q import TrackerQ
        return TrackerQ()
    except (ImportError, AttributeError, OSError) as e:
        pytest.skip(f"the integer tracker's bindings are not available: {e}")


@pytest.mark.parametrize("which", ["turning", "simseq"])
def test_fixed_is_the_integer_tracker(cli, need_lib, request, which):
    """--fixed: the integer detector's detections (native.detect_q, as lidet detect --fixed) into the integer
    tracker with dt in ms and the ego motion in mm / BAM32 (ref.track_q.quantise_dt, quantise_ego)."""
    from lidet_ref import track_q as ref
    from lidet_tools import native
    seq = request.getfixturevalue(which)
    sensor = "hdl64" if which == "turning" else "vlp16"
    tq = _tracker_q()
    P = _poses(seq)
    frames = []
    for k, scan in enumerate(sorted((seq / "velodyne").glob("*.bin"))):
        d = native.detect_q(native.to_mm(kitti.read_bin(scan)), sensor)
        rows = np.column_stack([d["cls"], d["boxes"], d["score_q15"]])
        ego = ref.quantise_ego(P[k, 5:8]) if k else None
        frames.append(ref.tracks_to_si(tq.update_q(rows, ref.quantise_dt(_dt(P, k)), ego)))
    _same(_lines(_run(cli, seq, "--sensor", sensor, "--fixed").stdout), _as_lines(frames))


def test_fixed_agrees_with_float(cli, need_lib, turning):
    """On the scene seen while turning: the tracks within 40 m pair up between the two runs, centres within 5 cm
    from a track's third detection (at its second the centre is the detection's, and the int8 detector's boxes
    differ from the float one's by a few cm). The scene holds one object at the edge of detection: a person at 14 m
    whom the float detector finds on scans 3 and 4 and the integer one does not (a decision within the int8
    arithmetic's error of a gate), so a scan may hold one track more in one run; every other track is in both."""
    fl = _lines(_run(cli, turning).stdout)
    fx = _lines(_run(cli, turning, "--fixed").stdout)
    unpaired = 0
    for k in range(1, N_SCANS):
        a = np.array([w[3][:2] for w in fl if w[0] == k and np.hypot(*w[3][:2]) < 40.0])
        b = np.array([w[3][:2] for w in fx if w[0] == k and np.hypot(*w[3][:2]) < 40.0])
        assert len(a) > 0 and len(b) > 0 and abs(len(a) - len(b)) <= 1, k
        d = np.linalg.norm(a[:, None] - b[None], axis=2)
        ha = np.array([w[4] for w in fl if w[0] == k and np.hypot(*w[3][:2]) < 40.0])
        hb = np.array([w[4] for w in fx if w[0] == k and np.hypot(*w[3][:2]) < 40.0])
        # every track of the run with more of them has a partner but at most one; partners within 5 cm
        near_a, near_b = d.min(axis=1) < 0.05, d.min(axis=0) < 0.05
        unpaired += int((~near_a[ha >= 3]).sum() + (~near_b[hb >= 3]).sum())
        assert (~near_a[ha >= 3]).sum() + (~near_b[hb >= 3]).sum() <= 1, (k, d, ha, hb)
    assert unpaired <= 2


# ---- (c) velocity ------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("fixed", [[], ["--fixed"]])
def test_known_velocity(cli, straight, turning, fixed):
    """The standing scene seen by a sensor driving at 5 m/s: without the ego motion every object moves at
    (-5, 0) m/s in the sensor frame; with it (straight or turning at 0.2 rad/s) it stands. Tracks within 60 m
    detected on every scan: within 0.3 m/s at the last. (A far car first detected at the third scan, whose box
    steps 0.3-0.6 m between scans where the scene moves 0.5 m, is 0.6 m/s off after its sixth detection: the
    estimate follows the boxes, and that is the detector's jitter, not the tracker's.)"""
    cases = ((straight, ("--ego", "none"), (-SPEED, 0.0)), (straight, (), (0.0, 0.0)), (turning, (), (0.0, 0.0)))
    for seq, opt, v in cases:
        rows = [w for w in _lines(_run(cli, seq, *opt, *fixed).stdout) if w[0] == N_SCANS - 1]
        near = [w for w in rows if np.hypot(w[3][0], w[3][1]) < 60.0 and w[4] == N_SCANS]
        assert len(near) >= 3, (seq.name, opt)
        for w in near:
            assert np.hypot(w[3][7] - v[0], w[3][8] - v[1]) < 0.3, (seq.name, opt, w)


# ---- --out, label_02 -----------------------------------------------------------------------------------------------


def test_out_folder(cli, need_lib, turning, tmp_path):
    """DIR/<stem>.txt: the stdout lines of the scan; DIR/tracks/<stem>.txt: lidet-eval track's prediction lines
    (lidet_tools.track.eval.read_tracks); DIR/label_02.txt: KITTI tracking lines in the camera frame, as
    lidet_tools.kitti.box_to_kitti converts the boxes (per-scan calib files here)."""
    from lidet_tools.track import eval as te
    out = tmp_path / "o"
    r = _run(cli, turning, "--out", out)
    lines = _lines(r.stdout)
    for k in range(N_SCANS):
        mine = [w for w in lines if w[0] == k]
        assert _lines((out / f"{k:06d}.txt").read_text()) == mine
        ev = te.read_tracks(out / "tracks" / f"{k:06d}.txt", gt=False)
        assert list(ev["id"]) == [w[1] for w in mine] and list(ev["cls"]) == [w[2] for w in mine]
        if mine:
            np.testing.assert_allclose(ev["box"], [w[3][:7] for w in mine], atol=1e-6)
            np.testing.assert_allclose(ev["vx"], [w[3][7] for w in mine], atol=1e-6)
            np.testing.assert_allclose(ev["score"], [w[3][9] for w in mine], atol=1e-6)
    calib = kitti.read_calib(HDL64 / "calib" / "000000.txt")
    rows = kitti.read_label02(out / "label_02.txt")
    front = [w for w in lines if (calib.velo_to_cam_points(kitti.box_corners(_box(w)))[:, 2] >= 0.1).all()]
    assert len(rows) == len(front) > 0
    for (frame, tid, o), w in zip(rows, front):
        assert (frame, tid, o.type) == (w[0], w[1], w[2]) and o.truncated == 0 and o.occluded == 0
        ref = kitti.box_to_kitti(_box(w), calib, score=w[3][9])
        np.testing.assert_allclose(o.loc, ref.loc, atol=1e-4)
        np.testing.assert_allclose([o.h, o.w, o.l], [ref.h, ref.w, ref.l], atol=1e-5)
        assert abs((o.ry - ref.ry + np.pi) % (2 * np.pi) - np.pi) < 1e-4
        np.testing.assert_allclose(o.bbox, ref.bbox, atol=0.01)
        assert abs(o.score - w[3][9]) < 1e-5


def _box(w):
    x, y, z, l, wd, h, yaw = w[3][:7]
    return kitti.Box3D(w[2], x, y, z, l, wd, h, yaw)


def test_label02_calibration_rules(cli, simseq, turning, tmp_path):
    """A sequence's one calib/<seq>.txt serves every scan; scans without a calibration write no label_02.txt
    (said once on stderr); --calib FILE gives one."""
    r = _run(cli, simseq, "--sensor", "vlp16", "--out", tmp_path / "a")
    assert (tmp_path / "a" / "label_02.txt").exists() and "not written" not in r.stderr
    rows = kitti.read_label02(tmp_path / "a" / "label_02.txt")
    assert rows and {f for f, _, _ in rows} <= set(range(N_SCANS))
    loose = tmp_path / "loose"
    loose.mkdir()
    for s in sorted((turning / "velodyne").glob("*.bin"))[:3]:
        shutil.copy(s, loose / s.name)
    scans = sorted(loose.glob("*.bin"))
    r = _run(cli, *scans, "--out", tmp_path / "b")
    assert r.stderr.count("label_02.txt is not written") == 1
    assert not (tmp_path / "b" / "label_02.txt").exists() and (tmp_path / "b" / "000002.txt").exists()
    _run(cli, *scans, "--out", tmp_path / "c", "--calib", HDL64 / "calib" / "000000.txt")
    assert (tmp_path / "c" / "label_02.txt").read_text().strip()


def test_out_is_scored_by_lidet_eval(cli, simseq, tmp_path):
    """`lidet track SEQ --out PRED/<seq>`, then lidet-eval track's reader and metrics on it (every scan a frame)."""
    pytest.importorskip("motmetrics")
    from lidet_tools.track import eval as te
    _run(cli, simseq, "--sensor", "vlp16", "--out", tmp_path / "pred" / simseq.name)
    res = te.evaluate_dirs([simseq], tmp_path / "pred")
    assert res["overall"]["num_frames"] == N_SCANS
    assert res["overall"]["num_matches"] > 0 and res["overall"]["mota"] > 0.0


# ---- (d) the picture --------------------------------------------------------------------------------------------


def test_png_is_deterministic(cli, turning, tmp_path):
    a, b = tmp_path / "a.png", tmp_path / "b.png"
    _run(cli, turning, "--png", a)
    _run(cli, turning, "--png", b, "--json")
    im = Image.open(a)
    im.load()
    assert im.mode == "RGB" and im.size[0] == 72 + 800 + 24 and im.size[1] > 800 + 150
    assert a.read_bytes() == b.read_bytes()
    px = np.asarray(im).reshape(-1, 3)
    assert ((px == (235, 235, 235)).all(axis=1)).sum() > 10  # velocity arrows (the sensor turns: objects move)
    assert ((px == (255, 80, 60)).all(axis=1)).sum() > 10     # track 1's colour
    c = tmp_path / "c.png"
    _run(cli, turning, "--png", c, "--fixed")
    Image.open(c).load()


# ---- (e) errors ------------------------------------------------------------------------------------------------------


def test_errors_are_clear(cli, turning, tmp_path):
    scans = sorted((turning / "velodyne").glob("*.bin"))
    s = list(map(str, scans[:3]))

    def err(*args, want):
        r = _run(cli, *args, ok=False)
        assert r.returncode == 1 and want in r.stderr, (args, r.stderr)
        assert "Traceback" not in r.stderr and not _lines(r.stdout)

    err(*s, tmp_path / "nope.bin", want="cannot open scan")
    trunc = tmp_path / "t.bin"
    trunc.write_bytes(scans[0].read_bytes()[:1001])
    err(*s, trunc, want="not a multiple of 16")
    empty = tmp_path / "empty"
    empty.mkdir()
    err(empty, want="no scans")
    err(turning, turning, want="is a folder")
    err(want="usage: lidet track")
    err(*s, "--frobnicate", want="unknown option --frobnicate")
    for bad in ("0", "abc", "nan", "2000"):
        err(*s, "--rate", bad, want="--rate needs")
    err(*s, "--rate", "10", "--dt-file", tmp_path / "x", want="not both")
    err(*s, "--ego", want="--ego needs a value")
    err(*s, "--ego", tmp_path / "missing.txt", want="cannot open the ego motion file")
    cases = {
        "short": ("0 0 0\n0.5 0 0\n", "has 2 lines for 3 scans"),
        "nan": ("0 0 0\n0.5 nan 0\n0 0 0\n", "not a finite number"),
        "word": ("0 0 0\n0.5 zero 0\n0 0 0\n", "'zero' is not a finite number"),
        "cols": ("0 0 0\n0.5 0\n0 0 0\n", "expected 'dx dy dyaw'"),
        "range": ("0 0 0\n0.5 0 4\n0 0 0\n", "out of range"),
        "far": ("0 0 0\n1e6 0 0\n0 0 0\n", "out of range"),
        "time": ("0 0 0 0 0 0 0 0\n1 0.1 0 0 0 0 0 0\n2 0.1 0 0 0 0 0 0\n", "dt must be in"),
        "long": ("0 " * 2000 + "\n", "line longer than"),
    }
    for name, (text, want) in cases.items():
        p = tmp_path / f"ego_{name}.txt"
        p.write_text(text)
        err(*s, "--ego", p, want=want)
    for name, (text, want) in {"short": ("0.1\n0.1\n", "has 2 lines for 3 scans"),
                               "zero": ("0.1\n0.1\n0\n", "outside [0.001, 10]"),
                               "big": ("0.1\n11\n0.1\n", "outside [0.001, 10]"),
                               "two": ("0.1\n0.1 0.2\n0.1\n", "expected one dt")}.items():
        p = tmp_path / f"dt_{name}.txt"
        p.write_text(text)
        err(*s, "--dt-file", p, want=want)
    # two scans of one name: one --out file
    other = tmp_path / "other"
    other.mkdir()
    shutil.copy(scans[0], other / scans[0].name)
    err(scans[0], other / scans[0].name, "--out", tmp_path / "o", want="two scans are named")
    err(*s, "--set", "nosuchfield=1", want="bad --set")
    err(*s, "--model", "nosuchmodel", want="no models cls_nosuchmodel")
    err(*s, "--range-only", want="add --fixed")
    err(*s, "--sensor", "hdl65", want="unknown sensor")
    bad_calib = tmp_path / "calib.txt"
    bad_calib.write_text("P2: 1 2 3\n")
    err(*s, "--out", tmp_path / "o2", "--calib", bad_calib, want="P2 needs 12 numbers")
    # an output folder that cannot be made
    err(*s, "--out", scans[0], want="not a folder")
    r = _run(cli, "--help", ok=False)
    assert "frame id class x y z l w h yaw vx vy score hits" in r.stderr and "--ego" in r.stderr
