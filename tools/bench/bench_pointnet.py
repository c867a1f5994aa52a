# SPDX-License-Identifier: MIT
"""PointNet forward pass: lidet's C classifier and box net (lidet_pn_classify / lidet_pn_box, through the
bindings; the loop over proposals and the clock are in C) against onnxruntime (one thread) on the same ONNX
models and the same proposals, in the same process, batch 1 and batch 64. Prints the ratio per model."""
from __future__ import annotations

import os
import pathlib
import sys
import time

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[2]


def _proposals(native, kitti, real: pathlib.Path):
    props = []
    scans = [(ROOT / "tests/data/sim_hdl64/velodyne/000000.bin", "hdl64"),
             (ROOT / "tests/data/sim_vlp16/velodyne/000000.bin", "vlp16")]
    scans += [(p, "hdl64") for p in sorted((real / "kitti").glob("*/velodyne/*.bin"))]
    for path, sensor in scans:
        pts = kitti.read_bin(path)
        g = native.ground(pts, sensor)
        cl = native.cluster(pts, sensor, ground=g.mask_point, planes=g.planes)
        props.append(native.proposals(cl, n_points=64))
    return (np.concatenate([p.xyz for p in props]), np.concatenate([p.mean for p in props]),
            np.concatenate([p.voxel for p in props]), len(scans))


def _ort_time(sess, feeds, batch, n, repeats):
    """Fastest of `repeats` passes over n proposals in batches of `batch`: seconds per proposal."""
    keys = list(feeds)
    chunks = [{k: feeds[k][i:i + batch] for k in keys} for i in range(0, n - batch + 1, batch)]
    for c in chunks[:3]:
        sess.run(None, c)
    best = float("inf")
    for _ in range(repeats):
        t = time.perf_counter()
        for c in chunks:
            sess.run(None, c)
        best = min(best, (time.perf_counter() - t) / (len(chunks) * batch))
    return best


def _portable_times(args, n_files, flags=("-DLIDET_NN_CLONES=OFF",), suffix="-portable") -> dict | None:
    """The same C timing from a second build of the bindings with other CMake flags, in a child process: by default
    the AVX2 / AVX-512 variants off (LIDET_NN_CLONES=OFF: the SSE2 baseline every x86-64 has); with
    -DLIDET_NN_FMA=OFF the clones of the portable kernel without the FMA kernel. None when it cannot be built."""
    import json
    import subprocess
    bdir = pathlib.Path(args.build).parent / (pathlib.Path(args.build).name + suffix)
    try:
        subprocess.run(["cmake", "-S", str(ROOT), "-B", str(bdir), "-DCMAKE_BUILD_TYPE=Release",
                        *flags, "-DLIDET_BUILD_TESTS=OFF"], check=True, capture_output=True)
        subprocess.run(["cmake", "--build", str(bdir), "--target", "lidet_py", "-j", "2"], check=True,
                       capture_output=True)
    except (OSError, subprocess.CalledProcessError) as e:
        print(f"bench_pointnet: portable build failed: {e}", file=sys.stderr)
        return None
    code = ("import json, sys, numpy as np; from lidet_tools import native; d = np.load(sys.argv[1]); "
            "print(json.dumps({f: native.pn_time('cls_' + f, 'box_' + f, d['xyz'], d['mean'], d['vox'], "
            "int(sys.argv[2])) for f in sys.argv[3:]}))")
    return code, bdir


