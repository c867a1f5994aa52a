# SPDX-License-Identifier: MIT
"""Firmware images (issue 17): the whole detector on one simulated VLP-16 scan stored in flash, run under QEMU
with exact instruction counting, per core; compared with the host build of the same program on the same scan.

Runs the firmware tests (`ctest -R '^firmware_'`, which write build/firmware/<board>/report.json through
tools/firmware/run_fw.py) and turns their reports into the firmware section (docs/benchmarks/firmware.md). Needs the
cross toolchains and QEMU (tools/scripts/install_deps.sh); without them the section says so. LIDET_BENCH_FW_REUSE=1: use the
reports of the last ctest run instead of running the images again."""
from __future__ import annotations

import json
import os
import pathlib
import shutil
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]
BOARDS = [  # board, core, FPU, QEMU machine
    ("mps2-an386", "Cortex-M4F", "single precision", "mps2-an386"),
    ("mps2-an500", "Cortex-M7", "single precision (fpv5-sp-d16)", "mps2-an500"),
    ("virt-rv32imafc", "RV32IMAFC", "single precision (F)", "virt"),
    # 64-bit Arm bare metal (ports/aarch64): the float dense layers in NEON (lib/src/nn/lidet_nn_f32_neon.c), and the
    # same image with the portable kernel (built and run here: _variant_image)
    ("virt-aarch64", "Cortex-A72 (aarch64; NEON float dense kernel)", "double precision + NEON", "virt"),
    ("virt-aarch64-portable", "Cortex-A72 (aarch64; portable float dense kernel)", "double precision + NEON", "virt"),
    # the M4F image with the fused Cortex-M kernel (LIDET_NN_CM_FMA=1: fewer instructions, more cycles by the M4's
    # TRM; built and run here: _variant_image)
    ("mps2-an386-fused", "Cortex-M4F, fused multiply-adds (`LIDET_NN_CM_FMA=1`, not the default)", "single precision",
     "mps2-an386"),
    ("mps2-an385", "Cortex-M3", "none (soft float)", "mps2-an385"),
    ("mps2-an385-m0plus", "Cortex-M0+ code (ARMv6-M) on the AN385's M3", "none (soft float)", "mps2-an385"),
    ("mps2-an500-hdl64", "Cortex-M7, **HDL-64 scan** (config/hdl64; detector in PSRAM)",
     "single precision (fpv5-sp-d16)", "mps2-an500"),
    ("virt-rv32imafc-hdl64", "RV32IMAFC, **HDL-64 scan** (config/hdl64)", "single precision (F)", "virt"),
    # the integer-only build (LIDET_FW_FIXED: integer detector, int8 models; compared with the host bit for bit)
    ("mps2-an385-q", "Cortex-M3, **integer build** (small pair vlp16s)", "none (no float at all)", "mps2-an385"),
    ("mps2-an385-m0plus-q", "Cortex-M0+ code, **integer build** (vlp16s)", "none (no float at all)", "mps2-an385"),
    ("virt-rv32imac-q", "RV32IMAC, **integer build** (vlp16s)", "none (no F extension)", "virt"),
    ("mps2-an386-q", "Cortex-M4, **integer build** (vlp16s; DSP: SMLAD int8 kernel)", "present, unused (no float at all)",
     "mps2-an386"),
    ("mps2-an500-q", "Cortex-M7, **integer build** (vlp16s; DSP: SMLAD int8 kernel)", "present, unused (no float at all)",
     "mps2-an500"),
    ("virt-aarch64-q", "Cortex-A72 (aarch64), **integer build** (vlp16s)", "present, unused (NEON integer lanes only)",
     "virt"),
]
AARCH64_PORTABLE = "virt-aarch64-portable"
M4F_FUSED = "mps2-an386-fused"
# images that are not part of tests/firmware.cmake's set: built here with another option
VARIANTS = {AARCH64_PORTABLE: ("virt-aarch64", "aarch64-bare-metal", ["-DLIDET_NN_NEON=OFF"], "fw_host_ref",
                               "aarch64-linux-gnu-size"),
            M4F_FUSED: ("mps2-an386", "arm-none-eabi", ["-DLIDET_NN_CM_FMA=1"], "fw_host_ref_fused",
                        "arm-none-eabi-size")}
# the packet application (LIDET_FW_APP=packets, ports/firmware/fw_packets.c; issue 37): VLP-16 payloads in flash
# decoded and streamed into the integer detector; image, core, the fw_detect.c image fed the same scan's returns
PACKET_BOARDS = [
    ("mps2-an386-q-packets", "Cortex-M4, integer build (vlp16s; DSP)", "mps2-an386-q"),
    ("mps2-an385-m0plus-q-packets", "Cortex-M0+ code, integer build (vlp16s)", "mps2-an385-m0plus-q"),
    ("virt-rv32imac-q-packets", "RV32IMAC, integer build (vlp16s)", "virt-rv32imac-q"),
]
DECODE_GOAL = 1_000_000  # issue 37: decoding adds at most 1 M instructions to a VLP-16 scan
# the Ouster packet image (LIDET_FW_LIDAR=ouster, ports/firmware/config/os1-32): a simulated OS1-32 scan as Ouster
# RNG19_RFL8_SIG16_NIR16 payloads decoded with lidet_ouster_packet and streamed into the integer detector (beams32)
OUSTER_PACKET_BOARDS = [
    ("mps2-an386-q-packets-os1-32", "Cortex-M4, integer build, **Ouster OS1-32** (beams32; DSP)", 200e6),
    ("mps2-an385-m0plus-q-packets-os1-32", "Cortex-M0+ code, integer build, Ouster OS1-32 (beams32)", 200e6),
    ("virt-rv32imac-q-packets-os1-32", "RV32IMAC, integer build, Ouster OS1-32 (beams32)", 200e6),
]
OUSTER_FRAMES_PER_S = 10  # lidar mode 1024x10
VLP16_PAYLOADS_PER_TURN = 75  # 900 blocks of 0.4 deg (600 rpm), 12 a payload
STAGES = ["project", "ground", "cluster", "classify", "box", "post"]



def _scan_file(name: str) -> str:
    """The scan file an image's scan name (tools/firmware/scan_to_c.py: <folder>/<id>) stands for."""
    head, _, stem = name.rpartition("/")
    return f"{head}/velodyne/{stem}.bin" if head.startswith("tests/data/") else name

