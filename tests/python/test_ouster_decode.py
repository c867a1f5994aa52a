# SPDX-License-Identifier: MIT
"""The Ouster packet decoder (lib/src/decode/lidet_ouster.c, docs/OUSTER.md).

Always run (packets made here by lidet_tools.ouster.write_packet): every profile at 16/32/64/128 beams and
512/1024/2048 columns decoded exactly (ring, measurement id, range, return, attributes, the azimuth's integer rule),
frame completion, the seam, lost packets, jumps, every rejection reason, garbage of every length, and a capacity
smaller than a packet's pixels (the bindings check nothing is written past it).

On the real captures of ../shared/data/packets/ouster (its README; skipped when absent): one frame per capture,
every column valid; the decoded ranges reproduce ouster-sdk's own regression digests (md5 of the RANGE / RANGE2
fields per packet and per frame: *_digest.json); with ouster-sdk installed (requirements-ouster.txt), ranges equal
to its packet_format's and x, y, z within 1 mm of its XYZLut; and a decoded frame runs through the detector.
"""
import hashlib
import json
import math
import os
import pathlib
import random
import warnings

import numpy as np
import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
PACKETS = pathlib.Path(os.environ.get("LIDET_PACKET_DATA", ROOT.parent / "shared" / "data" / "packets")) / "ouster"

#: capture -> metadata file, profile, beams (README of ../shared/data/packets)
CAPTURES = {
    "OS-1-64_1024x10_fw20": ("OS-1-64_sensor_config_reduced.json", "LEGACY", 64),
    "OS-1-32-G_v2.1.1_1024x10": ("OS-1-32-G_v2.1.1_1024x10.json", "LEGACY", 32),
    "OS-2-128-U1_v2.3.0_1024x10": ("OS-2-128-U1_v2.3.0_1024x10.json", "RNG19_RFL8_SIG16_NIR16", 128),
    "OS-0-128-U1_v2.3.0_1024x10": ("OS-0-128-U1_v2.3.0_1024x10.json", "RNG15_RFL8_NIR8", 128),
    "OS-0-32-U1_v2.2.0_1024x10": ("OS-0-32-U1_v2.2.0_1024x10.json", "RNG19_RFL8_SIG16_NIR16_DUAL", 32),
}
LIDET_OK, LIDET_TRUNCATED, LIDET_ERR_MODEL = 0, 1, -4


@pytest.fixture(scope="module")
def ou(need_lib):
    from lidet_tools import native, ouster
    if not hasattr(native.lib(), "lidet_py_ouster_decode"):
        pytest.skip("liblidet_py.so predates the Ouster decoder: rebuild")
    return ouster


def _meta(ou, profile, ppc, cpf, cpp=16, az_deg=None, header="STANDARD", init_id=0, prod_sn=0):
    """Metadata of a made-up sensor (uniform beams over +-22.5 deg, the given azimuth offsets)."""
    from lidet_tools import sensors
    s = sensors.custom_sensor(f"syn-{ppc}", min(cpf, 2048), fov_up_deg=22.5, fov_down_deg=-22.5, rows=ppc)
    az = np.zeros(ppc) if az_deg is None else np.asarray(az_deg, np.float64)
    return ou.OusterMeta(s, profile, ppc, cpf, cpp, header, np.degrees(s.beam_elev_rad), az, 15.806, 0.0,
                         ou.SDK_LIDAR_TO_SENSOR.copy(), init_id, prod_sn)


def _frame(ou, meta, frame_id, rng, zero=0.2):
    """One frame's packets with random pixels (a fraction `zero` of the ranges 0): (payloads, fields by column)."""
    cpf, cpp, ppc = meta.columns_per_frame, meta.columns_per_packet, meta.pixels_per_column
    dual = meta.profile == "RNG19_RFL8_SIG16_NIR16_DUAL"
    shape = (cpf, ppc, 2) if dual else (cpf, ppc)
    if meta.profile == "RNG15_RFL8_NIR8":
        ranges = rng.integers(1, 1 << 15, shape) * 8
    else:
        ranges = rng.integers(1, 1 << (20 if meta.profile == "LEGACY" else 19), shape)
    ranges[rng.random(shape) < zero] = 0
    f = {"ranges_mm": ranges,
         "reflectivity": rng.integers(0, 1 << (16 if meta.profile == "LEGACY" else 8), shape),
         "signal": rng.integers(0, 1 << 16, shape) if meta.profile != "RNG15_RFL8_NIR8" else np.zeros(shape, int),
         "flags": rng.integers(0, {"LEGACY": 16, "RNG15_RFL8_NIR8": 2}.get(meta.profile, 32), shape)}
    pays = [ou.write_packet(meta.profile, ppc, cpf, columns_per_packet=cpp, frame_id=frame_id, first_mid=c0,
                            header=meta.header_type, **{k: v[c0:c0 + cpp] for k, v in f.items()})
            for c0 in range(0, cpf, cpp)]
    return pays, f


