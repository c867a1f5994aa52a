# SPDX-License-Identifier: MIT
"""``lidet-viz``: pictures of scans, boxes, precision-recall curves and energies.

    lidet-viz bev SCAN.bin [--labels FILE.label] [--point-labels FILE] [--ground FILE]
                  [--color-by auto|height|ground|cluster|semantic] [--gt BOXES_OR_LABEL2]
                  [--pred BOXES_OR_LABEL2] [--calib CALIB] [--min-score S]
                  [--xlim A,B] [--ylim A,B] [--range M] [--title T] --out PNG
    lidet-viz pr --gt DIR --pred DIR [--protocol kitti|boxes] [--metric 3d|bev|2d] [--overlap SET]
                 [--classes Car,Pedestrian,Cyclist] --out PNG
    lidet-viz energy --id FILE --ood FILE [--threshold GAMMA] --out PNG
    lidet-viz demo [--kind bev|pr] --out PNG

Box files: lidet sensor-frame box lines (9 fields) or KITTI label_2 (15/16 fields, needs --calib;
DontCare skipped), told apart by their field count. --point-labels: one uint8 or uint32 per point
(by file size), e.g. a ground mask or cluster ids; --labels: SemanticKITTI .label (colour by class).
"""
from __future__ import annotations

import argparse
import os
import sys

import numpy as np

from .. import kitti


def _pair(s):
    a, b = (float(v) for v in s.split(","))
    return (a, b)


def read_any_boxes(path, calib_path=None) -> list:
    """lidet box lines or label_2 (converted to the sensor frame with the calib) -> list of Box3D."""
    with open(path) as f:
        first = next((ln.split("#", 1)[0].split() for ln in f if ln.split("#", 1)[0].strip()), [])
    if not first:
        return []
    if len(first) == 9:
        return kitti.read_boxes(path)
    if len(first) in (15, 16):
        if not calib_path:
            raise ValueError(f"{path} is a KITTI label_2 file: --calib is needed to place its boxes")
        calib = kitti.read_calib(calib_path)
        return [kitti.kitti_to_box(o, calib) for o in kitti.read_label2(path)
                if o.type.lower() != "dontcare"]
    raise ValueError(f"{path}: neither lidet box lines (9 fields) nor label_2 (15/16 fields)")


def read_point_labels(path, n_points, dtype="auto"):
    size = os.path.getsize(path)
    if dtype == "auto":
        if size == n_points:
            dtype = "uint8"
        elif size == 4 * n_points:
            dtype = "uint32"
        else:
            raise ValueError(f"{path}: {size} B is neither 1 nor 4 bytes for each of {n_points} points")
    lab = np.fromfile(path, dtype="<u1" if dtype == "uint8" else "<u4")
    if len(lab) != n_points:
        raise ValueError(f"{path}: {len(lab)} labels for {n_points} points")
    return lab


def build_parser():
    p = argparse.ArgumentParser(prog="lidet-viz", description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter, epilog=__doc__)
    sub = p.add_subparsers(dest="cmd", required=True)
    b = sub.add_parser("bev", help="bird's-eye view PNG of a scan with boxes")
    b.add_argument("scan", help="KITTI velodyne .bin (float32 x, y, z, intensity)")
    b.add_argument("--labels", help="SemanticKITTI .label (uint32 per point): colour by class")
    b.add_argument("--point-labels", help="uint8 or uint32 per point: ground mask or cluster ids")
    b.add_argument("--point-dtype", choices=("auto", "uint8", "uint32"), default="auto")
    b.add_argument("--ground", help="uint8 ground mask per point, drawn over cluster colours")
    b.add_argument("--color-by", default="auto",
                   choices=("auto", "height", "ground", "cluster", "semantic"))
    b.add_argument("--gt", help="ground-truth boxes: lidet box lines or label_2 (with --calib)")
    b.add_argument("--pred", help="predicted boxes: lidet box lines or label_2 (with --calib)")
    b.add_argument("--calib", help="KITTI calib file for label_2 boxes")
    b.add_argument("--min-score", type=float, help="hide predictions scoring below this")
    b.add_argument("--xlim", type=_pair, help="view along x in metres, e.g. 0,70")
    b.add_argument("--ylim", type=_pair, help="view along y in metres, e.g. -35,35")
    b.add_argument("--range", type=float, default=50.0, help="half-width of the default view (m)")
    b.add_argument("--ring-step", type=float, default=10.0, help="range ring spacing (m)")
    b.add_argument("--title")
    b.add_argument("--out", required=True, help="PNG to write")
    r = sub.add_parser("pr", help="precision-recall curves per class and difficulty / band")
    r.add_argument("--gt", required=True)
    r.add_argument("--pred", required=True)
    r.add_argument("--protocol", choices=("kitti", "boxes"), default="kitti")
    r.add_argument("--metric", choices=("3d", "bev", "2d"), default="3d")
    r.add_argument("--overlap", help="IoU set: strict|loose (kitti), kitti|0.25 (boxes)")
    r.add_argument("--classes", default="Car,Pedestrian,Cyclist")
    r.add_argument("--out", required=True)
    e = sub.add_parser("energy", help="histogram of ID and OOD energies with the gate threshold")
    e.add_argument("--id", required=True, help="ID energies: .npy or text, one value per line")
    e.add_argument("--ood", required=True, help="OOD energies: .npy or text")
    e.add_argument("--threshold", type=float, help="gate gamma (default: 95 %% TPR on ID)")
    e.add_argument("--title")
    e.add_argument("--out", required=True)
    d = sub.add_parser("demo", help="pictures of synthetic data for the docs (docs/img)")
    d.add_argument("--kind", choices=("bev", "pr"), default="bev",
                   help="bev: a synthetic street scene; pr: curves of 1000 synthetic KITTI-like frames")
    d.add_argument("--out", required=True)
    return p


