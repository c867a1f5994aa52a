# SPDX-License-Identifier: MIT
"""`lidet detect / track --pcap` on HDL-64E captures and with a unit's calibration (ports/host/cli_pcap.c,
cli_velodyne_calib.c; docs/CAPTURES.md, "From a capture"): no real HDL-64E capture is available, so the capture is
written here: lidet_tools.velodyne.hdl64e_packets turning 0.18 deg a firing over the simulated HDL-64 scan of
tests/data/sim_hdl64 (moved 0.3 m a rotation), with a position packet and an ARP frame between.

- `--sensor hdl64` and AUTO (the payloads' 0xDDFF flags) decode it into the hdl64 preset, rings from the top: per
  complete rotation `--fixed` gives native.detect_q(returns=...) on the bindings' decoding (velodyne.decode with
  ring_top_first), the float run the x, y, z and rings of that decoding (--save-scans, bit for bit) and the lines of
  `lidet detect` on them; `lidet track --pcap` runs the same rotations.
- `--velodyne-calib C --sensor hdl64` (a YAML and the same unit as db.xml, written here: rotational and distance
  corrections on some lasers, one laser's elevation moved above its neighbour's) gives the decoder the calibration:
  the returns are velodyne.decode(..., calibration=...)'s bit for bit (rings by the calibration's elevations), the
  detector projects with the calibration's table; the same for a VLP-16 capture with the VLP-16 calibrations of
  tests/data/sensors.
- `--print-sensor` with `--pcap` prints the sensor the capture is decoded as (the packets' model, the calibration).
- The refusals: a calibration without --sensor, and velodyne.calibration_table's own messages (laser count, laser
  ids, distance resolution, distance correction), word for word."""
import math
import pathlib
import re
import subprocess

import numpy as np
import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
SIM64 = ROOT / "tests" / "data" / "sim_hdl64"
SIM16 = ROOT / "tests" / "data" / "sim_vlp16"
SENSOR_DATA = ROOT / "tests" / "data" / "sensors"
CLASSES = ("Car", "Cyclist", "Pedestrian")
START64 = 34992       # 10.08 deg before the seam: the first 56 firings are a partial scan
N_PK = 1100           # 6600 firings: a partial scan, 3 complete rotations (2000 firings each), 544 unfinished
N_ROT = 3
SHIFT_M = 0.3         # the scene moves +x this much a rotation
# the calibration's corrections (laser id: value): rotational (0.01 deg), distance (mm), elevation (mdeg, moved)
ROT_CDEG = {5: 250, 40: -125, 63: 1000}
DIST_MM = {7: 300, 33: -120, 40: 45}
VERT_MOVE_MDEG = {38: 600}  # laser 38 (the lowest beam, -24.333 deg) moved above laser 39 (-23.833): rings swap


def _run(cli, *args, ok=True):
    r = subprocess.run([str(cli), *map(str, args)], capture_output=True, text=True)
    if ok:
        assert r.returncode == 0, r.stderr
    assert r.returncode in (0, 1), (r.returncode, r.stderr)  # never a crash
    return r


HEADER = re.compile(r"# scan (\d+): (\d+) returns, (\d+) detections, packets (\d+)\.\.(\d+)")


def _scans(out):
    """stdout of detect --pcap: [{'k', 'returns', 'n_det', 'cls', 'boxes' (n, 8), 'lines'}]"""
    scans = []
    for line in out.splitlines():
        m = HEADER.match(line)
        if m:
            scans.append(dict(k=int(m.group(1)), returns=int(m.group(2)), n_det=int(m.group(3)), cls=[], boxes=[],
                              lines=[]))
            continue
        scans[-1]["cls"].append(CLASSES.index(line.split()[0]))
        scans[-1]["boxes"].append([float(x) for x in line.split()[1:]])
        scans[-1]["lines"].append(line)
    for s in scans:
        s["boxes"] = np.array(s["boxes"]).reshape(-1, 8)
    return scans


