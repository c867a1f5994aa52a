# SPDX-License-Identifier: MIT
"""Ouster captures: the sensor metadata a decoder needs, a lidar packet writer, and the C packet decoder
(lib/src/decode/lidet_ouster.c, docs/OUSTER.md) run over a whole capture through the bindings, with x, y, z
computed as ouster-sdk computes them.

    meta = load_metadata("OS-2-128.json")                        # packet format + beam tables (+ meta.sensor)
    pay = [p for _, port, p in velodyne.read_pcap_payloads("OS-2-128.pcap") if port == meta.udp_port_lidar]
    d = decode(pay, meta)                                        # numpy arrays, one entry per return
    d.xyz[d.scan == 0]                                           # x y z (m, sensor frame) of the first scan's returns

x, y, z (`xyz`) follow ouster-sdk's make_xyz_lut + cartesian (ouster_client/src/xyzlut.cpp): for a return of row r
(beam r), measurement id m and range R (mm), with W columns per frame,
    theta_e = 2 pi (1 - m / W)            the encoder angle (lidar frame, clockwise from +x_lidar)
    theta_a = -beam_azimuth_angles[r]     phi = beam_altitude_angles[r]      (radians)
    d = (cos(theta_e + theta_a) cos phi, sin(theta_e + theta_a) cos phi, sin phi)
    n = beam_to_lidar_transform[0, 3] (= lidar_origin_to_beam_origin_mm), n_z = beam_to_lidar_transform[2, 3]
    o = (n cos theta_e - |n| d_x, n sin theta_e - |n| d_y, n_z - |n| d_z),  |n| = hypot(n, n_z)
    p_lidar = R d + o  (mm);  p = lidar_to_sensor_transform (rotation, translation in mm) applied, / 1000 (m).
Metadata without those fields get ouster-sdk's defaults (lidar_origin_to_beam_origin_mm 12.163; lidar to sensor:
a half turn about z and 36.18 mm up).
"""
from __future__ import annotations

import ctypes as C
import math
from dataclasses import dataclass, field

import numpy as np

from lidet_tools import native, sensors

#: udp_profile_lidar -> lidet_ouster_profile_t (ouster-sdk's UDPProfileLidar numbers)
PROFILES = {"LEGACY": 1, "RNG19_RFL8_SIG16_NIR16_DUAL": 2, "RNG19_RFL8_SIG16_NIR16": 3, "RNG15_RFL8_NIR8": 4}
PIXEL_BYTES = {"LEGACY": 12, "RNG19_RFL8_SIG16_NIR16_DUAL": 16, "RNG19_RFL8_SIG16_NIR16": 12, "RNG15_RFL8_NIR8": 4}
HEADERS = {"STANDARD": 0, "FUSA": 1}
FILTERS = {"both": 0, "first": 1, "second": 2}
SCAN_NONE, SCAN_COMPLETE, SCAN_PARTIAL, SCAN_ABORTED = 0, 1, 2, 3
REJECTS = ("none", "null", "truncated", "size", "header", "status", "order")
STATS = ("n_packets", "n_decoded") + tuple(f"n_rejected_{r}" for r in REJECTS) + (
    "n_returns", "n_truncated", "n_invalid_cols", "n_lost_cols", "n_jumps", "n_scans", "n_partial", "n_aborted",
    "n_fragment")
MAX_RETURNS = 16 * 128 * 2
ENCODER_TICKS = 90112
#: what ouster-sdk assumes for metadata without these fields
SDK_BEAM_ORIGIN_MM = 12.163
SDK_LIDAR_TO_SENSOR = np.array([[-1.0, 0, 0, 0], [0, -1.0, 0, 0], [0, 0, 1.0, 36.18], [0, 0, 0, 1.0]])
#: where each field lives in the metadata layouts (sensors.load_ouster_metadata's rule: sections, then top level)
_FORMAT = ("lidar_data_format", "data_format")


