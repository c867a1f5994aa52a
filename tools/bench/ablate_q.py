# SPDX-License-Identifier: MIT
"""Where the integer detector's AP goes (issue 16): the detector's geometry (projection, ground, clustering,
proposals) and its networks swapped one at a time, on the simulated HDL-64 benchmark of tools/bench/bench_detect.py.

    python tools/bench/ablate_q.py [SIM_DIR] [--out DIR] [--scans N]

Four detectors over the same scans, camera crop, both with the proposal refinement (their defaults):
  float geometry + float nets   the float detector (lidet detect --crop)
  float geometry + int8 nets    its candidate proposals rounded to 4 mm steps (lidet_codegen.quant.int_proposals)
  integer geometry + float nets the integer detector's proposals in metres (4 mm steps x 0.004)
  integer geometry + int8 nets  the integer detector (lidet detect --fixed)
The candidates (classified clusters, nearest first) come from each detector's own run
(lidet_tools.native.candidates_float / candidates_q); the networks, gates, size check, score and NMS are
applied here with the rules of the nets' side: the float detector's (float32 energies, box budget, float NMS) for
the float nets, the integer detector's (Q16 energies, Q15 score, lidet_post_q's size check and NMS in C) for the
int8 nets; the two pure combinations reproduce the detectors' outputs with the cars' flat-surface test off (it reads
the cluster's members, which the candidates do not carry; it is off in all four here). Prints AP R40 3D moderate per class and,
per class, the moderate objects each detector finds or loses against the float detector.
"""
from __future__ import annotations

import argparse
import math
import pathlib
import sys

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path[:0] = [str(ROOT / "tools"), str(ROOT / "codegen")]

from lidet_codegen import quant as QU  # noqa: E402
from lidet_ref import detector_q as RD  # noqa: E402
from lidet_tools import kitti, native  # noqa: E402
from lidet_tools.eval import kitti_ap as K  # noqa: E402

CLASSES = native.CLASSES
COMBOS = ("float+float", "float+int8", "int+float", "int+int8")  # geometry + nets
SIZE_MIN_M = np.array(RD.post_q.SIZE_MIN_MM) / 1000.0
SIZE_MAX_M = np.array(RD.post_q.SIZE_MAX_MM) / 1000.0
BAM = 2.0 * math.pi / 2.0 ** 32
#: the score's weight on gate 2's margin per class (car, cyclist, pedestrian): the defaults of
#: lidet_detector_cfg_default (score_box_weight) and lidet_detector_q_cfg_default (score_box_weight_q16 = w 2^16);
#: tests/python/test_ablate_q.py checks that these rules reproduce both detectors
SCORE_BOX_WEIGHT = (0.5, 0.0, 0.0)
SCORE_POINTS_WEIGHT = (0.1, 0.0, 0.0)  # score_points_weight (_q16 = round(v 2^16))
#: the classes gate 2 judges (car, cyclist, pedestrian): gate2_class of both detectors' defaults
GATE2_CLASS = RD.GATE2_CLASS
#: the operating point (car, cyclist, pedestrian): min_score of lidet_detector_cfg_default, and min_score_q15 =
#: round(v 2^15) of lidet_detector_q_cfg_default
MIN_SCORE = (0.6, 0.0, 0.0)