def _decoder_line(err):
    m = re.search(r"decoder velodyne (\S+) \(([^)]*)\): (\d+) packets: (\d+) decoded, (\d+) rejected", err)
    assert m, err
    return m.group(1), m.group(2), int(m.group(4)), int(m.group(5))


@pytest.fixture(scope="module")
def vd(need_lib):
    from lidet_tools import native, velodyne
    if not hasattr(native.lib(), "lidet_velodyne_decoder_xyz"):
        pytest.skip("liblidet_py.so predates the HDL-64E decoder: rebuild")
    return velodyne


@pytest.fixture(scope="module")
def ccli(pcli):
    """The CLI, when it reads both calibration formats (libxml2, libyaml)."""
    pytest.importorskip("yaml", reason="PyYAML (requirements.txt) reads the YAML calibrations")
    pytest.importorskip("defusedxml", reason="defusedxml (requirements.txt) reads the XML calibrations")
    for f in ("vlp16_db.xml", "vlp16.yaml"):
        r = subprocess.run([str(pcli), "project", "--velodyne-calib", str(SENSOR_DATA / f), "--print-sensor"],
                           capture_output=True, text=True)
        if r.returncode != 0 and "built without" in r.stderr:
            pytest.skip("the CLI was built without libxml2 / libyaml: " + r.stderr.strip())
    return pcli


def _sim64():
    from lidet_tools.sim import read_ring
    pts = np.fromfile(SIM64 / "velodyne" / "000000.bin", dtype="<f4").reshape(-1, 4)
    return pts, read_ring(SIM64 / "ring" / "000000.bin").astype(np.int64)


def _frames(vd, payloads):
    frames = []
    for i, p in enumerate(payloads):
        frames.append(vd.udp_frame(p))
        if i == 10:
            frames.append(vd.udp_frame(bytes(512), dport=8308))  # a position packet
        if i == 20:
            frames.append(b"\xff" * 6 + b"\x00" * 6 + b"\x08\x06" + bytes(28))  # ARP
    return frames


# ---- the unit's calibration, written here in both formats ----------------------------------------------------------

def _unit(vd):
    """Per laser id: elevation (mdeg; the nominal table, one laser moved), rotational (0.01 deg) and distance (mm)
    corrections."""
    vert = np.array(vd.HDL64E_ELEV_MDEG)[list(vd.HDL64E_LASER_RING)]
    for k, v in VERT_MOVE_MDEG.items():
        vert[k] += v
    rot, dist = np.zeros(64, np.int64), np.zeros(64, np.int64)
    for k, v in ROT_CDEG.items():
        rot[k] = v
    for k, v in DIST_MM.items():
        dist[k] = v
    return vert, rot, dist


def _yaml(path, vert, rot, dist, res="0.002", extra=None):
    """velodyne_pointcloud's YAML (radians, metres), lasers listed from the last id to the first."""
    lines = [f"num_lasers: {len(vert)}", f"distance_resolution: {res}", "lasers:"]
    for i in reversed(range(len(vert))):
        lines.append(f"- {{laser_id: {i}, vert_correction: {math.radians(vert[i] / 1000.0)!r}, "
                     f"rot_correction: {math.radians(rot[i] / 100.0)!r}, "
                     f"dist_correction: {float(dist[i]) / 1000.0!r}{extra or ''}}}")
    path.write_text("\n".join(lines) + "\n")
    return path


def _db_xml(path, vert, rot, dist, enabled=None, dist_lsb="0.2"):
    """Velodyne's db.xml (degrees, centimetres) listing every laser of vert; enabled: the enabled_ flags (None:
    none given, every laser)."""
    ids = range(len(vert))
    out = ['<?xml version="1.0"?>', '<boost_serialization signature="serialization::archive" version="4">', "<DB>",
           f"<distLSB_>{dist_lsb}</distLSB_>"]
    if enabled is not None:
        out.append(f"<enabled_><count>{len(enabled)}</count>" + "".join(f"<item>{e}</item>" for e in enabled) +
                   "</enabled_>")
    out.append(f"<points_><count>{len(ids)}</count><item_version>1</item_version>")
    for i in ids:
        out.append(f"<item><px><id_>{i}</id_><rotCorrection_>{float(rot[i]) / 100.0!r}</rotCorrection_>"
                   f"<vertCorrection_>{float(vert[i]) / 1000.0!r}</vertCorrection_>"
                   f"<distCorrection_>{float(dist[i]) / 10.0!r}</distCorrection_></px></item>")
    out += ["</points_></DB>", "</boost_serialization>"]
    path.write_text("\n".join(out) + "\n")
    return path


