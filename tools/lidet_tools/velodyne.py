# SPDX-License-Identifier: MIT
"""Velodyne captures: a classic libpcap reader for the sensors' UDP payloads, and the C packet decoder
(lib/src/decode/lidet_velodyne.c, docs/DECODING.md) run over a whole capture through the bindings.

    payloads = read_pcap_payloads("vlp16_dual.pcap")            # [(time_s, udp_port, bytes), ...]
    d = decode([p for _, _, p in payloads], model="auto")       # numpy arrays, one entry per return
    d.xyz[d.scan == 3]                                           # x y z (m) of the returns of scan 3
"""
from __future__ import annotations

import ctypes as C
import struct
from dataclasses import dataclass

import numpy as np

from lidet_tools import native

MODELS = {"auto": 0, "hdl32e": 0x21, "vlp16": 0x22, "vlp32c": 0x28}
FILTERS = {"both": 0, "strongest": 1, "last": 2}
SCAN_NONE, SCAN_COMPLETE, SCAN_PARTIAL, SCAN_ABORTED = 0, 1, 2, 3
REJECTS = ("none", "null", "size", "flag", "product", "mode", "azimuth")
STATS = ("n_packets", "n_decoded") + tuple(f"n_rejected_{r}" for r in REJECTS) + (
    "n_returns", "n_truncated", "n_jumps", "n_scans", "n_partial", "n_aborted", "n_fragment")
FLAG_LAST, FLAG_STRONGEST = 1, 2


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


def decode(payloads, model="auto", filt="both", seam_cdeg=0, max_step_cdeg=1000, force_model=False) -> Decoded:
    """Decode payloads (a list of bytes) with one decoder state, as firmware would, packet by packet
    (force_model: decode as `model` whatever the product byte says)."""
    global _ready
    L = native.lib()
    if not _ready:
        L.lidet_py_velodyne_decode.restype = C.c_int64
        L.lidet_py_velodyne_decode.argtypes = [C.c_void_p] * 2 + [C.c_uint32, C.c_void_p, C.c_uint32] + \
            [C.c_void_p] * 13
        _ready = True
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
    cfg = np.array([MODELS[model], FILTERS[filt], seam_cdeg, max_step_cdeg, int(force_model)], dtype=np.uint32)
    p = lambda a: a.ctypes.data_as(C.c_void_p)  # noqa: E731
    n = L.lidet_py_velodyne_decode(p(buf), p(lens), len(payloads), p(cfg), cap,
                                   *[p(arr[k]) for k in cols], p(xyz), p(events), p(scan_end), p(stats))
    if n < 0:
        raise ValueError(f"lidet_py_velodyne_decode: status {n}")
    k = len(payloads)
    return Decoded(**{c: a[:n] for c, a in arr.items()}, xyz=xyz[:n], scan_event=events[:k] & 0xFF,
                   reject=events[:k] >> 8, scan_end=scan_end[:k], stats=dict(zip(STATS, stats.tolist())))
