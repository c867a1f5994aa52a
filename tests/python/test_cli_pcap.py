# SPDX-License-Identifier: MIT
"""`lidet detect --pcap FILE` and `lidet track --pcap FILE` (ports/host/cli_pcap.c; docs/CAPTURES.md, "From a capture:
lidet detect --pcap"): a packet capture read with libpcap, the UDP datagrams to the Velodyne data port decoded
(lib/src/decode/lidet_velodyne.c), the detector run on every complete rotation.

Always run (they need the CLI built with libpcap and the bindings): a capture written here with Python's struct, of
synthetic VLP-16 packets (lidet_tools.velodyne.vlp16_packets) turning over the simulated VLP-16 scan, which moves
0.4 m a rotation, interleaved with frames the reader must skip and count (ARP, IPv6, another port, an IPv4
fragment, a frame the capture cut short, one whose IPv4 length is wrong, a VLAN tag, two payloads the decoder
rejects); the payloads' clock is 2.654 ms a packet (a rotation in 0.2 s) and wraps at the hour inside the capture,
the capture's own timestamps are 1 ms apart. On it: per complete rotation the boxes are those of the bindings on the
same decoded returns (--fixed: native.detect_q(returns=...); float: `lidet detect` on their x, y, z with their
rings); `lidet track --pcap --fixed` is the integer detector + tracker with dt from the payloads' timestamps; the
counts of the summary; outputs (--out DIR, --json, --png); link types; a scan past LIDET_MAX_POINTS; random frames;
bad files. The real captures of ../shared/data/packets/velodyne (skipped when absent) decode into the expected
number of complete scans. Ouster (--lidar ouster --ouster-meta M): a made-up 16-beam capture (always run) and
ouster-sdk's five test captures of ../shared/data/packets/ouster: one complete frame each, the bindings' returns, the
float run equal to `lidet detect` on the points it saves (--save-scans).
"""
import json
import os
import pathlib
import re
import struct
import subprocess

import numpy as np
import pytest
from PIL import Image

ROOT = pathlib.Path(__file__).resolve().parents[2]
PACKETS = pathlib.Path(os.environ.get("LIDET_PACKET_DATA", ROOT.parent / "shared" / "data" / "packets")) / "velodyne"
SIM = ROOT / "tests" / "data" / "sim_vlp16"
CLASSES = ("Car", "Cyclist", "Pedestrian")

START_CDEG = 18000            # the capture begins half a rotation before the seam
N_ROT = 6                     # complete rotations (75 packets each)
N_DATA = 38 + 75 * N_ROT + 10
PACKET_US = 2654              # the payloads' clock: a rotation in 0.19905 s
T0_US = 3_600_000_000 - 500_000  # half a second before the hour: the payload timestamps wrap
SHIFT_M = 0.4                 # the scene moves +x by this much a rotation


# ---- helpers ---------------------------------------------------------------------------------------------------


def _run(cli, *args, ok=True):
    r = subprocess.run([str(cli), *map(str, args)], capture_output=True, text=True)
    if ok:
        assert r.returncode == 0, r.stderr
    assert r.returncode in (0, 1), (r.returncode, r.stderr)  # never a crash (a signal: negative)
    return r


def _summary(err):
    """The stderr summary as numbers."""
    s = {}
    m = re.search(r"(\d+) frames: (\d+) UDP to port \d+, (\d+) UDP to other ports, (\d+) not UDP over IPv4, (\d+) "
                  r"truncated, (\d+) malformed, (\d+) IPv4 fragments", err)
    if m:
        s.update(zip(("frames", "port", "other_port", "not_udp", "truncated", "malformed", "fragments"),
                     map(int, m.groups())))
    m = re.search(r"(\d+) packets: (\d+) decoded, (\d+) rejected \(size (\d+), product (\d+), mode (\d+), flag (\d+), "
                  r"azimuth (\d+), unsupported (\d+)\); (\d+) azimuth jumps; (\d+) returns between", err)
    if m:
        s.update(zip(("packets", "decoded", "rejected", "size", "product", "mode", "flag", "azimuth", "unsupported",
                      "jumps", "fragment_returns"), map(int, m.groups())))
    m = re.search(r"scans: (\d+) complete; (?:skipped|also run): (\d+) partial .*?, (\d+) aborted .*?, (\d+) unfinished "
                  r"at the end \((\d+) returns\); (\d+) returns past LIDET_MAX_POINTS \((\d+)\) dropped in (\d+) scans",
                  err)
    if m:
        s.update(zip(("complete", "partial", "aborted", "unfinished", "unfinished_returns", "excess", "max_points",
                      "excess_scans"), map(int, m.groups())))
    m = re.search(r"decoder velodyne (\S+) \(", err)
    if m:
        s["sensor"] = m.group(1)
    return s


HEADER = re.compile(r"# scan (\d+): (\d+) returns, (\d+) detections, packets (\d+)\.\.(\d+)(?: \((\w+)\))?"
                    r"(?:; (\d+) returns past LIDET_MAX_POINTS dropped)?$")


def _scans(out):
    """stdout of detect --pcap: [{'k', 'returns', 'n_det', 'first', 'last', 'kind', 'excess', 'boxes' (n, 8), 'cls'}]"""
    scans = []
    for line in out.splitlines():
        m = HEADER.match(line)
        if m:
            k, n, nd, p, q, kind, ex = m.groups()
            scans.append(dict(k=int(k), returns=int(n), n_det=int(nd), first=int(p), last=int(q),
                              kind=kind or "complete", excess=int(ex or 0), boxes=[], cls=[], lines=[]))
            continue
        assert scans and line.split()[0] in CLASSES, line
        scans[-1]["cls"].append(CLASSES.index(line.split()[0]))
        scans[-1]["boxes"].append([float(x) for x in line.split()[1:]])
        scans[-1]["lines"].append(line)
    for s in scans:
        assert len(s["boxes"]) == s["n_det"]
        s["boxes"] = np.array(s["boxes"]).reshape(-1, 8)
    return scans


@pytest.fixture(scope="module")
def vd(need_lib):
    from lidet_tools import native, velodyne
    if not hasattr(native.lib(), "lidet_py_velodyne_decode"):
        pytest.skip("liblidet_py.so predates the Velodyne decoder: rebuild")
    return velodyne


