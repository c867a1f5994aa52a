# SPDX-License-Identifier: MIT
"""Ablation on the test split, like the paper's table: PVLE on/off, energy fine-tuning on/off, T-Net on/off.

    python -m lidet_tools.train.ablation --family hdl64 [--work data/train]

Needs `make weights` first (its dataset, checkpoints and state folders). "no energy fine-tuning" is the
model the energy phase started from (the best plain model of phase 1, kept in the state file), so it
costs nothing; "no PVLE" and "no T-Net" are trained again with the family's settings and the flag
(their own resumable state folders). Every variant is scored on the same test split.
"""
from __future__ import annotations

import argparse
import json
import pathlib
import sys

import numpy as np
import torch

from . import dataset as D
from . import evaluate as EV
from . import metrics as MX
from . import models as M
from .weights import FAMILIES


def _val_gamma_cls(m, data):
    from . import common as C
    va = C.split(data, 1)
    lg = MX.cls_logits(m, va)
    idm = va["label"] >= 0
    return C.per_class_gamma(MX.energy_np(lg)[idm], lg.argmax(1)[idm])


def _train(mod, fam, kind, flag, a):
    ck = a.work / f"{fam}_{kind}_{flag.strip('-').replace('-', '')}.pt"
    argv = ["--data", str(a.work / f"{fam}.npz"), "--work", str(a.work / f"{fam}_{kind}_{flag.strip('-')}_state"),
            "--out", str(ck), flag, "--threads", str(a.threads), "--seed", str(a.seed), "--sensor", fam] + \
        FAMILIES[fam][kind] + (["--no-progress"] if a.no_progress else [])
    p = mod.add_args(argparse.ArgumentParser()).parse_args(argv)
    p.command = "ablation"
    mod.train(p)
    return ck


def run(a) -> dict:
    from .export import load_checkpoint
    from . import train_box, train_cls
    fam = a.family
    data = D.load(a.work / f"{fam}.npz")
    res = dict(cls={}, box={})
    # classifier
    res["cls"]["full"] = EV.evaluate(data, 2, cls_ck=a.work / f"{fam}_cls.pt")["cls"]
    st = torch.load(a.work / f"{fam}_cls_state" / "state.pt", map_location="cpu", weights_only=False)
    _, ck = load_checkpoint(a.work / f"{fam}_cls.pt")
    m = M.ClassifierNet(**ck["cfg"])
    m.load_state_dict(st["best_ce"]["state_dict"])
    m.eval()
    res["cls"]["no energy fine-tuning"] = EV.evaluate(data, 2, cls_model=(m, _val_gamma_cls(m, data)))["cls"]
    if not a.skip_training:
        res["cls"]["no PVLE"] = EV.evaluate(data, 2, cls_ck=_train(train_cls, fam, "cls", "--no-pvle", a))["cls"]
    # box net
    res["box"]["full"] = EV.evaluate(data, 2, box_ck=a.work / f"{fam}_box.pt")["boxnet"]
    st = torch.load(a.work / f"{fam}_box_state" / "state.pt", map_location="cpu", weights_only=False)
    _, ck = load_checkpoint(a.work / f"{fam}_box.pt")
    m = M.BoxNet(**ck["cfg"])
    m.load_state_dict(st["best_box"]["state_dict"])
    m.eval()
    res["box"]["no energy fine-tuning"] = EV.evaluate(data, 2, box_model=(m, ck["meta"]["gamma"]))["boxnet"]
    if not a.skip_training:
        res["box"]["no PVLE"] = EV.evaluate(data, 2, box_ck=_train(train_box, fam, "box", "--no-pvle", a))["boxnet"]
        res["box"]["no T-Net"] = EV.evaluate(data, 2, box_ck=_train(train_box, fam, "box", "--no-tnet", a))["boxnet"]
    return res


def markdown(res: dict, fam: str) -> str:
    f = MX.fmt
    L = [f"**{fam}, test split: classifier**", "",
         "| variant | Car acc | Cyclist acc | Pedestrian acc | gate 1 AUROC | gate 1 FPR at 95 % TPR |",
         "|---|---:|---:|---:|---:|---:|"]
    for k, c in res["cls"].items():
        L.append(f"| {k} | " + " | ".join(f(c["acc"][n]["acc"], True) for n in M.CLASSES) +
                 f" | {f(c['gate1']['auroc'], nd=3)} | {f(c['gate1']['fpr95'], True)} |")
    L += ["", f"**{fam}, test split: box net**", "",
          "| variant | Car IoU / >= 0.7 | Cyclist IoU / >= 0.5 | Pedestrian IoU / >= 0.5 | gate 2 AUROC | gate 2 FPR at 95 % TPR |",
          "|---|---:|---:|---:|---:|---:|"]
    for k, r in res["box"].items():
        cells = []
        for n in M.CLASSES:
            b = r["box"][n]
            cells.append(f"{b['iou_mean']:.3f} / {f(b['share_iou'], True)}" if b.get("n") else "-")
        L.append(f"| {k} | " + " | ".join(cells) + f" | {f(r['gate2']['auroc'], nd=3)} | {f(r['gate2']['fpr95'], True)} |")
    return "\n".join(L) + "\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m lidet_tools.train.ablation", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--family", choices=sorted(FAMILIES), default="hdl64")
    ap.add_argument("--work", type=pathlib.Path, default=pathlib.Path("data/train"))
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--skip-training", action="store_true", help="only the variants that need no training")
    ap.add_argument("--no-progress", action="store_true")
    a = ap.parse_args(argv)
    try:
        res = run(a)
    except (FileNotFoundError, ValueError) as e:
        print(f"ablation: {e} (run make weights first)", file=sys.stderr)
        return 2
    md = markdown(res, a.family)
    print(md)
    (a.work / f"{a.family}_ablation.md").write_text(md)
    (a.work / f"{a.family}_ablation.json").write_text(json.dumps(res, indent=1, default=float))
    return 0


if __name__ == "__main__":
    sys.exit(main())
