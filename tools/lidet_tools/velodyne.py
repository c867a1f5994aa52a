# SPDX-License-Identifier: MIT
"""Velodyne captures: a classic libpcap reader for the sensors' UDP payloads, and the C packet decoder
(lib/src/decode/lidet_velodyne.c, docs/DECODING.md) run over a whole capture through the bindings.

    payloads = read_pcap_payloads("vlp16_dual.pcap")            # [(time_s, udp_port, bytes), ...]
    d = decode([p for _, _, p in payloads], model="auto")       # numpy arrays, one entry per return
    d.xyz[d.scan == 3]                                           # x y z (m) of the returns of scan 3
    cal = sensors.load_velodyne_calibration("db.xml")            # a unit's calibration, applied by the decoder:
    d = decode(payloads, model="hdl64e", calibration=cal)        # azimuth and distance corrections, rings by its
                                                                 # elevations

Writers for the tests: synthetic VLP-16 and HDL-64E payloads over a simulated scene (vlp16_packets,
hdl64e_packets; hdl64e_dual_packets for the HDL-64E's dual-return layout) and classic pcap files (udp_frame,
write_pcap).
"""
from __future__ import annotations

import ctypes as C
import struct
from dataclasses import dataclass

import numpy as np

from lidet_tools import native

MODELS = {"auto": 0, "hdl32e": 0x21, "vlp16": 0x22, "vlp32c": 0x28, "hdl64e": 0x64}
FILTERS = {"both": 0, "strongest": 1, "last": 2}
SCAN_NONE, SCAN_COMPLETE, SCAN_PARTIAL, SCAN_ABORTED = 0, 1, 2, 3
REJECTS = ("none", "null", "size", "flag", "product", "mode", "azimuth", "unsupported")
STATS = ("n_packets", "n_decoded") + tuple(f"n_rejected_{r}" for r in REJECTS) + (
    "n_returns", "n_truncated", "n_jumps", "n_scans", "n_partial", "n_aborted", "n_fragment", "n_short_range")
FLAG_LAST, FLAG_STRONGEST = 1, 2
#: lasers of each model (the rows of its calibration table)
N_LASERS = {"hdl32e": 32, "vlp16": 16, "vlp32c": 32, "hdl64e": 64}
#: the distance unit of each model's packets, mm (a calibration's distance resolution must be it)
DIST_UNIT_MM = {"hdl32e": 2, "vlp16": 2, "vlp32c": 4, "hdl64e": 2}


def read_pcap_payloads(path) -> list[tuple[float, int, bytes]]:
    """UDP payloads of a classic libpcap file (Ethernet / IPv4 / UDP; other frames skipped): (time, dst port, bytes)."""
    data = open(path, "rb").read()
    magic = data[:4]
    if magic in (b"\xd4\xc3\xb2\xa1", b"\x4d\x3c\xb2\xa1"):
        end, frac = "<", 1e-6 if magic[0] == 0xD4 else 1e-9
    elif magic in (b"\xa1\xb2\xc3\xd4", b"\xa1\xb2\x3c\x4d"):
        end, frac = ">", 1e-6 if magic[3] == 0xD4 else 1e-9
    else:
        raise ValueError(f"{path}: not a classic pcap file")
    linktype = struct.unpack(end + "I", data[20:24])[0]
    if linktype != 1:
        raise ValueError(f"{path}: link type {linktype}, only Ethernet (1) is read")
    out, off = [], 24
    while off + 16 <= len(data):
        sec, sub, incl, _ = struct.unpack(end + "IIII", data[off:off + 16])
        frame = data[off + 16:off + 16 + incl]
        off += 16 + incl
        if len(frame) < 42 or frame[12:14] != b"\x08\x00" or frame[23] != 17:
            continue
        ihl = (frame[14] & 15) * 4
        udp = 14 + ihl
        port = struct.unpack(">H", frame[udp + 2:udp + 4])[0]
        ulen = struct.unpack(">H", frame[udp + 4:udp + 6])[0]
        out.append((sec + sub * frac, port, frame[udp + 8:udp + max(ulen, 8)]))
    return out