def _m(v: int) -> str:
    return f"{v / 1e6:,.1f} M"


def _kib(v: int) -> str:
    return f"{v / 1024:,.1f} KiB"


def _cycle_estimates(build, reports):
    """tools/firmware/cycles.py on the Cortex-M4, M3 and M0+ integer images and the M4F float image with either dense
    kernel (skipped without QEMU or the images)"""
    import importlib.util
    spec = importlib.util.spec_from_file_location("cycles", ROOT / "tools" / "firmware" / "cycles.py")
    cyc = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(cyc)
    out = []
    for board, core, label, mhz in (("mps2-an386-q", "m4", "Cortex-M4, integer build (vlp16s)", 200.0),
                                    ("mps2-an385-q", "m3", "Cortex-M3, integer build (vlp16s)", 100.0),
                                    ("mps2-an385-m0plus-q", "m0plus", "Cortex-M0+, integer build (vlp16s; the "
                                     "RP2040's clock)", 133.0),
                                    ("mps2-an386", "m4", "Cortex-M4F, float build (VMUL + VADD, the default)", 200.0),
                                    (M4F_FUSED, "m4", "Cortex-M4F, float build (VFMA, `LIDET_NN_CM_FMA=1`)", 200.0)):
        elf = build / "firmware" / board / "lidet_fw.elf"
        if board not in reports or not elf.exists() or not shutil.which("qemu-system-arm"):
            continue
        try:
            out.append((board, label, mhz, cyc.estimate(str(elf), core, "arm-none-eabi-nm")))
        except (OSError, RuntimeError, ValueError, subprocess.SubprocessError) as e:
            print(f"bench_firmware: cycle estimate of {board} failed: {e}", file=sys.stderr)
    return out


def _kernel_rows(head: str, rows) -> list:
    """A table of float dense kernels: head, then per (name, run `default` counts) its classify, box net, both and scan
    instructions."""
    out = [f"| {head} | classify | box net | classify + box net | **scan** |", "|---|---|---|---|---|"]
    for name, m in rows:
        out.append(f"| {name} | {m['classify']:,} | {m['box']:,} | {m['classify'] + m['box']:,} | **{m['scan']:,}** |")
    return out


def _variant_image(build, reports, name):
    """An image of VARIANTS (the virt-aarch64 float image with the portable float dense kernel, for the ratio of the
    NEON kernel to it; the M4F image with the fused Cortex-M kernel): configured, built and run here next to the
    build's images (tests/firmware.cmake builds only the defaults, to keep CI short), compared with the host like them
    (tools/firmware/run_fw.py). -> its report, or None (its board's image not in this build, or a step failed)."""
    board, toolchain, defs, ref_name, size_tool = VARIANTS[name]
    bdir = build / "firmware" / name
    rep = bdir / "report.json"
    if os.environ.get("LIDET_BENCH_FW_REUSE") == "1":
        return json.loads(rep.read_text()) if rep.exists() else None
    ref = build / "tests" / ref_name
    if not ref.exists():
        ref = build / "tests" / "fw_host_ref"
    if board not in reports or not ref.exists():
        return None
    steps = [
        ["cmake", "-S", str(ROOT / "ports" / "firmware"), "-B", str(bdir),
         f"-DCMAKE_TOOLCHAIN_FILE={ROOT / 'cmake' / 'toolchains' / f'{toolchain}.cmake'}",
         f"-DLIDET_FW_BOARD={board}", "-DLIDET_FW_SENSOR=vlp16", *defs, f"-DPython3_EXECUTABLE={sys.executable}"],
        ["cmake", "--build", str(bdir), "-j", "2"],
        [sys.executable, str(ROOT / "tools" / "firmware" / "run_fw.py"), "--board", board, "--label", name,
         "--elf", str(bdir / "lidet_fw.elf"), "--host-ref", str(ref), "--size", size_tool, "--json", str(rep)],
    ]
    for cmd in steps:
        p = subprocess.run(cmd, capture_output=True, text=True)
        if p.returncode != 0:
            print(f"bench_firmware: {name}: {' '.join(cmd[:3])} failed:\n{p.stdout[-2000:]}{p.stderr[-2000:]}",
                  file=sys.stderr)
            break
    return json.loads(rep.read_text()) if rep.exists() else None


