# SPDX-License-Identifier: MIT
"""Write the real labelled frames of one side of the split in lidet's sensor-frame layout, for
``python -m lidet_tools.train.finetune`` (docs/TRAINING.md, "Fine-tuning on your own labelled scans").

    python -m lidet_tools.real.export --side train --out data/real_train [--root ../shared/data/real]
                                      [--sources kitti,pandaset] [--split tools/lidet_tools/real/split.txt]

Only the HDL-64-like sources (:data:`SOURCES`: kitti, kitti360, pandaset, semantickitti, squeezeseg; argoverse, two
stacked VLP-32C, is validation only). Each frame (``real.load_frame``: points and boxes already in the sensor frame)
becomes

* ``velodyne/<source>_<id>.bin``: the points, float32 x, y, z, intensity;
* ``boxes/<source>_<id>.txt``: one ``<class> x y z l w h yaw score`` line per box (``kitti.write_boxes``, score 1):
  Car, Pedestrian, Cyclist, and the classes an evaluation ignores (Van, Person_sitting, DontCare, Other);
* an entry of ``meta.json``'s ``frames``: ``sensor``, ``mount_height_m``, ``fov_half_deg`` (labels exist where
  |azimuth| <= it; null: all around), ``classes`` (the classes the source labels: KITTI-360 labels cars only, so
  its unlabelled clusters are not negatives), ``approx_boxes`` (boxes fitted to the points), ``source``, ``frame_id``.

The data stay under the sources' licences (../shared/data/real/README.md): write them outside the repository or to a
git-ignored folder (data/). Exit status 0; 2 for a missing root or an unknown source.
"""
from __future__ import annotations

import argparse
import json
import math
import pathlib
import sys

import numpy as np

from .. import kitti
from . import EVAL_CLASSES, load_frame

#: the sources recorded with an HDL-64-like sensor (the hdl64 family's training data)
SOURCES = ("kitti", "kitti360", "pandaset", "semantickitti", "squeezeseg")


def export(root, frames, out) -> dict:
    """Write frames [(source, frame_id)] of root to out; returns the meta dict written to out/meta.json."""
    from ..eval_real import LABELLED_CLASSES
    out = pathlib.Path(out)
    (out / "velodyne").mkdir(parents=True, exist_ok=True)
    (out / "boxes").mkdir(parents=True, exist_ok=True)
    meta = {"format": "lidet sensor-frame layout: velodyne/<name>.bin, boxes/<name>.txt", "root": str(root),
            "frames": {}}
    for src, fid in frames:
        fr = load_frame(root, src, fid)
        name = f"{src}_{fid}"
        np.ascontiguousarray(fr.points, np.float32).tofile(out / "velodyne" / f"{name}.bin")
        kitti.write_boxes(out / "boxes" / f"{name}.txt", fr.boxes)
        meta["frames"][name] = {
            "source": src, "frame_id": fid, "sensor": fr.sensor, "mount_height_m": float(fr.mount_height_m),
            "fov_half_deg": None if fr.fov_half_rad is None else math.degrees(fr.fov_half_rad),
            "classes": list(LABELLED_CLASSES.get(src, EVAL_CLASSES)), "approx_boxes": bool(fr.approx_boxes),
            "n_points": int(len(fr.points)), "boxes": fr.class_counts()}
    (out / "meta.json").write_text(json.dumps(meta, indent=1, sort_keys=True) + "\n")
    return meta


def main(argv=None) -> int:
    from ..eval_real import add_frame_args, read_split
    ap = argparse.ArgumentParser(prog="python -m lidet_tools.real.export", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    add_frame_args(ap)
    ap.add_argument("--side", choices=("train", "val"), required=True)
    ap.add_argument("--sources", help=f"comma-separated, among {', '.join(SOURCES)} (default: all of them)")
    ap.add_argument("--out", type=pathlib.Path, required=True)
    a = ap.parse_args(argv)
    want = a.sources.split(",") if a.sources else list(SOURCES)
    bad = sorted(set(want) - set(SOURCES))
    if bad:
        print(f"real.export: unknown or non-HDL-64 source(s) {', '.join(bad)}; sources: {', '.join(SOURCES)}",
              file=sys.stderr)
        return 2
    root = pathlib.Path(a.root)
    if not root.is_dir():
        print(f"real.export: {root}: no such folder (the real frames live in ../shared/data/real)", file=sys.stderr)
        return 2
    frames = [(s, f) for s, f, side in read_split(a.split) if side == a.side and s in want]
    if not frames:
        print(f"real.export: no {a.side} frames of {', '.join(want)} in {a.split}", file=sys.stderr)
        return 2
    meta = export(root, frames, a.out)
    n = {}
    for f in meta["frames"].values():
        for c, k in f["boxes"].items():
            n[c] = n.get(c, 0) + k
    print(f"real.export: {len(frames)} {a.side} frames -> {a.out} (boxes: "
          + ", ".join(f"{c} {k}" for c, k in sorted(n.items())) + ")")
    return 0


if __name__ == "__main__":
    sys.exit(main())