@dataclass
class Decoded:
    """One entry per return, in decoding order; events / scan_end / reject per payload; stats by STATS name."""
    range_mm: np.ndarray
    azimuth: np.ndarray       # BAM16, counterclockwise from +x
    ring: np.ndarray
    t_ns: np.ndarray          # after the payload's timestamp
    azimuth_cdeg: np.ndarray  # Velodyne azimuth (clockwise), 0.01 deg
    intensity: np.ndarray
    flags: np.ndarray
    packet: np.ndarray        # index of the payload
    scan: np.ndarray          # 0 = the scan in progress at the start, +1 at each scan event
    xyz: np.ndarray           # (n, 3) float32, metres
    scan_event: np.ndarray    # per payload: SCAN_*
    reject: np.ndarray        # per payload: index into REJECTS
    scan_end: np.ndarray
    stats: dict

    def scan_kinds(self) -> list[int]:
        """How each scan number ended (SCAN_COMPLETE, ...; SCAN_NONE for the one still in progress)."""
        kinds = [int(e) for e in self.scan_event if e != SCAN_NONE]
        return kinds + [SCAN_NONE]


_ready = False


def calibration_table(calibration, model: str) -> np.ndarray:
    """The decoder's calibration table (lidet_velodyne_calib_t) of a unit's calibration: (n_lasers, 3) int32 rows
    by laser id of (elevation in millidegrees, rotational correction in 0.01 deg, distance correction in mm), each
    rounded to the nearest unit. `calibration` is what `sensors.load_velodyne_calibration` returns (its tables are
    in ring order, `velodyne.laser_id` giving each ring's laser), or such a table already (returned as int32).
    Raises ValueError when it does not fit the model: another number of lasers, laser ids that are not 0 .. n-1,
    a distance resolution other than the model's packets' unit (2 mm; VLP-32C 4 mm), a distance correction beyond
    +-32.767 m."""
    if model not in N_LASERS:
        raise ValueError(f"a calibration needs the model (one of {', '.join(N_LASERS)}), got {model!r}")
    n = N_LASERS[model]
    if isinstance(calibration, np.ndarray):
        t = np.asarray(calibration)
        if t.shape != (n, 3) or not np.issubdtype(t.dtype, np.integer):
            raise ValueError(f"a calibration table for {model} is ({n}, 3) integers, got {t.shape} {t.dtype}")
        return t.astype(np.int32)
    corr = getattr(calibration, "velodyne", None)
    if corr is None:
        raise ValueError("calibration: expected a sensor read by sensors.load_velodyne_calibration (or a table)")
    if calibration.rows != n:
        raise ValueError(f"calibration: {calibration.rows} lasers, the {model} has {n}")
    ids = np.asarray(corr.laser_id, np.int64)
    if sorted(ids.tolist()) != list(range(n)):
        raise ValueError(f"calibration: the laser ids are not 0 .. {n - 1}")
    if round(corr.distance_resolution_m * 1000.0, 6) != DIST_UNIT_MM[model]:
        raise ValueError(f"calibration: distance resolution {corr.distance_resolution_m * 1000.0:g} mm, the "
                         f"{model}'s packets count {DIST_UNIT_MM[model]} mm")
    deg = calibration.beam_elev_deg if calibration.beam_elev_deg is not None else \
        np.degrees(calibration.beam_elev_rad)
    t = np.zeros((n, 3), np.int64)
    t[ids, 0] = np.round(np.asarray(deg, np.float64) * 1000.0)
    t[ids, 1] = np.round(np.degrees(np.asarray(calibration.beam_azimuth_rad, np.float64)) * 100.0)
    t[ids, 2] = np.round(np.asarray(corr.dist_correction_m, np.float64) * 1000.0)
    if np.abs(t[:, 2]).max() > 32767:
        raise ValueError("calibration: a distance correction beyond +-32.767 m")
    return t.astype(np.int32)