def nets_float(fam, xyz, mean, vox, cid, max_boxes, npts):
    """Float nets on proposals in metres, the float detector's rules: (cls, score, box (m, rad)) kept."""
    m = native.pn_models()[f"cls_{fam}"]
    mb = native.pn_models()[f"box_{fam}"]
    c = native.pn_classify(f"cls_{fam}", xyz, mean, vox)
    b = native.pn_box(f"box_{fam}", xyz, mean, vox, c["cls"])
    dets, n_boxed, ms = [], 0, MIN_SCORE
    for k in range(len(xyz)):
        if not c["passed"][k]:
            continue
        if n_boxed == max_boxes:
            continue
        n_boxed += 1
        if GATE2_CLASS[int(c["cls"][k])] and not b["passed"][k]:
            continue
        cl, bx = int(c["cls"][k]), b["box"][k]
        if not (np.all(bx[3:6] >= SIZE_MIN_M[cl]) and np.all(bx[3:6] <= SIZE_MAX_M[cl])):
            continue
        t = np.float32(c["energy"][k] - m.gamma[cl]) + np.float32(SCORE_BOX_WEIGHT[cl]) * np.float32(
            b["energy"][k] - mb.gamma[cl])
        if SCORE_POINTS_WEIGHT[cl] != 0.0:  # - v ln(n / 64), in float32 as lidet_detector.c
            ln_n = np.float32(np.log(np.float32(max(int(npts[k]), 1)))) - np.float32(4.15888309)
            t = np.float32(t - np.float32(SCORE_POINTS_WEIGHT[cl]) * ln_n)
        s = np.float32(1.0) / (np.float32(1.0) + np.exp(np.float32(t)))
        if s < np.float32(ms[cl]):
            continue
        dets.append((float(s), int(cid[k]), cl, bx.astype(np.float64)))
    dets.sort(key=lambda d: (-d[0], d[1]))
    kept = []
    for d in dets:
        if not any(native.bev_iou_float(d[3][None], k[3][None])[0] > np.float32(0.1) for k in kept):
            kept.append(d)
    return [(d[2], d[0], d[3]) for d in kept]


def nets_int8(fam, q4, m4, vox, cid, npts):
    """int8 nets on 4 mm proposals, the integer detector's rules: (cls, score, box (m, rad)) kept."""
    gam = native.pnq_models()[f"cls_{fam}_s8"]["gamma_q16"]
    gam_b = native.pnq_models()[f"box_{fam}_s8"]["gamma_q16"]
    c = native.pnq_classify(f"cls_{fam}_s8", q4, m4, vox)
    b = native.pnq_box(f"box_{fam}_s8", q4, m4, vox, c["cls"])
    g2 = np.asarray(GATE2_CLASS, bool)[c["cls"]]
    keep = np.flatnonzero(c["passed"] & (b["passed"] | ~g2))
    if len(keep) == 0:
        return []
    cls = c["cls"][keep]
    score = np.array([RD.detection_score_q15(int(c["energy"][k]), int(b["energy"][k]), int(npts[k]),
                                             int(gam[c["cls"][k]]), int(gam_b[c["cls"][k]]),
                                             round(SCORE_BOX_WEIGHT[c["cls"][k]] * 65536),
                                             round(SCORE_POINTS_WEIGHT[c["cls"][k]] * 65536)) for k in keep], np.int32)
    above = score >= np.asarray([round(v * 32768) for v in MIN_SCORE])[cls]  # the operating point
    keep, cls, score = keep[above], cls[above], score[above]
    if len(keep) == 0:
        return []
    boxes = b["box"][keep]
    ok = native.post_q(boxes, score, cid[keep], cls, 3277)
    # post_q returns the kept cluster ids in order (size check applied first)
    by_id = {int(cid[k]): i for i, k in enumerate(keep)}
    out = []
    for ci in ok["kept"]:
        i = by_id[int(ci)]
        bx = boxes[i].astype(np.float64)
        bx[:6] /= 1000.0
        bx[6] = (int(boxes[i][6]) & 0xFFFFFFFF) * BAM
        bx[6] = (bx[6] + math.pi) % (2 * math.pi) - math.pi
        out.append((int(cls[i]), score[i] / 32768.0, bx))
    return out


