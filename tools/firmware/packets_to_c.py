#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Scan -> lidar UDP payloads as const C data, for the firmware application that decodes packets
(LIDET_FW_APP=packets, ports/firmware/fw_packets.c, fw_packets.h): VLP-16 payloads (default), or Ouster payloads
(--lidar ouster: LIDET_FW_LIDAR=ouster).

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

--lidar ouster (a simulated Ouster scan, `lidet-sim --sensor os1-32`: ring 0 = the top beam, Ouster's row order
and the os1-32 preset's): the scan's returns as an Ouster sensor of the --sensor preset (default os1-32: 32 x
1024) sends them, profile RNG19_RFL8_SIG16_NIR16 (single return, 12-byte pixels, 16 columns a payload: 6,400
bytes at 32 beams), STANDARD header, written by lidet_tools.ouster.write_packet (so this mode needs numpy: run it
with the project's venv). Each point goes to the pixel of its ring (row) and of measurement id m = its column in
lidet's convention, floor((pi - azimuth) x W / (2 pi)) (the simulator casts its rays at those columns' centres;
the decoder's azimuth for m is the column's edge, pi - 2 pi m / W: half a column, 0.18 deg at 1024 columns, from
the ray), range round(|p| x 1000) mm, reflectivity round(intensity x 255); the nearest point of a pixel wins (as
for the VLP-16). Beam azimuth offsets 0, no beam origin offset (the simulator casts from the origin). Payloads: the
last --lead payloads (default 1) of frame 1000, the 64 of frame 1001 and the first of frame 1002, so that a
decoder started on the first one reports a PARTIAL scan, then frame 1001 COMPLETE (66 payloads; column timestamps
97,656 ns apart). The C file also holds the decoder's configuration (fw_ouster_meta_t: the metadata's profile,
beams, columns, beam azimuth offsets, init id, serial number); --meta writes that metadata as Ouster's JSON and
--pcap the payloads to port 7502, for `lidet detect --pcap FILE --lidar ouster --ouster-meta META --fixed`.

    python3 tools/firmware/packets_to_c.py SCAN.bin --ring RING.bin [--name NAME] [--start-cdeg C]
                                           [--packets N] [--pcap OUT.pcap] --out fw_scan.c
    .venv/bin/python tools/firmware/packets_to_c.py SCAN.bin --ring RING.bin --lidar ouster [--sensor os1-32]
                                           [--lead N] [--name NAME] [--meta OUT.json] [--pcap OUT.pcap] --out fw_scan.c