def decode(payloads, model="auto", filt="both", seam_cdeg=0, max_step_cdeg=1000, force_model=False,
           calibration=None, ring_top_first=False) -> Decoded:
    """Decode payloads (a list of bytes) with one decoder state, as firmware would, packet by packet
    (force_model: decode as `model` whatever the product byte says). calibration: None (the model's nominal
    tables), or the unit's calibration (`sensors.load_velodyne_calibration`, or `calibration_table`'s array; needs
    `model`): rings ordered by its elevations, its rotational and distance corrections applied, xyz from its
    elevations. ring_top_first: ring 0 = the highest beam (the hdl64 preset's order) instead of the lowest."""
    global _ready
    L = native.lib()
    if not _ready:
        L.lidet_py_velodyne_decode.restype = C.c_int64
        L.lidet_py_velodyne_decode.argtypes = [C.c_void_p] * 2 + [C.c_uint32, C.c_void_p, C.c_void_p, C.c_uint32] \
            + [C.c_void_p] * 13
        _ready = True
    table = None
    if calibration is not None:
        table = np.concatenate([[N_LASERS.get(model, 0)],
                                calibration_table(calibration, model).reshape(-1)]).astype(np.int32)
    lens = np.array([len(p) for p in payloads], dtype=np.uint32)
    buf = np.frombuffer(b"".join(payloads) + b"\0", dtype=np.uint8)
    cap = 384 * max(len(payloads), 1)
    cols = {"range_mm": np.uint32, "azimuth": np.uint16, "ring": np.uint16, "t_ns": np.uint32,
            "azimuth_cdeg": np.uint16, "intensity": np.uint8, "flags": np.uint8, "packet": np.uint32,
            "scan": np.uint32}
    arr = {k: np.zeros(cap, dtype=t) for k, t in cols.items()}
    xyz = np.zeros((cap, 3), dtype=np.float32)
    events = np.zeros(max(len(payloads), 1), dtype=np.uint32)
    scan_end = np.zeros_like(events)
    stats = np.zeros(len(STATS), dtype=np.uint32)
    cfg = np.array([MODELS[model], FILTERS[filt], seam_cdeg, max_step_cdeg, int(force_model), int(ring_top_first)],
                   dtype=np.uint32)
    p = lambda a: a.ctypes.data_as(C.c_void_p)  # noqa: E731
    n = L.lidet_py_velodyne_decode(p(buf), p(lens), len(payloads), p(cfg), None if table is None else p(table), cap,
                                   *[p(arr[k]) for k in cols], p(xyz), p(events), p(scan_end), p(stats))
    if n < 0:
        raise ValueError(f"lidet_py_velodyne_decode: status {n}")
    k = len(payloads)
    return Decoded(**{c: a[:n] for c, a in arr.items()}, xyz=xyz[:n], scan_event=events[:k] & 0xFF,
                   reject=events[:k] >> 8, scan_end=scan_end[:k], stats=dict(zip(STATS, stats.tolist())))


# ---- writing: synthetic VLP-16 packets and classic pcap files (tests of `lidet detect --pcap`) ----------------------

