# SPDX-License-Identifier: MIT
"""HDL-64E dual-return payloads (lib/src/decode/lidet_velodyne.c; docs/DECODING.md, "HDL-64E", "Dual return"),
written by lidet_tools.velodyne.hdl64e_dual_packets over the simulated HDL-64 scan of tests/data, through a pcap file
and back, decoded through the bindings with every filter: every return is the simulated one (range in 2 mm steps,
ring, firing time, azimuth of the rule, intensity, flags) in packet order, computed here from the scenes by the
documented rule without the writer's code. Always run (no real HDL-64E dual capture is available). With
velodyne_decoder installed (requirements-velodyne.txt; skipped without it), its decoding of the same payloads gives
the same returns, and the same last returns.

The layout decoded: per firing four blocks at one azimuth, upper and lower bank of the strongest return, then upper
and lower bank of the last return; three firings a payload, 57.6 us a firing. A laser with one return repeats it in
both pairs. Filters: both (the last return, and the other one where its distance differs), last, strongest (the
return of higher intensity; tie: the last)."""
import math

import numpy as np
import pytest

# the single-return tests' simulated scan, first payload (0.08 deg before the seam) and decoder fixture
from test_velodyne_decode import START64 as START  # noqa: E402
from test_velodyne_decode import _sim64, vdec  # noqa: E402,F401

N_PK = 1400    # 4200 firings: 2.1 rotations, crossing the seam 3 times
L, S = 1, 2    # FLAG_LAST, FLAG_STRONGEST


@pytest.fixture(scope="module")
def vd(vdec):
    return vdec


