#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Run the aarch64 Linux cross build under qemu-aarch64 and compare its CLI with the host's (ctest aarch64_linux).

    python3 tests/aarch64/run_aarch64.py --build build/aarch64 --tests proj,proj_q,... --src . \\
        --host-cli build/ports/host/lidet --host-cli-portable build/tests/lidet_cli_portable \\
        [--host-cli-fma build/ports/host/lidet] [--qemu qemu-aarch64]

The cross build (tests/aarch64.cmake: this repository configured with cmake/toolchains/aarch64-linux-gnu.cmake,
targets lidet_unit_tests and lidet_cli) is made by the normal build. This script:
1. runs every Unity test binary of tests/unit under qemu-aarch64 (-L the cross sysroot); each must exit 0;
2. runs the aarch64 CLI and the host CLI on the simulated scans of tests/data (`lidet detect --dump`):
   - the integer detector (`--fixed`, and `--fixed --returns` with the rings): the dumps must be byte-identical;
   - the float detector (the aarch64 build's float dense kernel is the NEON one, lib/src/nn/lidet_nn_f32_neon.c,
     unless it was configured with LIDET_NN_NEON=OFF):
     - against the host CLI with the x86 FMA kernel (--host-cli-fma; only where the host CPU has FMA, the
       comparison is skipped with a note elsewhere): byte for byte, since both kernels compute each output by the
       same chain of fused multiply-adds;
     - against the host CLI built with the portable float dense kernel (LIDET_NN_FMA off), whose last bits differ:
       per-point labels and ground flags, cluster records' counts and outcomes, voxel bins, detections' classes,
       cluster ids and point counts identical; floats within the tolerances of the firmware comparison
       (tools/firmware/run_fw.py: positions 1e-3 m, yaw 1e-3 rad, score 1e-4, energies 1e-4 relative), since
       glibc's expf/logf/sinf/cosf/atan2f are separate builds on the two architectures; everything else is IEEE
       single precision in the same order (-ffp-contract=off). The report says how many values were
       bit-identical.