class H64:
    """The capture of the simulated scene (nominal lasers), and one of the calibrated unit seeing the same scene."""

    def __init__(self, vd, folder):
        pts, ring = _sim64()
        self.grids = []
        for r in range(N_ROT + 2):
            p = pts.copy()
            p[:, 0] += SHIFT_M * r
            self.grids.append(vd.hdl64e_grid(p, ring))
        self.payloads = [p for _, p in vd.hdl64e_packets(self.grids, N_PK, start_cdeg=START64)]
        self.path = folder / "hdl64e.pcap"
        vd.write_pcap(self.path, _frames(vd, self.payloads))
        self.d = vd.decode(self.payloads, ring_top_first=True)
        kinds = self.d.scan_kinds()
        self.complete = [s for s, k in enumerate(kinds) if k == vd.SCAN_COMPLETE]
        assert len(self.complete) == N_ROT
        # the calibrated unit: its files, the Sensor Python reads, and its payloads (laser l sees the scene's ring of
        # its elevation order: the calibration's ring, numbered from the top for the simulator)
        from lidet_tools import sensors
        vert, rot, dist = _unit(vd)
        self.yaml = _yaml(folder / "unit.yaml", vert, rot, dist)
        self.xml = _db_xml(folder / "unit_db.xml", vert, rot, dist)
        self.cal = sensors.load_velodyne_calibration(self.yaml)
        np.testing.assert_array_equal(vd.calibration_table(self.cal, "hdl64e"), np.stack([vert, rot, dist], 1))
        ring_of = np.empty(64, np.int64)
        ring_of[np.asarray(self.cal.velodyne.laser_id)] = np.arange(64)
        assert (ring_of != np.array(vd.HDL64E_LASER_RING)).sum() == 2  # lasers 38 and 39 swapped
        self.cal_payloads = [p for _, p in vd.hdl64e_packets(self.grids, N_PK, start_cdeg=START64,
                                                             laser_ring=63 - ring_of, dist_corr_mm=dist)]
        self.cal_path = folder / "hdl64e_unit.pcap"
        vd.write_pcap(self.cal_path, _frames(vd, self.cal_payloads))
        self.dc = vd.decode(self.cal_payloads, model="hdl64e", calibration=self.cal)
        self.dn = vd.decode(self.cal_payloads, model="hdl64e", ring_top_first=True)  # the unit without calibration

    @staticmethod
    def returns(d, s):
        from lidet_tools import native
        sel = d.scan == s
        return native.as_returns(d.range_mm[sel], d.azimuth[sel], d.ring[sel])


@pytest.fixture(scope="module")
def h64(vd, tmp_path_factory):
    return H64(vd, tmp_path_factory.mktemp("hdl64e"))


def _saved(folder, k):
    p = np.fromfile(folder / "velodyne" / f"{k:06d}.bin", np.float32).reshape(-1, 4)
    return p, np.fromfile(folder / "ring" / f"{k:06d}.bin", np.uint16)


# ---- HDL-64E: --sensor hdl64 and AUTO -------------------------------------------------------------------------------