def packet_bytes(profile: str, pixels_per_column: int, columns_per_packet: int = 16) -> int:
    """Bytes of a lidar payload (ouster-sdk's packet_format: header, columns, footer)."""
    if profile == "LEGACY":
        return columns_per_packet * (16 + pixels_per_column * 12 + 4)
    return 32 + columns_per_packet * (12 + pixels_per_column * PIXEL_BYTES[profile]) + 32


@dataclass(frozen=True)
class OusterMeta:
    """What a decoder takes from Ouster's sensor metadata: the packet format and the beam tables (ring order,
    row 0 = the top beam), plus the detector's `sensor` (sensors.load_ouster_metadata)."""
    sensor: sensors.Sensor
    profile: str
    pixels_per_column: int
    columns_per_frame: int
    columns_per_packet: int
    header_type: str
    beam_altitude_deg: np.ndarray = field(repr=False)
    beam_azimuth_deg: np.ndarray = field(repr=False)
    #: beam_to_lidar_transform[0, 3] and [2, 3], mm (from lidar_origin_to_beam_origin_mm when not given)
    beam_origin_mm: float
    beam_origin_z_mm: float
    lidar_to_sensor: np.ndarray = field(repr=False)  # 4 x 4, translation in mm
    init_id: int = 0       # 0: unknown (not checked)
    prod_sn: int = 0       # 0: unknown (not checked)
    udp_port_lidar: int = 7502
    column_window: tuple = (0, 0)
    pixel_shift_by_row: tuple = ()

    @property
    def beam_azimuth_mdeg(self) -> np.ndarray:
        """The beam azimuth offsets in millidegrees (int32), what lidet_ouster_cfg_t takes."""
        return np.round(self.beam_azimuth_deg * 1000.0).astype(np.int32)

    @property
    def azimuth_offset_bam(self) -> int:
        """lidet_ouster_cfg_t.azimuth_offset_bam: the turn about z of lidar_to_sensor_transform, BAM16."""
        r = self.lidar_to_sensor[:3, :3]
        if not np.allclose(r[2], [0, 0, 1], atol=1e-6) or not np.allclose(r[:2, 2], 0, atol=1e-6):
            raise ValueError("lidar_to_sensor_transform is not a turn about z: the decoder's azimuth cannot say it")
        yaw = math.atan2(r[1, 0], r[0, 0])
        return int(round(yaw / (2 * math.pi) * 65536.0)) % 65536

    @property
    def packet_bytes(self) -> int:
        return packet_bytes(self.profile, self.pixels_per_column, self.columns_per_packet)


def _find(root: dict, sections, key):
    for sec in sections:
        if isinstance(root.get(sec), dict) and key in root[sec]:
            return root[sec][key]
    return root.get(key)


def _id(v, bits: int) -> int:
    """An identifier of the metadata (an integer, or digits in a string: prod_sn) that fits `bits`; else 0 (unknown:
    not checked)."""
    if isinstance(v, bool):
        return 0
    try:
        v = int(v)
    except (TypeError, ValueError):
        return 0
    return v if 0 <= v < 1 << bits else 0


def _matrix(v, what: str) -> np.ndarray:
    a = np.asarray(v, dtype=np.float64)
    if a.size != 16 or not np.isfinite(a).all():
        raise sensors.SensorFileError(f"{what}: expected 16 finite numbers (a 4 x 4 matrix)")
    return a.reshape(4, 4)