def _sim_scene():
    from lidet_tools import kitti
    return kitti.read_bin(SIM / "velodyne" / "000000.bin"), np.fromfile(SIM / "ring" / "000000.bin", np.uint16)


def _sll(frame):
    """An Ethernet frame as Linux cooked capture (SLL): 16-byte header, the protocol last."""
    return struct.pack(">HHH8sH", 0, 1, 6, frame[6:12] + b"\0\0", struct.unpack(">H", frame[12:14])[0]) + frame[14:]


class Capture:
    """The synthetic capture: its file, payloads (data ones, in order), their times and frame indices."""

    def __init__(self, vd, path, linktype=1):
        pts, ring = _sim_scene()
        scenes = []
        for r in range(N_ROT + 2):
            p = pts.copy()
            p[:, 0] += SHIFT_M * r
            scenes.append(vd.vlp16_grid(p, ring))
        pk = vd.vlp16_packets(scenes, N_DATA, start_cdeg=START_CDEG, t0_us=T0_US, packet_us=PACKET_US)
        self.times_us = np.array([t for t, _ in pk], np.int64)
        self.payloads = [p for _, p in pk]
        frames, self.frame_of = [], []
        bad_size = self.payloads[3][:1205]
        bad_flag = b"\x00\x00" + self.payloads[3][2:]
        junk = {
            5: [b"\xff" * 6 + b"\x00\x11\x22\x33\x44\x55" + b"\x08\x06" + bytes(28)],  # ARP
            10: [vd.udp_frame(bytes(512), dport=8308)],  # a position packet
            15: [vd.udp_frame(self.payloads[15][:600], flags_frag=0x2000)],  # an IPv4 fragment (more fragments)
            20: [(vd.udp_frame(self.payloads[20])[:100], 1248)],  # cut by the capture's snap length
            25: [b"\xff" * 6 + b"\x00\x11\x22\x33\x44\x55" + b"\x86\xdd" + bytes(60)],  # IPv6
            30: [vd.udp_frame(bytes(100), ip_total=1234)],  # IPv4 total length past the frame (whole)
            33: [vd.udp_frame(bad_size), vd.udp_frame(bad_flag)],  # the decoder's size and flag rejects
        }
        for i, p in enumerate(self.payloads):
            for f in junk.get(i, []):
                frames.append(f)
            f = vd.udp_frame(p)
            if i == 40 and linktype != 101:  # an 802.1Q tag (in the link layer: none in raw IP)
                f = f[:12] + b"\x81\x00\x00\x05" + f[12:]
            self.frame_of.append(len(frames))
            frames.append(f)
        self.n_frames = len(frames)
        if linktype == 113:
            frames = [_sll(f) if isinstance(f, bytes) else (_sll(f[0]), f[1] + 2) for f in frames]
        elif linktype == 101:
            frames = [f[14:] if isinstance(f, bytes) else (f[0][14:], f[1] - 14) for f in frames]
        # the capture's clock: 1 ms apart (a burst, as rewritten captures have), not the payloads'
        vd.write_pcap(path, frames, [1_700_000_000 + 1e-3 * i for i in range(len(frames))], linktype=linktype)
        self.path = path
        self.d = vd.decode(self.payloads)
        kinds = self.d.scan_kinds()
        self.complete = [s for s, k in enumerate(kinds) if k == vd.SCAN_COMPLETE]
        ev = np.flatnonzero(self.d.scan_event != vd.SCAN_NONE)
        self.first_payload = {s: int(ev[s - 1]) for s in range(1, len(kinds))}
        self.last_payload = {s: int(ev[s]) for s in range(len(kinds) - 1)}

    def returns(self, s):
        from lidet_tools import native
        sel = self.d.scan == s
        return native.as_returns(self.d.range_mm[sel], self.d.azimuth[sel], self.d.ring[sel])

    def scan_time_us(self, s):
        return int(self.times_us[self.first_payload[s]])


@pytest.fixture(scope="module")
def cap(vd, tmp_path_factory):
    return Capture(vd, tmp_path_factory.mktemp("pcap") / "synth.pcap")


# ---- the synthetic capture ------------------------------------------------------------------------------------------


def test_summary_counts_every_frame(pcli, cap):
    """Every frame lands in one count; the decoder rejects only the two bad payloads; the rotations are the 6 whole
    ones, the capture's first (begun at 180 deg) and last skipped."""
    r = _run(pcli, "detect", "--pcap", cap.path, "--fixed")
    s = _summary(r.stderr)
    assert s["frames"] == cap.n_frames == N_DATA + 8
    assert (s["port"], s["other_port"], s["not_udp"], s["truncated"], s["malformed"], s["fragments"]) == \
        (N_DATA + 2, 1, 2, 1, 1, 1)
    assert s["decoded"] == N_DATA and (s["rejected"], s["size"], s["flag"]) == (2, 1, 1) and s["jumps"] == 0
    assert (s["complete"], s["partial"], s["aborted"], s["unfinished"], s["excess"]) == (N_ROT, 1, 0, 1, 0)
    assert s["sensor"] == "vlp16"  # from the packets' product byte (no --sensor)
    assert len(cap.complete) == N_ROT and len(_scans(r.stdout)) == N_ROT


def test_fixed_is_the_bindings_on_the_same_returns(pcli, cap):
    """--fixed: per complete rotation the integer detector on the decoder's returns as they are: the detections of
    native.detect_q(returns=...) on the bindings' decoding of the same payloads; the header's returns and packets
    (frames of the file) are the decoding's."""
    from lidet_tools import native
    scans = _scans(_run(pcli, "detect", "--pcap", cap.path, "--fixed").stdout)
    n_boxes = 0
    for k, s in enumerate(cap.complete):
        got = scans[k]
        rets = cap.returns(s)
        assert got["k"] == k and got["kind"] == "complete" and got["returns"] == len(rets)
        assert got["first"] == cap.frame_of[cap.first_payload[s]] and got["last"] == cap.frame_of[cap.last_payload[s]]
        q = native.detect_q(None, "vlp16", returns=rets)
        assert got["n_det"] == len(q["cls"])
        assert list(got["cls"]) == [int(c) for c in q["cls"]]
        np.testing.assert_allclose(got["boxes"][:, :6], q["boxes"][:, :6] / 1000.0, rtol=0, atol=6e-5)
        np.testing.assert_allclose(got["boxes"][:, 7], q["score_q15"] / 32768.0, rtol=0, atol=6e-5)
        n_boxes += len(q["cls"])
    assert n_boxes >= N_ROT  # road users found in every rotation