"""
import argparse
import math
import os
import pathlib
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


def _replace(path, write):
    """write(tmp) into path + '.tmp', then move it over path (a build never sees a half-written file)."""
    write(path + ".tmp")
    os.replace(path + ".tmp", path)


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


# ---- Ouster (--lidar ouster): lidet_tools.ouster's packet writer, numpy ------------------------------------------

OUSTER_PROFILE = "RNG19_RFL8_SIG16_NIR16"  # the sensors' default single-return profile (lidet_ouster_profile_t 3)
OUSTER_PROFILE_ID = 3
OUSTER_COLS_PER_PACKET = 16
OUSTER_FRAME0 = 1000           # the frame id of the first payload's columns
OUSTER_T0_NS = 10**12          # the first frame's column 0 timestamp
OUSTER_COL_NS = 97656          # 0.1 s / 1024 columns (write_packet's default step)
OUSTER_INIT_ID = 4711          # the sensor's initialization_id (24 bits) and prod_sn (40 bits): the decoder checks
OUSTER_PROD_SN = 992233000111  # them (lidet_ouster_cfg_t), as a product would with its sensor's metadata
OUSTER_PORT = 7502


def _ouster_tools():
    """numpy and lidet_tools (this repository's tools/, importable without installing it)."""
    root = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
    if root not in sys.path:
        sys.path.insert(0, root)
    try:
        import numpy as np
        from lidet_tools import ouster, sensors, velodyne
    except ImportError as e:
        sys.exit(f"packets_to_c: --lidar ouster writes its payloads with lidet_tools.ouster, which needs numpy: run it "
                 f"with the project's venv (.venv/bin/python; make deps) ({e})")
    return np, ouster, sensors, velodyne


def ouster_grid(np, points, intensity, ring, rows, cols):
    """(ranges mm, reflectivity) as [cols, rows] int64 arrays: each point at the pixel of its ring (row) and of its
    column in lidet's convention, floor(0.5 (1 - azimuth / pi) cols) (= the measurement id); the nearest point of
    a pixel wins, equal ranges the later in the scan (vlp16's rule); points with ring >= rows or a range outside
    (0, 2^19) mm are dropped."""
    p = np.asarray(points, dtype=np.float64)
    ring = np.asarray(ring, dtype=np.int64)
    az = np.arctan2(p[:, 1], p[:, 0])
    col = np.floor(0.5 * (1.0 - az / np.pi) * cols).astype(np.int64) % cols
    rng = np.round(np.sqrt((p * p).sum(axis=1)) * 1000.0).astype(np.int64)
    rfl = np.round(np.clip(np.asarray(intensity, dtype=np.float64), 0.0, 1.0) * 255.0).astype(np.int64)
    ok = np.flatnonzero((ring < rows) & (rng > 0) & (rng < 1 << 19))
    order = ok[np.argsort(-rng[ok], kind="stable")]  # far first; the last of a pixel wins
    key = col[order] * rows + ring[order]
    _, last = np.unique(key[::-1], return_index=True)
    win = order[len(order) - 1 - last]
    grid = np.zeros((cols, rows), np.int64)
    refl = np.zeros((cols, rows), np.int64)
    grid[col[win], ring[win]] = rng[win]
    refl[col[win], ring[win]] = rfl[win]
    return grid, refl


def ouster_payloads(ouster, np, grid, refl, rows, cols, lead):
    """The payloads: the last `lead` of frame OUSTER_FRAME0, every one of the next frame, the first of the one
    after. -> (list of payload bytes, the first payload's measurement id)."""
    per_frame = cols // OUSTER_COLS_PER_PACKET
    first = cols - OUSTER_COLS_PER_PACKET * lead
    out = []
    for k in range(lead + per_frame + 1):
        a = first + OUSTER_COLS_PER_PACKET * k  # columns since frame OUSTER_FRAME0's column 0
        m0 = a % cols
        out.append(ouster.write_packet(
            OUSTER_PROFILE, rows, cols, frame_id=OUSTER_FRAME0 + a // cols, first_mid=m0,
            ranges_mm=grid[m0:m0 + OUSTER_COLS_PER_PACKET], reflectivity=refl[m0:m0 + OUSTER_COLS_PER_PACKET],
            timestamps_ns=OUSTER_T0_NS + (a + np.arange(OUSTER_COLS_PER_PACKET)) * OUSTER_COL_NS,
            init_id=OUSTER_INIT_ID, prod_sn=OUSTER_PROD_SN))
    return out, first


def ouster_metadata(sensor, rows, cols):
    """Ouster's sensor metadata (JSON object) of these payloads: what lidet_tools.ouster.load_metadata and `lidet
    --ouster-meta` read. Beam altitudes: the preset's; azimuth offsets 0; no beam origin offset; lidar to sensor
    half a turn about z, no translation (the simulator's sensor frame)."""
    return {
        "beam_intrinsics": {"beam_altitude_angles": [math.degrees(float(e)) for e in sensor.beam_elev_rad],
                            "beam_azimuth_angles": [0.0] * rows, "lidar_origin_to_beam_origin_mm": 0.0},
        "lidar_intrinsics": {"lidar_to_sensor_transform": [-1.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0, 0.0, 1.0,
                                                           0.0, 0.0, 0.0, 0.0, 1.0]},
        "lidar_data_format": {"pixels_per_column": rows, "columns_per_frame": cols,
                              "columns_per_packet": OUSTER_COLS_PER_PACKET, "column_window": [0, cols - 1],
                              "udp_profile_lidar": OUSTER_PROFILE},
        "config_params": {"lidar_mode": f"{cols}x10", "udp_port_lidar": OUSTER_PORT,
                          "udp_profile_lidar": OUSTER_PROFILE},
        "sensor_info": {"prod_line": "OS-1-%d" % rows if sensor.name.startswith("os1-") else sensor.name,
                        "prod_sn": str(OUSTER_PROD_SN), "initialization_id": OUSTER_INIT_ID},
    }


def ouster_main(a, raw, rring, n, name):
    """--lidar ouster: the C file (and --meta, --pcap) from the scan's records."""
    import json
    np, ouster, sensors, velodyne = _ouster_tools()
    try:
        sensor = sensors.get_sensor(a.sensor)
    except ValueError as e:
        sys.exit(f"packets_to_c: --sensor: {e}")
    rows, cols = sensor.rows, sensor.cols
    if not sensor.name.startswith("os") or cols % OUSTER_COLS_PER_PACKET or rows > 128:
        sys.exit(f"packets_to_c: --sensor {a.sensor}: not an Ouster preset (os0-*, os1-*, os2-*)")
    if not 1 <= a.lead <= cols // OUSTER_COLS_PER_PACKET:
        sys.exit(f"packets_to_c: --lead {a.lead}: 1 to {cols // OUSTER_COLS_PER_PACKET} payloads")
    rec = np.frombuffer(raw, dtype="<f4").reshape(n, 4).astype(np.float64)
    ring = np.frombuffer(rring, dtype="<u2")
    if not np.isfinite(rec[:, :3]).all():
        sys.exit("packets_to_c: NaN or Inf coordinate")
    grid, refl = ouster_grid(np, rec[:, :3], rec[:, 3], ring, rows, cols)
    pays, first = ouster_payloads(ouster, np, grid, refl, rows, cols, a.lead)
    nbytes = len(pays[0])
    assert all(len(p) == nbytes == ouster.packet_bytes(OUSTER_PROFILE, rows) for p in pays)
    meta = ouster_metadata(sensor, rows, cols)
    az = ", ".join("0" for _ in range(rows))
    out = [
        f"/* GENERATED by tools/firmware/packets_to_c.py --lidar ouster from {name} ({n} points, "
        f"{int((grid > 0).sum())} {sensor.name} returns): {len(pays)} {OUSTER_PROFILE} payloads of {nbytes} bytes from "
        f"frame {OUSTER_FRAME0} column {first} - DO NOT EDIT */",
        '#include "fw_packets.h"',
        "",
        f"const uint32_t fw_pkt_n = {len(pays)}u;",
        f"const uint32_t fw_pkt_bytes = {nbytes}u;",
        f"const uint32_t fw_pkt_first_mid = {first}u;",
        f'const char fw_pkt_name[] = "{name}";',
        "/* the sensor's metadata, as lidet_ouster_cfg_t takes it (profile, beams, columns, columns per packet, init "
        "id, serial number's low 32 and high 8 bits, beam azimuth offsets in mdeg) */",
        f"const fw_ouster_meta_t fw_pkt_ouster = {{{OUSTER_PROFILE_ID}u, {rows}u, {cols}u, {OUSTER_COLS_PER_PACKET}u, "
        f"{OUSTER_INIT_ID}u, {OUSTER_PROD_SN & 0xFFFFFFFF}u, {OUSTER_PROD_SN >> 32}u, {{{az}}}}};",
        f"const uint8_t fw_pkt_payload[{len(pays)}u * {nbytes}u] = {{",
    ]
    for p in pays:
        for i in range(0, nbytes, 32):
            out.append("    " + ",".join(str(v) for v in p[i:i + 32]) + ",")
    out.append("};")
    _replace(a.out, lambda t: pathlib.Path(t).write_text("\n".join(out) + "\n"))
    if a.meta:
        _replace(a.meta, lambda t: pathlib.Path(t).write_text(json.dumps(meta, indent=1)))
    if a.pcap:
        frames = [velodyne.udp_frame(p, dport=OUSTER_PORT, sport=OUSTER_PORT) for p in pays]
        _replace(a.pcap, lambda t: velodyne.write_pcap(t, frames))
    return 0


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
    ap.add_argument("--lidar", choices=("velodyne", "ouster"), default="velodyne",
                    help="velodyne (default: VLP-16 payloads, standard library only) or ouster (needs numpy)")
    ap.add_argument("--sensor", default="os1-32", help="--lidar ouster: the Ouster preset (default os1-32)")
    ap.add_argument("--lead", type=int, default=1,
                    help="--lidar ouster: payloads of the frame before the complete one (default 1)")
    ap.add_argument("--meta", help="--lidar ouster: also write the sensor's metadata (Ouster's JSON) here")
    a = ap.parse_args(argv)

    if a.lidar == "velodyne" and a.meta:
        sys.exit("packets_to_c: --meta is --lidar ouster's")
    if a.lidar == "ouster" and a.packets:
        sys.exit("packets_to_c: --packets is --lidar velodyne's (ouster: --lead)")
    if not 0 <= a.start_cdeg < 36000 or a.start_cdeg % BLOCK_CDEG:
        sys.exit(f"packets_to_c: --start-cdeg {a.start_cdeg}: a multiple of 40 in [0, 36000)")
    with open(a.scan, "rb") as f:
        raw = f.read()
    if len(raw) % 16 != 0 or not raw:
        sys.exit(f"packets_to_c: {a.scan}: {len(raw)} bytes is not a whole number of 16-byte records")
    n = len(raw) // 16
    with open(a.ring, "rb") as f:
        rraw = f.read()
    if len(rraw) != 2 * n:
        sys.exit(f"packets_to_c: {a.ring}: {len(rraw)} bytes for {n} points (need 2 per point)")
    if a.lidar == "ouster":
        return ouster_main(a, raw, rraw, n, a.name or os.path.basename(a.scan))
    rec = struct.unpack(f"<{4 * n}f", raw)
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
    _replace(a.out, lambda t: pathlib.Path(t).write_text("\n".join(out) + "\n"))
    if a.pcap:
        _replace(a.pcap, lambda t: write_pcap(t, pkts))
    return 0


if __name__ == "__main__":
    sys.exit(main())