def _packets_section(reports) -> list:
    """The packet images' table (PACKET_BOARDS): decoding, projection, the rest, per scan; RAM and flash."""
    rows = [(b, core, det) for b, core, det in PACKET_BOARDS if "default" in reports.get(b, {}).get("insn", {})]
    if not rows:
        return []
    r0 = reports[rows[0][0]]
    d0 = r0["decode"]["default"]
    out = [
        "",
        "**Packets from flash** (issue 37; `LIDET_FW_APP=packets`, ports/firmware/fw_packets.c, docs/PORTING.md "
        "\"Streaming the returns\"): the images `*-q-packets` hold the scan above as "
        f"{d0['packets']} VLP-16 data payloads ({(r0.get('header') or {}).get('packets', '?')} x 1206 bytes of const "
        "data, made at build time by tools/firmware/packets_to_c.py: lidet_tools.velodyne's vlp16_grid and "
        "vlp16_packets, strongest return, 0.4 deg a block, the first payload half a packet before the seam), decode "
        "them one at a time with `lidet_velodyne_packet` into a buffer of `LIDET_VELODYNE_MAX_RETURNS` (384) returns "
        "and stream each into the integer detector (`lidet_detector_q_stream_begin` at the first seam, "
        "`_stream_returns` per payload, `_stream_end` when the decoder reports the rotation `COMPLETE`), with no "
        f"buffer for the scan: {d0['scan_returns']:,} returns from payloads {d0['first']}..{d0['last']} (the "
        "simulated scan's points, one per 0.2 deg cell and ring, their azimuths now the firing times' and their "
        "ranges in 2 mm steps, so the stages' counts differ a little from the `-q` images'). Compared with `fw_host_ref_pkt` (the same payloads "
        "decoded on the host into a buffer of the whole scan, `lidet_detector_q_run_returns` on it) by "
        "tools/firmware/run_fw.py: detections, counts, the decoder's counts and a digest of the scan's returns "
        "identical. Run `default`; decode = `lidet_velodyne_packet` over all "
        f"{d0['packets']} payloads (the counter reads' own instructions subtracted), projection = "
        "`stream_begin` + every `stream_returns` + the projection's end inside `stream_end`, rest = ground, "
        "clustering, networks and NMS (the rest of `stream_end`), total = the first payload to the detections:",
        "",
        "| core | **decode** (per payload: mean / largest) | projection (largest `stream_returns`) | rest | "
        "**total per scan** | fw_detect.c's `-q` image (the scan's points as returns in RAM) | flash (no payloads) | "
        "payloads in flash | **RAM** (data + bss + stack) | stack used |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for board, core, det in rows:
        r = reports[board]
        ins, pk, d, sz = r["insn"]["default"], r.get("pktinsn", {}).get("default", {}), r["decode"]["default"], r["size"]
        rest = sum(ins[k] for k in ("ground", "cluster", "classify", "box", "post"))
        ref = reports.get(det, {}).get("insn", {}).get("default")
        out.append(
            f"| {core} | **{_m(ins['decode'])}** ({ins['decode'] / d['packets'] / 1e3:,.1f} k / "
            f"{pk.get('decode_max', 0) / 1e3:,.1f} k) | {_m(ins['project'])} ({pk.get('stream_max', 0) / 1e3:,.1f} k) "
            f"| {_m(rest)} | **{_m(ins['scan'])}** | " + (f"{_m(ref['scan'])}" if ref else "-") +
            f" | {_kib(sz['flash_without_scan'])} | {_kib(sz['rodata_scan'])} | **{_kib(sz['ram'])}** "
            f"({sz['ram']:,} B) | {r['stack']['used']:,} B |")
    m4 = reports.get("mps2-an386-q-packets")
    if m4 and "default" in m4.get("insn", {}):
        ins, d = m4["insn"]["default"], m4["decode"]["default"]
        turn = ins["decode"] * VLP16_PAYLOADS_PER_TURN / d["packets"]
        per_ret = ins["decode"] / max(d["returns"], 1)
        out += [
            "",
            f"Goal (issue 37): decoding adds at most 1 M instructions to a VLP-16 scan. On the Cortex-M4 "
            f"`lidet_velodyne_packet` takes {ins['decode']:,} instructions for the {d['packets']} payloads "
            f"({turn / 1e6:.2f} M for the {VLP16_PAYLOADS_PER_TURN} payloads of one rotation; {per_ret:.0f} per "
            f"return of the {d['returns']:,} decoded): "
            + ("**the goal holds**." if turn <= DECODE_GOAL else
               f"**the goal does not hold** ({turn / DECODE_GOAL:.1f}x; docs/DECODING.md).")
            + f" With decoding the scan takes {_m(ins['scan'])} from the first payload to the detections; the "
            f"latency from the last payload to them is `stream_end`'s {_m(m4['pktinsn']['default']['end'])}.",
        ]
    out += ["", "Measured by `ctest --test-dir build -R q-packets` (tools/firmware/run_fw.py writes "
            "`build/firmware/<image>/report.json`), tabulated by this benchmark (tools/bench/bench_firmware.py).", ""]
    for b, core, _ in rows:
        r = reports[b]
        out.append(f"- {core}, against `fw_host_ref_pkt`: " + " / ".join(r.get("comparison", [])[:2]) +
                   (" **FAILED: " + "; ".join(r["errors"]) + "**" if r.get("errors") else ""))
    return out


def _ouster_section(reports) -> list:
    """The Ouster packet image's table (OUSTER_PACKET_BOARDS): decoding per payload and per return, its share of the
    scan, the scan with decoding; RAM and flash."""
    rows = [b for b in OUSTER_PACKET_BOARDS if "default" in reports.get(b[0], {}).get("insn", {})]
    if not rows:
        return []
    r0 = reports[rows[0][0]]
    h, d0, mem = r0.get("header") or {}, r0["decode"]["default"], r0.get("mem") or {}
    out = [
        "",
        "**Ouster packets from flash** (`LIDET_FW_LIDAR=ouster`, docs/OUSTER.md \"On a microcontroller\"): the image "
        f"`{rows[0][0]}` holds a simulated OS1-32 scan (`lidet-sim --sensor os1-32 --seed 0`, scan 000000, made at "
        f"build time in `build/firmware/sim_os1-32`) as {h.get('packets', '?')} Ouster lidar payloads "
        f"({h.get('packets', '?')} x {int(h.get('payload_bytes', 0)):,} bytes: RNG19_RFL8_SIG16_NIR16, 32 beams x 16 "
        "columns, written by lidet_tools.ouster's `write_packet` through tools/firmware/packets_to_c.py --lidar "
        "ouster: "
        "the last payload of one frame, the 64 of the next, the first of the one after), decodes them one at a time "
        f"with `lidet_ouster_packet` into a buffer of {mem.get('max_returns', '?')} returns "
        f"({mem.get('buffer_bytes', 0):,} B; the decoder {mem.get('decoder_bytes', 0):,} B) and streams them into the "
        "integer detector as the VLP-16 images do; the frame completes when the next frame's first payload arrives "
        f"(`COMPLETE`: {d0['scan_returns']:,} returns from payloads {d0['first']}..{d0['last']}). Capacities of "
        f"`ports/firmware/config/os1-32` ({mem.get('max_rows')} x {mem.get('max_cols')} pixels, "
        f"{mem.get('max_points', 0):,} points, {mem.get('max_clusters')} clusters, the range-only pixel; the detector "
        f"{mem.get('detector_bytes', 0):,} B), models `{h.get('models', '?')}`. Compared with "
        "`fw_host_ref_pkt_ouster` (the same payloads decoded on the host into a buffer of the whole frame, "
        "`lidet_detector_q_run_returns` on it) by tools/firmware/run_fw.py: detections, counts, the decoder's counts "
        "and the digest of the frame's returns identical. Run `default`; columns as above, decode per return = over "
        "all the returns decoded:",
        "",
        "| core | **decode** (per payload: mean / largest; per return) | share of the scan | projection (largest "
        "`stream_returns`) | rest | **total per scan** | flash (no payloads) | payloads in flash | **RAM** (data + bss "
        "+ stack) | stack used |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for board, core, _ in rows:
        r = reports[board]
        ins, pk, d, sz = (r["insn"]["default"], r.get("pktinsn", {}).get("default", {}), r["decode"]["default"],
                          r["size"])
        rest = sum(ins[k] for k in ("ground", "cluster", "classify", "box", "post"))
        out.append(
            f"| {core} | **{_m(ins['decode'])}** ({ins['decode'] / d['packets'] / 1e3:,.1f} k / "
            f"{pk.get('decode_max', 0) / 1e3:,.1f} k; {ins['decode'] / max(d['returns'], 1):.0f}) | "
            f"{100.0 * ins['decode'] / ins['scan']:.1f}% | {_m(ins['project'])} "
            f"({pk.get('stream_max', 0) / 1e3:,.1f} k) | {_m(rest)} | **{_m(ins['scan'])}** | "
            f"{_kib(sz['flash_without_scan'])} | {_kib(sz['rodata_scan'])} | "
            f"**{_kib(sz['ram'])}** ({sz['ram']:,} B) | {r['stack']['used']:,} B |")
    board, core, hz = rows[0]
    r = reports[board]
    ins, d, sz = r["insn"]["default"], r["decode"]["default"], r["size"]
    per_frame = int(r["mem"]["max_cols"]) // 16
    frame = ins["decode"] * per_frame / d["packets"]
    out += [
        "",
        f"On the Cortex-M4 `lidet_ouster_packet` takes {ins['decode']:,} instructions for the {d['packets']} payloads "
        f"({frame / 1e6:.2f} M for the {per_frame} payloads of a frame, {frame * OUSTER_FRAMES_PER_S / 1e6:.1f} M a "
        f"second at {OUSTER_FRAMES_PER_S} Hz; {ins['decode'] / max(d['returns'], 1):.0f} per return of the "
        f"{d['returns']:,} decoded), {100.0 * ins['decode'] / ins['scan']:.1f}% of the {_m(ins['scan'])} from the "
        f"first payload to the detections; the latency from the payload that completes the frame (the next frame's "
        f"first) to them is `stream_end`'s {_m(r['pktinsn']['default']['end'])}. A single-issue core retires at most "
        "one instruction a cycle: at "
        f"{hz / 1e6:.0f} MHz the M4 runs at most {hz / ins['scan']:.1f} such scans a second (the sensor sends "
        f"{OUSTER_FRAMES_PER_S} frames a second). RAM {sz['ram']:,} B: "
        + ("within" if sz["ram"] <= 256 * 1024 else f"{(sz['ram'] - 256 * 1024):,} B over")
        + f" the VLP-16 images' 256 KiB (the {mem.get('max_rows')} x {mem.get('max_cols')} image has "
        f"{100.0 * (int(mem.get('max_rows', 0)) * int(mem.get('max_cols', 0)) / (16 * 1800) - 1):.0f} % more pixels "
        "than 16 x 1800; docs/FIRMWARE.md).",
        "",
    ]
    for board, core, _ in rows:
        r = reports[board]
        out.append(f"- {core}, against `fw_host_ref_pkt_ouster`: " + " / ".join(r.get("comparison", [])[:3]) +
                   (" **FAILED: " + "; ".join(r["errors"]) + "**" if r.get("errors") else ""))
    return out


def _sectors_section(reports) -> list:
    """The packet images' run `sectors` (lidet_detector_q_cfg_t.stream_sectors) against run `default`: the latency
    from the last payload to the detections (`stream_end`), the streamed ground's share of the payloads' calls, the
    whole scan."""
    rows = [(b, core) for b, core, _ in PACKET_BOARDS + OUSTER_PACKET_BOARDS
            if "sectors" in reports.get(b, {}).get("pktinsn", {}) and "default" in reports[b]["pktinsn"]]
    if not rows:
        return []
    out = [
        "",
        "**The ground stage while the payloads arrive** (`lidet_detector_q_cfg_t.stream_sectors`, docs/PORTING.md "
        "\"Streaming the returns\"): the packet images' third run, `sectors`, is run `default` with the ground stage "
        "done on each of its sectors as soon as the stream has moved past it, inside the `stream_returns` calls, so "
        "`stream_end` has only the last sectors (the first payload's, and those within the margin of the last "
        "payload) and the fallback left. Its results equal the host's `lidet_detector_q_run_returns` with the same "
        "configuration bit for bit (the comparisons below; the configuration draws a RANSAC stream per ground cell, "
        "so its detections may differ from run `default`'s). Latency = `stream_end`, from the payload that completes "
        "the scan to the detections; ground = the ground stage's instructions inside `stream_end`; streaming = "
        "`stream_begin` + every `stream_returns` (the projection, and in run `sectors` the streamed ground):",
        "",
        "| core | **latency** `default` | **latency** `sectors` | ratio | ground in `stream_end` | streaming "
        "(largest call) | total per scan |",
        "|---|---:|---:|---:|---|---|---|",
    ]
    for board, core in rows:
        r = reports[board]
        pd, ps = r["pktinsn"]["default"], r["pktinsn"]["sectors"]
        idf, isc = r["insn"]["default"], r["insn"]["sectors"]
        out.append(
            f"| {core} | **{_m(pd['end'])}** | **{_m(ps['end'])}** | {ps['end'] / max(pd['end'], 1):.2f} | "
            f"{_m(idf['ground'])} -> {_m(isc['ground'])} | {_m(idf['project'])} ({pd['stream_max'] / 1e3:,.1f} k) -> "
            f"{_m(isc['project'])} ({ps['stream_max'] / 1e3:,.1f} k) | {_m(idf['scan'])} -> {_m(isc['scan'])} |")
    out += [""]
    for board, core in rows:
        r = reports[board]
        cmp = [c for c in r.get("comparison", []) if c.startswith("run sectors")]
        out.append(f"- {core}, run sectors: " + " / ".join(cmp) +
                   (" **FAILED: " + "; ".join(r["errors"]) + "**" if r.get("errors") else ""))
    return out


def run(args) -> str:
    build = pathlib.Path(args.build)
    if os.environ.get("LIDET_BENCH_FW_REUSE") == "1":  # the reports of the last ctest run, as they are
        p = subprocess.CompletedProcess([], 0)
    else:
        p = subprocess.run(["ctest", "--test-dir", str(build), "-R", "^firmware_", "--output-on-failure"],
                           capture_output=True, text=True)
    reports = {}
    for board, *_ in BOARDS:
        f = build / "firmware" / board / "report.json"
        if f.exists() and board not in VARIANTS:
            reports[board] = json.loads(f.read_text())
    for board, *_ in PACKET_BOARDS + OUSTER_PACKET_BOARDS:
        f = build / "firmware" / board / "report.json"
        if f.exists():
            reports[board] = json.loads(f.read_text())
    for name in VARIANTS:
        v = _variant_image(build, reports, name)
        if v:
            reports[name] = v
    out = ["## Firmware: Cortex-M and RISC-V under QEMU (issue 17)", ""]
    if not reports:
        out += ["Not measured in this run: no firmware image was built (the cross toolchains and QEMU come with "
                "`tools/scripts/install_deps.sh`).", ""]
        return "\n".join(out) + "\n"
    if p.returncode != 0:
        out += ["**Some firmware tests failed in this run** (`ctest -R '^firmware_'`); the figures below are "
                "those of the images that reported.", ""]
    any_rep = next(iter(reports.values()))
    hdr = any_rep.get("header") or {}
    mem = any_rep.get("mem") or {}
    out += [
        f"The whole float detector (`lidet_detector_run`, models `{hdr.get('models', '?')}`) on one simulated "
        f"VLP-16 scan stored in flash (`{_scan_file(hdr.get('scan', '?'))}`, {hdr.get('points', '?')} points with their ring "
        f"indices), capacities of `ports/firmware/config/vlp16/lidet_user_config.h` ({mem.get('max_rows')} x "
        f"{mem.get('max_cols')} pixels, {mem.get('max_points'):,} points, {mem.get('max_clusters')} clusters). "
        "Images built with GCC 12 (Debian's gcc-arm-none-eabi + newlib-nano, gcc-riscv64-unknown-elf + picolibc, "
        "gcc-aarch64-linux-gnu without a C library: ports/aarch64/virt_libc.c), "
        "-O2, and run under QEMU 7.2 with `-icount`. Two runs per image: `default` (the configuration a user gets: "
        "gates and size checks on) and `open` (gates and "
        "size checks off, so that every classified proposal is boxed and compared). The rows marked **HDL-64 scan** "
        "are the KITTI-like images: the simulated HDL-64 scan `tests/data/sim_hdl64/velodyne/000000.bin` (124,205 points) with "
        "the capacities of `ports/firmware/config/hdl64/lidet_user_config.h` (64 x 2048, 131,072 points, 1024 "
        "clusters). Its detector (4.4 MiB) does not fit "
        "the MPS2 boards' 4 MiB SRAM: on the AN500's Cortex-M7 it is placed in the 16 MiB PSRAM with a section "
        "attribute (`-DLIDET_FW_DETECTOR_SECTION='\".bss.extram\"'`, docs/PORTING.md), on QEMU virt it is in RAM.",
        "",
        "**Instructions per scan** (exact: QEMU's instruction count, read through the detector's `clock` hook; "
        "the method is below), run `default`:",
        "",
        "| core | FPU | project | ground | cluster | classify | box net | post | **scan** | stack high-water |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for board, core, fpu, _ in BOARDS:
        r = reports.get(board)
        if not r or "default" not in r.get("insn", {}):
            continue
        ins = r["insn"]["default"]
        out.append(f"| {core} | {fpu} | " + " | ".join(_m(ins[s]) for s in STAGES) +
                   f" | **{_m(ins['scan'])}** | {r['stack']['used']:,} B |")
    pts = [(b, core, fpu) for b, core, fpu, _ in BOARDS if "points" in reports.get(b, {}).get("insn", {})]
    if pts:
        out += [
            "",
            "The integer images' runs `default` and `open` feed the scan as the sensor's returns (ring, azimuth, "
            "range: `lidet_detector_q_run_returns`, the way in for a driver with the sensor's packets, "
            "docs/PORTING.md); their run `points` is run `default`'s configuration on the same scan as x, y, z in "
            "mm (`lidet_detector_q_run`: the projection finds row and column from the coordinates):",
            "",
            "| core (run `points`) | FPU | project | ground | cluster | classify | box net | post | **scan** | "
            "vs run `default` |",
            "|---|---|---|---|---|---|---|---|---|---|",
        ]
        for board, core, fpu in pts:
            ins, d = reports[board]["insn"]["points"], reports[board]["insn"]["default"]
            out.append(f"| {core} | {fpu} | " + " | ".join(_m(ins[s]) for s in STAGES) +
                       f" | **{_m(ins['scan'])}** | +{_m(ins['scan'] - d['scan'])} |")
    a64, a64p = reports.get("virt-aarch64"), reports.get(AARCH64_PORTABLE)
    if a64 and a64p and "default" in a64.get("insn", {}) and "default" in a64p.get("insn", {}):
        n, p = a64["insn"]["default"], a64p["insn"]["default"]
        both = lambda m: m["classify"] + m["box"]
        out += [
            "",
            "**aarch64: the NEON float dense kernel against the portable one.** `virt-aarch64` is QEMU's Arm `virt` "
            "machine with a Cortex-A72 (the cores of a Raspberry Pi 4) run bare metal (ports/aarch64: EL1, MMU on, "
            "console on the PL011, exit through semihosting); its float image runs the PointNets' dense layers with "
            "the NEON kernel (lib/src/nn/lidet_nn_f32_neon.c: 8 x 8 register tiles of fused multiply-adds, the x86 "
            "FMA kernel's arithmetic), the same image built with `-DLIDET_NN_NEON=OFF` the portable kernel (at -O2, "
            "as every image: GCC 12 leaves its loops scalar there). Instructions per scan, run `default` (the stages "
            "before the networks are the same code in both):",
            "",
            *_kernel_rows("float dense kernel", [("NEON", n), ("portable", p)]),
            f"| NEON / portable | {n['classify'] / p['classify']:.3f} | {n['box'] / p['box']:.3f} | "
            f"{both(n) / both(p):.3f} | **{n['scan'] / p['scan']:.3f}** |",
            "",
            f"Run `open` (every classified proposal boxed): scan {a64['insn']['open']['scan']:,} against "
            f"{a64p['insn']['open']['scan']:,} ({a64['insn']['open']['scan'] / a64p['insn']['open']['scan']:.3f}). "
            "Instruction counts, not time: how many cycles each takes on a Cortex-A72 or A76 (dual-issue, out of order) "
            "is not measured here. The NEON image's detections agree with the host's within the firmware comparison's "
            "tolerances below (its kernel fuses the multiply-adds: the last bits differ from the portable "
            "arithmetic); the portable image's only differ where libm's do.",
        ]
    m4, m4f = reports.get("mps2-an386"), reports.get(M4F_FUSED)
    if m4 and m4f and "default" in m4.get("insn", {}) and "default" in m4f.get("insn", {}):
        u, f = m4["insn"]["default"], m4f["insn"]["default"]
        out += [
            "",
            "**Cortex-M4F: fused multiply-adds or not.** The Cortex-M float dense kernel (lib/src/nn/lidet_nn_f32_cm.c) "
            "has two arithmetics: by default the portable kernel's (VMUL + VADD, the bits of the portable kernel), with "
            "`LIDET_NN_CM_FMA=1` the fused one of the x86-64 and NEON kernels (VFMA), which the Cortex-M7 images use. "
            "The M4F image built both ways (the fused one compared with `fw_host_ref_fused`), instructions per scan, run "
            "`default`:",
            "",
            *_kernel_rows("Cortex-M4F dense kernel", [("VMUL + VADD (default)", u), ("VFMA (`LIDET_NN_CM_FMA=1`)", f)]),
            "",
            "Fewer instructions, not fewer cycles on this core: the Cortex-M4 TRM gives VFMA.F32 3 cycles against 1 "
            "each for VMUL.F32 and VADD.F32, so a sweep of 8 outputs by four inputs costs about 153 cycles fused against "
            "121 unfused (zero wait states; docs/journal/firmware.md), and the whole scan priced the same way takes more "
            "cycles fused (\"Cycles, estimated\" below). The default stays unfused on the M4F.",
        ]
    out += [
        "",
        "Run `open` (gates and size checks off) differs only in `post` (size check and NMS on "
        f"{reports.get('mps2-an386', any_rep)['stats']['open']['boxed']} boxes; HDL-64: "
        f"{reports.get('virt-rv32imafc-hdl64', any_rep)['stats']['open']['boxed']}): "
        + "; ".join(f"{core.split(' ')[0].rstrip(',')}{' HDL-64' if b.endswith('hdl64') else ''} "
                    f"{r['insn']['open']['post']:,}"
                    for b, core, *_ in BOARDS
                    if (r := reports.get(b)) and "open" in r.get("insn", {}) and b not in VARIANTS)
        + " instructions.",
        "",
        "**Size** (bytes, `size -A` of the linked image; the scan is test data and not part of a product's flash):",
        "",
        "| core | .text | weights (.rodata) | other .rodata | .data | .bss (of which the detector; the tracker) | "
        "stack reserved | "
        "**flash** (text + rodata + data, no scan) | **RAM** (data + bss + stack) | scan in flash |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for board, core, *_ in BOARDS:
        r = reports.get(board)
        if not r or not r.get("size"):
            continue
        s = r["size"]
        out.append(f"| {core} | {s['text']:,} | {s['rodata_weights']:,} | {s['rodata_other']:,} | {s['data']:,} | "
                   f"{s['bss']:,} ({r['mem']['detector_bytes']:,}"
                   + (f"; {r['mem']['tracker_bytes']:,}" if "tracker_bytes" in r["mem"] else "")
                   + f") | {s['stack_reserved']:,} | "
                   f"**{_kib(s['flash_without_scan'])}** | **{_kib(s['ram'])}** | {_kib(s['rodata_scan'])} |")
    trk = [(b, core, fpu) for b, core, fpu, _ in BOARDS
           if "synthetic" in reports.get(b, {}).get("track", {}) and "insn_max" in reports[b]["track"]["synthetic"]]
    if trk:
        syn0 = reports[trk[0][0]]["track"]["synthetic"]
        out += [
            "",
            "**The tracker after the detector** (issue 38; docs/TRACKING.md, \"On the board\"): the integer images run "
            "`lidet_tracker_q`, the float images `lidet_tracker`, with the image's capacities (VLP-16: "
            f"`LIDET_TRACK_MAX_TRACKS` {mem.get('track_max_tracks')}, `LIDET_TRACK_MAX_DETS` "
            f"{mem.get('track_max_dets')}, config/vlp16; HDL-64: the library's 64 and 64), default configuration "
            "(optimal assignment). Its cost per update on a scene the image generates (integers only, the same on "
            f"every core and on the host): {syn0['dets']} road users in 4 lanes (cars, cyclists, pedestrians at "
            "-1.2 to +8 m/s), +-5 cm of noise on the centres, a sensor that moves at 5 m/s and turns at 7 deg/s (the "
            f"tracker gets it as its ego motion), {syn0['updates']} scans at 10 Hz; every update from the third on "
            f"has {syn0['dets']} confirmed tracks and {syn0['dets']} detections, all matched (the image fails "
            "otherwise). Instructions of one `lidet_tracker_q_update` / `lidet_tracker_update` call: the maximum, "
            f"mean and minimum over those {syn0['updates'] - 2} updates, the first update (no track yet: "
            f"{syn0['dets']} births) and the second (the first assignment); then the tracker on run `default`'s "
            "own detections (the same scan twice, dt 0.1 s): its second update. Goal: <= 0.5 M instructions per "
            "update on the M4 for 32 tracks.",
            "",
            f"| core | tracker (sizeof) | **per update, {syn0['dets']} tracks: max** | mean | min | first update "
            "(births) | second update | run `default`'s detections: second update |",
            "|---|---|---|---|---|---|---|---|",
        ]
        for board, core, _ in trk:
            r = reports[board]
            sy, dt = r["track"]["synthetic"], r["track"].get("default", {})
            out.append(f"| {core} | {r['mem'].get('tracker_bytes', 0):,} B | **{sy['insn_max'] / 1e6:.3f} M** | "
                       f"{sy['insn_mean'] / 1e6:.3f} M | {sy['insn_min'] / 1e6:.3f} M | {sy['insn_first']:,} | "
                       f"{sy['insn_second']:,} | "
                       + (f"{dt['insn_second']:,} ({dt['dets']} detections, {dt['tracks']} tracks)"
                          if "insn_second" in dt else "-") + " |")
        m4q = reports.get("mps2-an386-q", {}).get("track", {}).get("synthetic")
        if m4q and "insn_max" in m4q:
            out += ["", f"On the Cortex-M4 (integer build) the tracker takes at most {m4q['insn_max']:,} instructions per "
                    f"update with {m4q['dets']} tracks ({100.0 * m4q['insn_max'] / 500000:.0f}% of the 0.5 M goal; "
                    f"{100.0 * m4q['insn_max'] / reports['mps2-an386-q']['insn']['default']['scan']:.2f}% of the "
                    "detector's scan). The tracker runs after the detector's stages: their counts above and the detections "
                    "are the same as without it; its state is in the RAM figures below."]
    out += [
        "",
        f"`sizeof(lidet_detector_t)` = `lidet_detector_bytes()` = {any_rep['mem']['detector_bytes']:,} B "
        f"({_kib(any_rep['mem']['detector_bytes'])}) at the VLP-16 capacities on the 32-bit targets"
        + (f", {reports['virt-rv32imafc-hdl64']['mem']['detector_bytes']:,} B at the HDL-64 ones."
           if "virt-rv32imafc-hdl64" in reports else "."),
        "",
        "**Against the host build** (`fw_host_ref`: the same program built for x86-64 against lidet with the same "
        "capacities, on the same generated scan; for the Cortex-M7, RV32IMAFC and aarch64 float images, whose dense "
        "layers fuse their multiply-adds, `fw_host_ref_fused` and `fw_host_ref_hdl64_fused`, the same with the "
        "x86-64 FMA kernel; `tools/firmware/run_fw.py` compares every count of the detector "
        "and every detection, matched by cluster id, and for the tracker the counts of its last update and every "
        "track in id order):",
        "",
    ]
    for board, core, *_ in BOARDS:
        r = reports.get(board)
        if r:
            out.append(f"- {core}: " + " / ".join(r.get("comparison", [])) +
                       (" **FAILED: " + "; ".join(r["errors"]) + "**" if r.get("errors") else ""))
    out += [
        "",
        "Tolerances (the test fails beyond them): boxes 1e-3 m, yaw 1e-3 rad, score 1e-4, energies 1e-4 "
        "relative (the tracker's values: 1e-3 m, m/s and rad, covariances 1e-4 relative, the integer images' exactly); "
        "counts, classes, cluster ids and point counts, the tracks' ids, states, hits and detection indices must be "
        "identical. Only expf/logf/sinf/cosf/"
        "tanf/atan2f differ between glibc, newlib, picolibc and the aarch64 image's own (an ulp or two); every other "
        "operation is IEEE single precision in the same order on both sides (-ffp-contract=off), soft float included, "
        "but for the aarch64 float image's dense layers (fused multiply-adds, above).",
        "",
        "**Method.** Instruction counts are QEMU's own (`-icount`: the virtual clock advances exactly 2^shift ns per "
        "executed guest instruction). RISC-V: `-icount shift=0` and the `minstret` CSR, which QEMU then derives from "
        "that count. aarch64 (`virt-aarch64`): `-icount shift=0` and the PMU's event counter 0 on event 0x08, "
        "INST_RETIRED, which QEMU counts from that same instruction count (32 bits, extended to 64 in software). "
        "MPS2: `-icount shift=8` and CMSDK timer 0 at the board's 25 MHz (6.4 ticks per instruction, "
        "rounded back exactly; its wrap interrupt extends it to 64 bits). The detector's `clock` hook records 64-bit "
        "timestamps, from which the stages are rebuilt (their low 32 bits must equal the detector's own uint32 "
        "ticks). Every image first measures hand-written loops of known length (2n+1 instructions) and fails unless "
        "the counter gives exactly their difference. Counts include the few instructions of the clock hook itself.",
        "",
        "**Cycles on silicon: not measured.** QEMU counts instructions, not cycles. Bounds only: a single-issue "
        "core (M0+, M3, M4) needs at least one cycle per instruction, so the M4F at 200 MHz needs at least "
        f"{reports['mps2-an386']['insn']['default']['scan'] / 200e6:.2f} s per scan"
        if "mps2-an386" in reports else "**Cycles on silicon: not measured.**",
    ]
    if "mps2-an386" in reports and "mps2-an500" in reports:
        out[-1] += (f"; the dual-issue M7 at least {reports['mps2-an500']['insn']['default']['scan'] / 2 / 480e6:.2f} s "
                    "at 480 MHz (two instructions per cycle at best). Real times are longer (flash wait states, "
                    "multi-cycle loads, 14-cycle divides and square roots).")
    est = _cycle_estimates(build, reports)
    if est:
        out += ["", "**Cycles, estimated** (`python3 tools/firmware/cycles.py --elf "
                "build/firmware/<image>/lidet_fw.elf --core m4|m3|m0plus --report build/firmware/<image>/report.json`): "
                "QEMU's trace of every executed instruction (all runs, lidet's and the application's code), each "
                "priced with the cycle counts of the core's Technical Reference Manual at zero wait states (loads 1-2 "
                "with the TRM's pipelining, taken branches 1 + P with P 1-3, divides 2-12, M3 long multiplies 3-7; "
                "the M4's FPU: VADD and VMUL 1, VFMA and VMLA 3, VDIV and VSQRT 14, VLDR 2, VLDM 1 + N; the M0+ by its "
                "own TRM: loads and stores 2, taken branches 2, BL 3, MULS 1 as on the RP2040, no divide); the "
                "trace's cycles per instruction applied to run `default`'s exact count; low and high estimates, not "
                "measurements: flash wait states and bus contention come on top.", "",
                "| image | CPI (low - high) | cycles per scan, estimated | time per scan at the clock |",
                "|---|---|---|---|"]
        for board, core, mhz, r in est:
            ins = reports[board]["insn"]["default"]["scan"]
            out.append(f"| {core} | {r['cpi_low']:.2f} - {r['cpi_high']:.2f} | {ins * r['cpi_low'] / 1e6:.1f} - "
                       f"{ins * r['cpi_high'] / 1e6:.1f} M | {ins * r['cpi_low'] / mhz / 1e3:.0f} - "
                       f"{ins * r['cpi_high'] / mhz / 1e3:.0f} ms at {mhz:.0f} MHz |")
    m4 = reports.get("mps2-an386")
    if m4 and m4.get("size") and "default" in m4.get("insn", {}):
        ins, sz = m4["insn"]["default"], m4["size"]
        out += [
            "",
            "Goals of issue 17 (set for the integer build): <= 20 M instructions per "
            "scan on Cortex-M, RAM (data + bss + stack) <= 256 KB, flash <= 512 KB with the weights. The float "
            f"build on the M4F, measured the same way: flash {_kib(sz['flash_without_scan'])} "
            f"({'within' if sz['flash_without_scan'] <= 512 * 1024 else 'over'}; weights {_kib(sz['rodata_weights'])}), "
            f"{ins['scan'] / 20e6:.1f}x the instruction goal (the classify and box stages, i.e. "
            f"{m4['stats']['default']['classified']} proposals through the two PointNets, are "
            f"{100.0 * (ins['classify'] + ins['box']) / ins['scan']:.0f}% of the instructions), "
            f"{sz['ram'] / (256 * 1024):.1f}x the RAM goal (the stage workspace: docs/MEMORY.md).",
        ]
    q = reports.get("mps2-an385-q")
    if q and q.get("size") and "default" in q.get("insn", {}):
        ins, sz = q["insn"]["default"], q["size"]
        rams = {b: reports[b]["size"]["ram"] for b in ("mps2-an385-q", "mps2-an385-m0plus-q", "virt-rv32imac-q")
                if b in reports and reports[b].get("size")}
        m4q = ""
        if "default" in reports.get("mps2-an386-q", {}).get("insn", {}):
            m = reports["mps2-an386-q"]["insn"]["default"]
            m4q = (f", {m['scan'] / 20e6:.1f}x on the M4 ({_m(m['scan'])}: the ground stage "
                   f"{100.0 * m['ground'] / m['scan']:.0f}%, the two PointNets "
                   f"{100.0 * (m['classify'] + m['box']) / m['scan']:.0f}%, projection and clustering "
                   f"{100.0 * (m['project'] + m['cluster']) / m['scan']:.0f}%)")
        out += [
            "",
            "The integer build against the same goals (its images use `ports/firmware/config/vlp16` as they are: the "
            "range-only pixel, `LIDET_Q_PIXEL_XYZ 0`, and 4 KiB of stack, docs/MEMORY.md; the small VLP-16 pair, "
            f"models `{(q.get('header') or {}).get('models', '?')}`, docs/PORTING.md, with the int8 scratch that pair "
            "needs, `LIDET_DETECTOR_Q_PN_SCRATCH` 4,128 B; and the tracker, "
            f"{(q.get('mem') or {}).get('tracker_bytes', 0):,} B at 32 tracks, docs/TRACKING.md): RAM "
            + ", ".join(f"{_kib(v)} ({v:,} B)" for v in rams.values())
            + f" on the M3, M0+ and RV32IMAC images ({'within' if max(rams.values()) <= 256 * 1024 else 'over'} "
            f"256 KiB), flash {_kib(sz['flash_without_scan'])} on the M3 "
            f"({'within' if sz['flash_without_scan'] <= 512 * 1024 else 'over'} 512 KiB; weights "
            f"{_kib(sz['rodata_weights'])}), {ins['scan'] / 20e6:.1f}x the instruction goal on the M3 (the two "
            f"PointNets {100.0 * (ins['classify'] + ins['box']) / ins['scan']:.0f}% of it)" + m4q + ".",
        ]
    out += _packets_section(reports)
    out += _ouster_section(reports)
    out += _sectors_section(reports)
    out += [
        "",
        "**Cost in CI.** Installing the toolchains and QEMU (`tools/scripts/install_deps.sh`, Debian 12: "
        "gcc-arm-none-eabi, libnewlib-arm-none-eabi, qemu-system-arm, gcc-riscv64-unknown-elf, "
        "picolibc-riscv64-unknown-elf, qemu-system-misc and their dependencies, 36 packages) took 59 s wall on this "
        "machine after `apt-get update` (314 MB downloaded in 2 s, the rest unpacking; 2.4 GB on disk, most of it "
        "the C libraries' multilib variants: picolibc-riscv64 1.0 GB, newlib-arm 0.37 GB, gcc-arm 0.44 GB). "
        f"Building the {len([b for b in reports if b not in VARIANTS])} images adds about a minute to `make build` "
        "on 2 cores; running them adds about "
        "a minute to ctest at -j2 (48 s of test time in all), most of it the two soft-float images"
        + (" (M0+ and M3: " + " and ".join(f"{sum(r['scan'] for r in reports[b]['insn'].values()) / 1e9:.1f} G"
                                          for b in ("mps2-an385-m0plus", "mps2-an385"))
           + " instructions under QEMU for their two runs; 14.6 s and 7.7 s in ctest at -j2)"
           if all(b in reports for b in ("mps2-an385-m0plus", "mps2-an385")) else "") + ". "
        "The two virt-aarch64 images (float with the NEON kernel, integer) need no package beyond those of the aarch64 "
        "Linux test (gcc-aarch64-linux-gnu) and qemu-system-arm (which has qemu-system-aarch64): 15 s and 7 s to "
        "build at -j1, about 3 s each to run; the portable-kernel image of the comparison above is built by this "
        "benchmark only (20 s).",
        "",
        "Commands: `make firmware` (builds every image; or `cmake --build build --target firmware`), "
        "`make firmware-run` (= `ctest --test-dir build -R '^firmware_' -V`: each image under QEMU, compared with "
        "the host, reports in `build/firmware/<board>/report.json`); one image by hand, e.g. "
        "`qemu-system-arm -M mps2-an386 -icount shift=8 -semihosting-config enable=on,target=native -display none "
        "-monitor none -serial null -kernel build/firmware/mps2-an386/lidet_fw.elf` or `qemu-system-riscv32 -M virt "
        "-bios none -icount shift=0 -display none -monitor none -serial stdio -kernel "
        "build/firmware/virt-rv32imafc/lidet_fw.elf` or `qemu-system-aarch64 -M virt -cpu cortex-a72 -nic none "
        "-semihosting-config enable=on,target=native -icount shift=0 -display none -monitor none -serial stdio "
        "-kernel build/firmware/virt-aarch64/lidet_fw.elf`. This section: `.venv/bin/python tools/bench/run_bench.py "
        "--only firmware --update` (it also builds and runs the portable-kernel aarch64 image).",
        "",
    ]
    return "\n".join(out) + "\n"


if __name__ == "__main__":
    sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
    from run_bench import standalone

    standalone(run, __doc__)