def _scenes(vd):
    """Two rotations (the second sees the scan 0.5 m further on): the last returns (the scene), the strongest pair's
    returns (a nearer echo in a fifth of the cells, an echo at the same distance in another fifth, an echo where the
    scene has none in a few, else 0: one return, repeated) and both pairs' intensities (random, some tied)."""
    pts, ring = _sim64()
    shifted = pts.copy()
    shifted[:, 0] -= 0.5
    last = [vd.hdl64e_grid(pts, ring), vd.hdl64e_grid(shifted, ring)]
    rng = np.random.default_rng(64)
    strong, i_last, i_strong = [], [], []
    for g in last:
        col, rr = np.meshgrid(np.arange(g.shape[0]), np.arange(64), indexing="ij")
        sel = (col * 7 + rr * 3) % 5
        s = np.where((sel == 0) & (g > 3000), g * 3 // 5, 0)           # a nearer echo (glass, foliage)
        s = np.where((sel == 1) & (g > 0), g, s)                         # the same distance: one return
        s = np.where((g == 0) & ((col + rr) % 97 == 0), 2500 + rr, s)    # an echo only in the strongest pair
        il = rng.integers(0, 256, g.shape)
        ist = np.where(rng.random(g.shape) < 0.1, il, rng.integers(0, 256, g.shape))  # ties
        strong.append(s)
        i_last.append(il)
        i_strong.append(ist)
    return last, strong, i_last, i_strong


def _rule_cdeg(az, step, off_units, firing_units):
    """The interpolation rule (docs/DECODING.md): the firing's azimuth plus step x off / firing, in 1/240 of
    0.01 deg rounded half up, then rounded to 0.01 deg."""
    fine = az * 240 + (step * 240 * off_units + firing_units // 2) // firing_units
    return ((fine % (36000 * 240)) + 120) // 240 % 36000


def _expected(vd, last, strong, i_last, i_strong, filt, n_packets=N_PK, step=18, start=START):
    """The returns a filter must give, in output order (firing by firing, upper bank then lower, laser by laser; per
    laser the last return first), as dict of arrays: packet, laser, range_mm, t_ns, azimuth_cdeg, intensity, flags."""
    k, f, bank, j = np.meshgrid(np.arange(n_packets), np.arange(3), np.arange(2), np.arange(32), indexing="ij")
    k, f, bank, j = (a.reshape(-1) for a in (k, f, bank, j))
    laser = 32 * bank + j
    a = start + step * (3 * k + f)
    rot = np.minimum(a // 36000, len(last) - 1)
    az = a % 36000
    col = az * last[0].shape[0] // 36000
    cell = (rot, col, 63 - np.array(vd.HDL64E_LASER_RING)[laser])  # the simulator's rings: from the top
    rl, rs = np.stack(last)[cell], np.stack(strong)[cell]
    il, ist = np.stack(i_last)[cell], np.stack(i_strong)[cell]
    d0 = rl // 2                                   # the last pair
    d1 = np.where(rs > 0, rs // 2, d0)             # the strongest pair (a lone return repeated)
    i1 = np.where(rs > 0, ist, il)
    second = (d1 != 0) & (d1 != d0)
    second_strong = second & ((d0 == 0) | (i1 > il))
    if filt == "strongest":
        keep0, keep1 = (d0 != 0) & ~second_strong, second_strong
    else:
        keep0, keep1 = d0 != 0, second & (filt == "both")
    flags0 = np.where(second_strong, L, L | S)
    flags1 = np.where(second_strong, S, 0)
    off = np.array(vd.HDL64E_OFF_UNITS)[j]
    per = dict(packet=k, laser=laser, t_ns=f * 57600 + off * vd.HDL64E_DUAL_UNIT_NS,
               azimuth_cdeg=_rule_cdeg(az, step, off, vd.HDL64E_FIRING_UNITS))
    out = {n: np.stack([v, v], axis=1) for n, v in per.items()}
    out.update(range_mm=np.stack([2 * d0, 2 * d1], axis=1), intensity=np.stack([il, i1], axis=1),
               flags=np.stack([flags0, flags1], axis=1))
    keep = np.stack([keep0, keep1], axis=1).reshape(-1)
    return {n: v.reshape(-1)[keep] for n, v in out.items()}


@pytest.fixture(scope="module")
def capture(vd, tmp_path_factory):
    """The dual-return capture as a pcap (a position packet and an ARP frame among its frames), read back."""
    last, strong, i_last, i_strong = _scenes(vd)
    pk = vd.hdl64e_dual_packets(last, strong, N_PK, start_cdeg=START, t0_us=3_599_900_000,
                                last_intensity=i_last, strongest_intensity=i_strong)
    frames = []
    for i, (_, p) in enumerate(pk):
        frames.append(vd.udp_frame(p))
        if i == 10:
            frames.append(vd.udp_frame(bytes(512), dport=8308))
        if i == 20:
            frames.append(b"\xff" * 6 + b"\x00" * 6 + b"\x08\x06" + bytes(28))
    path = tmp_path_factory.mktemp("hdl64_dual") / "hdl64e_dual.pcap"
    vd.write_pcap(path, frames, times_s=[1_700_000_000 + 1.728e-4 * i for i in range(len(frames))])
    pay = [p for _, port, p in vd.read_pcap_payloads(path) if port == 2368]
    assert len(pay) == N_PK and pay == [p for _, p in pk]
    return (last, strong, i_last, i_strong), pay


def test_layout_written(vd, capture):
    """What the writer puts in a payload: four blocks a firing at one azimuth (upper, lower, upper, lower flags),
    three firings 0.18 deg apart, the strongest pair first; the timestamp wraps at the hour."""
    import struct
    _, pay = capture
    p = pay[0]
    flags = [struct.unpack("<H", p[100 * b:100 * b + 2])[0] for b in range(12)]
    az = [struct.unpack("<H", p[100 * b + 2:100 * b + 4])[0] for b in range(12)]
    assert flags == [0xEEFF, 0xDDFF] * 6
    assert az == [START] * 4 + [START + 18] * 4 + [START + 36] * 4
    t = [struct.unpack("<I", q[1200:1204])[0] for q in pay[:600]]
    assert t[0] == 3_599_900_000 % 3_600_000_000 and min(t) < 100_000  # wrapped


@pytest.mark.parametrize("filt", ["both", "last", "strongest"])
def test_dual_capture_decodes_exactly(vd, capture, filt):
    """Every return of each filter is the simulated one: range, ring (the hdl64 preset's, ring_top_first), firing time
    (57.6 us firings), azimuth by the rule, intensity and flags, in packet order; the payloads say dual return."""
    scenes, pay = capture
    d = vd.decode(pay, filt=filt, ring_top_first=True)
    st = d.stats
    assert st["n_decoded"] == N_PK and st["n_jumps"] == 0 and st["n_truncated"] == 0
    assert sum(st[f"n_rejected_{r}"] for r in vd.REJECTS[1:]) == 0
    want = _expected(vd, *scenes, filt)
    assert len(d.range_mm) == len(want["range_mm"])
    np.testing.assert_array_equal(d.packet, want["packet"])
    np.testing.assert_array_equal(d.range_mm, want["range_mm"])
    np.testing.assert_array_equal(d.ring, 63 - np.array(vd.HDL64E_LASER_RING)[want["laser"]])
    np.testing.assert_array_equal(d.t_ns, want["t_ns"])
    np.testing.assert_array_equal(d.azimuth_cdeg, want["azimuth_cdeg"])
    np.testing.assert_array_equal(d.intensity, want["intensity"])
    np.testing.assert_array_equal(d.flags, want["flags"])
    # every case occurs: two distinct returns (the other stronger, or weaker), one return, the strongest pair only
    if filt == "both":
        assert {0, L, S, L | S} <= set(np.unique(d.flags).tolist())
    assert (d.range_mm > 0).all()
    # x, y, z from the nominal elevation of each ring (numbered from the top)
    e = np.radians(np.array(vd.HDL64E_ELEV_MDEG)[63 - d.ring] / 1000.0)
    a = d.azimuth.astype(np.float64) * (2 * np.pi / 65536)
    r = d.range_mm / 1000.0
    np.testing.assert_allclose(d.xyz, np.stack([r * np.cos(e) * np.cos(a), r * np.cos(e) * np.sin(a),
                                                r * np.sin(e)], axis=1), rtol=0, atol=1e-4)


def test_dual_rotation_is_the_scene(vd, capture):
    """The complete rotation (scan 1) with the last returns is every cell of its scene once; with both returns, the
    scene's cells plus every distinct echo of the strongest pair, once each."""
    (last, strong, _, _), pay = capture
    dl = vd.decode(pay, filt="last", ring_top_first=True)
    assert dl.scan_kinds()[:3] == [vd.SCAN_PARTIAL, vd.SCAN_COMPLETE, vd.SCAN_COMPLETE]
    assert dl.stats["n_scans"] == 2
    sel = dl.scan == 1
    assert sel.sum() == (last[1] > 0).sum()
    firing = dl.packet[sel].astype(np.int64) * 3 + dl.t_ns[sel] // 57600
    col = (START + 18 * firing) % 36000 // 18
    assert col.min() == 0 and col.max() == 1999 and len(set(zip(col, dl.ring[sel]))) == sel.sum()
    np.testing.assert_array_equal(dl.range_mm[sel], last[1][col, dl.ring[sel]] // 2 * 2)
    db = vd.decode(pay, filt="both", ring_top_first=True)
    distinct = (strong[1] > 0) & (strong[1] // 2 != last[1] // 2)
    assert (db.scan == 1).sum() == (last[1] > 0).sum() + distinct.sum()


def test_dual_agrees_with_velodyne_decoder(vd, capture, tmp_path):
    """velodyne_decoder (pip install -r requirements-velodyne.txt; skipped without it), as an HDL-64E S2 with the
    nominal table as its calibration, on the first 300 payloads (no seam): the same returns (ring, range, position
    within 0.01 deg x range), and its last returns are the decoder's with filt="last"; so it reads the pairs the
    same way round (the strongest first) and drops a repeated return as both does."""
    vdd = pytest.importorskip("velodyne_decoder")
    _, pay = capture
    pay = pay[34:334]  # firings from 8.28 deg to 170.1 deg
    lines = ["num_lasers: 64", "distance_resolution: 0.002", "lasers:"]
    for i in range(64):
        e = vd.HDL64E_ELEV_MDEG[vd.HDL64E_LASER_RING[i]] / 1000.0
        lines.append(f"- {{laser_id: {i}, vert_correction: {math.radians(e)!r}, rot_correction: 0.0, "
                     f"dist_correction: 0.0}}")
    path = tmp_path / "hdl64e_nominal.yaml"
    path.write_text("\n".join(lines) + "\n")
    cfg = vdd.Config(model=vdd.Model.HDL64E_S2, calibration=vdd.Calibration.read(str(path)))
    cfg.min_range, cfg.max_range = 0.0, 1000.0
    packets = vdd.PacketVector()
    for i, p in enumerate(pay):
        packets.append(vdd.VelodynePacket(i * 172.8e-6, p))
    _, cloud = vdd.ScanDecoder(cfg).decode(packets)
    cloud = np.asarray(cloud, np.float64)
    theirs = np.lexsort((np.round(np.linalg.norm(cloud[:, :3], axis=1) * 1000), cloud[:, 6], cloud[:, 5]))
    cloud = cloud[theirs]
    for filt in ("both", "last"):
        d = vd.decode(pay, filt=filt)
        firing = d.packet.astype(np.int64) * 3 + d.t_ns // 57600
        ours = np.lexsort((d.range_mm, d.ring, firing))
        c = cloud if filt == "both" else cloud[(cloud[:, 7].astype(np.int64) & int(vdd.ReturnMode.LAST.value)) != 0]
        assert len(c) == len(d.range_mm), (filt, len(c), len(d.range_mm))
        np.testing.assert_array_equal(c[:, 5].astype(np.int64), firing[ours])
        np.testing.assert_array_equal(c[:, 6].astype(np.int64), d.ring[ours])
        r = d.range_mm[ours] / 1000.0
        np.testing.assert_allclose(np.linalg.norm(c[:, :3], axis=1), r, rtol=0, atol=1e-4)
        err = np.linalg.norm(d.xyz[ours].astype(np.float64) - c[:, :3], axis=1)
        assert (err <= 1e-4 + r * math.radians(0.01)).all(), float((err / r).max())
