# SPDX-License-Identifier: MIT
"""`lidet detect` (host CLI): the JSON contract, the box files, the KITTI label_2 output against the Python
conversion (lidet_tools.kitti.box_to_kitti), the batch script, and clear errors."""
import json
import pathlib
import subprocess
import sys

import numpy as np
import pytest

from lidet_tools import kitti

ROOT = pathlib.Path(__file__).resolve().parents[2]
SIM = ROOT / "tests" / "data" / "sim_hdl64"
SCAN = SIM / "velodyne" / "000000.bin"


def _run(cli, *args, ok=True):
    r = subprocess.run([str(cli), "detect", *map(str, args)], capture_output=True, text=True)
    if ok:
        assert r.returncode == 0, r.stderr
    return r


def test_json_contract(cli):
    js = json.loads(_run(cli, SCAN, "--sensor", "hdl64", "--json", "--repeat", "3").stdout)
    for k in ("points", "project_ms", "ground_ms", "cluster_ms", "classify_ms", "box_ms", "total_ms"):
        assert k in js and js[k] >= 0, k
    assert js["points"] == len(kitti.read_bin(SCAN))
    assert js["budget"] == 256  # hdl64 default
    assert js["too_tall"] > 0  # the sample's trees and poles: not classified (max_height_extent_m 2.5)
    assert js["classified"] == min(js["clusters"] - js["out_of_crop"] - js["too_tall"] - js["out_of_range"],
                                   js["budget"])
    assert js["classified"] == js["gate1_rejected"] + js["boxed"]
    assert js["boxed"] == (js["gate2_rejected"] + js["size_rejected"] + js["score_rejected"] + js["nms_suppressed"] +
                           js["detections"])
    assert len(js["boxes"]) == js["detections"]
    assert js["total_ms"] >= js["box_ms"]


def test_crop_keeps_the_front(cli):
    # the crop draws a RANSAC stream per ground cell (seed_per_cell): the whole scan with the same draws
    full = json.loads(_run(cli, SCAN, "--json", "--set", "stages.ground.seed_per_cell=1").stdout)
    crop = json.loads(_run(cli, SCAN, "--json", "--crop").stdout)
    # without the clustering's window (pi; the projection's follows it) every cluster is made and the crop
    # leaves the rear ones out
    nowin = json.loads(_run(cli, SCAN, "--json", "--crop", "--set", "stages.cluster.azimuth_half_rad=3.14159").stdout)
    assert nowin["out_of_crop"] > 0 and full["out_of_crop"] == 0 and nowin["clusters"] == full["clusters"]
    # with them (the default: crop + 15 deg, the projection one ground sector more) the rear is neither
    # projected nor clustered; the same proposals are classified, the same detections come out
    assert crop["clusters"] < full["clusters"] and crop["out_of_crop"] < nowin["out_of_crop"]
    assert crop["classified"] == nowin["classified"] == min(crop["clusters"] - crop["out_of_crop"] - crop["too_tall"],
                                                            crop["budget"])
    assert crop["detections"] == nowin["detections"] > 0
    strip = [{k: v for k, v in b.items() if k != "cluster"} for b in crop["boxes"]]
    assert strip == [{k: v for k, v in b.items() if k != "cluster"} for b in nowin["boxes"]]


@pytest.mark.parametrize("fixed", [False, True])
def test_ground_seed_settings_reach_both_detectors(cli, tmp_path, fixed):
    """stages.ground.seed and seed_per_cell change the ground RANSAC's draws in the float and the integer detector
    alike (--fixed once ignored them); the default seed given explicitly changes nothing"""
    fx = ["--fixed"] if fixed else []

    def dump(*sets):
        out = tmp_path / f"d{len(list(tmp_path.iterdir()))}.bin"
        _run(cli, SCAN, *fx, *[a for s in sets for a in ("--set", s)], "--dump", out)
        return out.read_bytes()

    base = dump()
    assert dump("stages.ground.seed=12345") == base
    assert dump("stages.ground.seed=777") != base
    assert dump("stages.ground.seed_per_cell=1") != base


