# SPDX-License-Identifier: MIT
"""Tracking across scans (issue 38): lidet's tracker (float and integer) against an AB3DMOT-style peer
(tools/lidet_tools/track/peer.py: filterpy Kalman filters, scipy's Hungarian assignment, AB3DMOT's KITTI
settings), fed the same detections of lidet's detector on held-out simulated sequences, same run.

Contract of tools/bench/run_bench.py: `run(args) -> str` returns a markdown section (args.build: the CMake build
with liblidet_py.so; args.quick: fewer sequences). Alone: `python tools/bench/bench_track.py [--quick]`.

Sets (`lidet-sim --sequence FRAMES --scenes N --seed S`, cached in data/bench/track_*; the tracker's defaults were
chosen on seeds 100-102, docs/journal/tracking.md, "How the defaults were chosen"): HDL-64 street scenes with the
sensor standing and driving at 8 m/s, and
VLP-16 crowded streets with the robot walking at 1 m/s. Scored by `lidet_tools.track.eval` (py-motmetrics, BEV
centre distance, objects within 40 m with >= 10 points).
"""
from __future__ import annotations

import os
import pathlib
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]
DATA = ROOT / "data" / "bench"
#: (name, title, sensor, frames, seed, extra lidet-sim options)
SETS = (("track_hdl64_stand", "HDL-64, standing", "hdl64", 40, 7100, ("--scene", "street")),
        ("track_hdl64_drive", "HDL-64, driving 8 m/s", "hdl64", 40, 7200, ("--scene", "street", "--ego-speed", "8")),
        ("track_vlp16_crowd", "VLP-16 robot, crowd, 1 m/s", "vlp16", 60, 7300, ("--crowd", "--ego-speed", "1")))


def _sim(out: pathlib.Path, sensor: str, frames: int, n: int, seed: int, extra) -> list:
    seqs = sorted(p for p in out.glob("[0-9]*") if p.is_dir()) if out.is_dir() else []
    if len(seqs) < n or any(len(list((p / "velodyne").glob("*.bin"))) < frames for p in seqs[:n]):
        env = dict(os.environ, PYTHONPATH=str(ROOT / "tools") + os.pathsep + os.environ.get("PYTHONPATH", ""))
        subprocess.run([sys.executable, "-m", "lidet_tools.sim.cli", "--sensor", sensor, "--sequence", str(frames),
                        "--scenes", str(n), "--seed", str(seed), *extra, "--out", str(out), "--jobs", "2",
                        "--no-progress"], env=env, check=True)
        seqs = sorted(p for p in out.glob("[0-9]*") if p.is_dir())
    return seqs[:n]


def _f(v, fmt=".3f"):
    return "-" if v is None else format(v, fmt)


def run(args=None) -> str:
    build = pathlib.Path(getattr(args, "build", ROOT / "build"))
    os.environ["LIDET_BUILD_DIR"] = str(build)
    sys.path.insert(0, str(ROOT / "tools"))
    from lidet_tools.track import run as R
    from lidet_tools.track.native import Tracker
    from lidet_tools.track.peer import PeerTracker
    n = 4 if getattr(args, "quick", False) else 20
    trackers = {"lidet": lambda: Tracker(), "lidet integer": lambda: Tracker(fixed=True), "peer": PeerTracker}
    lines = ["## Tracking (issue 38)", "",
             f"lidet's tracker (float, and the integer build through its bindings) against an AB3DMOT-style peer "
             f"(`tools/lidet_tools/track/peer.py`: filterpy Kalman filters, scipy's Hungarian assignment, AB3DMOT's "
             f"KITTI settings), both fed lidet's float detector's detections and the sensor's ego motion, on "
             f"{n} held-out simulated sequences per set (`lidet-sim --sequence FRAMES --scenes {n} --seed S`; the "
             "tracker's defaults were chosen on seeds 100-102). Scored by `lidet_tools.track.eval` (py-motmetrics; "
             "BEV centre distance within 2 m car, 1.5 m cyclist, 1 m pedestrian; objects within 40 m with >= 10 "
             "points). IDs/100: id switches per 100 ground-truth tracks; velocity error: confirmed tracks matched "
             "to an object, m/s. Command: `python tools/bench/bench_track.py`.", "",
             "| set | tracker | MOTA | IDF1 | IDs/100 | MOTP (m) | vel. err. median | vel. err. p90 | ms/scan | "
             "MOTA / peer | IDF1 / peer |", "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for name, title, sensor, frames, seed, extra in SETS:
        seqs = [R.load_sequence(p) for p in _sim(DATA / name, sensor, frames, n, seed, extra)]
        dets = [R.detect_sequence(s) for s in seqs]
        res = R.run(seqs, dets, trackers)
        peer = res["peer"]["overall"]
        for tname, r in res.items():
            o = r["overall"]
            ratio = (lambda k: "" if tname == "peer" or not peer[k] else f"{o[k] / peer[k]:.2f}")  # noqa: E731
            lines.append(f"| {title} ({len(seqs)} x {frames} scans) | {tname} | {_f(o['mota'])} | {_f(o['idf1'])} | "
                         f"{_f(o['ids_per_100'], '.1f')} | {_f(o['motp'])} | {_f(o['vel_err']['median'], '.2f')} | "
                         f"{_f(o['vel_err']['p90'], '.2f')} | {_f(r['ms_per_scan'], '.3f')} | {ratio('mota')} | "
                         f"{ratio('idf1')} |")
        st = R.detection_stats(seqs, dets)
        lines.append(f"| ({st['scans']} scans, {st['per_scan']:.1f} detections per scan) | | | | | | | | | | |")
    lines += ["", "ms/scan: the tracker's update through its Python binding or, for the peer, in Python, one core.", ""]
    return "\n".join(lines)


if __name__ == "__main__":
    sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
    from run_bench import standalone
    standalone(run, __doc__)