# VLP-16 lasers in packet order: their elevations (deg) and lidet rings (ring 0 = the lowest beam, the sensor preset's)
VLP16_LASER_ELEV_DEG = (-15, 1, -13, 3, -11, 5, -9, 7, -7, 9, -5, 11, -3, 13, -1, 15)
VLP16_LASER_RING = tuple((e + 15) // 2 for e in VLP16_LASER_ELEV_DEG)
VLP16_COLS = 1800          # firing sequences per rotation at 0.2 deg (600 rpm)
VLP16_PACKET_US = 1327     # 12 blocks of 110.592 us
HOUR_US = 3_600_000_000


def vlp16_grid(points, ring) -> np.ndarray:
    """A VLP-16 scene as the sensor sees it: (VLP16_COLS, 16) ranges in mm (0: no return), column c covering the
    Velodyne azimuths (clockwise from +x) [0.2 c, 0.2 (c + 1)) deg, by lidet ring; the nearest point of a cell kept."""
    p = np.asarray(points, dtype=np.float64)[:, :3]
    ring = np.asarray(ring, dtype=np.int64)
    cw_cdeg = np.mod(-np.degrees(np.arctan2(p[:, 1], p[:, 0])) * 100.0, 36000.0)
    col = np.floor(cw_cdeg / (36000.0 / VLP16_COLS)).astype(np.int64) % VLP16_COLS
    rng = np.round(np.linalg.norm(p, axis=1) * 1000.0).astype(np.int64)
    ok = (ring >= 0) & (ring < 16) & (rng > 0) & (rng < 2 * 65535)
    grid = np.zeros((VLP16_COLS, 16), np.int64)
    order = np.argsort(-rng[ok], kind="stable")  # far first: the nearest written last wins
    grid[col[ok][order], ring[ok][order]] = rng[ok][order]
    return grid


def vlp16_payload(block_cdeg, dist_2mm, time_us, intensity=100, mode=0x37, product=0x22) -> bytes:
    """One VLP-16 data payload (1206 bytes): 12 blocks at the azimuths block_cdeg (0.01 deg, clockwise), distances
    dist_2mm (12, 32) in 2 mm units (a block's two firing sequences of 16 lasers, packet order), the timestamp
    (microseconds past the hour) and the factory bytes."""
    d = np.asarray(dist_2mm, dtype=np.int64).reshape(12, 32)
    out = bytearray()
    for b in range(12):
        out += struct.pack("<HH", 0xEEFF, int(block_cdeg[b]) % 36000)
        for j in range(32):
            out += struct.pack("<HB", int(d[b, j]), intensity)
    out += struct.pack("<IBB", int(time_us) % HOUR_US, mode, product)
    assert len(out) == 1206
    return bytes(out)


def vlp16_packets(scenes, n_packets, start_cdeg=0, t0_us=0, packet_us=VLP16_PACKET_US):
    """Strongest-return VLP-16 payloads of a sensor turning 0.4 deg a block over a scene per rotation: scenes[r]
    (a vlp16_grid) is what rotation r sees (the last one past the list), a rotation counted from the seam (0 deg);
    the first block at start_cdeg (a multiple of 40). Returns [(time_us, payload)], time_us unwrapped (the payload
    holds it modulo the hour)."""
    if start_cdeg % 40:
        raise ValueError("start_cdeg must be a multiple of 40 (0.4 deg blocks)")
    lasers = np.array(VLP16_LASER_RING)
    out = []
    for k in range(n_packets):
        cdeg, dist = [], np.zeros((12, 32), np.int64)
        for b in range(12):
            a = start_cdeg + 40 * (12 * k + b)
            grid = scenes[min(a // 36000, len(scenes) - 1)]
            c0 = (a % 36000) // 20
            dist[b, :16] = grid[c0, lasers] // 2
            dist[b, 16:] = grid[(c0 + 1) % VLP16_COLS, lasers] // 2
            cdeg.append(a % 36000)
        t = t0_us + k * packet_us
        out.append((t, vlp16_payload(cdeg, dist, t)))
    return out


# ---- HDL-64E (single and dual return): mirrored from lib/src/decode/lidet_velodyne.c ---------------------------------

#: each laser id's ring by nominal elevation, lowest first (a payload's upper-bank block holds lasers 0..31, its
#: lower-bank block lasers 32..63); the order published unit calibrations share (docs/DECODING.md)
HDL64E_LASER_RING = (36, 37, 58, 59, 38, 39, 32, 33, 40, 41, 34, 35, 48, 49, 42, 43, 50, 51, 44, 45, 52, 53, 46, 47,
                     60, 61, 54, 55, 62, 63, 56, 57, 4, 5, 26, 27, 6, 7, 0, 1, 8, 9, 2, 3, 16, 17, 10, 11,
                     18, 19, 12, 13, 20, 21, 14, 15, 28, 29, 22, 23, 30, 31, 24, 25)
#: each ring's nominal elevation in millidegrees (ring 0 = the lowest): the lower block -24.333 .. -8.833 deg every
#: 0.5 deg, the upper -8.333 .. +2 deg every 1/3 deg
HDL64E_ELEV_MDEG = tuple(-24333 + 500 * r if r < 32 else 2000 - round((63 - r) * 1000 / 3) for r in range(64))
#: a block's data point j fires HDL64E_OFF_UNITS[j] x 60 ns into its firing (groups of four every 6 us, at 0, 1.26,
#: 2.46, 3.66 us); a firing (an upper and a lower block) lasts HDL64E_FIRING_UNITS units (48 us)
HDL64E_OFF_UNITS = tuple(100 * (j // 4) + (0, 21, 41, 61)[j % 4] for j in range(32))
HDL64E_FIRING_UNITS = 800
HDL64E_UNIT_NS = 60
#: the simulated sensor of hdl64e_packets: 0.18 deg a firing, 2000 firings a turn (10.4 Hz at 48 us a firing)
HDL64E_STEP_CDEG = 18
HDL64E_PACKET_US = 288     # 6 firings of 48 us
#: dual return: four blocks a firing (upper, lower: the strongest return; upper, lower: the last), three firings a
#: payload, 57.6 us a firing: the single-return table stretched (HDL64E_OFF_UNITS of 72 ns, HDL64E_FIRING_UNITS a
#: firing), so a data point's share of its firing, and its interpolated azimuth, are single return's
HDL64E_DUAL_UNIT_NS = 72
HDL64E_DUAL_PACKET_NS = 3 * HDL64E_FIRING_UNITS * HDL64E_DUAL_UNIT_NS  # 172.8 us


def hdl64e_grid(points, ring, cols=36000 // HDL64E_STEP_CDEG) -> np.ndarray:
    """An HDL-64E scene as the sensor sees it: (cols, 64) ranges in mm (0: no return), column c covering the Velodyne
    azimuths (clockwise from +x) [360 c / cols, 360 (c + 1) / cols) deg, by the given rings (any numbering of 64
    rings: the simulator's are the hdl64 preset's, ring 0 = the top beam); the nearest point of a cell kept."""
    p = np.asarray(points, dtype=np.float64)[:, :3]
    ring = np.asarray(ring, dtype=np.int64)
    cw_cdeg = np.mod(-np.degrees(np.arctan2(p[:, 1], p[:, 0])) * 100.0, 36000.0)
    col = np.floor(cw_cdeg * cols / 36000.0).astype(np.int64) % cols
    rng = np.round(np.linalg.norm(p, axis=1) * 1000.0).astype(np.int64)
    ok = (ring >= 0) & (ring < 64) & (rng > 0) & (rng < 2 * 65535)
    grid = np.zeros((cols, 64), np.int64)
    order = np.argsort(-rng[ok], kind="stable")  # far first: the nearest written last wins
    grid[col[ok][order], ring[ok][order]] = rng[ok][order]
    return grid


def hdl64e_payload(block_cdeg, dist_2mm, time_us, intensity=100, status=(0x48, 0), flags=None) -> bytes:
    """One HDL-64E data payload (1206 bytes): 12 blocks at the azimuths block_cdeg (0.01 deg, clockwise; a
    single-return firing is a pair of blocks at one azimuth, a dual-return one four), their flags (default: upper
    bank 0xEEFF and lower bank 0xDDFF alternating, upper first), distances dist_2mm (12, 32) in 2 mm units in packet
    order, intensity (a number or (12, 32)), the timestamp (microseconds past the hour) and the two status bytes
    (type, value)."""
    d = np.asarray(dist_2mm, dtype=np.int64).reshape(12, 32)
    inten = np.broadcast_to(np.asarray(intensity, dtype=np.int64), (12, 32))
    flags = [0xDDFF if b % 2 else 0xEEFF for b in range(12)] if flags is None else flags
    out = bytearray()
    for b in range(12):
        out += struct.pack("<HH", flags[b], int(block_cdeg[b]) % 36000)
        for j in range(32):
            out += struct.pack("<HB", int(d[b, j]), int(inten[b, j]))
    out += struct.pack("<IBB", int(time_us) % HOUR_US, status[0], status[1])
    assert len(out) == 1206
    return bytes(out)


def hdl64e_packets(scenes, n_packets, start_cdeg=0, t0_us=0, packet_us=HDL64E_PACKET_US, step_cdeg=HDL64E_STEP_CDEG,
                   laser_ring=None, dist_corr_mm=None, intensity=100):
    """Single-return HDL-64E payloads of a sensor turning step_cdeg a firing over a scene per rotation: scenes[r] (an
    hdl64e_grid of 36000 // step_cdeg columns) is what rotation r sees (the last one past the list), a rotation
    counted from the seam (0 deg); firing k at start_cdeg + k step_cdeg sees column (its azimuth) // step_cdeg.
    laser_ring[l]: the scene's ring laser l reports (default: the hdl64 preset's order, ring 0 = the top beam,
    which the decoder emits with ring_top_first). dist_corr_mm[l]: the distance correction of laser l that the
    decoder will add (the payload holds (range - correction) // 2; ranges it would leave at 0 or below are written
    as no return). Returns [(time_us, payload)], time_us unwrapped (the payload holds it modulo the hour)."""
    lr = np.array([63 - r for r in HDL64E_LASER_RING] if laser_ring is None else laser_ring, np.int64)
    corr = np.zeros(64, np.int64) if dist_corr_mm is None else np.asarray(dist_corr_mm, np.int64)
    out = []
    for k in range(n_packets):
        cdeg, dist = [], np.zeros((12, 32), np.int64)
        for f in range(6):
            a = start_cdeg + step_cdeg * (6 * k + f)
            grid = scenes[min(a // 36000, len(scenes) - 1)]
            c = (a % 36000) * grid.shape[0] // 36000
            dist[2 * f:2 * f + 2] = _hdl64e_raw(grid[c, lr], corr).reshape(2, 32)
            cdeg += [a % 36000] * 2
        t = t0_us + k * packet_us
        out.append((t, hdl64e_payload(cdeg, np.clip(dist, 0, 65535), t, intensity=intensity)))
    return out


def _hdl64e_raw(cells_mm, corr_mm) -> np.ndarray:
    """A firing's 64 packet distances (2 mm units, by laser id) of the ranges the decoder must give (mm, 0: no
    return), less each laser's distance correction; a range it would leave at 0 or below is no return."""
    r = cells_mm - corr_mm
    return np.where((cells_mm > 0) & (r > 0), np.clip(r, 0, None) // 2, 0)


def hdl64e_dual_packets(last_scenes, strongest_scenes, n_packets, start_cdeg=0, t0_us=0, step_cdeg=HDL64E_STEP_CDEG,
                        laser_ring=None, dist_corr_mm=None, last_intensity=100, strongest_intensity=100):
    """Dual-return HDL-64E payloads of a sensor turning step_cdeg a firing, three firings a payload: firing k at
    start_cdeg + k step_cdeg sees column (its azimuth) // step_cdeg of rotation r's scenes (the last ones past the
    lists, as hdl64e_packets). Per firing four blocks at its azimuth: upper and lower bank of the strongest return
    (strongest_scenes[r]: ranges in mm, hdl64e_grid's layout; 0 where the pair repeats the last return, as the sensor
    does for a lone return), then upper and lower bank of the last return (last_scenes[r]). Intensities: a number, or
    per rotation an array of the scenes' shape (last_intensity[r], strongest_intensity[r]; a repeated return keeps
    the last one's). laser_ring, dist_corr_mm: as hdl64e_packets. Timestamps 172.8 us apart (three 57.6 us firings),
    in whole microseconds. Returns [(time_us, payload)], time_us unwrapped (the payload holds it modulo the hour)."""
    lr = np.array([63 - r for r in HDL64E_LASER_RING] if laser_ring is None else laser_ring, np.int64)
    corr = np.zeros(64, np.int64) if dist_corr_mm is None else np.asarray(dist_corr_mm, np.int64)

    def per_laser(table, r, c):  # a number, or rotation r's array: column c, each laser's ring
        if np.ndim(table) == 0:
            return np.full(64, int(table), np.int64)
        return np.asarray(table[min(r, len(table) - 1)], np.int64)[c, lr]

    out = []
    for k in range(n_packets):
        cdeg, dist, inten = [], np.zeros((12, 32), np.int64), np.zeros((12, 32), np.int64)
        for f in range(3):
            a = start_cdeg + step_cdeg * (3 * k + f)
            r = a // 36000
            last = last_scenes[min(r, len(last_scenes) - 1)]
            c = (a % 36000) * last.shape[0] // 36000
            strong = np.asarray(strongest_scenes[min(r, len(strongest_scenes) - 1)], np.int64)[c, lr]
            d_last = _hdl64e_raw(last[c, lr], corr)
            i_last = per_laser(last_intensity, r, c)
            lone = strong <= 0
            d_strong = np.where(lone, d_last, _hdl64e_raw(strong, corr))
            i_strong = np.where(lone, i_last, per_laser(strongest_intensity, r, c))
            dist[4 * f:4 * f + 2], dist[4 * f + 2:4 * f + 4] = d_strong.reshape(2, 32), d_last.reshape(2, 32)
            inten[4 * f:4 * f + 2], inten[4 * f + 2:4 * f + 4] = i_strong.reshape(2, 32), i_last.reshape(2, 32)
            cdeg += [a % 36000] * 4
        t = t0_us + k * HDL64E_DUAL_PACKET_NS // 1000
        out.append((t, hdl64e_payload(cdeg, np.clip(dist, 0, 65535), t, intensity=inten)))
    return out


def _ip_checksum(h: bytes) -> int:
    s = sum(struct.unpack(f">{len(h) // 2}H", h))
    while s >> 16:
        s = (s & 0xFFFF) + (s >> 16)
    return ~s & 0xFFFF


def udp_frame(payload: bytes, dport=2368, sport=2368, src="192.168.1.201", dst="255.255.255.255", flags_frag=0x4000,
              ip_total=None) -> bytes:
    """An Ethernet / IPv4 / UDP frame carrying payload (flags_frag: the IPv4 flags and fragment offset field, 0x4000 =
    don't fragment; ip_total: a wrong IPv4 total length for malformed frames)."""
    udp = struct.pack(">HHHH", sport, dport, 8 + len(payload), 0) + payload
    ips = bytes(int(x) for x in src.split(".")) + bytes(int(x) for x in dst.split("."))
    total = 20 + len(udp) if ip_total is None else ip_total
    h = struct.pack(">BBHHHBBH", 0x45, 0, total, 0, flags_frag, 64, 17, 0) + ips
    h = h[:10] + struct.pack(">H", _ip_checksum(h)) + h[12:]
    return b"\xff" * 6 + b"\x60\x76\x88\x00\x00\x01" + b"\x08\x00" + h + udp


def write_pcap(path, frames, times_s=None, snaplen=65535, linktype=1):
    """A classic little-endian microsecond pcap file. frames: bytes, or (bytes, original length) for a frame the
    capture cut short; times_s: one timestamp per frame (default 1 ms apart)."""
    with open(path, "wb") as f:
        f.write(struct.pack("<IHHiIII", 0xA1B2C3D4, 2, 4, 0, 0, snaplen, linktype))
        for i, fr in enumerate(frames):
            data, orig = (fr, len(fr)) if isinstance(fr, (bytes, bytearray)) else fr
            t = times_s[i] if times_s is not None else 1_700_000_000 + i * 1e-3
            sec = int(t)
            f.write(struct.pack("<IIII", sec, int(round((t - sec) * 1e6)), len(data), orig))
            f.write(data)