Exit status: 0 pass, 1 fail, 77 skipped (qemu-aarch64 or the cross build missing: ctest reports it skipped).
"""
import argparse
import os
import pathlib
import shutil
import struct
import subprocess
import sys
import time

# the firmware comparison's tolerances and angle difference (one definition for both comparisons)
sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[2] / "tools" / "firmware"))
from run_fw import ATOL_M, ATOL_RAD, ATOL_SCORE, RTOL_ENERGY, ang_diff  # noqa: E402

SKIP = 77
SCANS = ("vlp16", "hdl64")


def run(cmd, cwd=None, timeout=600.0):
    t0 = time.monotonic()
    r = subprocess.run(cmd, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=timeout)
    return r.returncode, r.stdout.decode("utf-8", "replace"), time.monotonic() - t0


def parse_float_dump(b):
    """cli_detect.c write_dump -> (discrete bytes per part, float values per kind)."""
    if b[:4] != b"LDTD":
        raise ValueError("not a float detector dump (LDTD)")
    n, n_cl, n_det = struct.unpack_from("<3I", b, 4)
    off = 16
    points = b[off:off + 5 * n]
    off += 5 * n
    det_bytes = 52 * n_det
    rest = len(b) - off - det_bytes
    if n_cl == 0:
        per_cl = 0
    else:
        per_cl = rest // n_cl
        if per_cl * n_cl != rest or (per_cl - 16 - 36 - 24) % 12 != 0:
            raise ValueError("cluster records of an unexpected size")
    rows = (per_cl - 16 - 36 - 24) // 12 if n_cl else 0
    discrete, floats = [], {"m": [], "score": [], "energy": [], "yaw": []}
    for _ in range(n_cl):
        discrete.append(b[off:off + 16])  # n_points, seed_pixel, n_rescued, outcome
        off += 16
        floats["m"] += struct.unpack_from("<9f", b, off)  # mean, min, max (interleaved)
        off += 36
        floats["m"] += struct.unpack_from(f"<{3 * rows}f", b, off)  # proposal points
        off += 12 * rows
        for _ in range(3):
            floats["m"].append(struct.unpack_from("<f", b, off)[0])  # proposal mean
            discrete.append(b[off + 4:off + 8])  # voxel bin
            off += 8
    for _ in range(n_det):
        discrete.append(b[off:off + 12])  # class, cluster id, n_points
        score, e_cls, e_box, cx, cy, cz, l, w, h, yaw = struct.unpack_from("<10f", b, off + 12)
        floats["score"].append(score)
        floats["energy"] += [e_cls, e_box]
        floats["m"] += [cx, cy, cz, l, w, h]
        floats["yaw"].append(yaw)
        off += 52
    return (n, n_cl, n_det), points, discrete, floats


def compare_float(host, arm):
    """-> (ok, message)"""
    hc, hp, hd, hf = parse_float_dump(host)
    ac, ap, ad, af = parse_float_dump(arm)
    if hc != ac:
        return False, f"counts differ: host (points, clusters, detections) {hc}, aarch64 {ac}"
    if hp != ap:
        return False, "per-point cluster ids or ground flags differ"
    if hd != ad:
        return False, "cluster records (counts, outcomes, voxel bins) or detections (class, cluster, points) differ"
    n_vals = n_same = 0
    worst = {}
    bad = []
    for kind, tol in (("m", ATOL_M), ("score", ATOL_SCORE), ("energy", RTOL_ENERGY), ("yaw", ATOL_RAD)):
        for x, y in zip(hf[kind], af[kind]):
            n_vals += 1
            if struct.pack("<f", x) == struct.pack("<f", y):
                n_same += 1
                continue
            if kind == "yaw":
                d = ang_diff(x, y)
            else:
                d = abs(x - y)
            lim = tol * max(1.0, abs(x)) if kind == "energy" else tol
            worst[kind] = max(worst.get(kind, 0.0), d)
            if not d <= lim:
                bad.append(f"{kind}: host {x!r} aarch64 {y!r}")
    msg = f"{n_same}/{n_vals} float values bit-identical"
    if worst:
        msg += "; max |diff| " + ", ".join(f"{k} {v:.3g}" for k, v in sorted(worst.items()))
    if bad:
        return False, msg + "; beyond the tolerances: " + "; ".join(bad[:5])
    return True, msg


def host_has_fma(cpuinfo="/proc/cpuinfo"):
    """-> (bool, why): whether the x86 FMA kernel runs on this host (lidet_nn_f32_x86.c's resolver: AVX-512F, or
    AVX2 and FMA)."""
    try:
        with open(cpuinfo) as f:
            flags = set()
            for line in f:
                if line.startswith("flags"):
                    flags |= set(line.split(":", 1)[1].split())
    except OSError as e:
        return False, f"cannot read {cpuinfo}: {e}"
    if "avx512f" in flags or {"avx2", "fma"} <= flags:
        return True, ""
    return False, "the host CPU has no FMA (neither AVX-512F nor AVX2 + FMA in /proc/cpuinfo)"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--build", help="the aarch64 build folder")
    ap.add_argument("--tests", default="", help="comma-separated unit test names (tests/unit/test_<name>.c)")
    ap.add_argument("--src", help="the repository")
    ap.add_argument("--host-cli", help="this build's lidet (the integer comparison)")
    ap.add_argument("--host-cli-portable", help="a host lidet with the portable float dense kernel")
    ap.add_argument("--host-cli-fma", help="a host lidet with the x86 FMA float dense kernel (compared byte for byte "
                    "where the host CPU has FMA)")
    ap.add_argument("--qemu", default="qemu-aarch64")
    ap.add_argument("--sysroot", default="/usr/aarch64-linux-gnu")
    ap.add_argument("--work", help="folder for the dumps (default: <build>/cli_compare)")
    ap.add_argument("--timeout", type=float, default=600.0, help="seconds per program")
    ap.add_argument("--skip", help="print this reason and exit 77 (ctest: skipped)")
    a = ap.parse_args(argv)
    if a.skip:
        print(f"SKIPPED aarch64_linux: {a.skip}")
        return SKIP
    qemu = shutil.which(a.qemu)
    if qemu is None:
        print(f"SKIPPED aarch64_linux: {a.qemu} not found (tools/scripts/install_deps.sh installs qemu-user)")
        return SKIP
    if not a.build or not os.path.isdir(a.build):
        print(f"aarch64_linux: no cross build at {a.build} (cmake --build the main build first)")
        return 1
    emu = [qemu, "-L", a.sysroot]
    failed = []
    t_all = time.monotonic()

    # 1. the unit tests
    tdir = os.path.join(a.build, "tests")
    names = [n for n in a.tests.split(",") if n]
    t_unit = 0.0
    for n in names:
        exe = os.path.join(tdir, f"test_{n}")
        if not os.path.exists(exe):
            print(f"FAIL unity_{n}: {exe} not built")
            failed.append(f"unity_{n}")
            continue
        rc, out, dt = run(emu + [exe], cwd=tdir, timeout=a.timeout)
        t_unit += dt
        tail = [ln for ln in out.splitlines() if ln.strip()][-2:]
        print(f"{'ok  ' if rc == 0 else 'FAIL'} unity_{n:<14} {dt:6.2f} s  {' / '.join(tail)}")
        if rc != 0:
            print(out)
            failed.append(f"unity_{n}")
    print(f"unit tests under qemu-aarch64: {len(names) - sum(f.startswith('unity_') for f in failed)}/{len(names)} "
          f"passed in {t_unit:.1f} s")

    # 2. the CLI against the host's
    cli = os.path.join(a.build, "ports", "host", "lidet")
    fma_ok, fma_why = host_has_fma()
    if a.host_cli and a.src:
        work = a.work or os.path.join(a.build, "cli_compare")
        os.makedirs(work, exist_ok=True)
        if not os.path.exists(cli):
            print(f"FAIL cli: {cli} not built")
            failed.append("cli")
        for sensor in SCANS if os.path.exists(cli) else ():
            data = os.path.join(a.src, "tests", "data", f"sim_{sensor}")
            scan = os.path.join(data, "velodyne", "000000.bin")
            ring = os.path.join(data, "ring", "000000.bin")
            # (label, options, host CLI, aarch64 dump's name: the float one is run once for both comparisons)
            runs = [("fixed", ["--fixed"], a.host_cli, "fixed")]
            if sensor == "vlp16" and os.path.exists(ring):
                runs.append(("fixed-returns", ["--fixed", "--ring", ring, "--returns"], a.host_cli, "fixed-returns"))
            if a.host_cli_fma:
                if fma_ok:
                    runs.append(("float-fma", [], a.host_cli_fma, "float"))
                else:
                    print(f"skip cli {sensor} detect (float) vs host (x86 FMA kernel), byte for byte: {fma_why}")
            if a.host_cli_portable:
                runs.append(("float", [], a.host_cli_portable, "float"))
            arm_dumps = {}
            for label, opts, host, arm_name in runs:
                dumps = {}
                sides = [("host", [host], label)]
                if arm_name not in arm_dumps:
                    sides.append(("aarch64", emu + [cli], arm_name))
                else:
                    dumps["aarch64"] = arm_dumps[arm_name]
                for side, cmd, name in sides:
                    path = os.path.join(work, f"{sensor}_{name}_{side}.bin")
                    rc, out, dt = run(cmd + ["detect", scan, "--sensor", sensor, *opts, "--dump", path],
                                      timeout=a.timeout)
                    if rc != 0 or not os.path.exists(path):
                        print(f"FAIL cli {sensor} {label}: {side} run failed ({rc}):\n{out}")
                        break
                    with open(path, "rb") as f:
                        dumps[side] = f.read()
                    if side == "aarch64":
                        arm_dumps[arm_name] = dumps[side]
                if len(dumps) < 2:
                    failed.append(f"cli {sensor} {label}")
                    continue
                if label != "float":
                    # the integer detector, and the float one against the x86 FMA kernel: byte for byte
                    ok = dumps["host"] == dumps["aarch64"]
                    msg = (f"{len(dumps['host'])} bytes identical" if ok else
                           f"dumps differ ({work}/{sensor}_{label}_host.bin, {sensor}_{arm_name}_aarch64.bin)")
                    if not ok and label == "float-fma":
                        try:
                            msg += " (" + compare_float(dumps["host"], dumps["aarch64"])[1] + ")"
                        except ValueError as e:
                            msg += f" ({e})"
                else:
                    try:
                        ok, msg = compare_float(dumps["host"], dumps["aarch64"])
                    except ValueError as e:
                        ok, msg = False, str(e)
                what = {"float": " (portable float kernel)", "float-fma": " (x86 FMA kernel), byte for byte"}
                print(f"{'ok  ' if ok else 'FAIL'} cli {sensor} detect {' '.join(o for o in opts if '/' not in o) or '(float)'}"
                      f" vs host{what.get(label, '')}: {msg}")
                if not ok:
                    failed.append(f"cli {sensor} {label}")
    print(f"aarch64_linux: {time.monotonic() - t_all:.1f} s")
    if failed:
        print("aarch64_linux: FAIL: " + ", ".join(failed))
        return 1
    print("aarch64_linux: PASS")
    return 0


if __name__ == "__main__":
    sys.exit(main())