def test_float_is_detect_on_the_points(pcli, cap, tmp_path):
    """Float: each complete rotation's returns as x, y, z (lidet_velodyne_xyz) with their rings through the float
    detector: the lines of `lidet detect SCAN.bin --ring RING.bin --sensor vlp16` on the bindings' x, y, z."""
    from lidet_tools import kitti
    out = tmp_path / "out"
    scans = _scans(_run(pcli, "detect", "--pcap", cap.path, "--out", out).stdout)
    assert sorted(p.name for p in out.iterdir()) == [f"{k:06d}.txt" for k in range(N_ROT)]
    for k, s in enumerate(cap.complete[:3]):
        sel = cap.d.scan == s
        pts = np.column_stack([cap.d.xyz[sel], np.zeros(sel.sum(), np.float32)]).astype(np.float32)
        kitti.write_bin(tmp_path / "scan.bin", pts)
        cap.d.ring[sel].astype(np.uint16).tofile(tmp_path / "ring.bin")
        _run(pcli, "detect", tmp_path / "scan.bin", "--ring", tmp_path / "ring.bin", "--sensor", "vlp16", "--out",
             tmp_path / "one.txt")
        want = (tmp_path / "one.txt").read_text()
        assert (out / f"{k:06d}.txt").read_text() == want
        assert "\n".join(scans[k]["lines"]) + ("\n" if scans[k]["lines"] else "") == want
    assert sum(s["n_det"] for s in scans) >= N_ROT


def test_json_png_and_partial(pcli, cap, tmp_path):
    """--json: one object per scan with the scan's number, kind, frames, returns, times, then lidet detect's
    fields; --png draws the last scan (or --png-scan K); --partial also runs the first and last rotations."""
    r = _run(pcli, "detect", "--pcap", cap.path, "--json", "--png", tmp_path / "last.png")
    objs = [json.loads(line) for line in r.stdout.splitlines()]
    assert [o["scan"] for o in objs] == list(range(N_ROT)) and all(o["kind"] == "complete" for o in objs)
    for o, s in zip(objs, cap.complete):
        assert o["returns"] == o["points"] == int((cap.d.scan == s).sum()) and o["excess_returns"] == 0
        assert o["sensor"] == "vlp16" and o["detections"] == len(o["boxes"])
        assert o["sensor_time_s"] == pytest.approx(cap.scan_time_us(s) * 1e-6, abs=1e-6)  # unwrapped
    assert (objs[1]["sensor_time_s"] - objs[0]["sensor_time_s"]) == pytest.approx(75 * PACKET_US * 1e-6, abs=1e-6)
    img = Image.open(tmp_path / "last.png")
    assert img.size[0] > 800
    _run(pcli, "detect", "--pcap", cap.path, "--png", tmp_path / "k1.png", "--png-scan", 1)
    assert (tmp_path / "k1.png").read_bytes() != (tmp_path / "last.png").read_bytes()
    r = _run(pcli, "detect", "--pcap", cap.path, "--png", tmp_path / "x.png", "--png-scan", N_ROT, ok=False)
    assert r.returncode == 1 and f"gives {N_ROT} scans" in r.stderr
    scans = _scans(_run(pcli, "detect", "--pcap", cap.path, "--partial", "--fixed").stdout)
    assert [s["kind"] for s in scans] == ["partial"] + ["complete"] * N_ROT + ["unfinished"]
    assert [s["returns"] for s in scans] == [int((cap.d.scan == s).sum()) for s in range(N_ROT + 2)]


def test_stream_and_stream_sectors(pcli, cap, tmp_path):
    """--fixed --stream N feeds each rotation's decoded returns N at a time (lidet_detector_q_stream_*): the boxes of
    the whole rotation at once, and stream_end_ms; --stream-sectors (the ground stage sector by sector while the
    returns arrive) gives the boxes of --stream-sectors without --stream (run_returns with the same configuration)
    with most of the 32 sectors done before stream_end (stream_sectors), none without --stream."""
    def objs(*extra):
        return [json.loads(line) for line in _run(pcli, "detect", "--pcap", cap.path, "--fixed", "--json",
                                                  *extra).stdout.splitlines()]

    def boxes(os_):
        return [o["boxes"] for o in os_]

    whole, streamed = objs(), objs("--stream", 384)
    assert len(whole) == N_ROT and boxes(streamed) == boxes(whole)
    assert all(o["stream_chunk"] == 384 and o["stream_end_ms"] > 0 and "stream_sectors" not in o for o in streamed)
    sec, sec_streamed = objs("--stream-sectors"), objs("--stream-sectors", "--stream", 384)
    assert boxes(sec_streamed) == boxes(sec) and any(o["boxes"] for o in sec)
    assert all(o["stream_sectors"] == 0 for o in sec)
    assert all(24 <= o["stream_sectors"] < 32 for o in sec_streamed), [o["stream_sectors"] for o in sec_streamed]
    assert boxes(objs("--stream-sectors", "--stream", 1)) == boxes(sec)  # a return at a time
    # refusals: without --fixed, a bad count, a scan given as points
    r = _run(pcli, "detect", "--pcap", cap.path, "--stream", 384, ok=False)
    assert r.returncode == 1 and "--stream is a setting of the integer detector: add --fixed" in r.stderr
    r = _run(pcli, "detect", "--pcap", cap.path, "--fixed", "--stream", 0, ok=False)
    assert r.returncode == 1 and "--stream 0: returns per chunk, 1 to 1000000" in r.stderr
    r = _run(pcli, "detect", SIM / "velodyne" / "000000.bin", "--sensor", "vlp16", "--fixed", "--stream", 384, ok=False)
    assert r.returncode == 1 and "--stream: needs the scan as the sensor's returns" in r.stderr


