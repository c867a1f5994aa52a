# SPDX-License-Identifier: MIT
"""tools/firmware: the scan -> C generator and the QEMU-vs-host comparison of run_fw.py (issue 17).

The images themselves run under ctest (firmware_<board>, tests/firmware.cmake); these tests check that the
tools they rely on read exactly what was written and that the comparison fails when it should."""
import copy
import importlib.util
import os
import pathlib
import re
import struct
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]


def _load(name):
    spec = importlib.util.spec_from_file_location(name, ROOT / "tools" / "firmware" / f"{name}.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


run_fw = _load("run_fw")
scan_to_c = _load("scan_to_c")


def test_scan_to_c_writes_the_exact_bits(tmp_path):
    pts = [(1.0, -2.5, 0.1, 0.3), (-0.0, 1e-30, 3.4028234e38, 7.0), (12.345678, -98.7654, 1.5e-3, 0.0)]
    scan = tmp_path / "s.bin"
    scan.write_bytes(b"".join(struct.pack("<4f", *p) for p in pts))
    ring = tmp_path / "r.bin"
    ring.write_bytes(struct.pack("<3H", 0, 15, 7))
    out = tmp_path / "fw_scan.c"
    assert scan_to_c.main([str(scan), "--ring", str(ring), "--name", "tiny", "--out", str(out)]) == 0
    text = out.read_text()
    assert "const uint32_t fw_scan_n = 3u;" in text and "fw_scan_has_ring = 1" in text
    body = text.split("fw_scan_xyz[9] = {")[1].split("};")[0]
    lits = re.findall(r"(-?0x[0-9a-f.]+p[+-]\d+)f", body)
    got = [float.fromhex(x) for x in lits]
    want = [struct.unpack("<f", struct.pack("<f", v))[0] for p in pts for v in p[:3]]
    assert got == want  # every coordinate bit for bit, the intensity dropped
    assert struct.pack("<9f", *got) == struct.pack("<9f", *want)
    assert "0, 15, 7," in text


def test_scan_to_c_rejects_bad_files(tmp_path):
    scan = tmp_path / "s.bin"
    scan.write_bytes(b"\0" * 20)
    with pytest.raises(SystemExit):
        scan_to_c.main([str(scan), "--out", str(tmp_path / "x.c")])
    scan.write_bytes(b"\0" * 32)
    ring = tmp_path / "r.bin"
    ring.write_bytes(b"\0" * 2)
    with pytest.raises(SystemExit):
        scan_to_c.main([str(scan), "--ring", str(ring), "--out", str(tmp_path / "x.c")])


def _bits(v):
    return "%08x" % struct.unpack("<I", struct.pack("<f", v))[0]


def _report(dets, counts=None):
    """A firmware-style report with the given detections of run 'open': (cluster, class, [10 floats])."""
    counts = counts or {"clusters": 5, "detections": len(dets)}
    lines = ["lidet-fw board=x core=y build=float", "mem detector_bytes=100 max_rows=16",
             "stats run=open status=0 " + " ".join(f"{k}={v}" for k, v in counts.items())]
    for k, (cl, cls, vals) in enumerate(dets):
        lines.append(f"det open {k} {cls} {cl} 20 " + " ".join(_bits(v) for v in vals) + " # readable")
    lines.append("lidet-fw: PASS")
    return "\n".join(lines) + "\n"


BASE = [(3, "Car", [0.9, 10.0, -2.0, 0.5, 4.0, 1.7, 1.5, 0.3, -5.0, -3.0]),
        (7, "Pedestrian", [0.6, 4.0, 1.0, 0.8, 0.6, 0.6, 1.7, -3.1415, -2.0, -1.0])]


def test_compare_accepts_identical_and_tiny_differences():
    host = run_fw.parse(_report(BASE))
    assert host["pass"] and set(host["det"]["open"]) == {3, 7}
    assert run_fw.compare(host, copy.deepcopy(host))[0] == []
    near = copy.deepcopy(BASE)
    near[0][2][1] += 2e-4                 # 0.2 mm
    near[1][2][7] = 3.1415  # the same heading across the +-pi seam (0.2 mrad apart)
    assert run_fw.compare(host, run_fw.parse(_report(near)))[0] == []


@pytest.mark.parametrize("mutate, message", [
    (lambda d: d[0][2].__setitem__(2, d[0][2][2] + 5e-3), "cy"),          # 5 mm off
    (lambda d: d[1][2].__setitem__(7, d[1][2][7] + 0.01), "yaw"),
    (lambda d: d.__setitem__(0, (3, "Cyclist", d[0][2])), "Cyclist"),
    (lambda d: d.pop(), "detections of clusters"),
])
def test_compare_rejects(mutate, message):
    host = run_fw.parse(_report(BASE))
    bad = copy.deepcopy(BASE)
    mutate(bad)
    errors, _ = run_fw.compare(host, run_fw.parse(_report(bad)))
    assert errors and any(message in e for e in errors), errors


def test_compare_rejects_different_counts():
    host = run_fw.parse(_report(BASE, {"clusters": 5, "gate1_rejected": 0}))
    fw = run_fw.parse(_report(BASE, {"clusters": 5, "gate1_rejected": 1}))
    errors, _ = run_fw.compare(host, fw)
    assert any("counts differ" in e for e in errors)


def test_skip_exit_code(capsys):
    assert run_fw.main(["--board", "mps2-an386", "--skip", "no compiler"]) == 77
    assert "SKIPPED firmware_mps2-an386: no compiler" in capsys.readouterr().out


def test_host_reference_reports_two_runs_with_detections():
    """The host build of the firmware application (fw_host_ref): both runs, boxes in the open run."""
    exe = pathlib.Path(os.environ.get("LIDET_BUILD_DIR", ROOT / "build")) / "tests" / "fw_host_ref"
    if not exe.exists():
        pytest.skip(f"{exe} not built")
    p = subprocess.run([str(exe)], capture_output=True, text=True, timeout=120)
    assert p.returncode == 0, p.stdout + p.stderr
    rep = run_fw.parse(p.stdout)
    assert rep["pass"] and set(rep["stats"]) == {"default", "open"}
    assert rep["mem"]["max_rows"] == 16 and rep["mem"]["max_cols"] == 1800
    assert len(rep["det"]["open"]) == rep["stats"]["open"]["detections"] > 0
    for d in rep["det"]["open"].values():
        assert d["l"] > 0 and d["w"] > 0 and d["h"] > 0 and 0 < d["score"] < 1


def _trk_report(tracks, fixed=False, counts=None, run="synthetic"):
    """A firmware-style report with one tracker run: tracks = [(id, class, state, [13 values], [4 ints])]."""
    counts = counts or {"dets": len(tracks), "updates": 20, "status": 0, "tracks": len(tracks),
                        "confirmed": len(tracks), "matched": len(tracks)}
    word = (lambda v: "%08x" % (v & 0xffffffff)) if fixed else _bits
    lines = [f"lidet-fw board=x core=y build={'fixed' if fixed else 'float'}", "mem detector_bytes=100 max_rows=16",
             f"track run={run} insn_max=123 insn_mean=100 " + " ".join(f"{k}={v}" for k, v in counts.items())]
    for k, (tid, cls, state, vals, ints) in enumerate(tracks):
        lines.append(f"trk {run} {k} {tid} {cls} {state} " + " ".join(word(v) for v in vals) + " "
                     + " ".join(str(v) for v in ints) + " # xy 1 2 v 3 4")
    lines.append("lidet-fw: PASS")
    return "\n".join(lines) + "\n"


TRKS = [(1, "Car", "confirmed", [10.0, -2.0, -0.7, 4.2, 1.8, 1.6, 0.3, 7.5, -1.9, 0.02, 0.05, 0.2, 0.6], [20, 0, 19, 1]),
        (2, "Pedestrian", "coasting", [4.0, 1.0, -0.9, 0.6, 0.6, 1.75, -3.1415, -1.2, 0.2, 0.01, 0.03, 0.1, 0.5],
         [5, 1, 6, -1])]
TRKS_Q = [(1, "Car", "confirmed", [10000, -2000, -700, 4200, 1800, 1600, -12345, 7500, -1900, 20000, 50000, 200000,
                                   19660], [20, 0, 19, 1])]


def test_tracker_lines_parse_and_compare():
    host = run_fw.parse(_trk_report(TRKS))
    assert host["track"]["synthetic"]["insn_max"] == 123 and host["track"]["synthetic"]["tracks"] == 2
    t = host["trk"]["synthetic"]
    assert [(r["id"], r["cls"], r["state"], r["det_index"]) for r in t] == [(1, "Car", "confirmed", 1),
                                                                              (2, "Pedestrian", "coasting", -1)]
    assert abs(t[0]["vx"] - 7.5) < 1e-6 and abs(t[1]["yaw"] + 3.1415) < 1e-6
    # the instruction counts are the image's own: not compared
    fw = run_fw.parse(_trk_report(TRKS).replace("insn_max=123", "insn_max=456"))
    errors, lines = run_fw.compare_tracks(host, fw)
    assert errors == [] and "26/26 values bit-identical" in lines[0]
    near = copy.deepcopy(TRKS)
    near[0][3][0] += 2e-4  # 0.2 mm
    near[1][3][6] = 3.1415  # the same yaw across the +-pi seam
    assert run_fw.compare_tracks(host, run_fw.parse(_trk_report(near)))[0] == []
    hq = run_fw.parse(_trk_report(TRKS_Q, fixed=True))
    assert hq["trk"]["synthetic"][0]["bits"][6] == "%08x" % (-12345 & 0xffffffff)
    errors, lines = run_fw.compare_tracks(hq, run_fw.parse(_trk_report(TRKS_Q, fixed=True)))
    assert errors == [] and "13/13 integer values identical" in lines[0]


@pytest.mark.parametrize("fixed, mutate, message", [
    (False, lambda t: t[0][3].__setitem__(1, t[0][3][1] + 5e-3), "cy"),     # 5 mm off
    (False, lambda t: t[0][3].__setitem__(9, t[0][3][9] * 1.01), "p_pp"),   # 1 % off
    (False, lambda t: t.__setitem__(1, (3,) + t[1][1:]), "id, cls, state"),    # another id
    (False, lambda t: t.__setitem__(1, t[1][:2] + ("confirmed",) + t[1][3:]), "id, cls, state"),
    (False, lambda t: t[1][4].__setitem__(3, 0), "id, cls, state"),            # another detection
    (False, lambda t: t.pop(), "tracks on the host"),
    (True, lambda t: t[0][3].__setitem__(7, t[0][3][7] + 1), "integer values differ"),  # 1 mm/s: exact or fail
])
def test_tracker_compare_rejects(fixed, mutate, message):
    base = TRKS_Q if fixed else TRKS
    host = run_fw.parse(_trk_report(base, fixed))
    bad = copy.deepcopy(base)
    mutate(bad)
    errors, _ = run_fw.compare_tracks(host, run_fw.parse(_trk_report(bad, fixed, counts=None if len(bad) == len(
        base) else {"dets": 2, "updates": 20, "status": 0, "tracks": 2, "confirmed": 2, "matched": 2})))
    assert errors and any(message in e for e in errors), errors


def test_tracker_compare_rejects_different_counts_and_an_unconfirmed_scene():
    host = run_fw.parse(_trk_report(TRKS))
    fw = run_fw.parse(_trk_report(TRKS, counts={"dets": 2, "updates": 20, "status": 0, "tracks": 2, "confirmed": 2,
                                                "matched": 1}))
    assert any("counts differ" in e for e in run_fw.compare_tracks(host, fw)[0])
    # the benchmark's premise: every road user tracked and confirmed at the end
    weak = {"dets": 2, "updates": 20, "status": 0, "tracks": 2, "confirmed": 1, "matched": 2}
    errors, _ = run_fw.compare_tracks(run_fw.parse(_trk_report(TRKS, counts=weak)),
                                      run_fw.parse(_trk_report(TRKS, counts=weak)))
    assert any("not every road user" in e for e in errors)
    # a run missing on one side
    assert any("tracker runs differ" in e for e in run_fw.compare_tracks(host, run_fw.parse(_report(BASE)))[0])


@pytest.mark.parametrize("exe_name", ["fw_host_ref", "fw_host_ref_q"])
def test_host_reference_runs_the_tracker(exe_name):
    """The host build runs the tracker after the detector: run default's detections twice, and the generated
    scene's 32 road users, all tracked and confirmed at the firmware capacities (32 tracks, 32 detections)."""
    exe = pathlib.Path(os.environ.get("LIDET_BUILD_DIR", ROOT / "build")) / "tests" / exe_name
    if not exe.exists():
        pytest.skip(f"{exe} not built")
    p = subprocess.run([str(exe)], capture_output=True, text=True, timeout=120)
    assert p.returncode == 0, p.stdout + p.stderr
    rep = run_fw.parse(p.stdout)
    assert rep["mem"]["track_max_tracks"] == 32 and rep["mem"]["track_max_dets"] == 32
    syn, det = rep["track"]["synthetic"], rep["track"]["default"]
    assert syn["dets"] == syn["tracks"] == syn["confirmed"] == syn["matched"] == 32 and syn["status"] == 0
    assert not any(k.startswith("insn_") for k in syn)  # the host counts no instructions
    assert [t["id"] for t in rep["trk"]["synthetic"]] == list(range(1, 33))
    assert all(t["state"] == "confirmed" and t["hits"] == 20 and t["misses"] == 0 for t in rep["trk"]["synthetic"])
    assert det["dets"] == rep["stats"]["default"]["detections"] == det["tracks"] == det["confirmed"] > 0
    assert sorted(t["det_index"] for t in rep["trk"]["default"]) == list(range(det["dets"]))
    assert run_fw.compare_tracks(rep, copy.deepcopy(rep))[0] == []


cycles = _load("cycles")


@pytest.mark.parametrize("insn, core, prev_ls, want", [
    ("adds r0, r1, #1", "m4", False, (1, 1, "")),
    ("bics.w r2, r2, r3", "m4", False, (1, 1, "")),
    ("movs r0, #0", "m4", False, (1, 1, "")),
    ("lsls r3, r3, #2", "m4", False, (1, 1, "")),
    ("teq r0, r1", "m4", False, (1, 1, "")),
    ("sxtble.w r9, r2", "m4", False, (1, 1, "")),
    ("ssat r2, #8, r2", "m4", False, (1, 1, "")),
    ("ite ge", "m4", False, (1, 1, "")),
    ("smlal r0, r1, r2, r3", "m4", False, (1, 1, "")),
    ("smlal r0, r1, r2, r3", "m3", False, (4, 7, "")),
    ("umull r0, r1, r2, r3", "m3", False, (3, 5, "")),
    ("mla r0, r1, r2, r3", "m3", False, (2, 2, "")),
    ("smlad r0, r1, r2, r3", "m4", False, (1, 1, "")),
    ("udiv r0, r1, r2", "m4", False, (2, 12, "")),
    ("udivls r3, r0, r1", "m4", False, (2, 12, "")),
    ("ldr.w r8, [r1]", "m4", False, (2, 2, "ls")),
    ("ldrb.w r3, [r6, #1]!", "m4", True, (1, 2, "ls")),
    ("strbne r3, [r0]", "m4", True, (1, 2, "ls")),
    ("ldrd r4, r5, [sp, #84]", "m4", True, (3, 3, "")),
    ("stmdb sp!, {r4, r5, r6, r7, r8, r9, sl, fp, lr}", "m4", False, (10, 10, "")),
    ("pop {r4, r5, r6, pc}", "m4", False, (5, 5, "pc")),
    ("push {r4-r7, lr}", "m4", False, (6, 6, "")),
    ("bhi.n #0x8b7e", "m4", False, (1, 1, "br")),
    ("bls #0x100", "m4", False, (1, 1, "br")),
    ("bl #0xcedc", "m4", False, (1, 1, "br")),
    ("bx lr", "m4", False, (1, 1, "br")),
    ("tbb [pc, r3]", "m4", False, (2, 2, "pc")),
    # the M4F's FPU (the float images)
    ("vadd.f32 s0, s1, s2", "m4", False, (1, 1, "")),
    ("vfma.f32 s0, s1, s2", "m4", False, (3, 3, "")),
    ("vmla.f32 s0, s1, s2", "m4", False, (3, 3, "")),
    ("vdiv.f32 s0, s1, s2", "m4", False, (14, 14, "")),
    ("vldr s15, [r5, #0x14]", "m4", False, (2, 2, "")),
    ("vldmia r0!, {s0-s7}", "m4", False, (9, 9, "")),
    ("vstmia r1, {d8-d11}", "m4", False, (9, 9, "")),
    ("vmovgt.f32 s0, s1", "m4", False, (1, 1, "")),
])
def test_cycle_prices_follow_the_trm(insn, core, prev_ls, want):
    """tools/firmware/cycles.py prices each instruction with the TRM's counts (zero wait states): condition and
    flag suffixes stripped, register lists counted, loads pipelined after a load or store (low estimate)."""
    mn, _, ops = insn.partition(" ")
    assert cycles.price(mn, ops, core, prev_ls) == want


def test_cycle_prices_refuse_an_unknown_instruction():
    with pytest.raises(ValueError, match="no cycle count"):
        cycles.price("vrintz.f32", "s0, s1", "m4", False)


def test_cycle_estimate_of_the_m4_integer_image():
    """The estimate on the Cortex-M4 integer image: the trace holds the instructions of all runs, the detector's
    and the tracker's updates (within 5 % of the exact counts: the port's counter and console code is left out)
    and the CPI lies in the range a single-issue core with 1-3 cycle loads, branches and divides can have."""
    bdir = pathlib.Path(os.environ.get("LIDET_BUILD_DIR", ROOT / "build")) / "firmware" / "mps2-an386-q"
    elf, rep = bdir / "lidet_fw.elf", bdir / "report.json"
    if not (elf.exists() and rep.exists()):
        pytest.skip(f"{elf} or its report not there (make firmware-run)")
    for tool in ("qemu-system-arm", "arm-none-eabi-nm"):
        if subprocess.run(["which", tool], capture_output=True).returncode != 0:
            pytest.skip(f"{tool} not installed")
    r = cycles.estimate(str(elf), "m4", "arm-none-eabi-nm", timeout=600, lines=True)
    import json
    report = json.loads(rep.read_text())
    ins = report["insn"]
    exact = sum(run["scan"] for run in ins.values())  # every run (the integer images: default, open, points)
    exact += sum(run.get("insn_total", 0) for run in report.get("track", {}).values())  # and the tracker's updates
    assert abs(r["instructions"] - exact) <= 0.05 * exact, (r, exact)
    assert 1.0 < r["cpi_low"] < r["cpi_high"] < 3.0, r
    # the profile (--functions): every traced instruction in one function, the int8 dense kernel first, and the
    # projection's initialisation among the callers of the 64-bit division helper (its column tables)
    pf = r["per_function"]
    assert sum(pf.values()) == r["instructions"]
    assert next(iter(pf)).startswith("lidet__nn_acc_s8"), list(pf)[:5]
    assert any(h.startswith("__aeabi_uldivmod") and c == "lidet_proj_q_init" for h, c, _ in r["helper_calls"])
    # the lines (--lines): every traced instruction on a source line of the repository, the busiest one in the int8
    # kernel (its SMLAD loop)
    pl = r["per_line"]
    assert sum(pl.values()) == r["instructions"]
    assert next(iter(pl)).startswith("lib/src/nn/lidet_nn_s8.c:"), list(pl)[:5]


@pytest.mark.parametrize("insn, want", [
    ("adds r0, r1, #1", (1, 1, "")),
    ("muls r2, r3", (1, 1, "")),  # the single-cycle multiplier (RP2040)
    ("ldr r0, [r1, #4]", (2, 2, "")),  # no pipelining of neighbouring loads on the M0+
    ("ldrsb r0, [r1, r2]", (2, 2, "")),
    ("stmia r0!, {r1, r2, r3}", (4, 4, "")),
    ("push {r4, r5, r6, r7, lr}", (6, 6, "")),
    ("pop {r4, pc}", (4, 4, "pc")),  # 3 + N with the refill
    ("bne.n #0x100", (1, 1, "br")),
    ("bl #0x2000", (2, 2, "br")),  # 3 with the refill
    ("bx lr", (1, 1, "br")),
])
def test_cycle_prices_of_the_m0plus(insn, want):
    """The Cortex-M0+'s own table (its TRM): loads and stores 2, the refill of a taken branch 1 (tally adds it)."""
    mn, _, ops = insn.partition(" ")
    assert cycles.price(mn, ops, "m0plus", True) == want
    with pytest.raises(ValueError, match="M0"):
        cycles.price("udiv", "r0, r1, r2", "m0plus", False)  # ARMv6-M has no divide


M0_LOG = """----------------
IN: fw_main
0x00000100:  2001       movs r0, #1
0x00000102:  6809       ldr r1, [r1]
0x00000104:  d100       bne #0x108

Trace 0: 0x7f0000000100 [00000000/00000100/00000000/ff000000]
----------------
IN: lidet_x
0x00000108:  4348       muls r0, r1, r0
0x0000010a:  f000 f801  bl #0x110

Trace 0: 0x7f0000000200 [00000000/00000108/00000000/ff000000]
----------------
IN: __aeabi_uidiv
0x00000110:  4770       bx lr

Trace 0: 0x7f0000000300 [00000000/00000110/00000000/ff000000]
Trace 0: 0x7f0000000100 [00000000/00000100/00000000/ff000000]
"""

RV_LOG = """----------------
IN: fw_main
Priv: 3; Virt: 0
0x80000100:  1141              addi                    sp,sp,-16
0x80000102:  26d1              jal                     ra,14                   # 0x80000110

Trace 0: 0x7fe144000100 [00000000/80000100/00109003/ff020200]
----------------
IN: __udivdi3
Priv: 3; Virt: 0
0x80000110:  02b50533          mul                     a0,a0,a1
0x80000114:  00008067          ret

Trace 0: 0x7fe144000200 [00000000/80000110/00109003/ff020200]
Trace 0: 0x7fe144000200 [00000000/80000110/00109003/ff020200]
"""


def test_tally_prices_a_hand_made_m0plus_log():
    """tally on a hand-made trace: blocks logged once and run again, a taken branch's refill, a call into a C
    library routine (bl to a '__' symbol) counted by caller, instructions per function and per address."""
    syms = [(0x100, 0x108, "fw_main", True), (0x108, 0x110, "lidet_x", True), (0x110, 0x112, "__aeabi_uidiv", True)]
    r = cycles.tally(M0_LOG.splitlines(True), syms, "m0plus", lines=True)
    assert r["instructions"] == 3 + 2 + 1 + 3
    # block 1: 1 + 2 + 1 = 4, run twice; block 2: 1 + 2 = 3; block 3: 1; refills: block 1 -> 0x108 (its branch
    # taken: 0x106 is next), block 2's bl (taken), block 3's bx (taken): 3
    assert r["cycles_low"] == r["cycles_high"] == 4 * 2 + 3 + 1 + 3
    assert r["per_function"] == {"fw_main": 6, "lidet_x": 2, "__aeabi_uidiv": 1}
    assert r["helper_calls"] == [("__aeabi_uidiv", "lidet_x", 1)]
    assert r["per_addr"][0x100] == 2 and r["per_addr"][0x10a] == 1


def test_tally_profiles_a_hand_made_rv32_log():
    """RV32 (no cycle model): instructions, the per-function profile and the calls into C library routines (jal ra
    to a '__' symbol, its target from QEMU's comment); compressed instructions are 2 bytes."""
    syms = [(0x80000100, 0x80000110, "fw_main", True), (0x80000110, 0x80000118, "__udivdi3", True)]
    r = cycles.tally(RV_LOG.splitlines(True), syms, "rv32", lines=True)
    assert r["instructions"] == 2 + 2 * 2
    assert r["cycles_low"] is None and r["cpi_high"] is None
    assert r["per_function"] == {"__udivdi3": 4, "fw_main": 2}
    assert r["helper_calls"] == [("__udivdi3", "fw_main", 1)]
    assert sorted(r["per_addr"]) == [0x80000100, 0x80000102, 0x80000110, 0x80000114]
    with pytest.raises(RuntimeError, match="empty trace"):
        cycles.tally([], syms, "rv32")


@pytest.mark.parametrize("image, core, nm, qemu", [
    ("mps2-an385-m0plus-q", "m0plus", "arm-none-eabi-nm", "qemu-system-arm"),
    ("virt-rv32imac-q", "rv32", "riscv64-unknown-elf-nm", "qemu-system-riscv32"),
])
def test_profile_of_the_small_cores_images(image, core, nm, qemu):
    """The M0+ and RV32 integer images through the same trace: within 5 % of their exact counts (all runs and the
    tracker's updates; the M0+ 10 %: its initialisation, the projection's column tables by 64-bit divisions in
    software, is about 7 % of its trace), every instruction of the M0+ image priced (CPI of a core whose loads take 2 cycles), the
    RV32 one a profile only, the int8 list kernel first in both."""
    bdir = pathlib.Path(os.environ.get("LIDET_BUILD_DIR", ROOT / "build")) / "firmware" / image
    elf, rep = bdir / "lidet_fw.elf", bdir / "report.json"
    if not (elf.exists() and rep.exists()):
        pytest.skip(f"{elf} or its report not there (make firmware-run)")
    for tool in (qemu, nm):
        if subprocess.run(["which", tool], capture_output=True).returncode != 0:
            pytest.skip(f"{tool} not installed")
    r = cycles.estimate(str(elf), core, nm, timeout=900)
    import json
    report = json.loads(rep.read_text())
    exact = sum(run["scan"] for run in report["insn"].values())
    exact += sum(run.get("insn_total", 0) for run in report.get("track", {}).values())
    assert abs(r["instructions"] - exact) <= (0.10 if core == "m0plus" else 0.05) * exact, (r["instructions"], exact)
    if core == "m0plus":
        assert r["cycles_low"] == r["cycles_high"] and 1.1 < r["cpi_low"] < 2.0, r["cpi_low"]
    else:
        assert r["cycles_low"] is None
    assert next(iter(r["per_function"])).startswith("list_run"), list(r["per_function"])[:5]


# ---- the packet application (LIDET_FW_APP=packets, ports/firmware/fw_packets.c; issue 37) -----------------------

packets_to_c = _load("packets_to_c")
SIM_VLP16 = ROOT / "tests" / "data" / "sim_vlp16"


def test_packets_to_c_writes_lidet_tools_payloads(tmp_path):
    """packets_to_c.py (standard library only: the build runs it before any venv) writes, byte for byte, the payloads
    of lidet_tools.velodyne.vlp16_packets over vlp16_grid of the shipped scan, in the C file and in the pcap."""
    np = pytest.importorskip("numpy")
    from lidet_tools import velodyne as V
    out, pcap = tmp_path / "fw_scan.c", tmp_path / "p.pcap"
    assert packets_to_c.main([str(SIM_VLP16 / "velodyne" / "000000.bin"), "--ring", str(SIM_VLP16 / "ring" / "000000.bin"),
                              "--name", "sim", "--out", str(out), "--pcap", str(pcap)]) == 0
    pts = np.fromfile(SIM_VLP16 / "velodyne" / "000000.bin", np.float32).reshape(-1, 4)
    ring = np.fromfile(SIM_VLP16 / "ring" / "000000.bin", np.uint16)
    want = [p for _, p in V.vlp16_packets([V.vlp16_grid(pts, ring)], 76, start_cdeg=35760)]
    text = out.read_text()
    assert "const uint32_t fw_pkt_n = 76u;" in text and "fw_pkt_start_cdeg = 35760u;" in text
    body = text.split("[LIDET_VELODYNE_PAYLOAD_BYTES] = {")[1].rsplit("};", 1)[0]
    got = [bytes(int(v) for v in blk.replace("\n", "").split(",") if v.strip())
           for blk in body.replace("{", "").split("}")[:-1]]
    assert got == want
    assert [p for _, _, p in V.read_pcap_payloads(pcap)] == want
    V.write_pcap(tmp_path / "ref.pcap", [V.udp_frame(p) for p in want])
    assert (tmp_path / "ref.pcap").read_bytes() == pcap.read_bytes()


def test_packets_to_c_closes_one_rotation(tmp_path, need_lib):
    """The payloads begin half a packet before the seam and end in the one crossing it again: decoded, a PARTIAL
    scan, then one COMPLETE rotation holding every cell of the scene (the simulated scan's 23,252 points)."""
    from lidet_tools import velodyne as V
    pcap = tmp_path / "p.pcap"
    packets_to_c.main([str(SIM_VLP16 / "velodyne" / "000000.bin"), "--ring", str(SIM_VLP16 / "ring" / "000000.bin"),
                       "--out", str(tmp_path / "fw_scan.c"), "--pcap", str(pcap)])
    d = V.decode([p for _, _, p in V.read_pcap_payloads(pcap)], model="vlp16")
    assert d.scan_kinds() == [V.SCAN_PARTIAL, V.SCAN_COMPLETE, V.SCAN_NONE]
    assert int((d.scan == 1).sum()) == 23252 and sum(d.stats[f"n_rejected_{r}"] for r in V.REJECTS) == 0


def test_packets_to_c_ouster_closes_one_frame(tmp_path, need_lib):
    """--lidar ouster (the Ouster packet image's payloads): a simulated OS1-32 scan as RNG19_RFL8_SIG16_NIR16 payloads,
    with the metadata written beside them; decoded with lidet's decoder, a PARTIAL frame (the lead payload), then one
    COMPLETE frame in which every simulated point comes back as one return, at its range, nothing rejected."""
    np = pytest.importorskip("numpy")
    from lidet_tools import ouster as O
    from lidet_tools import velodyne as V
    from lidet_tools.sim.simulate import simulate_scan
    sc = simulate_scan("os1-32", seed=0, index=0)
    scan, ring = tmp_path / "s.bin", tmp_path / "r.bin"
    np.asarray(sc.points, np.float32).reshape(-1, 4).tofile(scan)
    np.asarray(sc.ring, np.uint16).tofile(ring)
    out, pcap, meta = tmp_path / "fw_scan.c", tmp_path / "p.pcap", tmp_path / "meta.json"
    assert packets_to_c.main([str(scan), "--ring", str(ring), "--lidar", "ouster", "--sensor", "os1-32",
                              "--out", str(out), "--pcap", str(pcap), "--meta", str(meta)]) == 0
    payloads = [p for _, _, p in V.read_pcap_payloads(pcap)]
    assert len(payloads) == 1024 // 16 + 2 and {len(p) for p in payloads} == {O.packet_bytes("RNG19_RFL8_SIG16_NIR16", 32)}
    d = O.decode(payloads, O.load_metadata(meta))
    assert d.scan_kinds()[:2] == [O.SCAN_PARTIAL, O.SCAN_COMPLETE]
    full = d.scan == 1
    assert int(full.sum()) == len(sc.points) and int(d.reject.sum()) == 0
    rng = np.linalg.norm(np.asarray(sc.points, np.float64)[:, :3], axis=1) * 1000.0
    np.testing.assert_allclose(np.sort(d.range_mm[full].astype(np.float64)), np.sort(rng), atol=1.0)
    assert "fw_pkt_n" in out.read_text()


def test_packets_to_c_rejects_bad_arguments(tmp_path):
    scan, ring = SIM_VLP16 / "velodyne" / "000000.bin", SIM_VLP16 / "ring" / "000000.bin"
    with pytest.raises(SystemExit):
        packets_to_c.main([str(scan), "--ring", str(ring), "--start-cdeg", "30", "--out", str(tmp_path / "x.c")])
    short = tmp_path / "r.bin"
    short.write_bytes(b"\0" * 4)
    with pytest.raises(SystemExit):
        packets_to_c.main([str(scan), "--ring", str(short), "--out", str(tmp_path / "x.c")])


PKT_LINES = """lidet-fw board=b core=c build=fixed app=packets sensor=vlp16 models=vlp16s_s8 scan=s packets=76
mem detector_bytes=1 decoder_bytes=2 buffer_bytes=3 max_rows=16 max_cols=1800 max_points=30000 max_clusters=64
stats run=default status=0 clusters=3 detections=1 proj_in=100
det default 0 Car 1 50 00004000 00000001 00000002 00000003 00000004 00000005 00000006 00000007 00000008 00000009
decode run=default packets=76 decoded=76 returns=300 partial=1 complete=1 aborted=0 first=0 last=75 scan_returns=280
stats run=open status=0 clusters=3 detections=1 proj_in=100
det open 0 Car 1 50 00004000 00000001 00000002 00000003 00000004 00000005 00000006 00000007 00000008 00000009
decode run=open packets=76 decoded=76 returns=300 partial=1 complete=1 aborted=0 first=0 last=75 scan_returns=280
digest run=default returns=280 fnv1a=0123abcd
lidet-fw: PASS
"""


def test_packet_lines_parse_and_compare():
    """run_fw.py reads the packet application's decode / digest / pktinsn lines, and its comparison needs them
    identical on both sides (the detections bit for bit as for every integer image; no tracker)."""
    rep = run_fw.parse(PKT_LINES + "insn run=default decode=5 project=1 ground=2 cluster=3 classify=4 box=5 post=6 "
                       "scan=26\npktinsn run=default decode_max=9 stream_max=8 end=7 counter=3\n")
    assert rep["header"]["app"] == "packets" and rep["decode"]["default"]["scan_returns"] == 280
    assert rep["digest"]["default"] == {"returns": "280", "fnv1a": "0123abcd"}
    assert rep["insn"]["default"]["decode"] == 5 and rep["pktinsn"]["default"]["end"] == 7
    assert run_fw.compare(rep, copy.deepcopy(rep))[0] == []
    bad = run_fw.parse(PKT_LINES.replace("00000009\ndecode run=open", "0000000a\ndecode run=open"))
    assert any("integer values differ" in e for e in run_fw.compare(rep, bad)[0])


def test_host_reference_of_the_packet_application():
    """fw_host_ref_pkt: the payloads decoded on the host, the completed scan through lidet_detector_q_run_returns:
    the three runs (the third with the ground stage streamed sector by sector), detections in the open run, one
    partial then one complete scan, its digest."""
    exe = pathlib.Path(os.environ.get("LIDET_BUILD_DIR", ROOT / "build")) / "tests" / "fw_host_ref_pkt"
    if not exe.exists():
        pytest.skip(f"{exe} not built")
    p = subprocess.run([str(exe)], capture_output=True, text=True, timeout=120)
    assert p.returncode == 0, p.stdout + p.stderr
    rep = run_fw.parse(p.stdout)
    assert rep["pass"] and rep["header"]["app"] == "packets" and set(rep["stats"]) == {"default", "open", "sectors"}
    assert len(rep["det"]["open"]) == rep["stats"]["open"]["detections"] > 0 and not rep["track"]
    assert rep["stats"]["sectors"]["detections"] > 0
    for run in ("default", "open", "sectors"):
        d = rep["decode"][run]
        assert (d["packets"], d["decoded"], d["partial"], d["complete"], d["aborted"]) == (76, 76, 1, 1, 0)
        assert d["scan_returns"] == rep["stats"][run]["proj_in"] == int(rep["digest"]["default"]["returns"]) == 23252
