# SPDX-License-Identifier: MIT
"""What the integer detector's range-only pixel costs (issue 18, docs/MEMORY.md): the integer stages on the
stored pixel (x, y, z, range in 4 mm steps) against the same stages on the range-only pixel (x, y, z decoded from
row, column and range: lib/src/internal/lidet_qpix.h, here through its bit-exact mirror qmath.decode_pixels), on
labelled scan folders (velodyne/ + labels/): ground IoU (integer ground stage, every point, SemanticKITTI ground
classes with terrain) and cars within 40 m recovered as one cluster (integer clustering on the labelled ground
mask, as bench_pixel.py and bench_cluster do). The integer projection of the scan in mm, rows by elevation.

Usage: python tools/bench/bench_pixel_q.py SENSOR:DIR [SENSOR:DIR ...]
"""
from __future__ import annotations

import sys

import numpy as np

import bench_pixel  # the table (tools/bench/bench_pixel.py)
from lidet_ref import qmath
from lidet_tools import cluster_eval, native, sensors


def _image(pts, sensor: str, range_only: bool):
    """The integer projection of (N, >=3) float points (m) and its compact image, stored or decoded."""
    s = sensors.get_sensor(sensor)
    pj = native.project_q(native.to_mm(pts), sensor)
    rows, cols = s.rows, s.cols
    rng = pj["range_4mm"].reshape(rows, cols)
    if range_only:
        x, y, z = (a.astype(np.int16) for a in qmath.decode_pixels(rng, pj["row_elev_bam"]))
    else:
        x, y, z = (pj[k].reshape(rows, cols) for k in ("x_4mm", "y_4mm", "z_4mm"))
    return pj, x, y, z, rng


def ground_points(pts, sensor: str, range_only: bool) -> np.ndarray:
    pj, x, y, z, rng = _image(pts, sensor, range_only)
    img = native.CompactImage(x, y, z, rng, pj["point_pixel"], pj["row_elev_bam"], 0)
    mask = native.ground_q(img, sensor).mask.ravel()
    pp = pj["point_pixel"]
    return np.where(pp >= 0, mask[np.maximum(pp, 0)], 0)


def cluster_points(pts, lab, sensor: str, range_only: bool) -> np.ndarray:
    s = sensors.get_sensor(sensor)
    pj, x, y, z, rng = _image(pts, sensor, range_only)
    pp = pj["point_pixel"]
    ground = np.zeros(rng.size, np.uint8)
    g = cluster_eval.ground_mask(lab)
    ground[pp[(pp >= 0) & g]] = 1
    scan = native.CompactScan(s, x, y, z, rng, pj["row_elev_bam"], np.zeros(s.rows, np.float32), pp,
                              ground.reshape(rng.shape), np.zeros((0, 4), np.float32))
    c = native.cluster_q(scan)
    labels = c.labels.ravel()
    return np.where(pp >= 0, labels[np.maximum(pp, 0)], 0)


def run(sensor: str, data: str) -> list[str]:
    return [bench_pixel.table_row(sensor, data, title, lambda p, ro=ro: ground_points(p, sensor, ro),
                                  lambda p, lab, ro=ro: cluster_points(p, lab, sensor, ro))
            for title, ro in (("stored x, y, z, range (8 B)", False), ("range only, x, y, z decoded (2 B)", True))]


def main(argv=None) -> int:
    return bench_pixel.main(argv, run, "integer pixel")


if __name__ == "__main__":
    np.seterr(all="ignore")
    raise SystemExit(main())