def _load_values(path):
    return np.load(path).ravel() if path.endswith(".npy") else np.loadtxt(path, ndmin=1)


def main(argv=None) -> int:
    os.environ.setdefault("MPLBACKEND", "Agg")
    args = build_parser().parse_args(argv)
    import matplotlib.pyplot as plt

    try:
        d = os.path.dirname(os.path.abspath(args.out))
        os.makedirs(d, exist_ok=True)
        if args.cmd == "bev":
            from .bev import plot_bev

            pts = kitti.read_bin(args.scan)
            labels, color_by = None, args.color_by
            if args.labels:
                labels = read_point_labels(args.labels, len(pts), "uint32")
                color_by = "semantic" if color_by == "auto" else color_by
            elif args.point_labels:
                labels = read_point_labels(args.point_labels, len(pts), args.point_dtype)
            ground = read_point_labels(args.ground, len(pts), "uint8") if args.ground else None
            gt = read_any_boxes(args.gt, args.calib) if args.gt else None
            pred = read_any_boxes(args.pred, args.calib) if args.pred else None
            fig = plot_bev(pts, labels, gt, pred, color_by=color_by, ground=ground, xlim=args.xlim,
                           ylim=args.ylim, view_m=args.range, ring_step_m=args.ring_step,
                           min_score=args.min_score,
                           title=args.title or f"{os.path.basename(args.scan)}: {len(pts)} points")
        elif args.cmd == "pr":
            from ..eval import boxes_ap, kitti_ap
            from .curves import plot_pr

            classes = [c for c in args.classes.split(",") if c]
            if args.protocol == "kitti":
                res = kitti_ap.evaluate_dirs(args.gt, args.pred, classes=classes,
                                             overlap=args.overlap or "strict")
            else:
                if args.metric == "2d":
                    raise ValueError("the sensor-frame protocol has no 2D metric")
                res = boxes_ap.evaluate_dirs(args.gt, args.pred, classes=classes,
                                             overlap=args.overlap or "kitti")
            fig = plot_pr(res, args.metric, classes)
        elif args.cmd == "energy":
            from .curves import plot_energy_hist

            fig = plot_energy_hist(_load_values(args.id), _load_values(args.ood), args.threshold,
                                   title=args.title)
        elif args.kind == "pr":
            import tempfile

            from ..eval import kitti_ap, synth
            from .curves import plot_pr

            gt, pred = synth.synth_kitti(1000, seed=0)
            with tempfile.TemporaryDirectory() as tmp:
                synth.write_frames(os.path.join(tmp, "gt"), gt)
                synth.write_frames(os.path.join(tmp, "pred"), pred)
                res = kitti_ap.evaluate_dirs(os.path.join(tmp, "gt"), os.path.join(tmp, "pred"))
            fig = plot_pr(res, "3d")
        else:
            from .bev import plot_bev
            from .demo import demo_scene

            pts, clusters, ground, gt, pred = demo_scene()
            fig = plot_bev(pts, clusters, gt, pred, color_by="cluster", ground=ground,
                           xlim=(-20, 45), ylim=(-15, 15), ring_step_m=10.0,
                           title="Synthetic scene (32 beams): ground, clusters, ground truth and predictions",
                           figsize=(10, 5.6))
        fig.savefig(args.out)
        plt.close(fig)
    except (OSError, ValueError) as e:
        print(f"lidet-viz: error: {e}", file=sys.stderr)
        return 2
    print(args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