def test_hdl64e_fixed_is_the_bindings(pcli, h64):
    """--fixed: per complete rotation the integer detector with the hdl64 preset on the decoder's returns, rings from
    the top: native.detect_q(returns=...) on velodyne.decode(ring_top_first=True) of the same payloads; AUTO (no
    --sensor: the 0xDDFF flags) gives the same lines and the same summary."""
    from lidet_tools import native
    r = _run(pcli, "detect", "--pcap", h64.path, "--sensor", "hdl64", "--fixed")
    assert _decoder_line(r.stderr) == ("hdl64", "single return", N_PK, 0)
    assert re.search(rf"scans: {N_ROT} complete; skipped: 1 partial", r.stderr)
    scans = _scans(r.stdout)
    assert len(scans) == N_ROT
    n_boxes = 0
    for k, s in enumerate(h64.complete):
        rets = h64.returns(h64.d, s)
        assert scans[k]["returns"] == len(rets)
        q = native.detect_q(None, "hdl64", returns=rets)
        assert scans[k]["cls"] == [int(c) for c in q["cls"]]
        np.testing.assert_allclose(scans[k]["boxes"][:, :6], q["boxes"][:, :6] / 1000.0, rtol=0, atol=6e-5)
        np.testing.assert_allclose(scans[k]["boxes"][:, 7], q["score_q15"] / 32768.0, rtol=0, atol=6e-5)
        n_boxes += len(q["cls"])
    assert n_boxes >= 5 * N_ROT  # the scene's road users, every rotation
    auto = _run(pcli, "detect", "--pcap", h64.path, "--fixed")
    assert auto.stdout == r.stdout
    assert _decoder_line(auto.stderr) == ("hdl64", "single return", N_PK, 0)


def test_hdl64e_float_is_detect_on_the_points(pcli, h64, tmp_path):
    """Float: the x, y, z the detector gets (--save-scans) are the bindings' (lidet_velodyne_decoder_xyz: the nominal
    elevations, rings from the top) bit for bit, with their rings; the lines are `lidet detect SCAN --ring RING
    --sensor hdl64` on them."""
    from lidet_tools import kitti
    r = _run(pcli, "detect", "--pcap", h64.path, "--save-scans", tmp_path / "s", "--out", tmp_path / "out")
    scans = _scans(r.stdout)
    assert len(scans) == N_ROT and sum(s["n_det"] for s in scans) >= 5 * N_ROT
    for k, s in enumerate(h64.complete):
        sel = h64.d.scan == s
        pts, ring = _saved(tmp_path / "s", k)
        np.testing.assert_array_equal(pts[:, :3], h64.d.xyz[sel])
        np.testing.assert_array_equal(ring, h64.d.ring[sel])
        assert ring.max() == 63 and (pts[:, 3] == 0).all()
        if k == 0:
            kitti.write_bin(tmp_path / "scan.bin", np.column_stack([h64.d.xyz[sel], np.zeros(sel.sum(), np.float32)]))
            h64.d.ring[sel].astype(np.uint16).tofile(tmp_path / "ring.bin")
            _run(pcli, "detect", tmp_path / "scan.bin", "--ring", tmp_path / "ring.bin", "--sensor", "hdl64", "--out",
                 tmp_path / "one.txt")
            assert (tmp_path / "out" / "000000.txt").read_text() == (tmp_path / "one.txt").read_text()


def test_hdl64e_track(pcli, h64):
    """lidet track --pcap: the complete rotations in order (AUTO), float and --fixed; dt from the payloads' clock
    (288 us a packet, 2000 firings a rotation: 0.096 s)."""
    for opt in ([], ["--fixed"]):
        r = _run(pcli, "track", "--pcap", h64.path, *opt)
        heads = [line for line in r.stdout.splitlines() if line.startswith("# frame")]
        assert [h.split()[2] for h in heads] == [str(k) for k in range(N_ROT)]
        assert "decoder velodyne hdl64 (single return)" in r.stderr
        assert len([x for x in r.stdout.splitlines() if not x.startswith("#")]) >= 5


# ---- --velodyne-calib: the unit's calibration to the decoder ----------------------------------------------------------