def test_outputs_agree_with_python_conversion(cli, tmp_path):
    out, kout = tmp_path / "b.txt", tmp_path / "k.txt"
    # gates off so that the (possibly untrained) models still give boxes to compare; the size check and
    # NMS stay on
    js = json.loads(_run(cli, SCAN, "--json", "--out", out, "--calib", SIM / "calib" / "000000.txt",
                         "--kitti-out", kout, "--set", "gate1=0", "--set", "gate2=0", "--set", "nms_iou=1").stdout)
    boxes = kitti.read_boxes(out)
    assert len(boxes) == js["detections"]
    for b, j in zip(boxes, js["boxes"]):
        assert b.cls == j["class"] and abs(b.x - j["x"]) < 1e-3 and abs(b.score - j["score"]) < 1e-3
    calib = kitti.read_calib(SIM / "calib" / "000000.txt")
    objs = [o for o in kitti.read_label2(kout) if o.type != "DontCare"]
    front = [b for b in boxes if (calib.velo_to_cam_points(kitti.box_corners(b))[:, 2] >= 0.1).all()]
    assert len(objs) == len(front) and len(front) > 0
    for b, o in zip(front, objs):
        ref = kitti.box_to_kitti(b, calib, score=b.score)
        np.testing.assert_allclose(o.loc, ref.loc, atol=2e-3)
        np.testing.assert_allclose([o.h, o.w, o.l], [ref.h, ref.w, ref.l], atol=2e-3)
        assert abs((o.ry - ref.ry + np.pi) % (2 * np.pi) - np.pi) < 2e-3
        np.testing.assert_allclose(o.bbox, ref.bbox, atol=0.05)
        back = kitti.kitti_to_box(o, calib)
        assert abs(back.x - b.x) < 5e-3 and abs(back.y - b.y) < 5e-3


def test_errors_are_clear(cli, tmp_path):
    r = _run(cli, SCAN, "--model", "nosuchmodel", ok=False)
    assert r.returncode == 1 and "no models cls_nosuchmodel" in r.stderr
    r = _run(cli, SCAN, "--kitti-out", tmp_path / "k.txt", ok=False)
    assert r.returncode == 1 and "need --calib" in r.stderr
    bad = tmp_path / "calib.txt"
    bad.write_text("P2: 1 2 3\n")
    r = _run(cli, SCAN, "--calib", bad, "--kitti-out", tmp_path / "k.txt", ok=False)
    assert r.returncode == 1 and "P2 needs 12 numbers" in r.stderr
    r = _run(cli, SCAN, "--set", "max_proposals=0", ok=False)
    assert r.returncode == 1 and "init" in r.stderr
    r = _run(cli, SCAN, "--set", "nosuchfield=1", ok=False)
    assert r.returncode == 1 and "bad --set" in r.stderr
    trunc = tmp_path / "t.bin"
    trunc.write_bytes(SCAN.read_bytes()[:1001])
    r = _run(cli, trunc, ok=False)
    assert r.returncode == 1 and r.stderr.strip()


def test_batch_script_writes_a_prediction_folder(cli, tmp_path):
    kd = tmp_path / "kitti"
    for sub in ("velodyne", "calib"):
        (kd / sub).mkdir(parents=True)
    for k, src in enumerate(["000000"]):
        (kd / "velodyne" / f"{k:06d}.bin").write_bytes((SIM / "velodyne" / f"{src}.bin").read_bytes())
        (kd / "calib" / f"{k:06d}.txt").write_text((SIM / "calib" / f"{src}.txt").read_text())
    r = subprocess.run([sys.executable, "-m", "lidet_tools.detect", str(kd), "--out", str(tmp_path / "pred"),
                        "--set", "gate1=0"], capture_output=True, text=True,
                       env={**__import__("os").environ, "LIDET_BUILD_DIR": str(pathlib.Path(cli).parents[2])})
    assert r.returncode == 0 and "scans warned" not in r.stderr, r.stderr
    assert (tmp_path / "pred" / "label_2" / "000000.txt").exists()
    assert (tmp_path / "pred" / "boxes" / "000000.txt").exists()
    t = json.loads((tmp_path / "pred" / "timing.json").read_text())
    assert t[0]["frame"] == "000000" and t[0]["total_ms"] > 0
    r = subprocess.run([sys.executable, "-m", "lidet_tools.detect", str(tmp_path / "nothing"), "--out",
                        str(tmp_path / "p2")], capture_output=True, text=True)
    assert r.returncode == 1 and "no scans" in r.stderr