@pytest.mark.parametrize("capture", ["vlp16_dual", "OS-0-128-U1_v2.3.0_1024x10", "OS-1-32-G_v2.1.1_1024x10"])
def test_stream_sectors_on_real_captures(pcli, capture):
    """Real captures (../shared/data/packets): with --stream-sectors, streaming each rotation 384 returns at a time
    gives the boxes of the whole rotation at once, and most ground sectors are done before stream_end, also on the
    OS0-128 whose beams' azimuth offsets span +-11 degrees (its last returns come back to the first columns)."""
    if capture.startswith("OS"):
        path = PACKETS.parent / "ouster" / f"{capture}.pcap"
        extra = ["--lidar", "ouster", "--ouster-meta", PACKETS.parent / "ouster" / f"{capture}.json"]
    else:
        path, extra = PACKETS / f"{capture}.pcap", []
    if not path.exists():
        pytest.skip(f"{path} absent (../shared/data/packets)")

    def objs(*more):
        r = _run(pcli, "detect", "--pcap", path, *extra, "--fixed", "--stream-sectors", "--json", *more)
        return [json.loads(line) for line in r.stdout.splitlines()]

    whole, streamed = objs(), objs("--stream", 384)
    assert whole and [o["boxes"] for o in streamed] == [o["boxes"] for o in whole]
    assert all(o["stream_sectors"] >= 20 for o in streamed), [o["stream_sectors"] for o in streamed]


@pytest.mark.parametrize("linktype", [113, 101])
def test_link_types(pcli, vd, cap, tmp_path, linktype):
    """The same frames as Linux cooked (SLL) or raw IP captures give the same scans and boxes."""
    other = Capture(vd, tmp_path / f"link{linktype}.pcap", linktype=linktype)
    a = _run(pcli, "detect", "--pcap", cap.path, "--fixed")
    b = _run(pcli, "detect", "--pcap", other.path, "--fixed")
    assert a.stdout == b.stdout
    sa, sb = _summary(a.stderr), _summary(b.stderr)
    if linktype == 101:  # no link header: the ARP and IPv6 frames are just no IPv4
        sa["not_udp"] = sb["not_udp"]
    assert sa == sb


def _tracks(out):
    rows = []
    for line in out.splitlines():
        if line.startswith("#") or not line.strip():
            continue
        p = line.split()
        rows.append((int(p[0]), int(p[1]), p[2], tuple(float(x) for x in p[3:13]), int(p[13])))
    return rows


def test_track_fixed_is_the_integer_pipeline(pcli, cap):
    """lidet track --pcap --fixed: the same rotations, in order, through the integer detector (on the returns) and
    the integer tracker with dt from the payloads' timestamps (0.199 s a rotation across the hour's wrap, not the
    capture's 1 ms stamps nor the default 10 Hz), no ego motion: the Python pipeline's lines; the scene moving
    +0.4 m a rotation gives about +2 m/s."""
    from lidet_ref import track_q as ref
    from lidet_tools import native
    try:
        from lidet_tools.track.native_q import TrackerQ
        tq = TrackerQ()
    except (ImportError, AttributeError, OSError) as e:
        pytest.skip(f"the integer tracker's bindings are not available: {e}")
    r = _run(pcli, "track", "--pcap", cap.path, "--fixed")
    t = [cap.scan_time_us(s) for s in cap.complete]
    dt = [(t[1] - t[0]) * 1e-6] + [(t[k] - t[k - 1]) * 1e-6 for k in range(1, len(t))]
    assert all(abs(x - 0.19905) < 1e-6 for x in dt)
    want = []
    for k, s in enumerate(cap.complete):
        q = native.detect_q(None, "vlp16", returns=cap.returns(s))
        rows = np.column_stack([q["cls"], q["boxes"], q["score_q15"]])
        for tr in ref.tracks_to_si(tq.update_q(rows, ref.quantise_dt(dt[k]), None)):
            want.append((k, int(tr["id"]), CLASSES[tr["cls"]], tuple(float(tr[f]) for f in
                         ("x", "y", "z", "l", "w", "h", "yaw", "vx", "vy", "score")), int(tr["hits"])))
    got = _tracks(r.stdout)
    assert len(got) == len(want) > 0
    for g, w in zip(got, want):
        assert g[:3] == w[:3] and g[4] == w[4], (g, w)
        np.testing.assert_allclose(g[3], w[3], rtol=0, atol=2e-6)
    vx = [g[3][7] for g in got if g[0] == N_ROT - 1 and g[4] >= 4]
    assert len(vx) >= 3 and abs(np.median(vx) - SHIFT_M / 0.19905) < 0.25, vx
    # --rate 10: dt 0.1 s, the same motion reads twice as fast
    fast = [g[3][7] for g in _tracks(_run(pcli, "track", "--pcap", cap.path, "--fixed", "--rate", 10).stdout)
            if g[0] == N_ROT - 1 and g[4] >= 4]
    assert len(fast) >= 3 and abs(np.median(fast) - SHIFT_M / 0.1) < 0.5, fast
    assert "frames" in _summary(r.stderr) and _summary(r.stderr)["complete"] == N_ROT


def test_track_float_out_and_png(pcli, cap, tmp_path):
    """lidet track --pcap (float): frames 0..5 named FILE#K, --out DIR/<K:06d>.txt and tracks/, a picture; --ego
    FILE takes a line per complete rotation."""
    out = tmp_path / "trk"
    r = _run(pcli, "track", "--pcap", cap.path, "--out", out, "--png", tmp_path / "t.png")
    heads = [line for line in r.stdout.splitlines() if line.startswith("# frame")]
    assert [h.split()[2] for h in heads] == [str(k) for k in range(N_ROT)]
    assert heads[0].split()[3] == f"{cap.path}#0:"
    assert sorted(p.name for p in out.glob("*.txt")) == [f"{k:06d}.txt" for k in range(N_ROT)]
    assert len(list((out / "tracks").glob("*.txt"))) == N_ROT and (tmp_path / "t.png").stat().st_size > 0
    ego = tmp_path / "ego.txt"
    ego.write_text("0 0 0\n" * (N_ROT - 1))
    r = _run(pcli, "track", "--pcap", cap.path, "--ego", ego, ok=False)
    assert r.returncode == 1 and f"for {N_ROT} scans" in r.stderr
    ego.write_text("0 0 0\n" * N_ROT)
    _run(pcli, "track", "--pcap", cap.path, "--ego", ego)