def run(sim: pathlib.Path, out: pathlib.Path, n_scans: int, fam: str = "hdl64", max_boxes: int = 48):
    scans = sorted((sim / "velodyne").glob("*.bin"))[:n_scans]
    for combo in COMBOS:
        (out / combo / "label_2").mkdir(parents=True, exist_ok=True)
    for p in scans:
        pts = kitti.read_bin(p)
        calib = kitti.read_calib(sim / "calib" / f"{p.stem}.txt")
        cf = native.candidates_float(pts, fam, crop_half_rad=math.pi / 4, refine=True)
        cq = native.candidates_q(native.to_mm(pts), fam, crop_half_bam=1 << 29)
        f_q4, f_m4 = QU.int_proposals(cf["xyz"], cf["mean"]) if len(cf["xyz"]) else (cf["xyz"], cf["mean"])
        res = {
            "float+float": nets_float(fam, cf["xyz"], cf["mean"], cf["voxel"], cf["cluster_id"], max_boxes,
                                      cf["n_points"]),
            "float+int8": nets_int8(fam, f_q4, f_m4, cf["voxel"], cf["cluster_id"], cf["n_points"]),
            "int+float": nets_float(fam, cq["xyz"] * np.float32(0.004), cq["mean"] * np.float32(0.004), cq["voxel"],
                                    cq["cluster_id"], max_boxes, cq["n_points"]),
            "int+int8": nets_int8(fam, cq["xyz"], cq["mean"], cq["voxel"], cq["cluster_id"], cq["n_points"]),
        }
        for combo, dets in res.items():
            objs = [kitti.box_to_kitti(kitti.Box3D(CLASSES[cl], *map(float, bx), float(s)), calib, score=float(s))
                    for cl, s, bx in dets]
            kitti.write_label2(out / combo / "label_2" / f"{p.stem}.txt", objs)


def found(gt, pred_dir, cls):
    """Indices of the moderate `cls` objects of gt matched (3D IoU >= the class's threshold) by a detection."""
    dt = K.load_label_dir(pred_dir, gt.frame_ids, missing_ok=True)
    ov = K.compute_overlaps(gt, dt, ("3d",))
    ig, idt = K.ignore_flags(gt, dt, cls, 1)
    thr = K.MIN_OVERLAP["strict"]["3d"][cls.lower()]
    hit = {int(b) for a, b, o in zip(ov.pair_dt, ov.pair_gt, ov.ov["3d"]) if ig[b] == 0 and idt[a] == 0 and o >= thr}
    return hit, int((ig == 0).sum())


def report(sim: pathlib.Path, out: pathlib.Path, n_scans: int):
    ids = sorted(p.stem for p in (sim / "velodyne").glob("*.bin"))[:n_scans]
    gt = K.load_label_dir(sim / "label_2", ids)
    print(f"{len(ids)} scans of {sim}; AP R40 3D moderate (strict overlaps)")
    print("| geometry + nets | " + " | ".join(CLASSES) + " |")
    print("|---|" + "---:|" * len(CLASSES))
    for combo in COMBOS:
        r = K.evaluate(gt, K.load_label_dir(out / combo / "label_2", ids, missing_ok=True), metrics=("3d",))
        print(f"| {combo} | " + " | ".join(f"{r['ap'][c]['3d']['R40']['moderate']:.2f}" for c in CLASSES) + " |")
    for cls in CLASSES:
        base, n = found(gt, out / "float+float" / "label_2", cls)
        line = [f"{cls}: {n} moderate objects, float detector finds {len(base)}"]
        for combo in COMBOS[1:]:
            h, _ = found(gt, out / combo / "label_2", cls)
            lost = sorted(f"{gt.frame_ids[gt.frame[g]]}#{g}" for g in base - h)
            gained = sorted(f"{gt.frame_ids[gt.frame[g]]}#{g}" for g in h - base)
            line.append(f"  {combo}: finds {len(h)}, loses {lost}, gains {gained}")
        print("\n".join(line))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("sim", nargs="?", default=str(ROOT / "data" / "bench" / "sim_hdl64_s7000"),
                    help="simulated HDL-64 KITTI folder (tools/bench/bench_detect.py makes it: lidet-sim seed 7000)")
    ap.add_argument("--out", default=str(ROOT / "data" / "bench" / "ablate_q"))
    ap.add_argument("--scans", type=int, default=200)
    ap.add_argument("--report-only", action="store_true", help="evaluate the folders of an earlier run")
    a = ap.parse_args(argv)
    sim, out = pathlib.Path(a.sim), pathlib.Path(a.out)
    if not a.report_only:
        run(sim, out, a.scans)
    report(sim, out, a.scans)
    return 0


if __name__ == "__main__":
    sys.exit(main())