def load_metadata(path, mount_height_m: float | None = None) -> OusterMeta:
    """Ouster's sensor metadata JSON (any layout sensors.load_ouster_metadata reads, whose rules it applies) plus
    the packet format: udp_profile_lidar (absent: LEGACY, as older firmware), columns_per_packet (absent: 16),
    header_type (absent: STANDARD), the beam tables in degrees, the beam origin and lidar-to-sensor transforms
    (absent: ouster-sdk's defaults), initialization_id and prod_sn (the sensor the packets must come from)."""
    sensor = sensors.load_ouster_metadata(path, mount_height_m)
    root = sensors._read_object(path)
    where = f"{path}"
    profile = _find(root, _FORMAT + ("config_params",), "udp_profile_lidar") or "LEGACY"
    if profile not in PROFILES:
        raise sensors.SensorFileError(f'{where}: "udp_profile_lidar": {profile!r} is not decoded (decoded: '
                                      f'{", ".join(PROFILES)})')
    cpp = _find(root, _FORMAT, "columns_per_packet")
    cpp = 16 if cpp is None else cpp
    if isinstance(cpp, bool) or not isinstance(cpp, int) or not 1 <= cpp <= 16:
        raise sensors.SensorFileError(f'{where}: "columns_per_packet": {cpp!r} is not an integer in [1, 16]')
    header = _find(root, _FORMAT + ("config_params",), "header_type") or "STANDARD"
    if header not in HEADERS:
        raise sensors.SensorFileError(f'{where}: "header_type": {header!r} is not one of {", ".join(HEADERS)}')
    alt = np.asarray(_find(root, ("beam_intrinsics",), "beam_altitude_angles"), dtype=np.float64)
    az = _find(root, ("beam_intrinsics",), "beam_azimuth_angles")
    az = np.zeros(sensor.rows) if az is None else np.asarray(az, dtype=np.float64)
    b2l = _find(root, ("beam_intrinsics",), "beam_to_lidar_transform")
    if b2l is not None:
        m = _matrix(b2l, f'{where}: "beam_to_lidar_transform"')
        origin, origin_z = float(m[0, 3]), float(m[2, 3])
    else:
        origin = sensor.beam_origin_mm if sensor.beam_origin_mm is not None else SDK_BEAM_ORIGIN_MM
        origin_z = 0.0
    l2s = _find(root, ("lidar_intrinsics",), "lidar_to_sensor_transform")
    l2s = SDK_LIDAR_TO_SENSOR.copy() if l2s is None else _matrix(l2s, f'{where}: "lidar_to_sensor_transform"')
    init_id = _id(_find(root, ("sensor_info",), "initialization_id"), 24)
    sn = _id(_find(root, ("sensor_info",), "prod_sn"), 40)
    port = _find(root, ("config_params",), "udp_port_lidar") or 7502
    window = _find(root, _FORMAT, "column_window") or (0, sensor.cols - 1)
    shift = _find(root, _FORMAT, "pixel_shift_by_row") or ()
    return OusterMeta(sensor, profile, sensor.rows, sensor.cols, int(cpp), header, alt, az, float(origin),
                      float(origin_z), l2s, init_id, sn, int(port), tuple(window), tuple(shift))


def xyz(meta: OusterMeta, ring, measurement_id, range_mm) -> np.ndarray:
    """x, y, z (m, float64, Ouster's sensor frame: x forward, away from the connector) of returns, as ouster-sdk
    computes them (module docstring)."""
    ring = np.asarray(ring, dtype=np.int64)
    m = np.asarray(measurement_id, dtype=np.float64)
    r = np.asarray(range_mm, dtype=np.float64)
    w = meta.columns_per_frame
    enc = 2.0 * np.pi - m * (2.0 * np.pi / w)
    az = -meta.beam_azimuth_deg[ring] * np.pi / 180.0
    alt = meta.beam_altitude_deg[ring] * np.pi / 180.0
    d = np.stack([np.cos(enc + az) * np.cos(alt), np.sin(enc + az) * np.cos(alt), np.sin(alt)], axis=1)
    n, nz = meta.beam_origin_mm, meta.beam_origin_z_mm
    dist = math.hypot(n, nz) if nz != 0 else n
    off = np.stack([np.cos(enc) * n - d[:, 0] * dist, np.sin(enc) * n - d[:, 1] * dist, -d[:, 2] * dist + nz],
                   axis=1)
    p = r[:, None] * d + off
    p = np.where(r[:, None] > 0, p, 0.0)
    rot, t = meta.lidar_to_sensor[:3, :3], meta.lidar_to_sensor[:3, 3]
    return (p @ rot.T + t) * 0.001