def test_scan_past_max_points(pcli, vd, tmp_path):
    """A rotation of 36000 blocks 0.01 deg apart (1.15 M returns): its first LIDET_MAX_POINTS returns run, the rest
    counted (header, JSON, summary), nothing written past the buffer."""
    n_blocks = 1000 + 36000 + 1200
    n_pk = n_blocks // 12
    blk = np.zeros((n_pk, 12), np.dtype([("flag", "<u2"), ("az", "<u2"), ("pt", [("d", "<u2"), ("i", "u1")], 32)]))
    blk["flag"] = 0xEEFF
    blk["az"] = (35000 + np.arange(n_pk * 12).reshape(n_pk, 12)) % 36000
    blk["pt"]["d"] = 2500 + (np.arange(32) % 16) * 10  # a cylinder 5 m around the sensor
    blk["pt"]["i"] = 50
    tail = np.zeros(n_pk, np.dtype([("t", "<u4"), ("mode", "u1"), ("prod", "u1")]))
    tail["t"], tail["mode"], tail["prod"] = np.arange(n_pk) * 1327, 0x37, 0x22
    pays = [blk[k].tobytes() + tail[k].tobytes() for k in range(n_pk)]
    assert len(pays[0]) == 1206
    vd.write_pcap(tmp_path / "big.pcap", [vd.udp_frame(p) for p in pays])
    r = _run(pcli, "detect", "--pcap", tmp_path / "big.pcap", "--fixed", "--json")
    s = _summary(r.stderr)
    obj = json.loads(r.stdout)
    total = 36000 * 32
    assert s["complete"] == 1 and obj["returns"] == s["max_points"] == obj["points"]
    assert obj["excess_returns"] == s["excess"] == total - s["max_points"] and s["excess_scans"] == 1
    r = _run(pcli, "detect", "--pcap", tmp_path / "big.pcap", "--fixed")
    assert _scans(r.stdout)[0]["excess"] == total - s["max_points"]


def test_random_frames_never_crash(pcli, vd, cap, tmp_path):
    """Random frames (random bytes; Ethernet / IPv4 / UDP headers with random length fields; payloads of every size
    to the port) between the capture's frames: each counted once, never a crash, the rotations unchanged."""
    rnd = np.random.default_rng(37)
    frames = []
    for i, p in enumerate(cap.payloads):
        frames.append(vd.udp_frame(p))
        for _ in range(int(rnd.integers(0, 3))):
            kind = int(rnd.integers(0, 4))
            if kind == 0:
                f = rnd.bytes(int(rnd.integers(0, 1600)))
            elif kind == 1:
                f = bytearray(vd.udp_frame(rnd.bytes(int(rnd.integers(0, 1300))), dport=2368))
                for off in (14, 16, 17, 20, 21, 38, 39):  # IHL, total length, flags/offset, UDP length
                    if rnd.random() < 0.3:
                        f[off] = int(rnd.integers(0, 256))
                f = bytes(f[: int(rnd.integers(0, len(f) + 1))])
            elif kind == 2:
                f = vd.udp_frame(rnd.bytes(int(rnd.choice([0, 1, 100, 512, 1205, 1206, 1207, 1500]))))
            else:
                f = (vd.udp_frame(p)[: int(rnd.integers(0, 1248))], 1248)
            frames.append(f)
    vd.write_pcap(tmp_path / "noisy.pcap", frames)
    r = _run(pcli, "detect", "--pcap", tmp_path / "noisy.pcap", "--fixed", ok=False)
    s = _summary(r.stderr)
    assert s["frames"] == len(frames)
    assert s["port"] + s["other_port"] + s["not_udp"] + s["truncated"] + s["malformed"] + s["fragments"] == len(frames)
    assert s["decoded"] + s["rejected"] == s["port"]
    # random 1206-byte payloads may decode (a jump: a rotation aborted), so the rotations are at most the clean ones
    assert r.returncode in (0, 1) and s["complete"] <= N_ROT


def test_errors_are_clear(pcli, cap, tmp_path):
    """Bad captures and options: exit 1 with a message, nothing on stdout (a file cut short: the scans before it)."""
    data = pathlib.Path(cap.path).read_bytes()
    cases = {
        "empty.pcap": (b"", "is empty"),
        "magic.pcap": (b"\x00\x01\x02\x03" + data[4:], "unknown file format"),
        "text.pcap": (b"not a capture at all\n" * 3, "unknown file format"),
        "header.pcap": (data[:24], "holds no packet"),
        "cut_header.pcap": (data[:30], "no whole frame"),
    }
    for name, (raw, msg) in cases.items():
        (tmp_path / name).write_bytes(raw)
        r = _run(pcli, "detect", "--pcap", tmp_path / name, ok=False)
        assert r.returncode == 1 and msg in r.stderr and r.stdout == "", (name, r.stderr)
    # cut in the middle of a record: the rotations before it run, the status says the file is damaged
    (tmp_path / "cut.pcap").write_bytes(data[: 24 + 1264 * 300 + 700])
    r = _run(pcli, "detect", "--pcap", tmp_path / "cut.pcap", "--fixed", ok=False)
    assert r.returncode == 1 and "cut short or damaged at its frame" in r.stderr
    assert 1 <= len(_scans(r.stdout)) < N_ROT
    r = _run(pcli, "detect", "--pcap", cap.path, "--port", 2369, ok=False)
    assert r.returncode == 1 and "no UDP packet to port 2369" in r.stderr and "the most to port 2368" in r.stderr
    r = _run(pcli, "detect", "--pcap", cap.path, "--sensor", "vlp32c", ok=False)
    assert r.returncode == 1 and "is Velodyne data of the model of --sensor vlp32c" in r.stderr
    for args, msg in (
        (["--sensor", "os1-64"], "vlp16, vlp32c, hdl32 or hdl64"),
        (["--sensor", "hdl64"], "is Velodyne data of the model of --sensor hdl64"),  # VLP-16 payloads: no 0xDDFF
        (["--velodyne-calib", str(ROOT / "tests" / "data" / "sensors" / "vlp16.yaml")], "needs --sensor"),
        (["--force-sensor"], "--force-sensor needs --sensor"),
        (["--lidar", "lumotive"], "velodyne or ouster"),
        (["--port", "0"], "[1, 65535]"),
        (["--dual", "first"], "both, last or strongest"),
        ([str(SIM / "velodyne" / "000000.bin")], "not with --pcap"),
        (["--calib", str(SIM / "calib" / "000000.txt")], "--calib goes with one scan file"),
        (["--sensor-file", str(ROOT / "tests" / "data" / "sensors" / "vlp16.json")], "--sensor-file"),
    ):
        r = _run(pcli, "detect", "--pcap", cap.path, *args, ok=False)
        assert r.returncode == 1 and msg in r.stderr and r.stdout == "", (args, r.stderr)
    r = _run(pcli, "detect", SIM / "velodyne" / "000000.bin", "--port", 2368, ok=False)
    assert r.returncode == 1 and "go with --pcap" in r.stderr
    r = _run(pcli, "track", SIM / "velodyne" / "000000.bin", "--pcap", cap.path, ok=False)
    assert r.returncode == 1 and "not both" in r.stderr
    r = _run(pcli, "track", "--pcap", tmp_path / "empty.pcap", ok=False)
    assert r.returncode == 1 and "is empty" in r.stderr and r.stdout == ""