def test_calibration_applied_as_the_bindings(ccli, vd, h64, tmp_path):
    """--velodyne-calib C --sensor hdl64: every complete rotation's returns are velodyne.decode(model="hdl64e",
    calibration=...)'s (the x, y, z and rings the detector gets, bit for bit: rings by the calibration's elevations,
    lowest first, the description's order), so the corrected lasers' ranges and azimuths move exactly as there; the
    same from the db.xml of the unit; the detector projects with the calibration's table (`lidet detect SCAN --ring
    RING --velodyne-calib C` gives the same lines)."""
    from lidet_tools import kitti
    # the corrections move these lasers' returns, and only theirs (the bindings, with and without the calibration)
    laser_of_ring = np.asarray(h64.cal.velodyne.laser_id)
    lc = laser_of_ring[h64.dc.ring]
    ln = np.argsort(vd.HDL64E_LASER_RING)[63 - h64.dn.ring]  # laser of each nominal ring (ring = 63 - nominal)
    assert len(lc) == len(ln) and (lc == ln).all()
    dr = h64.dc.range_mm.astype(np.int64) - h64.dn.range_mm.astype(np.int64)
    for laser in range(64):
        sel = lc == laser
        assert (dr[sel] == DIST_MM.get(laser, 0)).all(), laser
    moved = np.isin(lc, list(ROT_CDEG))
    assert (h64.dc.azimuth_cdeg[~moved] == h64.dn.azimuth_cdeg[~moved]).all()
    assert (h64.dc.azimuth_cdeg[moved] != h64.dn.azimuth_cdeg[moved]).mean() > 0.99
    kinds = h64.dc.scan_kinds()
    complete = [s for s, k in enumerate(kinds) if k == vd.SCAN_COMPLETE]
    assert len(complete) == N_ROT
    outs = {}
    for name, calib in (("yaml", h64.yaml), ("xml", h64.xml)):
        r = _run(ccli, "detect", "--pcap", h64.cal_path, "--sensor", "hdl64", "--velodyne-calib", calib,
                 "--save-scans", tmp_path / name, "--out", tmp_path / f"out_{name}")
        assert re.search(r"decoder velodyne hdl64 \(single return, calibration \S+\): %d packets: %d decoded, 0 "
                         r"rejected" % (N_PK, N_PK), r.stderr), r.stderr
        assert "0 returns the distance correction left at or below 0 m dropped" in r.stderr
        scans = _scans(r.stdout)
        assert len(scans) == N_ROT and sum(s["n_det"] for s in scans) >= 5 * N_ROT
        for k, s in enumerate(complete):
            sel = h64.dc.scan == s
            pts, ring = _saved(tmp_path / name, k)
            assert scans[k]["returns"] == sel.sum()
            np.testing.assert_array_equal(ring, h64.dc.ring[sel])
            np.testing.assert_array_equal(pts[:, :3], h64.dc.xyz[sel])
        outs[name] = r.stdout
    # the detector: the calibration's sensor (its table, lowest beam first) on those points
    sel = h64.dc.scan == complete[1]
    kitti.write_bin(tmp_path / "scan.bin", np.column_stack([h64.dc.xyz[sel], np.zeros(sel.sum(), np.float32)]))
    h64.dc.ring[sel].astype(np.uint16).tofile(tmp_path / "ring.bin")
    _run(ccli, "detect", tmp_path / "scan.bin", "--ring", tmp_path / "ring.bin", "--velodyne-calib", h64.yaml,
         "--out", tmp_path / "one.txt")
    assert (tmp_path / "out_yaml" / "000001.txt").read_text() == (tmp_path / "one.txt").read_text()
    # --fixed: the integer detector on the same returns with the calibration's integer profile; track runs them
    r = _run(ccli, "detect", "--pcap", h64.cal_path, "--sensor", "hdl64", "--velodyne-calib", h64.yaml, "--fixed")
    fixed = _scans(r.stdout)
    assert [s["returns"] for s in fixed] == [int((h64.dc.scan == s).sum()) for s in complete]
    assert sum(s["n_det"] for s in fixed) >= 5 * N_ROT
    r = _run(ccli, "track", "--pcap", h64.cal_path, "--sensor", "hdl64", "--velodyne-calib", h64.xml, "--fixed")
    assert len([h for h in r.stdout.splitlines() if h.startswith("# frame")]) == N_ROT