def _int8_lines(native, xyz, mean, vox, fams, repeats) -> list:
    """The int8 nets (lidet_pointnet_q_classify / _box, integer proposals: the same proposals rounded to 4 mm)
    next to the float ones, and the flash size of the weights."""
    import json
    from lidet_codegen import emit as E
    from lidet_codegen import quant as QU
    q4, m4 = QU.int_proposals(xyz, mean)
    out = ["", "int8 (issue 16, lib/src/pointnet/lidet_pointnet_q.c, portable C99, no float) against float, same proposals "
               "(integer ones: the same points rounded to 4 mm steps), same clock; flash: the bytes of the weight "
               "arrays (float32 weights and biases; int8 weights, int32 biases, multipliers, one-hot biases, "
               "uint8 shifts).", "",
           "| model | float us/proposal | int8 us/proposal | int8 speed-up | float weights B | int8 weights B |",
           "|---|---:|---:|---:|---:|---:|"]
    for fam in fams:
        if not (ROOT / "weights" / f"cls_{fam}.calib.json").exists():
            continue
        tf = native.pn_time(f"cls_{fam}", f"box_{fam}", xyz, mean, vox, repeats)
        tq = native.pnq_time(f"cls_{fam}_s8", f"box_{fam}_s8", q4, m4, vox, repeats)
        for k, kind in enumerate(("cls", "box")):
            name = f"{kind}_{fam}"
            m = E.load(ROOT / "weights" / f"{name}.onnx", name)
            qm = QU.quantize(m, json.loads((ROOT / "weights" / f"{name}.calib.json").read_text()))
            out.append(f"| {name} | {tf[k] * 1e6:.1f} | {tq[k] * 1e6:.1f} | {tf[k] / tq[k]:.2f}x | {4 * m.params():,} "
                       f"| {qm.flash_bytes():,} |")
    return out