def test_usage_mentions_pcap(cli):
    for cmd in ("detect", "track"):
        r = subprocess.run([str(cli), cmd, "--help"], capture_output=True, text=True)
        assert "--pcap FILE" in r.stderr and "--port N" in r.stderr


# ---- real captures (../shared/data/packets/velodyne) ----------------------------------------------------------------


@pytest.fixture(scope="module")
def real(pcli):
    if not (PACKETS / "vlp16_dual.pcap").exists():
        pytest.skip(f"Velodyne captures not available at {PACKETS}")
    return PACKETS


@pytest.mark.parametrize("name, frames, complete, partial, aborted, unfinished", [
    # README: 603 packets = 4 rotations (151, 151, 151, 150): the first begins mid-rotation, 3 whole ones follow,
    # packet 602 begins a 5th
    ("vlp16_dual", 603, 3, 1, 0, 1),
    # 1000 packets at 75.4 a rotation: a partial one, 12 whole ones, the start of the 14th
    ("vlp16_strongest", 1000, 12, 1, 0, 1),
])
def test_real_captures_complete_scans(pcli, vd, real, name, frames, complete, partial, aborted, unfinished):
    r = _run(pcli, "detect", "--pcap", real / f"{name}.pcap", "--fixed")
    s = _summary(r.stderr)
    assert (s["frames"], s["port"], s["decoded"], s["rejected"], s["jumps"]) == (frames, frames, frames, 0, 0)
    assert (s["complete"], s["partial"], s["aborted"], s["unfinished"]) == (complete, partial, aborted, unfinished)
    scans = _scans(r.stdout)
    d = vd.decode([p for _, port, p in vd.read_pcap_payloads(real / f"{name}.pcap") if port == 2368])
    kinds = d.scan_kinds()
    whole = [k for k, x in enumerate(kinds) if x == vd.SCAN_COMPLETE]
    assert [x["returns"] for x in scans] == [int((d.scan == k).sum()) for k in whole]
    if name == "vlp16_dual":  # nebula's rotation 4 (packets 452..601) and the returns of 602 before the seam
        assert (scans[-1]["first"], scans[-1]["last"], scans[-1]["returns"]) == (452, 602, 14879)


def test_real_sector_and_mislabelled_captures(pcli, real):
    """vlp32c.pcap holds the 270..91 deg sector only (5 partial sweeps, each ended by a jump back): no complete
    rotation (exit 1, said), --partial runs the 11 pieces. hdl32e_rotation.pcap: VLP-16 data labelled HDL-32E
    (docs/DECODING.md), one rotation begun mid-way; its 16 position packets (to port 8308) claim an IPv4 total
    length of 1234 bytes in 554-byte frames: counted malformed. As HDL-32E (its product byte) or, with --sensor
    vlp16 --force-sensor, as the VLP-16 it is."""
    r = _run(pcli, "detect", "--pcap", real / "vlp32c.pcap", ok=False)
    s = _summary(r.stderr)
    assert r.returncode == 1 and "no complete rotation" in r.stderr and r.stdout == ""
    assert (s["decoded"], s["rejected"], s["jumps"], s["complete"], s["partial"], s["aborted"], s["sensor"]) == \
        (379, 0, 5, 0, 5, 5, "vlp32c")
    scans = _scans(_run(pcli, "detect", "--pcap", real / "vlp32c.pcap", "--partial", "--fixed").stdout)
    assert [x["kind"] for x in scans] == ["partial", "aborted"] * 5 + ["unfinished"]
    r = _run(pcli, "detect", "--pcap", real / "hdl32e_rotation.pcap", ok=False)
    s = _summary(r.stderr)
    assert (s["frames"], s["port"], s["malformed"], s["decoded"], s["rejected"], s["sensor"]) == \
        (100, 84, 16, 84, 0, "hdl32")
    assert (s["complete"], s["partial"], s["unfinished"]) == (0, 1, 1)
    r = _run(pcli, "detect", "--pcap", real / "hdl32e_rotation.pcap", "--sensor", "vlp16", ok=False)
    assert r.returncode == 1 and "product byte 84" in r.stderr and "--force-sensor" in r.stderr
    r = _run(pcli, "detect", "--pcap", real / "hdl32e_rotation.pcap", "--sensor", "vlp16", "--force-sensor",
             "--partial")
    assert [x["returns"] for x in _scans(r.stdout)] == [5602, 13977] and _summary(r.stderr)["sensor"] == "vlp16"