def test_vlp16_calibration_files(ccli, vd, tmp_path):
    """A VLP-16 capture with the VLP-16 calibrations of tests/data/sensors (db.xml and YAML, invented rotational and
    distance corrections): the returns of velodyne.decode(model="vlp16", calibration=...) bit for bit."""
    from lidet_tools import kitti, sensors
    pts = kitti.read_bin(SIM16 / "velodyne" / "000000.bin")
    ring = np.fromfile(SIM16 / "ring" / "000000.bin", np.uint16)
    grid = vd.vlp16_grid(pts, ring)
    pay = [p for _, p in vd.vlp16_packets([grid], 250, start_cdeg=18000)]  # half a turn, 2 turns, the rest
    vd.write_pcap(tmp_path / "vlp16.pcap", [vd.udp_frame(p) for p in pay])
    for f in ("vlp16_db.xml", "vlp16.yaml"):
        cal = sensors.load_velodyne_calibration(SENSOR_DATA / f)
        d = vd.decode(pay, model="vlp16", calibration=cal)
        complete = [s for s, k in enumerate(d.scan_kinds()) if k == vd.SCAN_COMPLETE]
        assert len(complete) == 2
        r = _run(ccli, "detect", "--pcap", tmp_path / "vlp16.pcap", "--sensor", "vlp16", "--velodyne-calib",
                 SENSOR_DATA / f, "--save-scans", tmp_path / f)
        assert "decoder velodyne vlp16 (strongest return, calibration" in r.stderr
        for k, s in enumerate(complete):
            sel = d.scan == s
            p, rg = _saved(tmp_path / f, k)
            np.testing.assert_array_equal(rg, d.ring[sel])
            np.testing.assert_array_equal(p[:, :3], d.xyz[sel])


# ---- --print-sensor with --pcap ---------------------------------------------------------------------------------------

def test_print_sensor_is_the_decoded_sensor(pcli, vd, h64, tmp_path):
    """--print-sensor with --pcap prints the sensor the capture is decoded as: the packets' model (AUTO), --sensor's,
    with --mount-height; detect and track alike; a capture the decoder takes nothing of is refused."""
    hdl64 = _run(pcli, "project", "--sensor", "hdl64", "--print-sensor").stdout
    vlp16 = _run(pcli, "project", "--sensor", "vlp16", "--print-sensor").stdout
    assert hdl64 != vlp16
    for cmd in ("detect", "track"):
        assert _run(pcli, cmd, "--pcap", h64.path, "--print-sensor").stdout == hdl64
        assert _run(pcli, cmd, "--pcap", h64.path, "--sensor", "hdl64", "--print-sensor").stdout == hdl64
    want = _run(pcli, "project", "--sensor", "hdl64", "--mount-height", "2.25", "--print-sensor").stdout
    assert _run(pcli, "detect", "--pcap", h64.path, "--mount-height", "2.25", "--print-sensor").stdout == want
    # a VLP-16 capture: the vlp16 preset (the default sensor, hdl64, is not what it is decoded as)
    pts = np.fromfile(SIM16 / "velodyne" / "000000.bin", np.float32).reshape(-1, 4)
    grid = vd.vlp16_grid(pts, np.fromfile(SIM16 / "ring" / "000000.bin", np.uint16))
    vd.write_pcap(tmp_path / "vlp16.pcap", [vd.udp_frame(p) for _, p in vd.vlp16_packets([grid], 40)])
    for cmd in ("detect", "track"):
        assert _run(pcli, cmd, "--pcap", tmp_path / "vlp16.pcap", "--print-sensor").stdout == vlp16
    r = _run(pcli, "detect", "--pcap", tmp_path / "vlp16.pcap", "--sensor", "hdl64", "--print-sensor", ok=False)
    assert r.returncode == 1 and r.stdout == "" and "of the model of --sensor hdl64" in r.stderr


