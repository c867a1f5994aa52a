# SPDX-License-Identifier: MIT
"""What a more compact pixel than float x, y, z, range would cost in accuracy (issue 18, docs/journal/memory.md, "What
a compact pixel would cost").

For each pixel model of the bindings (native.ScanContext: the image rewritten after the projection as a
pixel stored that way would decode, the stages unchanged), on labelled scan folders (velodyne/ +
labels/): ground IoU (ground stage, every point, SemanticKITTI ground classes with terrain) and cars
within 40 m recovered as one cluster (clustering on the label ground mask, as bench_cluster does).

Usage: python tools/bench/bench_pixel.py SENSOR:DIR [SENSOR:DIR ...]
"""
from __future__ import annotations

import sys

import numpy as np

from lidet_tools import cluster_eval, ground_eval, native

MODELS = [("float (stored today, 16 B)", "float", 0.0), ("s16: x, y, z, range in 2 mm (8 B)", "s16", 0.002),
          ("s16: x, y, z, range in 4 mm (8 B)", "s16", 0.004),
          ("recompute: range + beam elevation + column centre (4 B)", "recompute", 0.0),
          ("range + real elevation, column centre azimuth", "real_elev", 0.0),
          ("range + real azimuth, beam elevation", "real_azimuth", 0.0)]


def table_row(sensor: str, data: str, title: str, ground_points, cluster_points) -> str:
    """One table row: ground IoU of ground_points(points) (a per-point mask) on the folder's labelled scans, and
    cars within 40 m recovered by cluster_points(points, labels) (a per-point cluster id)."""
    pairs, _ = ground_eval.find_scans([data])
    g = ground_eval.evaluate_scans(pairs, ground_points, ("with_terrain",))["overall"]["with_terrain"]
    res = []
    for name, pts, lab in cluster_eval.scans(data):
        res += cluster_eval.evaluate_scan(cluster_points(pts, lab), lab, pts, scan=name)
    car = cluster_eval.summarize(res)["car"]["0-40"]
    return (f"| {sensor} | {title} | {100 * g['iou']:.2f} | {100 * car['recovered']:.1f} ({car['n']}) | "
            f"{100 * car['over']:.1f} | {100 * car['under']:.1f} |")


def run(sensor: str, data: str) -> list[str]:
    rows = []
    for title, model, q in MODELS:
        ctx = native.ScanContext(model, q)
        rows.append(table_row(
            sensor, data, title, lambda pts, ctx=ctx: native.ground(pts, sensor, context=ctx).mask_point,
            lambda pts, lab, ctx=ctx: native.cluster(pts, sensor, ground=cluster_eval.ground_mask(lab),
                                                     context=ctx).point_labels))
    return rows


def main(argv=None, run=run, what: str = "pixel") -> int:
    argv = sys.argv[1:] if argv is None else argv
    print(f"| data | {what} | ground IoU % | cars < 40 m recovered % (n) | over-seg % | under-seg % |")
    print("|---|---|---:|---:|---:|---:|")
    for arg in argv:
        sensor, _, d = arg.partition(":")
        for r in run(sensor, d):
            print(r, flush=True)
    return 0


if __name__ == "__main__":
    np.seterr(all="ignore")
    raise SystemExit(main())
