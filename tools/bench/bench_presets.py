# SPDX-License-Identifier: MIT
"""The detector on every sensor preset (issue 37, item 5): simulated AP per preset against the matching model
family on its own sensor (hdl64 on hdl64 for the presets of 32 beams or more, vlp16 on vlp16), same run.

Contract of tools/bench/run_bench.py: `run(args) -> str` returns a markdown section (args.build: the CMake build
with the host CLI; args.quick: fewer scans). Alone: `python tools/bench/bench_presets.py [--quick]`.

Per preset: `lidet-sim --sensor S --scenes N --seed 9100` (360 degrees, the preset's mount height), then
`python -m lidet_tools.detect SIM --sensor S --out PRED` (the preset's default model family) and the sensor-frame
evaluation `lidet_tools.eval.boxes_ap` (AP R40, KITTI overlaps 0.7 / 0.5 / 0.5, every distance band).
"""
from __future__ import annotations

import os
import pathlib
import subprocess
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parents[2]
SEED = 9100
CLASSES = ("Car", "Pedestrian", "Cyclist")
COLS = (("Car", "0-20"), ("Car", "20-40"), ("Pedestrian", "0-20"), ("Pedestrian", "20-40"), ("Cyclist", "0-20"))


def _ap(gt_dir, pred_dir) -> dict:
    sys.path.insert(0, str(ROOT / "tools"))
    from lidet_tools.eval import boxes_ap
    ap = boxes_ap.evaluate_dirs(gt_dir, pred_dir, warn=False, classes=CLASSES, overlap="kitti")["ap"]
    return {(c, b): ap.get(c, {}).get("3d", {}).get("R40", {}).get(b) for c, b in COLS}


def measure(sensor: str, scans: int, build: pathlib.Path, tmp: pathlib.Path) -> dict:
    env = dict(os.environ, LIDET_BUILD_DIR=str(build), OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1",
               PYTHONPATH=str(ROOT / "tools") + os.pathsep + os.environ.get("PYTHONPATH", ""))
    sim, pred = tmp / f"sim_{sensor}", tmp / f"pred_{sensor}"
    subprocess.run([sys.executable, "-m", "lidet_tools.sim.cli", "--sensor", sensor, "--scenes", str(scans),
                    "--seed", str(SEED), "--out", str(sim), "--no-progress"], env=env, check=True,
                   capture_output=True)
    subprocess.run([sys.executable, "-m", "lidet_tools.detect", str(sim), "--sensor", sensor, "--out", str(pred)],
                   env=env, check=True, capture_output=True)
    return _ap(sim / "boxes", pred / "boxes")


def run(args=None) -> str:
    sys.path.insert(0, str(ROOT / "tools"))
    from lidet_tools.sensors import SENSORS, model_family
    build = pathlib.Path(getattr(args, "build", ROOT / "build"))
    scans = 10 if getattr(args, "quick", False) else 40
    rows = []
    with tempfile.TemporaryDirectory() as t:
        res = {s: measure(s, scans, build, pathlib.Path(t)) for s in SENSORS}
    fmt = lambda v: "-" if v is None else f"{v:.1f}"  # noqa: E731
    for s, sen in SENSORS.items():
        fam = "vlp16" if s == "vlp16" else model_family(sen)
        ref = "vlp16" if fam == "vlp16" else "hdl64"
        cells = []
        for k in COLS:
            v, r = res[s][k], res[ref][k]
            d = "" if v is None or r is None or s == ref else f" ({v - r:+.1f})"
            cells.append(fmt(v) + d)
        rows.append(f"| {s} | {sen.rows} x {sen.cols} | {sen.mount_height_m:g} m | {fam} | " + " | ".join(cells) + " |")
    return "\n".join([
        "## Sensor presets (issue 37)", "",
        f"The detector on simulated scans of every preset ({scans} scans each, `lidet-sim --sensor S --seed {SEED}`, "
        "360 degrees, the preset's mount height), with the preset's default model family, against that family on "
        "its own sensor in the same run (hdl64 for 32 beams or more, vlp16): 3D AP R40 by distance band of the box "
        "centre, sensor frame, KITTI overlaps (car 0.7, pedestrian and cyclist 0.5); '-' where a band holds no "
        "object of the class; in brackets the difference from the "
        "family's own sensor (goal: within 5 AP). Command: `python tools/bench/bench_presets.py`.", "",
        "| preset | rows x cols | mount | family | car 0-20 m | car 20-40 m | ped 0-20 m | ped 20-40 m | cyc 0-20 m |",
        "|---|---|---|---|---:|---:|---:|---:|---:|", *rows, ""])


if __name__ == "__main__":
    sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
    from run_bench import standalone
    standalone(run, __doc__)
