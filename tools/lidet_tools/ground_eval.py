# SPDX-License-Identifier: MIT
"""Ground segmentation evaluation against SemanticKITTI labels.

Metrics per scan and overall (summed confusion counts over every input point, in input order):
precision, recall, accuracy, IoU and F1 of the "ground" class. Two ground definitions:

* ``with_terrain``: ground = {40 road, 44 parking, 48 sidewalk, 49 other-ground, 60 lane-marking,
  72 terrain} (Seppänen's benchmark, Ground-Segmentation-Benchmark);
* ``no_terrain``: the same with terrain 72 counted as non-ground.

Every point counts, including unlabeled (0) and outliers (1), which are non-ground; points the
projection drops (too close, out of the field of view) are predicted non-ground.

Usage::

    python -m lidet_tools.ground_eval --sensor hdl64 DATA_DIR_OR_SCANS... [--json] [--set key=value ...]

DATA_DIR: a folder holding ``velodyne/*.bin`` and ``labels/*.label`` (SemanticKITTI layout, as the
simulator writes it); or .bin files whose label sits at ``../labels/<stem>.label``. Scans without a
label are skipped (and listed). Exits 0 with a message when nothing is found (data absent).
"""
from __future__ import annotations

import argparse
import json
import pathlib
import sys
import time

import numpy as np

from . import kitti

DEFINITIONS = {"with_terrain": kitti.GROUND_IDS, "no_terrain": kitti.GROUND_IDS_NO_TERRAIN}


def confusion(pred: np.ndarray, truth: np.ndarray) -> np.ndarray:
    """(tp, fp, fn, tn) of boolean arrays of equal length."""
    pred = np.asarray(pred).astype(bool)
    truth = np.asarray(truth).astype(bool)
    if pred.shape != truth.shape:
        raise ValueError(f"prediction {pred.shape} and labels {truth.shape} differ in length")
    tp = int(np.count_nonzero(pred & truth))
    fp = int(np.count_nonzero(pred & ~truth))
    fn = int(np.count_nonzero(~pred & truth))
    return np.array([tp, fp, fn, pred.size - tp - fp - fn], np.int64)


def metrics(c) -> dict:
    """precision, recall, accuracy, IoU, F1 from (tp, fp, fn, tn); 0 where undefined."""
    tp, fp, fn, tn = (int(v) for v in c)

    def div(a, b):
        return a / b if b else 0.0
    p, r = div(tp, tp + fp), div(tp, tp + fn)
    return {"precision": p, "recall": r, "accuracy": div(tp + tn, tp + fp + fn + tn),
            "iou": div(tp, tp + fp + fn), "f1": div(2 * p * r, p + r), "tp": tp, "fp": fp, "fn": fn, "tn": tn}


def ground_truth(semantic: np.ndarray, definition: str = "with_terrain") -> np.ndarray:
    """Boolean ground mask of SemanticKITTI semantic ids (lower 16 bits)."""
    return np.isin(np.asarray(semantic) & 0xFFFF, DEFINITIONS[definition])


def find_scans(paths) -> tuple[list[tuple[pathlib.Path, pathlib.Path]], list[pathlib.Path]]:
    """(bin, label) pairs from folders and files, sorted; plus the .bin files that have no label."""
    pairs, unlabeled = [], []
    bins = []
    for p in map(pathlib.Path, paths):
        if p.is_dir():
            d = p / "velodyne" if (p / "velodyne").is_dir() else p
            bins += sorted(d.glob("*.bin"))
        elif p.suffix == ".bin" and p.exists():
            bins.append(p)
    for b in bins:
        lab = b.parent.parent / "labels" / (b.stem + ".label")
        (pairs.append((b, lab)) if lab.exists() else unlabeled.append(b))
    return pairs, unlabeled


def evaluate_scans(pairs, predict, definitions=tuple(DEFINITIONS)) -> dict:
    """Runs predict(points) -> per-point bool/uint8 mask on every scan; returns
    {"scans": [{name, n_points, ms, <definition>: metrics}], "overall": {<definition>: metrics},
    "median_ms": ...}. `ms` is the wall time of predict (whatever it includes)."""
    total = {d: np.zeros(4, np.int64) for d in definitions}
    scans, times = [], []
    for b, lab in pairs:
        pts = kitti.read_bin(b)
        sem, _ = kitti.read_label(lab, len(pts))
        t0 = time.perf_counter()
        pred = np.asarray(predict(pts)).astype(bool)
        ms = (time.perf_counter() - t0) * 1e3
        times.append(ms)
        row = {"name": b.stem, "n_points": int(len(pts)), "ms": ms}
        for d in definitions:
            c = confusion(pred, ground_truth(sem, d))
            total[d] += c
            row[d] = metrics(c)
        scans.append(row)
    return {"scans": scans, "overall": {d: metrics(total[d]) for d in definitions},
            "median_ms": float(np.median(times)) if times else 0.0}


def lidet_predictor(sensor: str = "hdl64", **cfg):
    """predict(points) with the C library through the bindings (projection + ground)."""
    from . import native

    def predict(pts):
        return native.ground(pts, sensor, **cfg).mask_point
    return predict


def format_table(res: dict, title: str = "") -> str:
    """Markdown table: one row per scan and the overall row, both definitions."""
    lines = []
    if title:
        lines.append(f"**{title}**\n")
    lines.append("| scan | points | P | R | Acc | IoU | P (no terrain) | R (no terrain) | IoU (no terrain) |")
    lines.append("|---|---:|---:|---:|---:|---:|---:|---:|---:|")

    def row(name, n, m):
        a, b = m["with_terrain"], m["no_terrain"]
        return (f"| {name} | {n} | {a['precision']:.3f} | {a['recall']:.3f} | {a['accuracy']:.3f} | "
                f"{a['iou']:.3f} | {b['precision']:.3f} | {b['recall']:.3f} | {b['iou']:.3f} |")
    for s in res["scans"]:
        lines.append(row(s["name"], s["n_points"], s))
    lines.append(row("**overall**", sum(s["n_points"] for s in res["scans"]), res["overall"]))
    return "\n".join(lines)


def _parse_value(v: str):
    try:
        return int(v)
    except ValueError:
        return float(v)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m lidet_tools.ground_eval", description=__doc__.split("\n\n")[0])
    ap.add_argument("paths", nargs="+", help="folders (velodyne/ + labels/) or .bin files")
    ap.add_argument("--sensor", default="hdl64")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    help="override a lidet_ground_cfg_t field (repeatable)")
    ap.add_argument("--json", action="store_true", help="print the result as JSON")
    a = ap.parse_args(argv)
    cfg = {}
    for kv in a.set:
        k, _, v = kv.partition("=")
        cfg[k] = _parse_value(v)
    pairs, unlabeled = find_scans(a.paths)
    if unlabeled:
        print(f"ground_eval: {len(unlabeled)} scan(s) without labels skipped", file=sys.stderr)
    if not pairs:
        print("ground_eval: no labeled scans found (data absent?): nothing to evaluate", file=sys.stderr)
        return 0
    res = evaluate_scans(pairs, lidet_predictor(a.sensor, **cfg))
    if a.json:
        print(json.dumps(res, indent=1))
    else:
        print(format_table(res, f"lidet ground, sensor {a.sensor}, {len(pairs)} scans"))
        print(f"\nmedian wall time per scan (bindings, projection + ground + copies): {res['median_ms']:.2f} ms")
    return 0


if __name__ == "__main__":
    sys.exit(main())
