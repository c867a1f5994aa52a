# SPDX-License-Identifier: MIT
"""lidet-sim: write simulated LiDAR scans with labels in KITTI's folder layout.

    lidet-sim --sensor hdl64 --scenes 200 --seed 0 --out data/sim/hdl64
    lidet-sim --sequence 50 --sensor hdl64 --scenes 4 --seed 0 --out data/sim/seq_hdl64 [--ego-speed 8]

Scan i of a run is fully determined by (--seed, i, options): the same command gives the same bytes,
and `--start` lets several processes share one long run. With --sequence FRAMES, --scenes counts sequences of
FRAMES scans each whose road users move, ids kept (sequence.py; out/<seq:04d>/...).
"""
from __future__ import annotations

import argparse
import functools
import sys
import time

from ..sensors import SENSORS
from .scene import SCENE_TYPES
from .simulate import simulate_scan
from .writer import write_scan


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="lidet-sim", description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--sensor", default="hdl64", choices=sorted(SENSORS), help="sensor profile (sensors.py)")
    p.add_argument("--scenes", type=int, default=10, help="number of scans to write")
    p.add_argument("--start", type=int, default=0, help="index of the first scan (file name and seed)")
    p.add_argument("--seed", type=int, default=0, help="run seed; scan i uses SeedSequence([seed, i])")
    p.add_argument("--out", required=True, help="output folder (velodyne/, labels/, label_2/, calib/, boxes/, ring/)")
    p.add_argument("--mount-height", type=float, default=None,
                   help="sensor height above the ground in m (default: the profile's; vlp16 robot 0.3-1.0)")
    p.add_argument("--pitch-deg", type=float, default=None, help="mount pitch (default: random, sigma 0.25 deg)")
    p.add_argument("--roll-deg", type=float, default=None, help="mount roll (default: random, sigma 0.25 deg)")
    p.add_argument("--scene", choices=SCENE_TYPES, default=None, help="force one scene type (default: mixed)")
    p.add_argument("--crowd", action="store_true",
                   help="crowded streets (issue 15): groups of people 0.2-1 m apart, people beside cars, poles, bins "
                        "and walls, cyclists beside parked cars, people pushing bicycles, darker and more broken cars")
    p.add_argument("--behind-cars", type=float, default=0.0, metavar="RATE",
                   help="mean number of people (alone or 2-4 side by side) standing just behind a parked car per scan, "
                        "seen from the waist or chest up (default 0: none)")
    p.add_argument("--foliage", type=float, default=0.0, metavar="M",
                   help="mean depth in m that rays reach into vegetation (canopies, bushes, hedges) before they return, "
                        "drawn per ray (default 0: from its surface; docs/SIMULATOR.md, \"Foliage\")")
    p.add_argument("--range-noise", type=float, default=0.02, help="1-sigma range noise in m")
    p.add_argument("--dropout", type=float, default=0.015, help="random dropout probability")
    g = p.add_argument_group("sequences (sequence.py)")
    g.add_argument("--sequence", type=int, default=None, metavar="FRAMES",
                   help="write --scenes sequences of FRAMES scans each (moving road users, ids kept, tracks/, "
                        "label_02/, poses.txt) instead of independent scans")
    g.add_argument("--rate", type=float, default=None, metavar="HZ",
                   help="scan rate (default the profile's: 10 Hz; vlp16 and vlp32c also 20, hdl32 20)")
    g.add_argument("--ego-speed", type=float, default=0.0, metavar="M_S",
                   help="the sensor drives along its lane (a robot: its sidewalk) at this speed (default 0: it stands)")
    g.add_argument("--ego-yaw-rate", type=float, default=0.05, metavar="RAD_S",
                   help="peak yaw rate of the driving sensor's gentle weave (default 0.05 rad/s)")
    p.add_argument("--jobs", type=int, default=1,
                   help="worker processes (each scan is independent: the bytes do not depend on --jobs)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    return p


def _one(a, i):
    r = simulate_scan(a.sensor, a.seed, i, a.mount_height, a.pitch_deg, a.roll_deg, a.scene,
                      a.range_noise, a.dropout, crowd=a.crowd, behind_cars=a.behind_cars,
                      foliage_m=a.foliage)
    write_scan(a.out, f"{i:06d}", r)
    return i


def main(argv=None) -> int:
    a = build_parser().parse_args(argv)
    if a.jobs < 1:
        print("lidet-sim: --jobs must be >= 1", file=sys.stderr)
        return 2
    if not (0.0 <= a.behind_cars <= 50.0):
        print("lidet-sim: --behind-cars must be in [0, 50]", file=sys.stderr)
        return 2
    if not (0.0 <= a.foliage <= 2.0):
        print("lidet-sim: --foliage must be in [0, 2] m", file=sys.stderr)
        return 2
    if a.foliage > 0.0 and a.sequence is not None:
        print("lidet-sim: --foliage applies to single scans, not to --sequence", file=sys.stderr)
        return 2
    if a.mount_height is not None and not 0.1 <= a.mount_height <= 5.0:
        print("lidet-sim: --mount-height must be in [0.1, 5] m", file=sys.stderr)
        return 2
    if a.sequence is not None:
        from .sequence import main_from_args
        return main_from_args(a)
    if a.rate is not None or a.ego_speed != 0.0:
        print("lidet-sim: --rate and --ego-speed need --sequence FRAMES", file=sys.stderr)
        return 2
    idx = range(a.start, a.start + a.scenes)
    job = functools.partial(_one, a)
    bar = None
    if not a.no_progress:
        from tqdm import tqdm
        bar = tqdm(total=a.scenes, desc=f"lidet-sim {a.sensor}", unit="scan")
    t0 = time.perf_counter()
    c0 = time.process_time()
    if a.jobs > 1:
        import multiprocessing as mp
        with mp.get_context("spawn").Pool(a.jobs) as pool:
            for _ in pool.imap_unordered(job, idx):
                if bar is not None:
                    bar.update(1)
    else:
        for i in idx:
            job(i)
            if bar is not None:
                bar.update(1)
    dt = time.perf_counter() - t0
    dc = time.process_time() - c0          # this process only (not the --jobs workers)
    if bar is not None:
        bar.close()
    cpu = (f"; CPU {dc:.2f} s, {a.scenes / max(dc, 1e-9):.2f} scans/s" if a.jobs == 1
           else f"; {a.jobs} worker processes")
    print(f"lidet-sim: {a.scenes} scans of {a.sensor} in {dt:.2f} s ({a.scenes / max(dt, 1e-9):.2f} scans/s"
          f"{cpu}) -> {a.out}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
