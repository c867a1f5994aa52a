# SPDX-License-Identifier: MIT
"""``lidet-eval``: KITTI and sensor-frame evaluation of 3D detections.

    lidet-eval kitti --gt GT_LABEL_DIR --pred PRED_LABEL_DIR [--classes Car,Pedestrian,Cyclist]
                     [--overlap strict|loose] [--flavour kitti|openpcdet] [--frames IDS.txt] [--json]
    lidet-eval boxes --gt GT_BOX_DIR --pred PRED_BOX_DIR [--classes ...] [--overlap kitti|0.25|loose] [--json]
    lidet-eval track --gt SEQ_DIR [SEQ_DIR ...] --pred PRED_DIR [--range 40] [--min-points 10] [--json]

``--json`` prints ``{class: {"3d"|"bev"|"2d": {"R11"|"R40": {"easy", "moderate", "hard"}}}}`` (kitti) or
the same with the distance bands "0-20", "20-40", "40+", "all" as keys (boxes); AP in percent, null
where a class has no valid ground truth. Without ``--json`` a table is printed. ``track`` (lidet_tools.track.eval):
MOTA, MOTP, IDF1, id switches, fragmentations, mostly tracked / lost (py-motmetrics) and velocity errors, per class
and overall, of tracks matched to the sequences' ground truth by BEV centre distance.
"""
from __future__ import annotations

import argparse
import json
import sys
import time

from . import boxes_ap, kitti_ap


def _round(ap, nd=4):
    return {c: {m: {r: {k: (None if v is None else round(v, nd)) for k, v in d.items()}
                    for r, d in per.items()} for m, per in pm.items()} for c, pm in ap.items()}


def _classes(s):
    return [c.strip() for c in s.split(",") if c.strip()]


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="lidet-eval", description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="cmd", required=True)
    k = sub.add_parser("kitti", help="KITTI label_2 evaluation (2D/BEV/3D AP, easy/moderate/hard)")
    k.add_argument("--gt", required=True, help="folder of ground-truth label_2 files (<id>.txt)")
    k.add_argument("--pred", required=True, help="folder of predicted label_2 files with scores")
    k.add_argument("--classes", default="Car,Pedestrian,Cyclist", type=_classes)
    k.add_argument("--metrics", default="3d,bev,2d", type=_classes, help="subset of 3d,bev,2d")
    k.add_argument("--overlap", choices=sorted(kitti_ap.MIN_OVERLAP), default="strict",
                   help="strict: Car 0.7, Ped/Cyc 0.5; loose: BEV/3D Car 0.5, Ped/Cyc 0.25")
    k.add_argument("--flavour", choices=("kitti", "openpcdet"), default="kitti",
                   help="height rounding of the C++ devkit (default) or of OpenPCDet's eval.py")
    k.add_argument("--dontcare-all-metrics", action="store_true",
                   help="also apply DontCare suppression to BEV and 3D (not the devkit)")
    k.add_argument("--frames", help="text file of frame ids to evaluate (e.g. KITTI val.txt)")
    k.add_argument("--json", action="store_true", help="print the AP dictionary as JSON")
    b = sub.add_parser("boxes", help="sensor-frame box lines, distance bands instead of difficulty")
    b.add_argument("--gt", required=True, help="folder of ground-truth box files")
    b.add_argument("--pred", required=True, help="folder of predicted box files (same stems)")
    b.add_argument("--classes", default="Car,Pedestrian,Cyclist", type=_classes)
    b.add_argument("--metrics", default="3d,bev", type=_classes, help="subset of 3d,bev")
    b.add_argument("--overlap", choices=sorted(boxes_ap.MIN_OVERLAP), default="kitti",
                   help="kitti: Car 0.7, Ped/Cyc 0.5; 0.25: every class 0.25")
    b.add_argument("--json", action="store_true", help="print the AP dictionary as JSON")
    t = sub.add_parser("track", help="tracking: CLEAR MOT / IDF1 (py-motmetrics) and velocity errors of sequences")
    t.add_argument("--gt", required=True, nargs="+", help="sequence folders (lidet-sim --sequence: tracks/, ...)")
    t.add_argument("--pred", required=True,
                   help="prediction folder: PRED/<seq>/tracks/<frame>.txt (or PRED/tracks/ for one sequence)")
    t.add_argument("--classes", default="Car,Pedestrian,Cyclist", type=_classes)
    t.add_argument("--range", type=float, default=40.0, help="ground truth farther than this (m, BEV) is ignored")
    t.add_argument("--min-points", type=int, default=10, help="ground truth with fewer points is ignored")
    t.add_argument("--match", default="", metavar="CLS=M,...",
                   help="centre-distance thresholds (default Car=2,Pedestrian=1,Cyclist=1.5)")
    t.add_argument("--json", action="store_true", help="print the results as JSON")
    return p


def main(argv=None) -> int:
    args = build_parser().parse_args(argv)
    t0 = time.perf_counter()
    try:
        if args.cmd == "track":
            from ..track import eval as tev
            match = {}
            for kv in _classes(args.match):
                k, _, v = kv.partition("=")
                match[k.strip()] = float(v)
            res = tev.evaluate_dirs(args.gt, args.pred, classes=tuple(args.classes), match_dist=match,
                                    max_range_m=args.range, min_points=args.min_points)
            if args.json:
                print(tev.to_json(res))
            else:
                print(tev.format_table(res, f"Tracking evaluation: {len(args.gt)} sequences, range {args.range:g} m, "
                                            f">= {args.min_points} points, BEV centre distance"))
                print(f"({time.perf_counter() - t0:.2f} s)")
            return 0
        if args.cmd == "kitti":
            bad = set(args.metrics) - set(kitti_ap.METRICS)
            if bad:
                raise ValueError(f"unknown metrics {sorted(bad)}")
            ids = None
            if args.frames:
                with open(args.frames) as f:
                    ids = [ln.strip() for ln in f if ln.strip()]
            res = kitti_ap.evaluate_dirs(args.gt, args.pred, frame_ids=ids, classes=args.classes,
                                         metrics=tuple(args.metrics), overlap=args.overlap,
                                         flavour=args.flavour,
                                         dontcare_all_metrics=args.dontcare_all_metrics)
            title = (f"KITTI evaluation: {res['n_frames']} frames, IoU set '{args.overlap}', "
                     f"flavour '{args.flavour}'")
        else:
            bad = set(args.metrics) - set(boxes_ap.METRICS)
            if bad:
                raise ValueError(f"unknown metrics {sorted(bad)}")
            res = boxes_ap.evaluate_dirs(args.gt, args.pred, classes=args.classes,
                                         metrics=tuple(args.metrics), overlap=args.overlap)
            title = (f"Sensor-frame evaluation: {res['n_frames']} frames, IoU set '{args.overlap}', "
                     f"bands by range of the box centre (m)")
    except (OSError, ValueError) as e:
        print(f"lidet-eval: error: {e}", file=sys.stderr)
        return 2
    if args.json:
        print(json.dumps(_round(res["ap"]), indent=1))
    else:
        print(kitti_ap.format_table(res, title))
        print(f"({time.perf_counter() - t0:.2f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