def test_print_sensor_with_calibration(ccli, h64):
    """With --velodyne-calib: the calibration's description (its table, lowest beam first), as `lidet project
    --velodyne-calib C --print-sensor` and sensors.description_json print it."""
    from lidet_tools import sensors
    want = _run(ccli, "project", "--velodyne-calib", h64.yaml, "--print-sensor").stdout
    assert want == sensors.description_json(h64.cal)
    for cmd in ("detect", "track"):
        r = _run(ccli, cmd, "--pcap", h64.cal_path, "--sensor", "hdl64", "--velodyne-calib", h64.yaml,
                 "--print-sensor")
        assert r.stdout == want


# ---- refusals -------------------------------------------------------------------------------------------------------

def _table_error(vd, path, model):
    from lidet_tools import sensors
    with pytest.raises(ValueError) as e:
        vd.calibration_table(sensors.load_velodyne_calibration(path), model)
    return str(e.value)


def test_calibration_refusals(ccli, vd, h64, tmp_path):
    """A calibration needs --sensor (the model); one that does not fit the model is refused with
    velodyne.calibration_table's message, word for word: another number of lasers, laser ids other than 0 .. n-1
    (a db.xml enabling 32 of its 64 lasers, not the first 32), a distance resolution other than the packets' unit
    (VLP-32C: 4 mm), a distance correction beyond +-32.767 m. --sensor with --velodyne-calib stays refused for scan
    files."""
    vert, rot, dist = _unit(vd)
    cases = []
    cases.append((SENSOR_DATA / "vlp16.yaml", "hdl64", "hdl64e"))
    cases.append((SENSOR_DATA / "vlp16.yaml", "vlp32c", "vlp32c"))
    en = ["1", "0"] * 32  # lasers 0, 2, .., 62 enabled: 32 lasers, not ids 0 .. 31
    cases.append((_db_xml(tmp_path / "odd.xml", vert, rot, dist, enabled=en), "hdl32", "hdl32e"))
    cases.append((_yaml(tmp_path / "res.yaml", vert, rot, dist, res="0.004"), "hdl64", "hdl64e"))
    cases.append((_db_xml(tmp_path / "res.xml", vert, rot, dist, dist_lsb="0.1"), "hdl64", "hdl64e"))
    far = dist.copy()
    far[12] = 40000
    cases.append((_yaml(tmp_path / "far.yaml", vert, rot, far), "hdl64", "hdl64e"))
    # a VLP-32C's packets count 4 mm: a 2 mm calibration of 32 lasers does not fit it
    cases.append((SENSOR_DATA / "hdl32e.yaml", "vlp32c", "vlp32c"))
    msgs = set()
    for path, sensor, model in cases:
        msg = _table_error(vd, path, model)
        msgs.add(msg.split(" ")[1])
        r = _run(ccli, "detect", "--pcap", h64.path, "--sensor", sensor, "--velodyne-calib", path, ok=False)
        assert r.returncode == 1 and r.stdout == "", r.stderr
        assert f"lidet detect: {path}: {msg} (--sensor {sensor})" in r.stderr, (msg, r.stderr)
    assert msgs == {"16", "the", "distance", "a"}  # the laser count, the ids, the resolution, the correction
    r = _run(ccli, "detect", "--pcap", h64.path, "--velodyne-calib", h64.yaml, ok=False)
    assert r.returncode == 1 and "--velodyne-calib with --pcap needs --sensor" in r.stderr
    r = _run(ccli, "track", "--pcap", h64.path, "--velodyne-calib", h64.yaml, "--print-sensor", ok=False)
    assert r.returncode == 1 and "needs --sensor" in r.stderr and r.stdout == ""
    r = _run(ccli, "detect", SIM64 / "velodyne" / "000000.bin", "--sensor", "hdl64", "--velodyne-calib", h64.yaml,
             ok=False)
    assert r.returncode == 1 and "give one of --sensor" in r.stderr
    # the calibrated capture decoded as another model: refused by the decoder (product), said
    r = _run(ccli, "detect", "--pcap", h64.cal_path, "--sensor", "vlp16", "--velodyne-calib", SENSOR_DATA / "vlp16.yaml",
             ok=False)
    assert r.returncode == 1 and "of the model of --sensor vlp16" in r.stderr