def test_real_track(pcli, real):
    """lidet track --pcap on the VLP-16 capture: its 12 rotations in order, float and --fixed."""
    for opt in ([], ["--fixed"]):
        r = _run(pcli, "track", "--pcap", real / "vlp16_strongest.pcap", *opt)
        heads = [line for line in r.stdout.splitlines() if line.startswith("# frame")]
        assert len(heads) == 12 and _summary(r.stderr)["complete"] == 12


# ---- Ouster (--lidar ouster --ouster-meta M: lib/src/decode/lidet_ouster.c) -----------------------------------------

OUSTER = PACKETS.parent / "ouster"
OUSTER_COLS, OUSTER_ROWS = 1024, 16


@pytest.fixture(scope="module")
def ou(need_lib):
    from lidet_tools import native, ouster
    if not hasattr(native.lib(), "lidet_py_ouster_decode"):
        pytest.skip("liblidet_py.so predates the Ouster decoder: rebuild")
    return ouster


class OusterCapture:
    """A made-up 16-beam Ouster (RNG19_RFL8_SIG16_NIR16, 1024 x 10) turning over the simulated VLP-16 scene (its 16
    rings are the beams, top first): half a frame, then 3 whole ones (the last ends the capture at its last column),
    the scene 0.5 m further +x each frame, 0.1 s a frame; the IMU's packets to port 7503 between."""

    def __init__(self, vd, ou, folder):
        pts, ring = _sim_scene()
        meta = {
            "beam_intrinsics": {"beam_altitude_angles": [15.0 - 2.0 * r for r in range(OUSTER_ROWS)],
                                "beam_azimuth_angles": [0.0] * OUSTER_ROWS, "lidar_origin_to_beam_origin_mm": 12.163},
            "lidar_data_format": {"pixels_per_column": OUSTER_ROWS, "columns_per_frame": OUSTER_COLS,
                                  "columns_per_packet": 16, "udp_profile_lidar": "RNG19_RFL8_SIG16_NIR16"},
            "config_params": {"lidar_mode": "1024x10", "udp_port_lidar": 7502},
            "sensor_info": {"prod_line": "OS-1-16", "prod_sn": "992233000111", "initialization_id": 4711},
        }
        self.meta_path = folder / "os16.json"
        self.meta_path.write_text(json.dumps(meta))
        self.meta = ou.load_metadata(self.meta_path)
        frames, times, self.payloads = [], [], []
        row = 15 - ring.astype(np.int64)  # Ouster row 0 = the top beam
        for f in range(4):
            p = pts[:, :3].astype(np.float64) + [0.5 * f, 0.0, 0.0]
            a_bam = np.mod(np.round(np.arctan2(p[:, 1], p[:, 0]) * 65536 / (2 * np.pi)), 65536)
            mid = np.mod(np.round((32768 - a_bam) * OUSTER_COLS / 65536), OUSTER_COLS).astype(np.int64)
            rng_mm = np.round(np.linalg.norm(p, axis=1) * 1000).astype(np.int64)
            grid = np.zeros((OUSTER_COLS, OUSTER_ROWS), np.int64)
            order = np.argsort(-rng_mm, kind="stable")
            grid[mid[order], row[order]] = rng_mm[order]
            for c0 in range(512 if f == 0 else 0, OUSTER_COLS, 16):
                ts = 10**12 + f * 10**8 + (c0 + np.arange(16)) * 97656
                pay = ou.write_packet("RNG19_RFL8_SIG16_NIR16", OUSTER_ROWS, OUSTER_COLS, frame_id=20 + f, first_mid=c0,
                                      ranges_mm=grid[c0:c0 + 16], timestamps_ns=ts, init_id=4711,
                                      prod_sn=992233000111)
                self.payloads.append(pay)
                frames.append(vd.udp_frame(pay, dport=7502, sport=7502))
                times.append(1_700_000_000 + len(frames) * 1e-3)
                if c0 % 256 == 0:  # an IMU packet
                    frames.append(vd.udp_frame(bytes(48), dport=7503, sport=7503))
                    times.append(times[-1])
        self.path = folder / "os16.pcap"
        vd.write_pcap(self.path, frames, times)
        self.n_frames = len(frames)
        self.d = ou.decode(self.payloads, self.meta)


@pytest.fixture(scope="module")
def ocap(vd, ou, tmp_path_factory):
    return OusterCapture(vd, ou, tmp_path_factory.mktemp("ouster"))


