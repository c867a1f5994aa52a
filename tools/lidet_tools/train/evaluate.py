# SPDX-License-Identifier: MIT
"""Figures of trained checkpoints on one split of a proposal dataset (the test split for the docs).

    python -m lidet_tools.train.evaluate --data data/train/hdl64.npz --cls data/train/hdl64_cls.pt \
        --box data/train/hdl64_box.pt --split test --json data/train/hdl64_test.json --energies data/train/hdl64_energy

Classifier: ID accuracy per class (argmax over Car, Cyclist, Pedestrian of the ID proposals), gate 1
AUROC (ID positive, score -E) and FPR at 95 % TPR (threshold from this split's ID energies: the
standard FPR95), plus the TPR and FPR of the shipped per-class gamma (from validation; class = the
predicted class). Box net (ID proposals with a box target, true-class one-hot): mean 3D IoU per class
(rotated IoU of eval/iou.py), the share at IoU >= 0.7 (car) / 0.5 (cyclist, pedestrian), heading
error; gate 2 the same two figures, OOD with a random class one-hot (fixed generator).
--energies writes id/ood energies as .npy for `lidet-viz energy`.
"""
from __future__ import annotations

import argparse
import json
import pathlib
import sys

import numpy as np

from . import dataset as D
from . import metrics as MX
from . import models as M


def evaluate(data: dict, split: int, cls_ck=None, box_ck=None, energies_dir=None, cls_model=None, box_model=None) -> dict:
    """cls_ck/box_ck: checkpoint paths (or give loaded models with their gamma via *_model=(model, gamma))."""
    from .export import load_checkpoint
    from . import common as C
    d = C.split(data, split)
    out = dict(n=int(len(d["label"])), n_scans=int(len(np.unique(d["scan"]))) if len(d["label"]) else 0)
    if cls_ck is not None or cls_model is not None:
        if cls_model is None:
            m, ck = load_checkpoint(cls_ck)
            gamma = ck["meta"]["gamma"]
        else:
            m, gamma = cls_model
        lg = MX.cls_logits(m, d)
        out["cls"] = MX.cls_figures(lg, d["label"], gamma)
        out["cls"]["gamma"] = list(map(float, gamma))
        if energies_dir is not None:
            p = pathlib.Path(energies_dir)
            p.mkdir(parents=True, exist_ok=True)
            e = MX.energy_np(lg)
            np.save(p / "cls_id.npy", e[d["label"] >= 0])
            np.save(p / "cls_ood.npy", e[d["label"] < 0])
    if box_ck is not None or box_model is not None:
        if box_model is None:
            m, ck = load_checkpoint(box_ck)
            gamma = ck["meta"]["gamma"]
        else:
            m, gamma = box_model
        if ((d["label"] >= 0) & ~np.isnan(d["box"][:, 0])).any():
            r = MX.eval_box(m, d, gamma=gamma)
            en = r.pop("energies")
            r["gamma"] = list(map(float, gamma))
            out["boxnet"] = r
            if energies_dir is not None:
                p = pathlib.Path(energies_dir)
                np.save(p / "box_id.npy", en["id"])
                np.save(p / "box_ood.npy", en["ood"])
    return out


def markdown(res: dict, title: str = "") -> str:
    f = MX.fmt
    L = []
    if title:
        L.append(f"**{title}** ({res['n']} proposals, {res['n_scans']} scans)\n")
    if "cls" in res:
        c = res["cls"]
        L.append("| classifier | " + " | ".join(M.CLASSES) + " | all ID |")
        L.append("|---|" + "---:|" * (len(M.CLASSES) + 1))
        L.append("| proposals | " + " | ".join(str(c["acc"][k]["n"]) for k in M.CLASSES) +
                 f" | {sum(c['acc'][k]['n'] for k in M.CLASSES)} |")
        L.append("| ID accuracy | " + " | ".join(f(c["acc"][k]["acc"], True) for k in M.CLASSES) +
                 f" | {f(c['acc_all'], True)} |")
        g = c["gate1"]
        L.append("")
        L.append("| gate | ID | OOD | AUROC | FPR at 95 % TPR | shipped gamma: TPR | shipped gamma: FPR |")
        L.append("|---|---:|---:|---:|---:|---:|---:|")
        L.append(f"| gate 1 (classifier energy) | {g['n_id']} | {g['n_ood']} | {f(g['auroc'], nd=3)} | "
                 f"{f(g['fpr95'], True)} | {f(g.get('tpr_gamma'), True)} | {f(g.get('fpr_gamma'), True)} |")
    if "boxnet" in res:
        g = res["boxnet"]["gate2"]
        if "cls" not in res:
            L.append("| gate | ID | OOD | AUROC | FPR at 95 % TPR | shipped gamma: TPR | shipped gamma: FPR |")
            L.append("|---|---:|---:|---:|---:|---:|---:|")
        L.append(f"| gate 2 (box-net energy) | {g['n_id']} | {g['n_ood']} | {f(g['auroc'], nd=3)} | "
                 f"{f(g['fpr95'], True)} | {f(g.get('tpr_gamma'), True)} | {f(g.get('fpr_gamma'), True)} |")
        L.append("")
        L.append("| box net | objects | mean 3D IoU | IoU >= thr | share | heading error median / mean | within 30 deg | centre error median |")
        L.append("|---|---:|---:|---:|---:|---:|---:|---:|")
        for k in M.CLASSES:
            b = res["boxnet"]["box"][k]
            if not b.get("n"):
                L.append(f"| {k} | 0 | - | - | - | - | - | - |")
                continue
            L.append(f"| {k} | {b['n']} | {b['iou_mean']:.3f} | {b['iou_thr']} | {f(b['share_iou'], True)} | "
                     f"{b['heading_err_median_deg']:.1f} / {b['heading_err_mean_deg']:.1f} deg | "
                     f"{f(b['heading_within_30deg'], True)} | {b['centre_err_median_m']:.3f} m |")
    return "\n".join(L) + "\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m lidet_tools.train.evaluate", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--data", type=pathlib.Path, required=True)
    ap.add_argument("--cls", type=pathlib.Path)
    ap.add_argument("--box", type=pathlib.Path)
    ap.add_argument("--split", choices=D.SPLITS, default="test")
    ap.add_argument("--json", type=pathlib.Path)
    ap.add_argument("--energies", type=pathlib.Path, help="folder for cls_id/cls_ood/box_id/box_ood .npy")
    ap.add_argument("--title", default="")
    a = ap.parse_args(argv)
    if a.cls is None and a.box is None:
        ap.error("give --cls and/or --box")
    try:
        data = D.load(a.data)
        res = evaluate(data, D.SPLITS.index(a.split), a.cls, a.box, a.energies)
    except (FileNotFoundError, ValueError) as e:
        print(f"evaluate: {e}", file=sys.stderr)
        return 2
    if res["n"] == 0:
        print(f"evaluate: no proposals in the {a.split} split of {a.data}", file=sys.stderr)
        return 1
    print(markdown(res, a.title))
    if a.json:
        a.json.parent.mkdir(parents=True, exist_ok=True)
        a.json.write_text(json.dumps(res, indent=1, default=float))
    return 0


if __name__ == "__main__":
    sys.exit(main())
