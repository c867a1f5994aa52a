# SPDX-License-Identifier: MIT
"""Benchmark of the KITTI evaluation: 3,769 frames (the size of KITTI val) of synthetic KITTI-like
ground truth against perturbed predictions (lidet_tools.eval.synth), one core.

Called by tools/bench/run_bench.py as run(args) -> markdown, or alone:
    .venv/bin/python tools/bench/bench_eval.py [--frames 3769] [--repeat 3]
"""
from __future__ import annotations

import argparse
import os
import platform
import shutil
import subprocess
import sys
import tempfile
import time

N_FRAMES = 3769


def _single_core_env():
    env = dict(os.environ)
    for k in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        env[k] = "1"
    env.setdefault("MPLBACKEND", "Agg")
    return env


def measure(n_frames: int = N_FRAMES, repeat: int = 3, seed: int = 0) -> dict:
    from lidet_tools.eval import kitti_ap, synth

    tmp = tempfile.mkdtemp(prefix="lidet_bench_eval_")
    try:
        gt, pred = synth.synth_kitti(n_frames, seed=seed)
        synth.write_frames(os.path.join(tmp, "gt"), gt)
        synth.write_frames(os.path.join(tmp, "pred"), pred)
        n_gt = sum(len(f) for f in gt)
        n_dt = sum(len(f) for f in pred)
        core = []
        for _ in range(repeat):
            t0, c0 = time.perf_counter(), time.process_time()
            res = kitti_ap.evaluate_dirs(os.path.join(tmp, "gt"), os.path.join(tmp, "pred"), warn=False)
            core.append((time.perf_counter() - t0, time.process_time() - c0))
        core.sort()
        cmd = [sys.executable, "-m", "lidet_tools.eval.cli", "kitti", "--gt", os.path.join(tmp, "gt"),
               "--pred", os.path.join(tmp, "pred"), "--json"]
        if shutil.which("taskset"):
            cmd = ["taskset", "-c", "0"] + cmd
        t0 = time.perf_counter()
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, env=_single_core_env())
        cli_s = time.perf_counter() - t0
        return dict(n_frames=n_frames, n_gt=n_gt, n_dt=n_dt, core_wall_s=core[len(core) // 2][0],
                    core_cpu_s=core[len(core) // 2][1], cli_wall_s=cli_s, pinned=cmd[0] == "taskset",
                    car_3d_mod_r40=res["ap"]["Car"]["3d"]["R40"]["moderate"])
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def run(args) -> str:
    m = measure(getattr(args, "eval_frames", None) or N_FRAMES)
    cpu = platform.machine()
    try:
        with open("/proc/cpuinfo") as f:
            cpu = next(ln.split(":", 1)[1].strip() for ln in f if ln.startswith("model name"))
    except (OSError, StopIteration):
        pass
    return "\n".join([
        "## Evaluation speed (lidet-eval kitti)",
        "",
        f"{m['n_frames']} synthetic KITTI-like frames ({m['n_gt']} ground-truth lines incl. DontCare, "
        f"{m['n_dt']} predictions; Car 3D AP|R40 moderate {m['car_3d_mod_r40']:.1f}), 3 classes x 3 difficulties x (3D, BEV, 2D), AP|R11 and AP|R40, "
        f"{cpu}, one core.",
        "",
        "| what | seconds |",
        "|---|---|",
        f"| evaluation core (read labels, IoU, matching, AP), wall, median of 3 | {m['core_wall_s']:.2f} |",
        f"| same, CPU time of the process | {m['core_cpu_s']:.2f} |",
        f"| `lidet-eval kitti --gt GT --pred PRED --json` end to end"
        f"{' (taskset -c 0)' if m['pinned'] else ''} | {m['cli_wall_s']:.2f} |",
        "",
        "Command: `.venv/bin/python tools/bench/bench_eval.py` (target: under 60 s).",
        "",
    ])


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--frames", type=int, default=N_FRAMES)
    a = p.parse_args(argv)
    print(run(argparse.Namespace(eval_frames=a.frames)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