def test_batch_script_passes_the_warnings_on(cli, tmp_path):
    """The batch script captures each scan's `lidet detect`; the warnings come through, one line per kind with how
    many scans drew it: two of three scans upside down (the frame, and the ground refused under them)."""
    kd = tmp_path / "kitti" / "velodyne"
    kd.mkdir(parents=True)
    p = np.fromfile(SCAN, np.float32).reshape(-1, 4)
    q = p.copy()
    q[:, 1:3] *= -1.0
    for k, a in enumerate((q, p, q)):
        a.tofile(kd / f"{k:06d}.bin")
    env = {**__import__("os").environ, "LIDET_BUILD_DIR": str(pathlib.Path(cli).parents[2])}
    r = subprocess.run([sys.executable, "-m", "lidet_tools.detect", str(kd.parent), "--out", str(tmp_path / "pred")],
                       capture_output=True, text=True, env=env)
    assert r.returncode == 0, r.stderr
    lines = [x for x in r.stderr.splitlines() if "scans warned" in x]
    assert any(x.startswith("lidet_tools.detect: 2 of 3 scans warned, the first (000000)") and
               "outside the hdl64's beams" in x for x in lines), r.stderr
    assert any("2 of 3 scans warned" in x and "is the mount height right?" in x for x in lines), r.stderr
    assert len(lines) == 2, lines


def test_set_refuses_nan_and_inf(cli):
    for kv in ("min_points=nan", "theta_rad=inf", "max_steps=-inf", "min_points=1e400"):
        r = subprocess.run([str(cli), "cluster", str(SCAN), "--set", kv], capture_output=True, text=True)
        assert r.returncode == 1 and "bad --set" in r.stderr, kv
    r = _run(cli, SCAN, "--set", "nms_iou=nan", ok=False)
    assert r.returncode == 1 and "bad --set" in r.stderr


def test_set_proposal_seed(cli):
    """--set proposal.seed draws each cluster's 64 points with another seed (both detectors): the default seed
    written out gives the default's results, another seed other energies on the same clusters, and values outside
    uint32 are refused."""
    for fixed in ([], ["--fixed"]):
        base = _run(cli, SCAN, "--sensor", "hdl64", "--json", *fixed).stdout
        same = _run(cli, SCAN, "--sensor", "hdl64", "--json", *fixed, "--set", "proposal.seed=1592594996").stdout
        other = json.loads(_run(cli, SCAN, "--sensor", "hdl64", "--json", *fixed, "--set", "proposal.seed=1").stdout)
        def results(js):  # the timings aside
            return {k: v for k, v in json.loads(js).items() if not k.endswith("_ms")}
        assert results(same) == results(base), fixed
        b = {d["cluster"]: d["energy_cls"] for d in json.loads(base)["boxes"]}
        o = {d["cluster"]: d["energy_cls"] for d in other["boxes"]}
        assert any(o[k] != b[k] for k in b.keys() & o.keys()), fixed  # another draw of the same clusters
    for bad in ("proposal.seed=-1", "proposal.seed=4294967296", "proposal.seed=1.5"):
        r = _run(cli, SCAN, "--sensor", "hdl64", "--set", bad, ok=False)
        assert r.returncode == 1 and "bad --set" in r.stderr, bad


