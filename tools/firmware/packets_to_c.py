#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Scan -> VLP-16 payloads as const C data, for the firmware application that decodes packets
(LIDET_FW_APP=packets, ports/firmware/fw_packets.c, fw_packets.h).

Reads a KITTI velodyne .bin (float32 x, y, z, intensity per point) and its ring file (uint16 per point, ring 0 =
the lowest beam, the vlp16 preset's order), lays the scene out as a VLP-16 sees it and writes the strongest-return
data payloads (1206 bytes each) of a sensor turning 0.4 deg a block over it: the first block at --start-cdeg
(default 357.6 deg, half a packet before the seam at 0 deg), then enough packets to cross the seam a second time,
so that a decoder started on the first one reports a PARTIAL scan, then one COMPLETE rotation (76 payloads).

The payloads are byte for byte those of lidet_tools.velodyne (vlp16_packets([vlp16_grid(points, ring)], n,
start_cdeg); tests/python/test_firmware_tools.py checks it), computed here with the standard library only, since
the build runs this before any virtual environment exists (as scan_to_c.py). --pcap also writes them as a classic
pcap capture (Ethernet / IPv4 / UDP to port 2368, lidet_tools.velodyne.udp_frame / write_pcap), for
`lidet detect --pcap FILE --fixed` on the same payloads.

    python3 tools/firmware/packets_to_c.py SCAN.bin --ring RING.bin [--name NAME] [--start-cdeg C]
                                           [--packets N] [--pcap OUT.pcap] --out fw_scan.c
"""
import argparse
import math
import os
import struct
import sys

PAYLOAD_BYTES = 1206
COLS = 1800            # lidet_tools.velodyne.VLP16_COLS: firing sequences per rotation at 0.2 deg (600 rpm)
PACKET_US = 1327       # VLP16_PACKET_US: 12 blocks of 110.592 us
HOUR_US = 3_600_000_000
BLOCK_CDEG = 40        # a block: two firing sequences, 0.4 deg
# VLP16_LASER_RING: the lidet ring of each laser in packet order (elevations -15, +1, -13, +3, ... deg)
LASER_RING = tuple((e + 15) // 2 for e in (-15, 1, -13, 3, -11, 5, -9, 7, -7, 9, -5, 11, -3, 13, -1, 15))


def grid_of(points, ring):
    """lidet_tools.velodyne.vlp16_grid: {(column, ring): range mm} of the nearest point of each cell (column c
    covers the Velodyne azimuths, clockwise from +x, [0.2 c, 0.2 (c + 1)) deg); the same float64 operations in the
    same order as the numpy original (degrees, floor-mod, round half to even)."""
    ranges = []
    for (x, y, z), r in zip(points, ring):
        cw_cdeg = (-math.degrees(math.atan2(y, x)) * 100.0) % 36000.0
        col = math.floor(cw_cdeg / (36000.0 / COLS)) % COLS
        rng = round(math.sqrt(x * x + y * y + z * z) * 1000.0)
        if 0 <= r < 16 and 0 < rng < 2 * 65535:
            ranges.append((rng, col, r))
    grid = {}
    # far first, a stable sort (equal ranges keep the scan's order): the nearest, written last, wins
    for i in sorted(range(len(ranges)), key=lambda i: -ranges[i][0]):
        rng, col, r = ranges[i]
        grid[(col, r)] = rng
    return grid


def payloads(grid, n_packets, start_cdeg, t0_us=0):
    """lidet_tools.velodyne.vlp16_packets([grid], n_packets, start_cdeg): [(time_us, payload bytes)]."""
    if start_cdeg % BLOCK_CDEG:
        raise ValueError("start_cdeg must be a multiple of 40 (0.4 deg blocks)")
    out = []
    for k in range(n_packets):
        t = t0_us + k * PACKET_US
        b = bytearray()
        for blk in range(12):
            a = start_cdeg + BLOCK_CDEG * (12 * k + blk)
            c0 = (a % 36000) // 20
            b += struct.pack("<HH", 0xEEFF, a % 36000)
            for c in (c0, (c0 + 1) % COLS):  # the block's two firing sequences
                for r in LASER_RING:
                    b += struct.pack("<HB", grid.get((c, r), 0) // 2, 100)
        b += struct.pack("<IBB", t % HOUR_US, 0x37, 0x22)  # strongest return, VLP-16
        assert len(b) == PAYLOAD_BYTES
        out.append((t, bytes(b)))
    return out


def _ip_checksum(h):
    s = sum(struct.unpack(f">{len(h) // 2}H", h))
    while s >> 16:
        s = (s & 0xFFFF) + (s >> 16)
    return ~s & 0xFFFF


def write_pcap(path, pkts):
    """lidet_tools.velodyne.write_pcap of udp_frame(payload) per payload, frames 1 ms apart."""
    with open(path, "wb") as f:
        f.write(struct.pack("<IHHiIII", 0xA1B2C3D4, 2, 4, 0, 0, 65535, 1))
        for i, (_, p) in enumerate(pkts):
            udp = struct.pack(">HHHH", 2368, 2368, 8 + len(p), 0) + p
            h = struct.pack(">BBHHHBBH", 0x45, 0, 20 + len(udp), 0, 0x4000, 64, 17, 0) + \
                bytes((192, 168, 1, 201)) + bytes((255, 255, 255, 255))
            h = h[:10] + struct.pack(">H", _ip_checksum(h)) + h[12:]
            frame = b"\xff" * 6 + b"\x60\x76\x88\x00\x00\x01" + b"\x08\x00" + h + udp
            t = 1_700_000_000 + i * 1e-3
            sec = int(t)
            f.write(struct.pack("<IIII", sec, int(round((t - sec) * 1e6)), len(frame), len(frame)))
            f.write(frame)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scan", help="KITTI .bin: float32 x y z intensity per point")
    ap.add_argument("--ring", required=True, help="uint16 ring index per point (ring 0 = the lowest beam)")
    ap.add_argument("--name", help="name printed by the firmware (default: the file name)")
    ap.add_argument("--start-cdeg", type=int, default=36000 - 6 * BLOCK_CDEG,
                    help="the first block's azimuth, 0.01 deg clockwise, a multiple of 40 (default 35760: the first "
                         "payload crosses the seam at its seventh block)")
    ap.add_argument("--packets", type=int, default=0,
                    help="payloads (default 0: up to the one that crosses the seam the second time)")
    ap.add_argument("--pcap", help="also write the payloads as a pcap capture here")
    ap.add_argument("--out", required=True, help="C file to write")
    a = ap.parse_args(argv)

    if not 0 <= a.start_cdeg < 36000 or a.start_cdeg % BLOCK_CDEG:
        sys.exit(f"packets_to_c: --start-cdeg {a.start_cdeg}: a multiple of 40 in [0, 36000)")
    with open(a.scan, "rb") as f:
        raw = f.read()
    if len(raw) % 16 != 0 or not raw:
        sys.exit(f"packets_to_c: {a.scan}: {len(raw)} bytes is not a whole number of 16-byte records")
    n = len(raw) // 16
    rec = struct.unpack(f"<{4 * n}f", raw)
    with open(a.ring, "rb") as f:
        rraw = f.read()
    if len(rraw) != 2 * n:
        sys.exit(f"packets_to_c: {a.ring}: {len(rraw)} bytes for {n} points (need 2 per point)")
    ring = struct.unpack(f"<{n}H", rraw)
    points = [(rec[4 * i], rec[4 * i + 1], rec[4 * i + 2]) for i in range(n)]
    if any(v != v or v in (float("inf"), float("-inf")) for p in points for v in p):
        sys.exit("packets_to_c: NaN or Inf coordinate")

    # the second seam crossing: the first block at or past 720 deg, in payload k = its block index // 12
    n_packets = a.packets or ((72000 - a.start_cdeg) // BLOCK_CDEG) // 12 + 1
    grid = grid_of(points, ring)
    pkts = payloads(grid, n_packets, a.start_cdeg)
    name = a.name or os.path.basename(a.scan)
    out = [
        f"/* GENERATED by tools/firmware/packets_to_c.py from {name} ({n} points, {len(grid)} VLP-16 returns): "
        f"{n_packets} payloads from {a.start_cdeg / 100:.2f} deg - DO NOT EDIT */",
        '#include "fw_packets.h"',
        "",
        f"const uint32_t fw_pkt_n = {n_packets}u;",
        f"const uint32_t fw_pkt_start_cdeg = {a.start_cdeg}u;",
        f'const char fw_pkt_name[] = "{name}";',
        f"const uint8_t fw_pkt_payload[{n_packets}][LIDET_VELODYNE_PAYLOAD_BYTES] = {{",
    ]
    for _, p in pkts:
        out.append("    {")
        for i in range(0, PAYLOAD_BYTES, 30):
            out.append("        " + ",".join(str(v) for v in p[i:i + 30]) + ",")
        out.append("    },")
    out.append("};")
    tmp = a.out + ".tmp"
    with open(tmp, "w") as f:
        f.write("\n".join(out) + "\n")
    os.replace(tmp, a.out)
    if a.pcap:
        write_pcap(a.pcap + ".tmp", pkts)
        os.replace(a.pcap + ".tmp", a.pcap)
    return 0


if __name__ == "__main__":
    sys.exit(main())