def _expected_bam(meta, ring, mid):
    """The decoder's azimuth rule in Python integers: offset - round(m 65536 / W) - round(beam mdeg 1024 / 5625)."""
    w = meta.columns_per_frame
    mdeg = meta.beam_azimuth_mdeg.astype(np.int64)[ring] * 1024
    beam = np.where(mdeg >= 0, (mdeg + 2812) // 5625, -((-mdeg + 2812) // 5625))
    return (meta.azimuth_offset_bam - (mid.astype(np.int64) * 65536 + w // 2) // w - beam) % 65536


@pytest.mark.parametrize("profile", ["LEGACY", "RNG19_RFL8_SIG16_NIR16", "RNG19_RFL8_SIG16_NIR16_DUAL",
                                     "RNG15_RFL8_NIR8"])
def test_synthetic_frames_decode_exactly(ou, profile):
    rng = np.random.default_rng(37)
    for ppc in (16, 32, 64, 128):
        for cpf in (512, 1024, 2048):
            az = rng.uniform(-12, 12, ppc).round(3)
            meta = _meta(ou, profile, ppc, cpf, az_deg=az)
            pays, f = _frame(ou, meta, 7, rng)
            nxt, _ = _frame(ou, meta, 8, rng)
            assert all(len(p) == meta.packet_bytes for p in pays)
            d = ou.decode(pays + nxt[:1], meta)
            assert d.stats["n_decoded"] == len(pays) + 1 and d.stats["n_jumps"] == 0
            # the frame began at measurement id 0 and the next frame id closed it: one COMPLETE scan
            assert d.scan_kinds()[:1] == [ou.SCAN_COMPLETE] and d.stats["n_scans"] == 1
            s0 = d.scan == 0
            assert (d.frame_id[s0] == 7).all() and (d.frame_id[~s0] == 8).all() and (d.packet[~s0] == len(pays)).all()
            ranges = f["ranges_mm"]
            dual = ranges.ndim == 3
            col, row, k = (np.nonzero(ranges) if dual else np.nonzero(ranges) + (None,))
            k = np.zeros(len(col), int) if k is None else k
            order = np.lexsort((k, row, col))  # packet order: column, row, first return before second
            col, row, k = col[order], row[order], k[order]
            assert s0.sum() == len(col), (ppc, cpf)
            idx = (col, row, k) if dual else (col, row)
            assert (d.measurement_id[s0] == col).all() and (d.ring[s0] == row).all()
            assert (d.return_index[s0] == k).all()
            assert (d.range_mm[s0] == ranges[idx]).all()
            assert (d.reflectivity[s0] == f["reflectivity"][idx]).all()
            assert (d.signal[s0] == f["signal"][idx]).all() and (d.flags[s0] == f["flags"][idx]).all()
            assert (d.timestamp_ns[s0] == 10**9 + col * 97656).all()
            assert (d.azimuth[s0] == _expected_bam(meta, row, col)).all()


def test_filters_and_azimuth_frame(ou):
    rng = np.random.default_rng(3)
    meta = _meta(ou, "RNG19_RFL8_SIG16_NIR16_DUAL", 32, 1024, az_deg=np.linspace(-3, 3, 32))
    pays, f = _frame(ou, meta, 1, rng)
    both, first, second = (ou.decode(pays, meta, filt=x) for x in ("both", "first", "second"))
    r = f["ranges_mm"]
    assert len(first.range_mm) == (r[..., 0] > 0).sum() and (first.return_index == 0).all()
    assert len(second.range_mm) == (r[..., 1] > 0).sum() and (second.return_index == 1).all()
    assert len(both.range_mm) == len(first.range_mm) + len(second.range_mm)
    # the azimuth is the direction ouster-sdk gives the pixel (the beam origin offset aside): atan2 of the unit
    # direction of xyz() with a zero origin offset and range, within one BAM16 step
    m0 = _meta(ou, "RNG19_RFL8_SIG16_NIR16", 32, 1024, az_deg=np.linspace(-3, 3, 32))
    m0 = ou.OusterMeta(**{**m0.__dict__, "beam_origin_mm": 0.0})
    ring = np.repeat(np.arange(32), 1024)
    mid = np.tile(np.arange(1024), 32)
    p = ou.xyz(m0, ring, mid, np.full(len(ring), 100000))
    want = np.degrees(np.arctan2(p[:, 1], p[:, 0])) / 360 * 65536
    diff = (want - _expected_bam(m0, ring, mid) + 32768) % 65536 - 32768
    assert np.abs(diff).max() <= 1.0
    # measurement id 0 of a beam without offset looks at lidar +x, i.e. sensor -x (behind: the connector side)
    m1 = ou.OusterMeta(**{**_meta(ou, "LEGACY", 32, 1024).__dict__, "beam_origin_mm": 0.0})
    assert np.allclose(ou.xyz(m1, [0], [0], [10000])[0, :2], [-10 * math.cos(m1.sensor.beam_elev_rad[0]), 0])
    assert ou.decode([ou.write_packet("LEGACY", 32, 1024, ranges_mm=10000)], m1).azimuth[0] == 32768


def test_scan_tracking(ou):
    rng = np.random.default_rng(5)
    meta = _meta(ou, "RNG19_RFL8_SIG16_NIR16", 16, 512)
    f1, _ = _frame(ou, meta, 10, rng)
    f2, _ = _frame(ou, meta, 11, rng)
    f3, _ = _frame(ou, meta, 12, rng)
    # starting mid-frame: PARTIAL, then COMPLETE; a lost packet is counted, the frame still COMPLETE
    d = ou.decode(f1[5:] + f2[:9] + f2[10:] + f3[:2], meta)
    assert d.scan_kinds()[:2] == [ou.SCAN_PARTIAL, ou.SCAN_COMPLETE]
    assert d.stats["n_lost_cols"] == 16 and d.stats["n_jumps"] == 0
    # a frame id jump (two frames lost) aborts the scan in progress
    d = ou.decode(f1 + f3, meta)
    assert d.scan_kinds()[:1] == [ou.SCAN_ABORTED] and d.stats["n_jumps"] == 1
    # the frame id wraps at 2^16
    w1, _ = _frame(ou, meta, 65535, rng)
    w2, _ = _frame(ou, meta, 0, rng)
    d = ou.decode(w1 + w2[:1], meta)
    assert d.scan_kinds()[:1] == [ou.SCAN_COMPLETE] and d.stats["n_jumps"] == 0
    # max_step_cols: a lost packet becomes a jump
    d = ou.decode(f1[:3] + f1[4:], meta, max_step_cols=8)
    assert d.stats["n_jumps"] == 1 and d.scan_kinds()[:1] == [ou.SCAN_ABORTED]
    # a seam at column 256: scans from 256 to 255 of the next frame
    d = ou.decode(f1 + f2 + f3, meta, seam_col=256)
    assert d.scan_kinds()[:3] == [ou.SCAN_PARTIAL, ou.SCAN_COMPLETE, ou.SCAN_COMPLETE]
    s1 = d.scan == 1
    assert d.measurement_id[s1][0] == 256 and d.measurement_id[s1][-1] == 255
    assert (d.frame_id[s1][[0, -1]] == [10, 11]).all()
    # LEGACY: a frame boundary inside a packet (its columns carry their own frame id)
    lm = _meta(ou, "LEGACY", 16, 512)
    pays = [ou.write_packet("LEGACY", 16, 512, frame_id=3, first_mid=c0, ranges_mm=1000) for c0 in range(0, 512, 16)]
    pays += [ou.write_packet("LEGACY", 16, 512, frame_id=3, first_mid=504, ranges_mm=2000)]
    d = ou.decode(pays[:-2] + pays[-1:], lm)  # ... 480..495, then 504..511 + 0..7 of frame 4
    assert d.scan_kinds()[:1] == [ou.SCAN_COMPLETE] and d.stats["n_lost_cols"] == 8
    last = d.packet == len(pays) - 2
    assert d.scan_end[-1] == 8 * 16 and (d.scan[last][: 8 * 16] == 0).all() and (d.scan[last][8 * 16:] == 1).all()
    # two boundaries in one payload: the seam at column 4 of it, then a jump: the columns between are dropped
    frag = ou.write_packet("LEGACY", 16, 512, measurement_ids=[508, 509, 510, 511, 0, 1, 2, 3] + list(range(200, 208)),
                           frame_ids=[3] * 4 + [4] * 12, ranges_mm=1000)
    d = ou.decode(pays[:31] + [frag], lm, max_step_cols=100)
    assert d.stats["n_fragment"] == 4 * 16 and d.stats["n_scans"] == 1 and d.stats["n_aborted"] == 0
    assert d.scan_event[-1] == ou.SCAN_COMPLETE and d.n_returns[-1] == 16 * 16 - 4 * 16


def _rejected(d, i, why, ou):
    assert d.status[i] == LIDET_ERR_MODEL and ou.REJECTS[d.reject[i]] == why, (i, ou.REJECTS[d.reject[i]], why)


def test_rejections(ou):
    meta = _meta(ou, "RNG19_RFL8_SIG16_NIR16", 64, 1024, init_id=0x52DFFC, prod_sn=122150000150)
    f1 = [ou.write_packet("RNG19_RFL8_SIG16_NIR16", 64, 1024, frame_id=5, first_mid=c0, ranges_mm=3000,
                          init_id=0x52DFFC, prod_sn=122150000150) for c0 in range(0, 1024, 16)]
    good = f1[1]

    def variant(**kw):
        a = dict(frame_id=5, first_mid=32, ranges_mm=3000, init_id=0x52DFFC, prod_sn=122150000150)
        a.update(kw)
        return ou.write_packet("RNG19_RFL8_SIG16_NIR16", 64, 1024, **a)

    stream = [f1[0], good,                              # 0, 1: decoded
              good[:-1], b"", good[:48],                 # 2-4: truncated (a cut datagram, empty, an IMU packet's size)
              good + b"\0",                              # 5: size
              ou.write_packet("LEGACY", 64, 1024, first_mid=32),  # 6: size (12608 bytes: LEGACY 64 beams)
              ou.write_packet("RNG15_RFL8_NIR8", 64, 1024, first_mid=32),  # 7: truncated (4352 bytes)
              variant(packet_type=2),                    # 8: header
              variant(init_id=0x111111),                 # 9: header (another sensor's init id)
              variant(prod_sn=1234),                     # 10: header (another serial number)
              variant(measurement_ids=np.arange(1020, 1036)),  # 11: header (measurement id >= 1024)
              variant(valid=np.zeros(16, bool)),         # 12: status (no valid column)
              good,                                      # 13: order (repeated)
              f1[0],                                     # 14: order (late)
              variant(frame_id=4),                       # 15: order (the frame before)
              variant(measurement_ids=np.arange(47, 31, -1)),  # 16: order (inside the payload)
              f1[2]]                                     # 17: decoded: the stream resumes
    d = ou.decode(stream, meta)
    for i, why in [(2, "truncated"), (3, "truncated"), (4, "truncated"), (5, "size"), (6, "size"), (7, "truncated"),
                   (8, "header"), (9, "header"), (10, "header"), (11, "header"), (12, "status"), (13, "order"),
                   (14, "order"), (15, "order"), (16, "order")]:
        _rejected(d, i, why, ou)
    assert (d.status[[0, 1, 17]] == LIDET_OK).all() and d.stats["n_decoded"] == 3
    assert d.stats["n_jumps"] == 0 and d.stats["n_lost_cols"] == 0 and len(d.range_mm) == 3 * 16 * 64
    # without the sensor check, another init id / serial number decodes
    d = ou.decode([f1[0], variant(init_id=0x111111, prod_sn=1234)], meta, check_sensor=False)
    assert d.stats["n_decoded"] == 2
    # some invalid columns: skipped and counted, the rest decoded
    d = ou.decode([variant(valid=np.arange(16) % 3 != 0)], meta)
    assert d.stats["n_invalid_cols"] == 6 and len(d.range_mm) == 10 * 64
    # LEGACY: an encoder count past a turn, an invalid status word
    lm = _meta(ou, "LEGACY", 32, 1024)
    d = ou.decode([ou.write_packet("LEGACY", 32, 1024, encoder=np.full(16, 90112), ranges_mm=1),
                   ou.write_packet("LEGACY", 32, 1024, valid=np.zeros(16, bool), ranges_mm=1)], lm)
    _rejected(d, 0, "header", ou)
    _rejected(d, 1, "status", ou)
    # FUSA header: 8-bit type, 32-bit frame id (ouster-sdk's reading of header_type FUSA)
    fm = _meta(ou, "RNG19_RFL8_SIG16_NIR16", 16, 512, header="FUSA")
    pays = [ou.write_packet("RNG19_RFL8_SIG16_NIR16", 16, 512, frame_id=70000 + k // 32, first_mid=(16 * k) % 512,
                            ranges_mm=500, header="FUSA", init_id=0x123456) for k in range(33)]
    d = ou.decode(pays, fm)
    assert d.stats["n_decoded"] == 33 and d.scan_kinds()[:1] == [ou.SCAN_COMPLETE] and d.frame_id[0] == 70000
    d = ou.decode(pays, _meta(ou, "RNG19_RFL8_SIG16_NIR16", 16, 512))  # read as STANDARD: packet type 0x5601
    assert d.stats["n_rejected_header"] == 33


def test_garbage_never_crashes(ou):
    rnd = random.Random(37)
    for profile, ppc in [("LEGACY", 16), ("RNG19_RFL8_SIG16_NIR16", 32), ("RNG19_RFL8_SIG16_NIR16_DUAL", 64),
                         ("RNG15_RFL8_NIR8", 128)]:
        meta = _meta(ou, profile, ppc, 1024)
        n = meta.packet_bytes
        junk = [bytes(rnd.randrange(256) for _ in range(k)) for k in (0, 1, 31, 32, 100, n - 1, n + 1, 65535)]
        junk += [bytes(rnd.randrange(256) for _ in range(n)) for _ in range(40)]
        # right-sized garbage with a valid packet type and valid columns (the checks that remain: ids, order)
        for _ in range(40):
            b = bytearray(rnd.randrange(256) for _ in range(n))
            if profile != "LEGACY":
                b[0:2] = b"\x01\x00"
            junk.append(bytes(b))
        d = ou.decode(junk, meta)
        st = d.stats
        assert st["n_packets"] == len(junk)
        assert st["n_decoded"] + sum(st[f"n_rejected_{r}"] for r in ou.REJECTS[1:]) == len(junk)
        assert (d.ring < ppc).all() and (d.measurement_id < 1024).all()
        assert st["n_returns"] == len(d.range_mm)


def test_capacity_smaller_than_a_packet(ou):
    rng = np.random.default_rng(9)
    for profile in ("RNG19_RFL8_SIG16_NIR16_DUAL", "LEGACY"):
        meta = _meta(ou, profile, 64, 1024)
        pays, _ = _frame(ou, meta, 2, rng, zero=0.0)
        nxt, _ = _frame(ou, meta, 3, rng, zero=0.0)
        full = ou.decode(pays + nxt[:1], meta)
        small = ou.decode(pays + nxt[:1], meta, cap=100)  # a packet holds 16 x 64 pixels (x 2 returns)
        per = 16 * 64 * (2 if "DUAL" in profile else 1)
        assert (small.status == LIDET_TRUNCATED).all() and (small.n_returns == 100).all()
        assert small.stats["n_truncated"] == len(small.n_returns) * (per - 100)
        # the first 100 of each packet are the full decode's, and the scan tracking is the same
        for i in range(len(pays) + 1):
            assert (small.range_mm[small.packet == i] == full.range_mm[full.packet == i][:100]).all()
        assert list(small.scan_event) == list(full.scan_event)
        # the scan boundary falls past the cap: scan_end says where it would be
        assert small.scan_end[-1] == 0 and full.scan_end[-1] == 0
        zero = ou.decode(pays[:2], meta, cap=1)
        assert zero.stats["n_returns"] == 2 and zero.stats["n_truncated"] == 2 * (per - 1)


# ---- the real captures ------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def caps(ou):
    if not (PACKETS / "OS-2-128-U1_v2.3.0_1024x10.pcap").exists():
        pytest.skip(f"Ouster captures not available at {PACKETS}")
    from lidet_tools import velodyne
    out = {}
    for name, (mf, profile, beams) in CAPTURES.items():
        meta = ou.load_metadata(PACKETS / mf)
        assert meta.profile == profile and meta.pixels_per_column == beams and meta.columns_per_frame == 1024
        pkts = velodyne.read_pcap_payloads(PACKETS / f"{name}.pcap")
        pay = [p for _, port, p in pkts if port == meta.udp_port_lidar]
        assert {port for _, port, _ in pkts} <= {7502, 7503} and len(pay) == 64  # lidar 7502, IMU 7503
        out[name] = (meta, pay, ou.decode(pay, meta))
    return out


def test_captures_one_frame_each(ou, caps):
    for name, (meta, pay, d) in caps.items():
        st = d.stats
        assert st["n_decoded"] == 64 and st["n_invalid_cols"] == 0 and st["n_lost_cols"] == 0, name
        assert st["n_jumps"] == 0 and (d.scan == 0).all() and len(np.unique(d.frame_id)) == 1, name
        # every column holds returns, except in the OS1-64's (indoors: walls at 2 to 7 m on 568 columns)
        assert len(np.unique(d.measurement_id)) == (568 if name.startswith("OS-1-64") else 1024), name
        assert np.median(d.range_mm) > 1000 and d.range_mm.max() < (1 << 19), name
        # the digests' frame id; LEGACY columns all carry it too
        dg = PACKETS / f"{name}_digest.json"
        if dg.exists():
            assert int(json.loads(dg.read_text())["scans"][0]["FRAME_ID"]) == d.frame_id[0], name
    # the IMU packets on 7503 are not lidar packets: rejected by size
    from lidet_tools import velodyne
    meta, _, _ = caps["OS-2-128-U1_v2.3.0_1024x10"]
    imu = [p for _, port, p in velodyne.read_pcap_payloads(PACKETS / "OS-2-128-U1_v2.3.0_1024x10.pcap")
           if port == 7503]
    assert len(imu) == 10 and ou.decode(imu, meta).stats["n_rejected_truncated"] == 10


def test_captures_match_sdk_digests(ou, caps):
    """ouster-sdk's digest hashes each field as its packet_format reads it: md5 over packets of the (beams x 16)
    uint32 RANGE image, and md5 of the frame's (beams x 1024) image. Both are rebuilt from the decoded returns
    (zero where no return), so equal hashes mean every pixel's range is ouster-sdk's, zeros included."""
    checked = 0
    for name, (meta, pay, d) in caps.items():
        path = PACKETS / f"{name}_digest.json"
        if not path.exists():
            continue
        dg = json.loads(path.read_text())
        fields = ["RANGE", "RANGE2"] if "RANGE2" in dg["packet_hash"] else ["RANGE"]
        h, w = meta.pixels_per_column, meta.columns_per_frame
        for k, f in enumerate(fields):
            ph = hashlib.md5()
            frame = np.zeros((h, w), np.uint32)
            for i in range(len(pay)):
                sel = (d.packet == i) & (d.return_index == k)
                img = np.zeros((h, 16), np.uint32)
                img[d.ring[sel], d.measurement_id[sel] - 16 * i] = d.range_mm[sel]
                ph.update(img.tobytes())
                frame[d.ring[sel], d.measurement_id[sel]] = d.range_mm[sel]
            assert ph.hexdigest() == dg["packet_hash"][f], (name, f)
            assert hashlib.md5(frame.tobytes()).hexdigest() == dg["scans"][0][f], (name, f)
            checked += 1
        # the frame's measurement ids and column timestamps (every column holds a return here)
        mid = np.zeros(w, np.uint16)
        ts = np.zeros(w, np.uint64)
        mid[d.measurement_id] = d.measurement_id
        ts[d.measurement_id] = d.timestamp_ns
        assert hashlib.md5(mid.tobytes()).hexdigest() == dg["scans"][0]["MEASUREMENT_ID"], name
        assert hashlib.md5(ts.tobytes()).hexdigest() == dg["scans"][0]["TIMESTAMP"], name
    assert checked == 5  # RANGE of the four captures with a digest, RANGE2 of the dual one


def _sdk():
    core = pytest.importorskip("ouster.sdk.core", reason="ouster-sdk not installed (requirements-ouster.txt)")
    warnings.filterwarnings("ignore", category=FutureWarning, module="ouster")
    return core


def test_captures_match_ouster_sdk(ou, caps):
    """ouster-sdk (its packet_format and XYZLut) as the reference: the same range at every pixel (zero where the
    decoder emits nothing), x, y, z within 1 mm."""
    core = _sdk()
    for name, (meta, pay, d) in caps.items():
        worst = 0.0
        info = core.SensorInfo((PACKETS / CAPTURES[name][0]).read_text())
        pf = core.PacketFormat(info)
        fields = ["RANGE", "RANGE2"] if "RANGE2" in pf.fields else ["RANGE"]
        lut = core.XYZLut(info, use_extrinsics=False)
        for k, f in enumerate(fields):
            ref = np.zeros((info.h, info.w), np.uint32)
            for p in pay:
                ref[:, pf.packet_header(core.ColHeader.MEASUREMENT_ID, p)] = pf.packet_field(f, p)
            sel = d.return_index == k
            mine = np.zeros_like(ref)
            mine[d.ring[sel], d.measurement_id[sel]] = d.range_mm[sel]
            assert np.array_equal(mine, ref), (name, f)
            assert sel.sum() == (ref > 0).sum()
            pts = lut(ref)[d.ring[sel], d.measurement_id[sel]]
            err = np.linalg.norm(d.xyz[sel] - pts, axis=1)
            assert err.max() < 0.001, (name, f, err.max())
            worst = max(worst, float(err.max()))
        print(f"{name}: {len(d.range_mm)} returns, ranges equal to ouster-sdk's, xyz max error {worst:.2g} m")


def test_writer_matches_ouster_sdk(ou):
    """The packet writer of these tests lays fields out as ouster-sdk's packet_format reads them."""
    core = _sdk()
    rng = np.random.default_rng(21)
    base = json.loads((ROOT / "tests" / "data" / "sensors" / "ouster_nested.json").read_text())
    for profile in ou.PROFILES:
        for header in ("STANDARD", "FUSA") if profile != "LEGACY" else ("STANDARD",):
            meta = _meta(ou, profile, 32, 1024, header=header)
            pays, f = _frame(ou, meta, 9, rng)
            if profile == "LEGACY":  # ouster-sdk 1.0 reads 8 bits of LEGACY's 16-bit reflectivity (firmware >= 2.1)
                f["reflectivity"] %= 256
                pays = [ou.write_packet(profile, 32, 1024, frame_id=9, first_mid=c0, **{k: v[c0:c0 + 16]
                                                                                      for k, v in f.items()})
                        for c0 in range(0, 1024, 16)]
            j = json.loads(json.dumps(base))
            j["lidar_data_format"].update({"udp_profile_lidar": profile, "columns_per_frame": 1024,
                                           "pixels_per_column": 32, "columns_per_packet": 16,
                                           "column_window": [0, 1023], "pixel_shift_by_row": [0] * 32,
                                           "header_type": header})
            j["config_params"].update({"lidar_mode": "1024x10", "udp_profile_lidar": profile})
            j["beam_intrinsics"]["beam_altitude_angles"] = list(meta.beam_altitude_deg)
            j["beam_intrinsics"]["beam_azimuth_angles"] = [0.0] * 32
            pf = core.PacketFormat(core.SensorInfo(json.dumps(j)))
            assert pf.lidar_packet_size == meta.packet_bytes
            rfield = {"RANGE": 0, "RANGE2": 1}
            for i, p in enumerate(pays[:4]):
                assert pf.frame_id(p) == 9
                mids = pf.packet_header(core.ColHeader.MEASUREMENT_ID, p)
                assert (mids == np.arange(16 * i, 16 * i + 16)).all()
                for name, k in rfield.items():
                    if name in pf.fields:
                        r = f["ranges_mm"][16 * i:16 * i + 16]
                        assert (pf.packet_field(name, p).T == (r[..., k] if r.ndim == 3 else r)).all(), profile
                for name, key in (("REFLECTIVITY", "reflectivity"), ("FLAGS", "flags"), ("SIGNAL", "signal")):
                    if name in pf.fields:
                        v = f[key][16 * i:16 * i + 16]
                        assert (pf.packet_field(name, p).T == (v[..., 0] if v.ndim == 3 else v)).all(), (profile, name)


def test_decoded_frames_run_through_detector(ou, caps):
    """A decoded OS0 / OS1 / OS2 frame, its points (x, y, z of the decoder's returns) detected with the sensor of
    its metadata: it runs and the counts are sane (the three street scenes: ground found, a few detections; the
    OS1-64's indoor scene, walls without a floor in view: it runs)."""
    from lidet_tools import native
    for name in ("OS-0-128-U1_v2.3.0_1024x10", "OS-1-32-G_v2.1.1_1024x10", "OS-2-128-U1_v2.3.0_1024x10",
                 "OS-1-64_1024x10_fw20"):
        meta, _, d = caps[name]
        pts = np.concatenate([d.xyz, d.reflectivity[:, None] / 255.0], axis=1).astype(np.float32)
        det = native.detect(pts, meta.sensor)
        n = len(pts)
        ground = det.point_ground.mean()
        print(f"{name}: {n} points, ground {ground:.2f}, {len(det.outcome)} clusters, {len(det.cls)} detections "
              f"({np.bincount(det.cls, minlength=3).tolist()} car/cyclist/pedestrian)")
        assert len(det.point_ground) == n and len(det.outcome) >= 1 and len(det.cls) <= 64
        if not name.startswith("OS-1-64"):
            assert 0.03 < ground < 0.95 and len(det.cls) >= 1
        assert np.isfinite(det.box).all() and (np.abs(det.box[:, :3]) < 150).all()


def test_load_metadata(ou, tmp_path):
    """The packet format from each metadata layout; ouster-sdk's defaults where a field is absent."""
    m = ou.load_metadata(ROOT / "tests" / "data" / "sensors" / "ouster_nested.json")
    assert (m.profile, m.pixels_per_column, m.columns_per_frame, m.columns_per_packet) == \
        ("RNG19_RFL8_SIG16_NIR16", 32, 2048, 16)
    assert m.header_type == "STANDARD" and m.packet_bytes == 6400 and m.azimuth_offset_bam == 32768
    nested = json.loads((ROOT / "tests" / "data" / "sensors" / "ouster_nested.json").read_text())
    assert m.beam_origin_mm == nested["beam_intrinsics"]["beam_to_lidar_transform"][3]
    assert np.array_equal(m.lidar_to_sensor.ravel(), nested["lidar_intrinsics"]["lidar_to_sensor_transform"])
    assert m.init_id == 0 and m.prod_sn == 0  # "000000000000": unknown, not checked
    # the flat layout of older firmware: LEGACY, 16 columns per packet, ouster-sdk's beam origin and transform
    flat = {"beam_altitude_angles": list(np.linspace(10, -10, 16)), "beam_azimuth_angles": [1.5] * 16,
            "lidar_mode": "512x20"}
    (tmp_path / "flat.json").write_text(json.dumps(flat))
    f = ou.load_metadata(tmp_path / "flat.json")
    assert (f.profile, f.columns_per_frame, f.columns_per_packet, f.packet_bytes) == ("LEGACY", 512, 16, 3392)
    assert f.beam_origin_mm == ou.SDK_BEAM_ORIGIN_MM and np.array_equal(f.lidar_to_sensor, ou.SDK_LIDAR_TO_SENSOR)
    assert (f.beam_azimuth_mdeg == 1500).all()
    # a turned lidar-to-sensor transform sets the decoder's azimuth offset; a tilted one is refused
    flat["lidar_to_sensor_transform"] = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 36.18, 0, 0, 0, 1]
    flat["udp_profile_lidar"] = "RNG15_RFL8_NIR8"
    (tmp_path / "flat.json").write_text(json.dumps(flat))
    f = ou.load_metadata(tmp_path / "flat.json")
    assert f.azimuth_offset_bam == 0 and f.profile == "RNG15_RFL8_NIR8"
    flat["lidar_to_sensor_transform"] = [1, 0, 0, 0, 0, 0, -1, 0, 0, 1, 0, 0, 0, 0, 0, 1]
    (tmp_path / "flat.json").write_text(json.dumps(flat))
    with pytest.raises(ValueError, match="not a turn about z"):
        _ = ou.load_metadata(tmp_path / "flat.json").azimuth_offset_bam
    flat["udp_profile_lidar"] = "FIVE_WORD_PIXEL"
    (tmp_path / "flat.json").write_text(json.dumps(flat))
    with pytest.raises(ValueError, match="is not decoded"):
        ou.load_metadata(tmp_path / "flat.json")