def test_project_out_covers_every_point_past_capacity(cli, tmp_path):
    from lidet_tools import native
    cap = native.capacity()["max_points"]
    rng = np.random.default_rng(0)
    n = cap + 1000
    pts = np.c_[rng.uniform(-30, 30, (n, 2)), rng.uniform(-2, 1, n), np.zeros(n)].astype(np.float32)
    scan = tmp_path / "big.bin"
    pts.tofile(scan)
    out = tmp_path / "pix.bin"
    r = subprocess.run([str(cli), "project", str(scan), "--out", str(out)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    pix = np.fromfile(out, np.int32)
    assert len(pix) == n  # one entry per input point, like ground and cluster
    assert np.all(pix[cap:] == -1) and np.any(pix[:cap] >= 0)


def test_mount_height_option(cli, tmp_path):
    """--mount-height gives the ground stage the sensor's real height: a VLP-16 mounted at 1.0 m, run with the
    profile's 0.5 m, has most of its sectors' planes refused (each is checked against a ground 0.5 m below the
    sensor, +-0.5 m), a warning says so, and road users sink into ground-sized clusters; told its height, the
    ground is found and more of the scene's cars are detected."""
    from lidet_tools.sim.simulate import simulate_scan
    scan = tmp_path / "m1.bin"
    sim = simulate_scan("vlp16", seed=8003, index=1, mount_height_m=1.0)
    sim.points.astype(np.float32).tofile(scan)
    gt = [b for b in sim.boxes if b.cls == "Car" and np.hypot(b.x, b.y) < 20.0]
    prof = _run(cli, scan, "--sensor", "vlp16", "--json")
    told = _run(cli, scan, "--sensor", "vlp16", "--json", "--mount-height", "1.0")
    assert "is the mount height right?" in prof.stderr and "--mount-height" in prof.stderr
    assert "warning" not in told.stderr
    jp, jt = json.loads(prof.stdout), json.loads(told.stdout)
    def cars(j):  # ground-truth cars within 20 m with a Car detection centred within 1 m
        return sum(any(d["class"] == "Car" and np.hypot(d["x"] - g.x, d["y"] - g.y) < 1.0 for d in j["boxes"])
                   for g in gt)
    assert len(gt) >= 3 and cars(jt) >= cars(jp) + 2, (len(gt), cars(jp), cars(jt))
    # the profile's own height given explicitly changes nothing
    same = json.loads(_run(cli, scan, "--sensor", "vlp16", "--json", "--mount-height", "0.5").stdout)
    assert same["boxes"] == jp["boxes"]
    # the integer detector takes it too
    fx = _run(cli, scan, "--sensor", "vlp16", "--json", "--fixed", "--mount-height", "1.0")
    assert cars(json.loads(fx.stdout)) >= cars(jp) and "warning" not in fx.stderr
    assert "is the mount height right?" in _run(cli, scan, "--sensor", "vlp16", "--json", "--fixed").stderr
    for bad in ("nan", "-0.1", "10.5", "abc", ""):
        r = _run(cli, scan, "--sensor", "vlp16", "--mount-height", bad, ok=False)
        assert r.returncode == 1 and "--mount-height needs metres in [0, 10]" in r.stderr, bad
    r = subprocess.run([str(cli), "ground", str(scan), "--sensor", "vlp16", "--mount-height", "1.0", "--json"],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr


def test_ground_speed_knobs_reach_both_detectors(cli):
    """--set stages.ground.{sample_step, sample_col_step, ransac_iters, refine_iters}: the float detector and
    --fixed take them (a firmware's speed trade, docs/FIXED_POINT.md); the profile's own value changes nothing,
    another changes the result, a value out of range is refused."""
    scan = ROOT / "tests" / "data" / "sim_vlp16" / "velodyne" / "000000.bin"

    def result(*extra):
        js = json.loads(_run(cli, scan, "--sensor", "vlp16", "--json", *extra).stdout)
        return {k: v for k, v in js.items() if not k.endswith("_ms")}

    for fixed in ((), ("--fixed",)):
        base = result(*fixed)
        # the vlp16 profile's defaults (lidet_ground_cfg_default: a low-row sensor): 2 refinements, every row
        assert result(*fixed, "--set", "stages.ground.refine_iters=2") == base
        assert result(*fixed, "--set", "stages.ground.sample_step=1") == base
        for kv in ("refine_iters=1", "sample_step=2", "ransac_iters=8", "sample_col_step=3"):
            assert result(*fixed, "--set", f"stages.ground.{kv}") != base, (fixed, kv)
        r = _run(cli, scan, "--sensor", "vlp16", *fixed, "--set", "stages.ground.sample_step=17", ok=False)
        assert r.returncode != 0 and "stages.ground.sample_step=17" in r.stderr
        r = _run(cli, scan, "--sensor", "vlp16", *fixed, "--set", "stages.ground.sample_step=0", ok=False)
        assert r.returncode != 0 and "LIDET_ERR_CONFIG" in r.stderr


def test_range_only_option_is_the_firmware_pixel(cli, tmp_path):
    """--fixed --range-only: the integer detector with the range-only pixel (lidet_detector_q_cfg_t.range_only),
    the integer firmware's; its detections are those of the bindings with range_only=True, bit for bit, and
    differ from the stored pixel's. Without --fixed the option is refused with a message."""
    from lidet_tools import native
    scan = ROOT / "tests" / "data" / "sim_vlp16" / "velodyne" / "000000.bin"
    out = tmp_path / "ro.txt"
    js = json.loads(_run(cli, scan, "--sensor", "vlp16", "--model", "vlp16s", "--fixed", "--range-only", "--json",
                         "--out", out).stdout)
    q = native.detect_q(native.to_mm(kitti.read_bin(scan)), "vlp16", model="vlp16s", range_only=True)
    assert js["detections"] == len(q["cls"]) > 0
    got = np.loadtxt(out, usecols=range(1, 8), ndmin=2)
    np.testing.assert_allclose(got[:, :6], q["boxes"][:, :6] / 1000.0, atol=1e-3)
    stored = json.loads(_run(cli, scan, "--sensor", "vlp16", "--model", "vlp16s", "--fixed", "--json").stdout)
    qs = native.detect_q(native.to_mm(kitti.read_bin(scan)), "vlp16", model="vlp16s", range_only=False)
    assert stored["detections"] == len(qs["cls"])
    assert [b["x"] for b in stored["boxes"]] != [b["x"] for b in js["boxes"]]
    r = _run(cli, scan, "--sensor", "vlp16", "--range-only", ok=False)
    assert r.returncode != 0 and "--range-only" in r.stderr and "--fixed" in r.stderr


def test_returns_option_feeds_the_sensors_returns(cli, tmp_path):
    """--fixed --ring R --returns: the scan converted to the sensor's returns (range, azimuth, ring) and fed to
    lidet_detector_q_run_returns, the integer firmware's way in; the detections are those of the bindings on the
    returns of ref.proj_q.returns_of_points. Without --fixed, or without the rings, the option is refused."""
    from lidet_ref import proj_q
    from lidet_tools import native
    sim = ROOT / "tests" / "data" / "sim_vlp16"
    scan, ring = sim / "velodyne" / "000000.bin", sim / "ring" / "000000.bin"
    out = tmp_path / "ret.txt"
    js = json.loads(_run(cli, scan, "--sensor", "vlp16", "--model", "vlp16s", "--fixed", "--range-only", "--ring", ring,
                         "--returns", "--json", "--out", out).stdout)
    rets = proj_q.returns_of_points(native.to_mm(kitti.read_bin(scan)), np.fromfile(ring, np.uint16))
    q = native.detect_q(None, "vlp16", model="vlp16s", range_only=True, returns=native.as_returns(*rets))
    assert js["detections"] == len(q["cls"]) > 0
    got = np.loadtxt(out, usecols=range(1, 8), ndmin=2)
    np.testing.assert_allclose(got[:, :6], q["boxes"][:, :6] / 1000.0, atol=1e-3)
    r = _run(cli, scan, "--sensor", "vlp16", "--ring", ring, "--returns", ok=False)
    assert r.returncode != 0 and "--returns" in r.stderr and "--fixed" in r.stderr
    r = _run(cli, scan, "--sensor", "vlp16", "--fixed", "--returns", ok=False)
    assert r.returncode != 0 and "--ring" in r.stderr
    r = subprocess.run([sys.executable, "-m", "lidet_tools.detect", str(tmp_path), "--out", str(tmp_path / "p"),
                        "--sensor", "vlp16", "--fixed", "--returns"], capture_output=True, text=True)
    assert r.returncode != 0 and "--ring" in r.stderr


def test_batch_script_firmware_options(cli, tmp_path):
    """python -m lidet_tools.detect --fixed --range-only --ring: each scan with its ring/<id>.bin, as the
    firmware's driver feeds it; the boxes are those of `lidet detect --fixed --range-only --ring` on the scan. A
    missing ring file and --range-only without --fixed are errors."""
    sim = ROOT / "tests" / "data" / "sim_vlp16"
    env = {**__import__("os").environ, "LIDET_BUILD_DIR": str(pathlib.Path(cli).parents[2])}
    kd = tmp_path / "kitti"
    for sub in ("velodyne", "ring"):
        (kd / sub).mkdir(parents=True)
        (kd / sub / "000000.bin").write_bytes((sim / sub / "000000.bin").read_bytes())
    args = ["--sensor", "vlp16", "--model", "vlp16s", "--fixed", "--range-only"]
    r = subprocess.run([sys.executable, "-m", "lidet_tools.detect", str(kd), "--out", str(tmp_path / "pred"),
                        "--ring", *args], capture_output=True, text=True, env=env)
    assert r.returncode == 0, r.stderr
    one = tmp_path / "one.txt"
    _run(cli, kd / "velodyne" / "000000.bin", *args, "--ring", kd / "ring" / "000000.bin", "--out", one)
    assert (tmp_path / "pred" / "boxes" / "000000.txt").read_text() == one.read_text() != ""
    # the ring file is read: one of the wrong length fails the frame with the CLI's message
    (kd / "ring" / "000000.bin").write_bytes((sim / "ring" / "000000.bin").read_bytes()[:-2])
    r = subprocess.run([sys.executable, "-m", "lidet_tools.detect", str(kd), "--out", str(tmp_path / "p1"),
                        "--ring", *args], capture_output=True, text=True, env=env)
    assert r.returncode == 1 and "ring file" in r.stderr
    (kd / "ring" / "000000.bin").unlink()
    r = subprocess.run([sys.executable, "-m", "lidet_tools.detect", str(kd), "--out", str(tmp_path / "p2"),
                        "--ring", *args], capture_output=True, text=True, env=env)
    assert r.returncode == 1 and "ring" in r.stderr and "missing" in r.stderr
    r = subprocess.run([sys.executable, "-m", "lidet_tools.detect", str(kd), "--out", str(tmp_path / "p3"),
                        "--range-only"], capture_output=True, text=True, env=env)
    assert r.returncode != 0 and "--fixed" in r.stderr


def test_fixed_dump_is_the_integer_run(cli, tmp_path):
    """--fixed --dump: the integer detector's per-point labels, outcomes, counts and detections in integer units
    (cli_detect_q_dump in ports/host/cli_detect_q.c); the same bytes on a second run, the same counts and boxes
    as --json (which converts them to metres, nats and [0, 1])."""
    scan = ROOT / "tests" / "data" / "sim_vlp16" / "velodyne" / "000000.bin"
    dumps = []
    for k in range(2):
        r = _run(cli, scan, "--sensor", "vlp16", "--fixed", "--json", "--dump", tmp_path / f"q{k}.bin")
        dumps.append((tmp_path / f"q{k}.bin").read_bytes())
    js = json.loads(r.stdout)
    b = dumps[0]
    assert b == dumps[1] and b[:4] == b"LDTQ"
    n, n_cl, n_det = np.frombuffer(b, "<u4", 3, 4)
    assert n == js["points"] == len(kitti.read_bin(scan)) and n_det == js["detections"] > 0
    off = 16
    pts = np.frombuffer(b, np.dtype([("id", "<u4"), ("g", "u1")]), int(n), off)
    off += int(n) * 5
    outcome = np.frombuffer(b, "<u4", int(n_cl), off)
    off += int(n_cl) * 4
    counts = np.frombuffer(b, "<u4", 14, off)
    off += 14 * 4
    det = np.frombuffer(b, np.dtype([("u", "<u4", 3), ("i", "<i4", 10)]), int(n_det), off)
    assert off + int(n_det) * 52 == len(b)
    assert pts["id"].max() > 0 and 0 < pts["g"].sum() < n and len(outcome) == n_cl
    assert list(counts[[0, 4, 5, 6, 11]]) == [js[k] for k in ("clusters", "classified", "gate1_rejected", "boxed",
                                                               "detections")]
    for d, box in zip(det, js["boxes"]):
        assert d["u"][1] == box["cluster"] and d["u"][2] == box["cluster_points"]
        assert round(d["i"][0] / 32768.0, 5) == box["score"]
        assert [round(float(v) / 1000.0, 4) for v in d["i"][3:9]] == [box[k] for k in ("x", "y", "z", "l", "w", "h")]


def test_regrow_cut_reaches_both_detectors(cli):
    """`--set stages.cluster.regrow_cut_m=M` (off by default) reaches the float clustering and, as regrow_cut_mm,
    the integer one: with a small extent limit (many components regrown) a high cut changes the clusters of both, 0
    is the default run, and values outside [0, 2] m are refused."""
    small = ("--set", "stages.cluster.max_extent_m=3")
    for fixed in ((), ("--fixed",)):
        base = json.loads(_run(cli, SCAN, "--json", *fixed, *small).stdout)
        off = json.loads(_run(cli, SCAN, "--json", *fixed, *small, "--set", "stages.cluster.regrow_cut_m=0").stdout)
        cut = json.loads(_run(cli, SCAN, "--json", *fixed, *small, "--set", "stages.cluster.regrow_cut_m=1").stdout)
        assert off["boxes"] == base["boxes"] and off["clusters"] == base["clusters"]
        assert cut["clusters"] != base["clusters"]
        r = _run(cli, SCAN, "--json", *fixed, "--set", "stages.cluster.regrow_cut_m=2.5", ok=False)
        assert r.returncode != 0 and r.stderr.strip()


def test_a_cloud_in_another_frame_is_named(cli, tmp_path):
    """A cloud that is not in lidet's frame (x forward, y left, z up, metres) is detected on as given, but the
    commands that project it say what looks wrong: the simulated HDL-64 scan turned upside down (y and z negated)
    or into a camera's frame (x right, y down, z forward) leaves many points outside the sensor's beams, the same
    scan in millimetres lies beyond the range the image keeps; the scan as simulated, or run on a sensor whose
    beams hold it, draws no warning."""
    p = np.fromfile(SCAN, np.float32).reshape(-1, 4)
    flip, cam, mm = p.copy(), p.copy(), p.copy()
    flip[:, 1:3] *= -1.0
    cam[:, 0], cam[:, 1], cam[:, 2] = -p[:, 1], -p[:, 2], p[:, 0]
    mm[:, :3] *= 1000.0
    files = {}
    for name, a in (("flip", flip), ("cam", cam), ("mm", mm)):
        files[name] = tmp_path / f"{name}.bin"
        a.astype(np.float32).tofile(files[name])
    beams = "lie outside the hdl64's beams"
    for extra in ((), ("--fixed",)):
        assert "warning" not in _run(cli, SCAN, "--sensor", "hdl64", *extra).stderr
        for name in ("flip", "cam"):
            r = _run(cli, files[name], "--sensor", "hdl64", "--json", *extra)
            assert beams in r.stderr and "x forward, y left, z up" in r.stderr, (name, extra, r.stderr)
            n_in, n_all = (int(v) for v in r.stderr.split(beams)[0].split(":")[-1].split("points")[0].split(" of "))
            assert n_all == len(p) and n_in > len(p) // 10, (name, n_in)
            json.loads(r.stdout)  # the run itself goes on
        r = _run(cli, files["mm"], "--sensor", "hdl64", *extra)
        assert "lie beyond the range the image keeps: are the coordinates in metres?" in r.stderr, (extra, r.stderr)
    for cmd in ("project", "ground", "cluster"):
        r = subprocess.run([str(cli), cmd, str(files["flip"]), "--sensor", "hdl64"], capture_output=True, text=True)
        assert r.returncode == 0 and f"lidet {cmd}: warning:" in r.stderr and beams in r.stderr, (cmd, r.stderr)
        r = subprocess.run([str(cli), cmd, str(SCAN), "--sensor", "hdl64"], capture_output=True, text=True)
        assert r.returncode == 0 and "warning" not in r.stderr, (cmd, r.stderr)
    # a sequence: named once, with the scan
    r = subprocess.run([str(cli), "track", str(files["flip"]), str(files["flip"]), "--sensor", "hdl64"],
                       capture_output=True, text=True)
    assert r.returncode == 0 and r.stderr.count(beams) == 1 and f"lidet track: warning: {files['flip']}:" in r.stderr
