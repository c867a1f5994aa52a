#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Run one lidet firmware image under QEMU and compare it with the host build (a ctest test per board).

    python3 tools/firmware/run_fw.py --board mps2-an386 --elf build/firmware/mps2-an386/lidet_fw.elf \\
        --host-ref build/tests/fw_host_ref [--qemu qemu-system-arm] [--size arm-none-eabi-size] [--json OUT]

1. Runs the host reference (fw_detect.c built for the host against lidet with the same capacities,
   ports/firmware/config/vlp16/lidet_user_config.h, on the same generated scan).
2. Runs the image under QEMU with exact instruction counting (-icount), with a timeout.
3. Checks: the image says PASS (its instruction counter matched loops of known length), and for every run
   (gates as they are, and gates + size checks off) the same counts at every step of the detector, the
   same detections (matched by cluster id: same number, same classes), boxes within ATOL_M metres and
   ATOL_RAD radians, scores within ATOL_SCORE and energies within RTOL_ENERGY (relative). The integer build
   (build=fixed: the integer detector on the scan in millimetres) must match the host bit for bit.
   Why not bit-identical: the host, newlib (Arm), picolibc (RISC-V) and the aarch64 image (ports/aarch64/virt_libc.c)
   each have their own expf, logf, sinf, cosf, tanf and atan2f (each within an ulp or two); everything else is IEEE
   single precision in the same order on both sides (-ffp-contract=off, no reassociation). The dense layers of the
   Cortex-M7, RV32IMAFC and aarch64 float images fuse their multiply-adds (lib/src/nn/lidet_nn_f32_cm.c with
   LIDET_NN_CM_FMA, _rv.c, _neon.c): their host reference (fw_host_ref_fused) runs the x86-64 FMA kernel, the same
   arithmetic, where the host CPU has FMA.
   The report says how many values were bit-identical and the largest differences.
   The tracker after the detector (`track` and `trk` lines: run `default` = two updates on run default's
   detections, run `synthetic` = the image's generated 32 road users over 20 scans with ego motion): the same
   counts of the last update, the same tracks in the same order (ids, classes, states, hits, misses, ages,
   detection indices), their values bit for bit in the integer build, within the tolerances below in the float
   build (ATOL_M on positions, sizes and velocities, ATOL_RAD on yaws, RTOL_COV on covariances, ATOL_SCORE);
   the synthetic run must end with all its road users tracked and confirmed.
4. Prints the instruction counts per stage and per tracker update, the stack high-water and a size report
   (`size -A`); the integer VLP-16 images must keep their RAM (data + bss + stack) within RAM_BUDGET_Q (the
   microcontrollers': not virt-aarch64).
The packet application (header app=packets, ports/firmware/fw_packets.c: VLP-16 payloads in flash decoded and
streamed into the integer detector; its host reference fw_host_ref_pkt decodes the same payloads into a buffer and
runs lidet_detector_q_run_returns on the completed scan; the Ouster image, header sensor=os1-32 lidar=ouster, the
same with Ouster payloads and fw_host_ref_pkt_ouster): the same checks bit for bit but the tracker's (it has
none), plus its `decode` lines (the decoder's counts, the completed scan's payloads and returns) and the `digest`
of the scan's returns identical to the host's, and its instructions (`insn`: decode, the stages, the scan) and the
largest payload's (`pktinsn`) in the report.
Exit status: 0 pass, 1 fail, 77 skipped (a tool is missing: ctest reports the test as skipped).
"""
import argparse
import json
import math
import os
import shutil
import struct
import subprocess
import sys

ATOL_M = 1e-3
ATOL_RAD = 1e-3
ATOL_SCORE = 1e-4
RTOL_ENERGY = 1e-4
RTOL_COV = 1e-4
RAM_BUDGET_Q = 256 * 1024  # issue 17: the integer VLP-16 images' RAM (data + bss + stack)
SKIP = 77

BOARDS = {
    # board: (qemu binary, machine args, icount shift)
    "mps2-an385": ("qemu-system-arm", ["-M", "mps2-an385"], 8),
    # Cortex-M0+ code (ARMv6-M) on the AN385's Cortex-M3: QEMU 7.2 has no M0+ board
    "mps2-an385-m0plus": ("qemu-system-arm", ["-M", "mps2-an385"], 8),
    "mps2-an386": ("qemu-system-arm", ["-M", "mps2-an386"], 8),
    "mps2-an500": ("qemu-system-arm", ["-M", "mps2-an500"], 8),
    "virt-rv32imafc": ("qemu-system-riscv32", ["-M", "virt", "-bios", "none"], 0),
    "virt-rv32imac": ("qemu-system-riscv32", ["-M", "virt", "-bios", "none"], 0),
    # bare-metal aarch64 (ports/aarch64): console on the PL011 (-serial stdio), exit through semihosting, the PMU's
    # INST_RETIRED counter (exact with -icount); no network card (the default one wants a boot ROM file)
    "virt-aarch64": ("qemu-system-aarch64", ["-M", "virt", "-cpu", "cortex-a72", "-nic", "none",
                                             "-semihosting-config", "enable=on,target=native"], 0),
}
# boards where the integer VLP-16 image's RAM budget (RAM_BUDGET_Q, a microcontroller's) does not apply: a Cortex-A
# board has memory to spare, and its 64-bit pointers and frames make the same objects larger
NO_RAM_BUDGET = {"virt-aarch64"}

FIELDS = ["score", "cx", "cy", "cz", "l", "w", "h", "yaw", "energy_cls", "energy_box"]
# a track's values on its `trk` line (fw_detect.c: put_track), then hits, misses, age, detection index
TRK_FIELDS = ["cx", "cy", "cz", "l", "w", "h", "yaw", "vx", "vy", "p_pp", "p_pv", "p_vv", "score"]
TRK_INTS = ["hits", "misses", "age", "det_index"]


def qemu_cmd(board, qemu, elf):
    _, machine, shift = BOARDS[board]
    cmd = [qemu] + machine + ["-icount", f"shift={shift}", "-display", "none", "-monitor", "none", "-kernel", elf]
    if board.startswith("mps2-"):
        cmd += ["-semihosting-config", "enable=on,target=native", "-serial", "null"]
    else:
        cmd += ["-serial", "stdio"]
    return cmd


def f32(hexbits):
    return struct.unpack("<f", struct.pack("<I", int(hexbits, 16)))[0]


def parse(text):
    """-> dict: header, mem, calib list, stats{run: {k: v}}, det{run: {cluster: rec}}, insn{run: {}}, stack,
    track{run: {k: v}} (the tracker's counts and instructions), trk{run: [track rec in output order]}."""
    out = {"stats": {}, "det": {}, "insn": {}, "calib": [], "track": {}, "trk": {}, "pass": False,
           "decode": {}, "digest": {}, "pktinsn": {}, "lines": text.splitlines()}
    for line in out["lines"]:
        tok = line.split("#")[0].split()
        if not tok:
            continue
        kv = {t.split("=", 1)[0]: t.split("=", 1)[1] for t in tok[1:] if "=" in t}
        if tok[0] == "lidet-fw:":
            out["pass"] = tok[1] == "PASS"
        elif tok[0] == "lidet-fw":
            out["header"] = kv
        elif tok[0] in ("mem", "stack"):
            out[tok[0]] = {k: int(v) for k, v in kv.items()}
        elif tok[0] == "calib":
            out["calib"].append({k: int(v) for k, v in kv.items()})
        elif tok[0] == "stats":
            run = kv.pop("run")
            out["stats"][run] = {k: int(v) for k, v in kv.items()}
        elif tok[0] in ("insn", "decode", "pktinsn"):
            run = kv.pop("run")
            out[tok[0]][run] = {k: int(v) for k, v in kv.items()}
        elif tok[0] == "digest":
            run = kv.pop("run")
            out["digest"][run] = kv
        elif tok[0] == "track":
            run = kv.pop("run")
            out["track"][run] = {k: int(v) for k, v in kv.items()}
        elif tok[0] == "trk":
            run, k, tid, cls, state = tok[1], int(tok[2]), int(tok[3]), tok[4], tok[5]
            n = len(TRK_FIELDS)
            rec = {"rank": k, "id": tid, "cls": cls, "state": state, "bits": tok[6:6 + n]}
            rec.update(dict(zip(TRK_FIELDS, (f32(h) for h in tok[6:6 + n]))))
            rec.update(dict(zip(TRK_INTS, (int(v) for v in tok[6 + n:6 + n + len(TRK_INTS)]))))
            out["trk"].setdefault(run, []).append(rec)
        elif tok[0] == "det":
            run, k, cls, cluster, npts = tok[1], int(tok[2]), tok[3], int(tok[4]), int(tok[5])
            vals = [f32(h) for h in tok[6:16]]
            rec = {"rank": k, "cls": cls, "n_points": npts, "bits": tok[6:16]}
            rec.update(dict(zip(FIELDS, vals)))
            out["det"].setdefault(run, {})[cluster] = rec
    return out


def ang_diff(a, b):
    d = math.fmod(a - b, 2.0 * math.pi)
    if d > math.pi:
        d -= 2.0 * math.pi
    if d < -math.pi:
        d += 2.0 * math.pi
    return abs(d)


def compare(host, fw):
    """-> (errors, summary lines). The integer build (header build=fixed) must match bit for bit."""
    errors, lines = [], []
    fixed = (fw.get("header") or {}).get("build") == "fixed"
    if fixed != ((host.get("header") or {}).get("build") == "fixed"):
        errors.append(f"builds differ: host {host.get('header')} firmware {fw.get('header')}")
        return errors, lines
    if set(host["stats"]) != set(fw["stats"]) or not host["stats"]:
        errors.append(f"runs differ: host {sorted(host['stats'])} firmware {sorted(fw['stats'])}")
        return errors, lines
    for run in sorted(host["stats"]):
        hs, fs = host["stats"][run], fw["stats"][run]
        if hs != fs:
            diff = {k: (hs.get(k), fs.get(k)) for k in set(hs) | set(fs) if hs.get(k) != fs.get(k)}
            errors.append(f"run {run}: counts differ (host, firmware): {diff}")
        hd, fd = host["det"].get(run, {}), fw["det"].get(run, {})
        if set(hd) != set(fd):
            errors.append(f"run {run}: detections of clusters {sorted(hd)} on the host, {sorted(fd)} on the firmware")
            continue
        worst = {f: 0.0 for f in FIELDS}
        same_bits = total = 0
        for cl in sorted(hd):
            h, f = hd[cl], fd[cl]
            if h["cls"] != f["cls"] or h["n_points"] != f["n_points"]:
                errors.append(f"run {run} cluster {cl}: host {h['cls']}/{h['n_points']} pts, "
                              f"firmware {f['cls']}/{f['n_points']} pts")
            if fixed:
                # the integer build: integers only on both sides, so every value must be identical
                total += len(FIELDS)
                same_bits += sum(a == b for a, b in zip(h["bits"], f["bits"]))
                if h["bits"] != f["bits"] or h["rank"] != f["rank"]:
                    errors.append(f"run {run} cluster {cl}: integer values differ: host {h['bits']} (rank {h['rank']}), "
                                  f"firmware {f['bits']} (rank {f['rank']})")
                continue
            for i, name in enumerate(FIELDS):
                total += 1
                same_bits += h["bits"][i] == f["bits"][i]
                if name == "yaw":
                    d = ang_diff(h[name], f[name])
                    tol = ATOL_RAD
                elif name == "score":
                    d, tol = abs(h[name] - f[name]), ATOL_SCORE
                elif name.startswith("energy"):
                    d, tol = abs(h[name] - f[name]), RTOL_ENERGY * max(1.0, abs(h[name]))
                else:
                    d, tol = abs(h[name] - f[name]), ATOL_M
                worst[name] = max(worst[name], d)
                if not d <= tol:
                    errors.append(f"run {run} cluster {cl}: {name} host {h[name]!r} firmware {f[name]!r} "
                                  f"(|diff| {d:.3g} > {tol:.3g})")
        if fixed:
            lines.append(f"run {run}: {len(hd)} detections, counts identical: {hs == fs}; "
                         f"{same_bits}/{total} integer values identical (the integer build must match exactly)")
            continue
        lines.append(f"run {run}: {len(hd)} detections, counts identical: {hs == fs}; "
                     f"{same_bits}/{total} values bit-identical; max |diff| box "
                     f"{max(worst[k] for k in ('cx', 'cy', 'cz', 'l', 'w', 'h')):.3g} m, yaw {worst['yaw']:.3g} rad, "
                     f"score {worst['score']:.3g}, energies {max(worst['energy_cls'], worst['energy_box']):.3g}")
    return errors, lines


def compare_tracks(host, fw):
    """The tracker runs (`track`, `trk` lines) -> (errors, summary lines): the same counts (instructions aside), the
    same tracks in the same order with the same ids, classes, states, hits, misses, ages and detection indices; the
    values bit for bit in the integer build, within tolerances in the float build (libm's sinf / cosf / atan2f
    differ between the host and the boards: the ego rotation, the reported heading)."""
    errors, lines = [], []
    fixed = (fw.get("header") or {}).get("build") == "fixed"
    if set(host["track"]) != set(fw["track"]) or "synthetic" not in host["track"]:
        errors.append(f"tracker runs differ: host {sorted(host['track'])} firmware {sorted(fw['track'])}")
        return errors, lines
    syn = fw["track"]["synthetic"]
    if not syn.get("dets") or syn.get("tracks") != syn.get("dets") or syn.get("confirmed") != syn.get("dets"):
        errors.append(f"tracker run synthetic: not every road user tracked and confirmed: {syn}")
    for run in sorted(host["track"]):
        n_err = len(errors)
        counts = lambda m: {k: v for k, v in m.items() if not k.startswith("insn_")}
        hc, fc = counts(host["track"][run]), counts(fw["track"][run])
        if hc != fc:
            diff = {k: (hc.get(k), fc.get(k)) for k in set(hc) | set(fc) if hc.get(k) != fc.get(k)}
            errors.append(f"tracker run {run}: counts differ (host, firmware): {diff}")
        ht, ft = host["trk"].get(run, []), fw["trk"].get(run, [])
        if len(ht) != len(ft) or len(ht) != hc.get("tracks"):
            errors.append(f"tracker run {run}: {len(ht)} tracks on the host, {len(ft)} on the firmware "
                          f"({hc.get('tracks')} counted)")
            continue
        same_bits = total = 0
        worst = {"pos": 0.0, "vel": 0.0, "yaw": 0.0, "cov": 0.0}
        for h, f in zip(ht, ft):
            keys = ["id", "cls", "state"] + TRK_INTS
            if [h[k] for k in keys] != [f[k] for k in keys]:
                errors.append(f"tracker run {run} track {h['rank']}: host {[h[k] for k in keys]}, firmware "
                              f"{[f[k] for k in keys]} ({', '.join(keys)})")
            total += len(TRK_FIELDS)
            same_bits += sum(a == b for a, b in zip(h["bits"], f["bits"]))
            if fixed:
                if h["bits"] != f["bits"]:
                    errors.append(f"tracker run {run} track id {h['id']}: integer values differ: host {h['bits']}, "
                                  f"firmware {f['bits']} ({', '.join(TRK_FIELDS)})")
                continue
            for name in TRK_FIELDS:
                if name == "yaw":
                    d, tol, grp = ang_diff(h[name], f[name]), ATOL_RAD, "yaw"
                elif name.startswith("p_"):
                    d, tol, grp = abs(h[name] - f[name]), RTOL_COV * max(1.0, abs(h[name])), "cov"
                elif name == "score":
                    d, tol, grp = abs(h[name] - f[name]), ATOL_SCORE, "pos"
                else:
                    d, tol, grp = abs(h[name] - f[name]), ATOL_M, "vel" if name in ("vx", "vy") else "pos"
                worst[grp] = max(worst[grp], d / max(1.0, abs(h[name])) if grp == "cov" else d)
                if not d <= tol:
                    errors.append(f"tracker run {run} track id {h['id']}: {name} host {h[name]!r} firmware "
                                  f"{f[name]!r} (|diff| {d:.3g} > {tol:.3g})")
        what = (f"{same_bits}/{total} integer values identical" if fixed else
                f"{same_bits}/{total} values bit-identical; max |diff| position/size {worst['pos']:.3g} m, velocity "
                f"{worst['vel']:.3g} m/s, yaw {worst['yaw']:.3g} rad, covariance {worst['cov']:.3g} relative")
        lines.append(f"tracker run {run}: {len(ht)} tracks ({hc.get('confirmed')} confirmed), ids, states and "
                     f"counts identical: {len(errors) == n_err}; {what}")
    return errors, lines


def size_report(size_tool, elf):
    out = subprocess.run([size_tool, "-A", elf], check=True, capture_output=True, text=True).stdout
    sec = {}
    for line in out.splitlines():
        t = line.split()
        if len(t) == 3 and t[0].startswith(".") and t[1].isdigit():
            sec[t[0]] = int(t[1])
    # code: .text plus the Arm unwind tables (loaded); .ARM.attributes and debug sections are not in flash
    text = sum(v for k, v in sec.items() if k in (".text", ".ARM.exidx", ".ARM.extab"))
    rep = {
        "text": text,
        "rodata_weights": sec.get(".rodata.weights", 0),
        "rodata_scan": sec.get(".rodata.scan", 0),
        "rodata_other": sec.get(".rodata", 0),
        "data": sec.get(".data", 0),
        "bss": sec.get(".bss", 0) + sec.get(".extram", 0),
        "bss_extram": sec.get(".extram", 0),  # placed in the board's external RAM (part of bss above)
        "stack_reserved": sec.get(".stack", 0),
    }
    rep["flash_without_scan"] = text + rep["rodata_weights"] + rep["rodata_other"] + rep["data"]
    rep["ram"] = rep["data"] + rep["bss"] + rep["stack_reserved"]
    return rep


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--board", required=True, choices=sorted(BOARDS))
    ap.add_argument("--label", help="name of the image in messages (default: the board)")
    ap.add_argument("--elf")
    ap.add_argument("--host-ref", help="fw_host_ref executable")
    ap.add_argument("--qemu", help="QEMU binary (default: by board)")
    ap.add_argument("--size", help="the toolchain's size tool, for the size report")
    ap.add_argument("--timeout", type=float, default=600.0)
    ap.add_argument("--json", help="write the parsed results and the size report here")
    ap.add_argument("--skip", help="print this reason and exit 77 (ctest: skipped)")
    a = ap.parse_args(argv)
    name = a.label or a.board

    if a.skip:
        print(f"SKIPPED firmware_{name}: {a.skip}")
        return SKIP
    qemu = shutil.which(a.qemu or BOARDS[a.board][0])
    if qemu is None:
        print(f"SKIPPED firmware_{name}: {a.qemu or BOARDS[a.board][0]} not found "
              "(tools/scripts/install_deps.sh installs qemu-system-arm / qemu-system-misc)")
        return SKIP
    if not a.elf or not os.path.isfile(a.elf) or not a.host_ref or not os.path.isfile(a.host_ref):
        print(f"FAIL firmware_{name}: image {a.elf} or host reference {a.host_ref} missing (make firmware)")
        return 1

    host_p = subprocess.run([a.host_ref], capture_output=True, text=True, timeout=a.timeout)
    host = parse(host_p.stdout)
    if host_p.returncode != 0 or not host["pass"]:
        print(host_p.stdout + host_p.stderr)
        print(f"FAIL firmware_{name}: the host reference failed (exit {host_p.returncode})")
        return 1

    cmd = qemu_cmd(a.board, qemu, a.elf)
    print("$ " + " ".join(cmd))
    try:
        # semihosting writes to QEMU's stderr, the UART (-serial stdio) to stdout: read both, in order
        fw_p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, timeout=a.timeout)
    except subprocess.TimeoutExpired as e:
        print((e.stdout or b"").decode(errors="replace") if isinstance(e.stdout, bytes) else (e.stdout or ""))
        print(f"FAIL firmware_{name}: QEMU did not finish within {a.timeout:.0f} s")
        return 1
    print(fw_p.stdout, end="")
    fw = parse(fw_p.stdout)
    errors = []
    if fw_p.returncode != 0 or not fw["pass"]:
        errors.append(f"the image failed (QEMU exit {fw_p.returncode}, PASS line {'seen' if fw['pass'] else 'missing'})")
    if len(fw["calib"]) < 3 or any(c["measured"] != c["expected"] for c in fw["calib"]):
        errors.append(f"instruction counter calibration: {fw['calib']}")
    # the capacities must agree; sizeof(lidet_detector_t) and of the tracker may not (pointers are 8 bytes on the
    # host)
    caps = lambda m: {k: v for k, v in (m or {}).items() if not k.endswith("_bytes")}
    if not caps(fw.get("mem")) or caps(fw.get("mem")) != caps(host.get("mem")):
        errors.append(f"capacities differ: host {host.get('mem')} firmware {fw.get('mem')}")
    if "open" not in fw["det"] or not fw["det"]["open"]:
        errors.append("run 'open' (gates and size checks off) produced no detection: the comparison would be vacuous")
    for run, ins in fw["insn"].items():
        stages = sum(v for k, v in ins.items() if k != "scan")
        # the stages (rebuilt in 64 bits from the clock hook's timestamps, fw_detect.c) must add up to the
        # 64-bit scan total but for the few instructions between them (the packet application: and its loop over
        # the payloads, a few hundred instructions each)
        slack = 10000 + 400 * fw["decode"].get(run, {}).get("packets", 0)
        if not 0 <= ins.get("scan", -1) - stages <= slack:
            errors.append(f"run {run}: stages add up to {stages:,} instructions, the scan took {ins.get('scan')}: "
                          "a stage count is wrong")
    cerr, summary = compare(host, fw)
    errors += cerr
    app = (fw.get("header") or {}).get("app", "detect")
    if app == "packets":
        # the packet application has no tracker; its decoding must be the host's, count for count
        if host["track"] or fw["track"]:
            errors.append(f"the packet application runs no tracker: host {sorted(host['track'])}, "
                          f"firmware {sorted(fw['track'])}")
        for what in ("decode", "digest"):
            if not host[what] or host[what] != fw[what]:
                errors.append(f"{what} lines differ: host {host[what]}, firmware {fw[what]}")
        for run, d in sorted(fw["decode"].items()):
            summary.append(f"run {run}: decoding identical: {host['decode'].get(run) == d} ({d.get('packets')} payloads, "
                           f"{d.get('returns'):,} returns; the completed scan: payloads {d.get('first')}..{d.get('last')}, "
                           f"{d.get('scan_returns'):,} returns)")
        summary.append(f"completed scan's returns (FNV-1a): host {host['digest']}, firmware {fw['digest']}")
    else:
        terr, tsummary = compare_tracks(host, fw)
        errors += terr
        summary += tsummary
    # the painted stack must keep a margin: an image whose reserved stack is trimmed to its measured high-water
    # (the integer VLP-16 build, ports/firmware/CMakeLists.txt) fails here before it overflows
    st = fw.get("stack") or {}
    if st and st.get("used", 0) * 5 > st.get("size", 0) * 4:
        errors.append(f"stack high-water {st.get('used')} B is over 80 % of the {st.get('size')} B reserved")

    print(f"---- firmware_{name}: comparison with the host build (same capacities, same scan)")
    for line in summary:
        print(line)
    for run, ins in sorted(fw["insn"].items()):
        print(f"instructions run {run}: " + ", ".join(f"{k} {v:,}" for k, v in ins.items()))
    for run, ins in sorted(fw["pktinsn"].items()):
        print(f"instructions run {run}, largest: " + ", ".join(f"{k} {v:,}" for k, v in ins.items()))
    for run, tr in sorted(fw["track"].items()):
        print(f"tracker run {run} ({tr.get('dets')} detections, {tr.get('updates')} updates), instructions per update: "
              + (", ".join(f"{k[5:]} {v:,}" for k, v in tr.items() if k.startswith("insn_")) or "not counted"))
    if "stack" in fw:
        print(f"stack high-water: {fw['stack']['used']} of {fw['stack']['size']} bytes")
    rep = None
    if a.size and shutil.which(a.size):
        rep = size_report(shutil.which(a.size), a.elf)
        print("size (bytes): " + ", ".join(f"{k} {v:,}" for k, v in rep.items()))
        hdr = fw.get("header") or {}
        if (hdr.get("build") == "fixed" and hdr.get("sensor") == "vlp16" and rep["ram"] > RAM_BUDGET_Q
                and a.board not in NO_RAM_BUDGET):
            errors.append(f"RAM (data + bss + stack) {rep['ram']:,} B is over the integer VLP-16 image's budget of "
                          f"{RAM_BUDGET_Q:,} B (docs/MEMORY.md)")
    if a.json:
        with open(a.json, "w") as f:
            json.dump({"board": a.board, "header": fw.get("header"), "mem": fw.get("mem"), "insn": fw["insn"],
                       "decode": fw["decode"], "digest": fw["digest"], "pktinsn": fw["pktinsn"],
                       "stack": fw.get("stack"), "stats": fw["stats"], "track": fw["track"], "size": rep, "qemu": cmd,
                       "comparison": summary, "errors": errors}, f, indent=1)
    if errors:
        for e in errors:
            print(f"FAIL firmware_{name}: {e}")
        return 1
    print(f"PASS firmware_{name}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