def _pixel_dtype(profile: str) -> np.dtype:
    """One pixel of a profile, packed little-endian (the layouts of docs/OUSTER.md)."""
    if profile == "LEGACY":
        return np.dtype([("word", "<u4"), ("rfl", "<u2"), ("sig", "<u2"), ("nir", "<u2"), ("pad", "<u2")])
    if profile == "RNG19_RFL8_SIG16_NIR16":
        return np.dtype([("word", "<u4"), ("rfl", "u1"), ("pad0", "u1"), ("sig", "<u2"), ("nir", "<u2"),
                         ("pad", "<u2")])
    if profile == "RNG19_RFL8_SIG16_NIR16_DUAL":
        return np.dtype([("word", "<u4", (2,)), ("sig", "<u2", (2,)), ("nir", "<u2"), ("pad", "<u2")])
    return np.dtype([("word", "<u2"), ("rfl", "u1"), ("nir", "u1")])  # RNG15_RFL8_NIR8


def write_packet(profile: str, pixels_per_column: int, columns_per_frame: int, *, columns_per_packet: int = 16,
                 frame_id: int = 0, first_mid: int = 0, measurement_ids=None, frame_ids=None, ranges_mm=None,
                 reflectivity=None, signal=None, flags=None, valid=None, timestamps_ns=None, encoder=None,
                 init_id: int = 0, prod_sn: int = 0, header: str = "STANDARD", packet_type: int = 1) -> bytes:
    """A lidar payload as an Ouster sensor writes it (the layouts of docs/OUSTER.md). Per column c and row r:
    ranges_mm[c, r] (DUAL: [c, r, k], k = 0 first and 1 second return; RNG15_RFL8_NIR8: multiples of 8 mm),
    reflectivity, signal and flags likewise (default 0; broadcast); measurement_ids (default first_mid + c,
    wrapping at columns_per_frame into the next frame: LEGACY columns carry their own frame id, frame_ids[c]
    when given), valid[c] (default all), timestamps_ns[c] (default 1e9 + m x 97656 ns), encoder[c] (LEGACY;
    default m x 90112 / W). Values out of their field's range raise ValueError."""
    cpp, ppc, w = columns_per_packet, pixels_per_column, columns_per_frame
    dual = profile == "RNG19_RFL8_SIG16_NIR16_DUAL"
    shape = (cpp, ppc, 2) if dual else (cpp, ppc)

    def arr(a, bits, what):
        v = np.zeros(shape, np.int64) if a is None else np.broadcast_to(np.asarray(a, np.int64), shape)
        if v.size and (v.min() < 0 or v.max() >= 1 << bits):
            raise ValueError(f"{what} outside [0, 2^{bits})")
        return v.astype(np.uint64)

    if profile == "RNG15_RFL8_NIR8":
        r = np.zeros(shape, np.int64) if ranges_mm is None else np.broadcast_to(np.asarray(ranges_mm, np.int64), shape)
        if (r % 8).any():
            raise ValueError("RNG15_RFL8_NIR8 ranges are multiples of 8 mm")
        rng = arr(r // 8, 15, "range / 8")
    else:
        rng = arr(ranges_mm, 20 if profile == "LEGACY" else 19, "range")
    rfl = arr(reflectivity, 16 if profile == "LEGACY" else 8, "reflectivity")
    sig = arr(signal, 16, "signal")
    flg = arr(flags, {"LEGACY": 4, "RNG15_RFL8_NIR8": 1}.get(profile, 5), "flags")
    if measurement_ids is None:
        mids = first_mid + np.arange(cpp)
        frames = frame_id + mids // w
        mids = mids % w
    else:
        mids = np.asarray(measurement_ids, np.int64)
        frames = np.full(cpp, frame_id)
    if frame_ids is not None:
        frames = np.asarray(frame_ids, np.int64)
    ok = np.ones(cpp, bool) if valid is None else np.asarray(valid, bool)
    ts = (10**9 + mids * 97656) if timestamps_ns is None else np.asarray(timestamps_ns, np.int64)
    enc = (mids * ENCODER_TICKS // w) if encoder is None else np.asarray(encoder, np.int64)
    pdt = _pixel_dtype(profile)
    if profile == "LEGACY":
        cdt = np.dtype([("ts", "<u8"), ("mid", "<u2"), ("frame", "<u2"), ("enc", "<u4"), ("px", pdt, (ppc,)),
                        ("status", "<u4")])
    else:
        cdt = np.dtype([("ts", "<u8"), ("mid", "<u2"), ("status", "<u2"), ("px", pdt, (ppc,))])
    cols = np.zeros(cpp, cdt)
    cols["ts"] = ts.astype(np.uint64)
    cols["mid"] = mids & 0xFFFF
    px = cols["px"]
    if profile == "LEGACY":
        cols["frame"] = frames & 0xFFFF
        cols["enc"] = enc & 0xFFFFFFFF
        cols["status"] = np.where(ok, 0xFFFFFFFF, 0)
        px["word"] = rng | flg << 28
        px["rfl"], px["sig"] = rfl, sig
    else:
        cols["status"] = ok.astype(np.uint16)
        if dual:
            px["word"] = rng | flg << 19 | rfl << 24
            px["sig"] = sig
        elif profile == "RNG19_RFL8_SIG16_NIR16":
            px["word"] = rng | flg << 19
            px["rfl"], px["sig"] = rfl, sig
        else:
            px["word"] = rng | flg << 15
            px["rfl"] = rfl
    body = cols.tobytes()
    if profile == "LEGACY":
        return body
    hdr = bytearray(32)
    if header == "FUSA":
        hdr[0] = packet_type & 0xFF
        hdr[1:4] = (init_id & 0xFFFFFF).to_bytes(3, "little")
        hdr[4:8] = (frame_id & 0xFFFFFFFF).to_bytes(4, "little")
        hdr[11:16] = (prod_sn & (2**40 - 1)).to_bytes(5, "little")
    else:
        hdr[0:2] = (packet_type & 0xFFFF).to_bytes(2, "little")
        hdr[2:4] = (frame_id & 0xFFFF).to_bytes(2, "little")
        hdr[4:7] = (init_id & 0xFFFFFF).to_bytes(3, "little")
        hdr[7:12] = (prod_sn & (2**40 - 1)).to_bytes(5, "little")
    return bytes(hdr) + body + bytes(32)


@dataclass
class Decoded:
    """One entry per return, in decoding order; per payload: scan_event, reject, status, scan_end, n_returns;
    stats by STATS name."""
    range_mm: np.ndarray
    azimuth: np.ndarray         # BAM16, counterclockwise from +x
    ring: np.ndarray            # the beam's row (row 0 = the top beam)
    measurement_id: np.ndarray
    timestamp_ns: np.ndarray    # the column's timestamp
    signal: np.ndarray
    reflectivity: np.ndarray
    return_index: np.ndarray    # 0 first, 1 second (DUAL)
    flags: np.ndarray
    packet: np.ndarray          # index of the payload
    frame_id: np.ndarray        # the payload's frame id (LEGACY: its first valid column's)
    scan: np.ndarray            # 0 = the scan in progress at the start, +1 at each scan event
    xyz: np.ndarray             # (n, 3) float64, metres (ouster-sdk's formula: `xyz`)
    scan_event: np.ndarray      # per payload: SCAN_*
    reject: np.ndarray          # per payload: index into REJECTS
    status: np.ndarray          # per payload: lidet_status_t
    scan_end: np.ndarray
    n_returns: np.ndarray       # per payload
    stats: dict

    def scan_kinds(self) -> list[int]:
        """How each scan number ended (SCAN_COMPLETE, ...; SCAN_NONE for the one still in progress)."""
        return [int(e) for e in self.scan_event if e != SCAN_NONE] + [SCAN_NONE]

    def frames(self) -> list[tuple[int, int, np.ndarray]]:
        """The scans that hold returns: (scan number, how it ended, indices of its returns)."""
        kinds = self.scan_kinds()
        return [(int(s), kinds[int(s)], np.flatnonzero(self.scan == s)) for s in np.unique(self.scan)]


_ready = False


def decode(payloads, meta: OusterMeta, filt: str = "both", seam_col: int = 0, max_step_cols: int = 0,
           check_sensor: bool = True, cap: int = 0, profile: str | None = None) -> Decoded:
    """Decode payloads (a list of bytes) with one decoder state, as firmware would, packet by packet. check_sensor:
    reject packets of another init id / serial number than the metadata's (when it gives them). cap: the room the
    decoder gets per payload (0: always enough; smaller: the returns past it are dropped and counted, and the
    bindings check that nothing was written past it). profile: decode as this profile instead of the metadata's."""
    global _ready
    L = native.lib()
    if not _ready:
        L.lidet_py_ouster_decode.restype = C.c_int64
        L.lidet_py_ouster_decode.argtypes = [C.c_void_p] * 2 + [C.c_uint32] + [C.c_void_p] * 2 + [C.c_uint32] + \
            [C.c_void_p] * 16
        _ready = True
    lens = np.array([len(p) for p in payloads], dtype=np.uint32)
    buf = np.frombuffer(b"".join(payloads) + b"\0", dtype=np.uint8)
    per = meta.columns_per_packet * meta.pixels_per_column * 2
    total = max(int(sum(min(len(p) // 4, per) for p in payloads)), 1)  # a pixel is >= 4 bytes
    cols = {"range_mm": np.uint32, "azimuth": np.uint16, "ring": np.uint16, "measurement_id": np.uint16,
            "timestamp_ns": np.uint64, "signal": np.uint16, "reflectivity": np.uint16, "return_index": np.uint8,
            "flags": np.uint8, "packet": np.uint32, "frame_id": np.uint32, "scan": np.uint32}
    arr = {k: np.zeros(total, dtype=t) for k, t in cols.items()}
    k = max(len(payloads), 1)
    events, scan_end, n_ret = (np.zeros(k, dtype=np.uint32) for _ in range(3))
    stats = np.zeros(len(STATS), dtype=np.uint32)
    sn = meta.prod_sn if check_sensor else 0
    cfg = np.array([PROFILES[profile or meta.profile], HEADERS[meta.header_type], FILTERS[filt],
                    meta.pixels_per_column, meta.columns_per_frame, meta.columns_per_packet, seam_col,
                    max_step_cols, meta.azimuth_offset_bam, meta.init_id if check_sensor else 0, sn & 0xFFFFFFFF,
                    sn >> 32, cap], dtype=np.uint32)
    az = np.ascontiguousarray(meta.beam_azimuth_mdeg, dtype=np.int32)
    p = lambda a: a.ctypes.data_as(C.c_void_p)  # noqa: E731
    n = L.lidet_py_ouster_decode(p(buf), p(lens), len(payloads), p(cfg), p(az), total,
                                 *[p(arr[c]) for c in cols], p(events), p(scan_end), p(n_ret), p(stats))
    if n == -100:
        raise AssertionError("lidet_ouster_packet wrote past the cap it was given")
    if n < 0:
        raise ValueError(f"lidet_py_ouster_decode: status {n}")
    m = len(payloads)
    out = {c: a[:n] for c, a in arr.items()}
    status = ((events[:m] >> 16) & 0xFF).astype(np.int8)
    return Decoded(**out, xyz=xyz(meta, out["ring"], out["measurement_id"], out["range_mm"]),
                   scan_event=events[:m] & 0xFF, reject=(events[:m] >> 8) & 0xFF, status=status,
                   scan_end=scan_end[:m], n_returns=n_ret[:m], stats=dict(zip(STATS, stats.tolist())))