def test_ouster_synthetic(pcli, ou, ocap, tmp_path):
    """--lidar ouster: the frames that begin at column 0 are the scans (the capture's last one too: it ends at its
    last column), the half frame at the start is skipped; the returns are the bindings' decoding; the float
    detector's points (--save-scans) are x, y, z of the beam altitude and the decoded azimuth from the lidar origin,
    and detect as the same scan given as a file with --ouster-meta."""
    r = _run(pcli, "detect", "--pcap", ocap.path, "--lidar", "ouster", "--ouster-meta", ocap.meta_path, "--out",
             tmp_path / "out", "--save-scans", tmp_path / "scans")
    s = _summary(r.stderr)
    assert (s["frames"], s["port"], s["other_port"]) == (ocap.n_frames, len(ocap.payloads), 14)
    m = re.search(r"decoder ouster (\S+) \(RNG19_RFL8_SIG16_NIR16, 16 x 1024\): (\d+) packets: (\d+) decoded, (\d+) "
                  r"rejected", r.stderr)
    assert m and m.group(1) == "os-1-16" and int(m.group(3)) == len(ocap.payloads) and m.group(4) == "0"
    assert (s["complete"], s["partial"], s["aborted"], s["unfinished"]) == (3, 1, 0, 0)
    scans = _scans(r.stdout)
    assert [x["returns"] for x in scans] == [int((ocap.d.scan == k).sum()) for k in (1, 2, 3)]
    assert sum(x["n_det"] for x in scans) >= 3
    for k, sc in zip((1, 2, 3), range(3)):
        sel = ocap.d.scan == k
        p = np.fromfile(tmp_path / "scans" / "velodyne" / f"{sc:06d}.bin", np.float32).reshape(-1, 4)
        ring = np.fromfile(tmp_path / "scans" / "ring" / f"{sc:06d}.bin", np.uint16)
        assert np.array_equal(ring, ocap.d.ring[sel])
        e = np.radians(ocap.meta.beam_altitude_deg[ring])
        a = ocap.d.azimuth[sel] * (2 * np.pi / 65536)
        rr = ocap.d.range_mm[sel] / 1000.0
        want = np.column_stack([rr * np.cos(e) * np.cos(a), rr * np.cos(e) * np.sin(a), rr * np.sin(e)])
        np.testing.assert_allclose(p[:, :3], want, rtol=0, atol=1e-4 + 2e-6 * rr.max())
        one = tmp_path / f"one{sc}.txt"
        _run(pcli, "detect", tmp_path / "scans" / "velodyne" / f"{sc:06d}.bin", "--ring",
             tmp_path / "scans" / "ring" / f"{sc:06d}.bin", "--ouster-meta", ocap.meta_path, "--out", one)
        assert one.read_text() == (tmp_path / "out" / f"{sc:06d}.txt").read_text()
    # track: dt from the columns' timestamps, 0.1 s a frame: the lines of --rate 10, not those of --rate 5; the
    # scene moving +0.5 m a frame reads as moving +x
    args = ("track", "--pcap", ocap.path, "--lidar", "ouster", "--ouster-meta", ocap.meta_path, "--fixed")
    r = _run(pcli, *args)
    assert [h.split()[2] for h in r.stdout.splitlines() if h.startswith("# frame")] == ["0", "1", "2"]
    lines = [x for x in r.stdout.splitlines() if not x.startswith("#")]
    assert lines and lines == [x for x in _run(pcli, *args, "--rate", 10).stdout.splitlines() if not x.startswith("#")]
    assert lines != [x for x in _run(pcli, *args, "--rate", 5).stdout.splitlines() if not x.startswith("#")]
    vx = [g[3][7] for g in _tracks(r.stdout) if g[0] == 2 and g[4] >= 3]
    assert vx and 2.0 < np.median(vx) < 7.0, vx


def test_ouster_errors(pcli, ocap, tmp_path):
    for args, msg in (
        (["--lidar", "ouster"], "needs the sensor's metadata: --ouster-meta"),
        (["--lidar", "ouster", "--ouster-meta", ocap.meta_path, "--force-sensor"], "velodyne decoder's"),
        (["--lidar", "ouster", "--ouster-meta", ocap.meta_path, "--dual", "last"], "both, first or second"),
        (["--lidar", "ouster", "--ouster-meta", ocap.meta_path, "--port", 7503], "none of the 14 packets to port 7503"),
        (["--ouster-meta", ocap.meta_path], "--lidar ouster reads it"),
    ):
        r = _run(pcli, "detect", "--pcap", ocap.path, *map(str, args), ok=False)
        assert r.returncode == 1 and msg in r.stderr and r.stdout == "", (args, r.stderr)
    # another sensor's metadata: its serial number (the packets' header) differs
    meta = json.loads(pathlib.Path(ocap.meta_path).read_text())
    meta["sensor_info"]["prod_sn"] = "992233000112"
    (tmp_path / "other.json").write_text(json.dumps(meta))
    r = _run(pcli, "detect", "--pcap", ocap.path, "--lidar", "ouster", "--ouster-meta", tmp_path / "other.json",
             ok=False)
    assert r.returncode == 1 and "header %d" % len(ocap.payloads) in r.stderr


@pytest.fixture(scope="module")
def oreal(pcli):
    if not (OUSTER / "OS-1-64_sensor_config_reduced.json").exists():
        pytest.skip(f"Ouster captures not available at {OUSTER}")
    return OUSTER


@pytest.mark.parametrize("name, meta, profile, imu", [
    ("OS-1-64_1024x10_fw20", "OS-1-64_sensor_config_reduced", "LEGACY", 11),
    ("OS-1-32-G_v2.1.1_1024x10", None, "LEGACY", 0),
    ("OS-2-128-U1_v2.3.0_1024x10", None, "RNG19_RFL8_SIG16_NIR16", 10),
    ("OS-0-128-U1_v2.3.0_1024x10", None, "RNG15_RFL8_NIR8", 10),
    ("OS-0-32-U1_v2.2.0_1024x10", None, "RNG19_RFL8_SIG16_NIR16_DUAL", 10),
])
def test_ouster_real_captures(pcli, vd, ou, oreal, tmp_path, name, meta, profile, imu):
    """ouster-sdk's test captures (README: one frame each, 64 packets to port 7502, the IMU's to 7503): one
    complete scan (frame id constant, measurement ids 0..1023), no reject; its returns are the bindings' decoding;
    the float run on the scan saved as a file detects the same."""
    mpath = oreal / f"{meta or name}.json"
    r = _run(pcli, "detect", "--pcap", oreal / f"{name}.pcap", "--lidar", "ouster", "--ouster-meta", mpath, "--out",
             tmp_path / "out", "--save-scans", tmp_path / "s")
    s = _summary(r.stderr)
    assert (s["port"], s["other_port"], s["not_udp"], s["truncated"], s["malformed"]) == (64, imu, 0, 0, 0)
    assert f"({profile}, " in r.stderr and " 64 decoded, 0 rejected" in r.stderr
    assert (s["complete"], s["partial"], s["aborted"], s["unfinished"]) == (1, 0, 0, 0)
    m = ou.load_metadata(mpath)
    d = ou.decode([p for _, port, p in vd.read_pcap_payloads(oreal / f"{name}.pcap") if port == m.udp_port_lidar], m)
    sc = _scans(r.stdout)
    assert len(sc) == 1 and sc[0]["returns"] == len(d.range_mm) and sc[0]["kind"] == "complete"
    one = tmp_path / "one.txt"
    _run(pcli, "detect", tmp_path / "s" / "velodyne" / "000000.bin", "--ring", tmp_path / "s" / "ring" / "000000.bin",
         "--ouster-meta", mpath, "--out", one)
    assert one.read_text() == (tmp_path / "out" / "000000.txt").read_text()
    r = _run(pcli, "detect", "--pcap", oreal / f"{name}.pcap", "--lidar", "ouster", "--ouster-meta", mpath, "--fixed")
    assert len(_scans(r.stdout)) == 1