def run(args) -> str:
    os.environ.setdefault("LIDET_BUILD_DIR", str(args.build))
    sys.path.insert(0, str(ROOT / "tools"))
    sys.path.insert(0, str(ROOT / "codegen"))
    import onnxruntime as ort
    from lidet_codegen.macs import count
    from lidet_tools import kitti, native
    from lidet_tools.train.models import to_model_frame

    repeats = 3 if getattr(args, "quick", False) else 10
    xyz, mean, vox, n_scans = _proposals(native, kitti, pathlib.Path(args.real))
    n = (len(xyz) // 64) * 64
    xyz, mean, vox = xyz[:n], mean[:n], vox[:n]
    mp = to_model_frame(xyz, mean)
    so = ort.SessionOptions()
    so.intra_op_num_threads = 1
    so.inter_op_num_threads = 1
    lines = ["## PointNet forward pass (issue 13)", "",
             f"{n} proposals (64 points) from {n_scans} scans (the two simulated samples and the real KITTI scans "
             "when present). lidet: `native.pn_time` (lidet_pn_classify, then lidet_pn_box with a class per "
             "proposal; model frame, PVLE, energies and decoding included; the loop and clock in C, fastest of "
             f"{repeats} passes). onnxruntime {ort.__version__}: one thread, the raw network only (points already in "
             "the model frame), fastest of the same number of passes. Same models (weights/*.onnx), same inputs, "
             "same process.", "",
             "| model | MACs | lidet us/proposal | onnxruntime batch 1 | batch 64 | lidet vs batch 1 | lidet vs batch 64 |",
             "|---|---:|---:|---:|---:|---:|---:|"]
    # the families of 64-point models (the proposals above): the small pair vlp16s (32 points per proposal, the
    # integer firmware's) is not in these tables
    pm = native.pn_models()
    fams = sorted(p.stem[4:] for p in (ROOT / "weights").glob("cls_*.onnx")
                  if f"cls_{p.stem[4:]}" in pm and pm[f"cls_{p.stem[4:]}"].n_points == xyz.shape[1])

    def other_build(flags, suffix):
        pc = _portable_times(args, len(fams), flags, suffix)
        if pc is None:
            return {}
        import json
        import subprocess
        import tempfile
        code, bdir = pc
        with tempfile.TemporaryDirectory() as td:
            np.savez(pathlib.Path(td) / "p.npz", xyz=xyz, mean=mean, vox=vox)
            env = dict(os.environ, LIDET_BUILD_DIR=str(bdir), LIDET_LIB=str(bdir / "ports/python/liblidet_py.so"))
            r = subprocess.run([sys.executable, "-c", code, str(pathlib.Path(td) / "p.npz"), str(repeats), *fams],
                               capture_output=True, text=True, env=env)
            if r.returncode == 0:
                return json.loads(r.stdout)
            print(r.stderr, file=sys.stderr)
            return {}

    portable = other_build(("-DLIDET_NN_CLONES=OFF",), "-portable")
    nofma = other_build(("-DLIDET_NN_FMA=OFF",), "-nofma")
    gmacs = {}
    for fam in fams:
        cls_name, box_name = f"cls_{fam}", f"box_{fam}"
        t_cls, t_box = native.pn_time(cls_name, box_name, xyz, mean, vox, repeats)
        oh = np.eye(3, dtype=np.float32)[np.arange(n) % 3]
        feeds_c = {"points": mp, "voxel": vox.astype(np.float32)}
        feeds_b = dict(feeds_c, onehot=oh)
        sc = ort.InferenceSession(str(ROOT / "weights" / f"{cls_name}.onnx"), so, providers=["CPUExecutionProvider"])
        sb = ort.InferenceSession(str(ROOT / "weights" / f"{box_name}.onnx"), so, providers=["CPUExecutionProvider"])
        o1c, o64c = _ort_time(sc, feeds_c, 1, n, repeats), _ort_time(sc, feeds_c, 64, n, repeats)
        o1b, o64b = _ort_time(sb, feeds_b, 1, n, repeats), _ort_time(sb, feeds_b, 64, n, repeats)
        mc, mb = count(ROOT / "weights" / f"{cls_name}.onnx")["macs"], count(ROOT / "weights" / f"{box_name}.onnx")["macs"]
        for name, macs, t, o1, o64 in ((cls_name, mc, t_cls, o1c, o64c), (box_name, mb, t_box, o1b, o64b),
                                       (f"both ({fam})", mc + mb, t_cls + t_box, o1c + o1b, o64c + o64b)):
            lines.append(f"| {name} | {macs:,} | {t * 1e6:.1f} | {o1 * 1e6:.1f} | {o64 * 1e6:.1f} "
                         f"| **{o1 / t:.2f}x** | {o64 / t:.2f}x |")
        gmacs[fam] = (mc / t_cls / 1e9, mc / portable[fam][0] / 1e9 if fam in portable else None,
                      mc / nofma[fam][0] / 1e9 if fam in nofma else None)
        for other, tag in ((nofma, "clones, no FMA"), (portable, "SSE2 only")):
            if fam in other:
                pcl, pbx = other[fam]
                for name, t, o1, o64 in ((f"{cls_name}, {tag}", pcl, o1c, o64c), (f"{box_name}, {tag}", pbx, o1b, o64b),
                                         (f"both ({fam}), {tag}", pcl + pbx, o1c + o1b, o64c + o64b)):
                    lines.append(f"| {name} | | {t * 1e6:.1f} | {o1 * 1e6:.1f} | {o64 * 1e6:.1f} | {o1 / t:.2f}x "
                                 f"| {o64 / t:.2f}x |")
    lines += _int8_lines(native, xyz, mean, vox, fams, repeats)
    g = gmacs.get("hdl64") or next(iter(gmacs.values()), (0.0, None, None))
    speeds = f"{g[0]:.0f} GMAC/s here" + (f", {g[2]:.0f} with the clones without FMA" if g[2] else "") + (
        f", {g[1]:.0f} with SSE2 only" if g[1] else "")
    lines += ["", "Ratios above 1 mean lidet is faster. The C kernels are portable C99 (lib/src/nn/lidet_nn_f32.c); "
              "on x86-64 hosts the build also compiles them for AVX2 (the float kernel also for AVX-512) and picks "
              "the variant at load time (CMake option LIDET_NN_CLONES, like onnxruntime's own dispatch), with "
              "identical results; on CPUs with FMA the float dense kernel is a register-tiled one with fused "
              "multiply-adds instead (lib/src/nn/lidet_nn_f32_x86.c, CMake LIDET_NN_FMA; its last bits differ from "
              "the portable kernel's, docs/POINTNET.md). The 'clones, no FMA' rows time a second build with "
              "LIDET_NN_FMA=OFF, the 'SSE2 only' rows a third with LIDET_NN_CLONES=OFF (the x86-64 baseline "
              "instruction set, as the portable code compiles without any -march flag), in the same run. Where the "
              "time goes: the shared per-point layers hold 98 % of the multiply-adds (e.g. 64 points x (3x32 + "
              f"32x64 + 64x128) of the classifier's 673 k); the whole classifier runs at {speeds} (its MACs over "
              "the times above); onnxruntime's MLAS uses AVX-512/AVX2 kernels.",
              "Command: `python tools/bench/bench_pointnet.py` (part of `make bench`).", ""]
    return "\n".join(lines)


if __name__ == "__main__":
    sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
    from run_bench import standalone
    standalone(run, __doc__)
