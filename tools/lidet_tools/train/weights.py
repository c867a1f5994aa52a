# SPDX-License-Identifier: MIT
"""`make weights`: from nothing to weights/{cls,box}_<family>.onnx, their C models and a model card per invocation
(`make weights` runs one per family: `--families hdl64 --card weights/MODEL_CARD_hdl64.md`, `--families vlp16` with
the default card weights/MODEL_CARD.md, `--families vlp16s --card weights/MODEL_CARD_vlp16s.md` for the small VLP-16
pair of the integer firmware, and so on; without `--families` one run trains hdl64 and vlp16 with one card).

    python -m lidet_tools.train.weights [--work data/train] [--weights weights] [--jobs 2] [--threads 1]
                                        [--real ../shared/data/real/kitti/training] [--device cpu]

Per sensor family: the proposal dataset (simulator, fixed seeds; skipped when its .npz exists), the
classifier and the box net (each resumable from its state folder under --work: an interrupted run
continues where it stopped), the ONNX export, the figures on the test split, the energy histograms
(`lidet-viz energy`), the classifier on the real KITTI frames (when --real exists), the MAC counts.
Then the C models (c_models): the int8 calibration of each new ONNX file (`python -m lidet_tools.train.calibrate`,
and `calibrate --refit` for a classifier not fine-tuned for int8) and every float and int8 C file of --weights
with lidet_weights.{c,h} (`python -m lidet_codegen regen`), and finally the model card. The same command on the
same machine gives the same models.
"""
from __future__ import annotations

import argparse
import json
import os
import pathlib
import shlex
import sys
import time

from . import dataset as D
from . import evaluate as EV
from . import macs as MC
from . import models as M

#: dataset and training settings per sensor family (the defaults of `make weights`)
FAMILIES = {
    # hdl64: simulated HDL-64E and Pandar64 scans at KITTI's 1.73 m and a 2.05 m mount (PandaSet's), 300 training scans
    # of each pair; the car gate keeps 92.5 % of the validation cars (chosen on the real training frames of
    # tools/lidet_tools/real/split.txt: at the shipped models' false positives per frame it finds more real cars;
    # docs/journal/real-streets.md, "Kept: the hdl64 family seen from two mounts and two sensors"); the classifier
    # trained with twice the simulator's point jitter (2 cm, clipped at 6 cm: over three training seeds 3.0 more real
    # pedestrians of 35 on the real training frames, cars the same; "Kept: a classifier trained on noisier points")
    "hdl64": dict(dataset=["--sensor", "hdl64", "--sim-sensors", "hdl64,pandar64", "--mounts", "1.73,2.05",
                           "--sim", "1200,150,150", "--seed", "1000"],
                  cls=["--epochs-ce", "20", "--epochs-energy", "10", "--gamma-tpr", "0.925,0.95,0.95",
                       "--aug", '{"jitter": 0.02, "jitter_clip": 0.06}'],
                  box=["--epochs-box", "30", "--epochs-energy", "10"]),
    # beams32: a family for the 32-beam presets (issue 37, item 5): simulated scans of the five presets (VLP-32C,
    # HDL-32E, Ouster OS0 / OS1 / OS2 at 32 beams) at four mount heights, each through its own C stages; the hdl64
    # family's schedule. Not any preset's default: on real frames it lets through about twice the false positives of
    # the hdl64 family (docs/SENSORS.md, "Model families"); `--model beams32` runs it
    "beams32": dict(sensor="vlp32c", dataset=["--sensor", "vlp32c", "--sim-sensors", "vlp32c,hdl32,os0-32,os1-32,os2-32",
                            "--mounts", "0.7,1.0,1.4,1.84", "--sim", "800,200,200", "--seed", "3000"],
                    cls=["--epochs-ce", "20", "--epochs-energy", "10"],
                    box=["--epochs-box", "30", "--epochs-energy", "10"]),
    # beams128: a family for the 128-beam presets (issue 37, item 5): simulated scans of the three Ouster 128-beam
    # presets (OS0 / OS1 / OS2) at four mount heights, each through its own C stages; the hdl64 family's schedule.
    # Not any preset's default (docs/SENSORS.md, "Model families"); `--model beams128` runs it
    "beams128": dict(sensor="os1-128", dataset=["--sensor", "os1-128", "--sim-sensors", "os0-128,os1-128,os2-128",
                              "--mounts", "0.7,1.0,1.4,1.84", "--sim", "600,150,150", "--seed", "4000"],
                     cls=["--epochs-ce", "20", "--epochs-energy", "10"],
                     box=["--epochs-box", "30", "--epochs-energy", "10"]),
    # beams64: a family for the Ouster 64-beam presets (issue 37, item 5): simulated scans of the three Ouster 64-beam
    # presets (OS0 / OS1 / OS2) at four mount heights, each through its own C stages; the hdl64 family's schedule.
    # Not any preset's default (docs/SENSORS.md, "Model families"); `--model beams64` runs it
    "beams64": dict(sensor="os1-64", dataset=["--sensor", "os1-64", "--sim-sensors", "os0-64,os1-64,os2-64",
                            "--mounts", "0.7,1.0,1.4,1.84", "--sim", "600,150,150", "--seed", "5000"],
                    cls=["--epochs-ce", "20", "--epochs-energy", "10"],
                    box=["--epochs-box", "30", "--epochs-energy", "10"]),
    # vlp16: 25 energy epochs with lam 0.3 (chosen on validation: FPR95 + 1 - balanced accuracy 0.127,
    # against 0.136 for 25 epochs at lam 0.1 and 0.197 for 10 epochs at lam 0.1)
    "vlp16": dict(dataset=["--sensor", "vlp16", "--mounts", "0.3,0.5,0.7,1.0", "--sim", "800,200,200", "--seed", "2000"],
                  cls=["--epochs-ce", "20", "--epochs-energy", "25", "--lam", "0.3"],
                  # 45 + 20 epochs: validation score (FPR95 - mean IoU) -0.545 against -0.442 for 30 + 10
                  box=["--epochs-box", "45", "--epochs-energy", "20"],
                  # then quantization-aware fine-tuning for the int8 build (finetune_q; docs/journal/fixed-point.md,
                  # "Quantization-aware fine-tuning"): its int8 classifier disagreed with float on 1.4 % of held-out
                  # proposals, 0.5-0.6 % after (seeds 7, 8, 9)
                  cls_finetune=["--epochs", "6", "--seed", "7"]),
    # vlp16s: the small VLP-16 pair for boards without an FPU (issue 17): 32 points per proposal, 9x fewer
    # multiply-adds than vlp16 (classifier 86 k, box net 144 k per proposal), the same scans and schedule;
    # the integer firmware images use it (docs/PORTING.md, "The small VLP-16 pair"). The box net's point MLP
    # is 24-40-64 (24-48-80 gives the same AP, docs/FIXED_POINT.md); the narrower classifiers tried
    # (16-32-48 and smaller) lost pedestrian AP or the int8 build's agreement with float at gate 1
    "vlp16s": dict(sensor="vlp16", small=True,
                   dataset=["--sensor", "vlp16", "--mounts", "0.3,0.5,0.7,1.0", "--sim", "800,200,200", "--seed", "2000",
                            "--n-points", "32"],
                   cls=["--epochs-ce", "20", "--epochs-energy", "25", "--lam", "0.3",
                        "--point", "16,32,64", "--pvle", "16,16", "--head", "32"],
                   box=["--epochs-box", "45", "--epochs-energy", "20", "--widths",
                        '{"tnet_point": [16, 32], "tnet_head": [32], "point": [24, 40, 64], "head": [64, 32], '
                        '"pvle": [16, 16]}'],
                   cls_finetune=["--epochs", "6", "--seed", "7"]),
}


def _log(msg):
    print(f"[weights {time.strftime('%H:%M:%S')}] {msg}", file=sys.stderr, flush=True)


def run_family(fam: str, a, timings: dict) -> dict:
    from . import train_box, train_cls
    w = a.work
    spec = FAMILIES[fam]
    data = w / f"{fam}.npz"
    t = time.perf_counter()
    if not data.exists():
        _log(f"{fam}: proposal dataset -> {data}")
        rc = D.main(spec["dataset"] + ["--jobs", str(a.jobs), "--out", str(data)] + (["--no-progress"] if a.no_progress else []))
        if rc:
            raise RuntimeError(f"dataset for {fam} failed ({rc})")
    timings[f"{fam} dataset"] = time.perf_counter() - t
    common = ["--threads", str(a.threads), "--device", a.device, "--seed", str(a.seed), "--sensor", spec.get("sensor", fam)] + \
        (["--no-progress"] if a.no_progress else [])
    out = {}
    for kind, mod, extra in (("cls", train_cls, spec["cls"]), ("box", train_box, spec["box"])):
        ck = w / f"{fam}_{kind}.pt"
        onnx = a.weights / f"{kind}_{fam}.onnx"
        t = time.perf_counter()
        argv = ["--data", str(data), "--work", str(w / f"{fam}_{kind}_state"), "--out", str(ck), "--onnx", str(onnx)] + extra + common
        _log(f"{fam}: {kind} -> {onnx}")
        p = mod.add_args(argparse.ArgumentParser()).parse_args(argv)
        p.command = f"python -m lidet_tools.train.{mod.__name__.rsplit('.', 1)[1]} " + shlex.join(argv)
        mod.train(p)
        if kind == "cls" and spec.get("cls_finetune"):
            from . import finetune_q as FQ
            fargv = ["--onnx", str(onnx), "--data", str(data), "--out", str(onnx), "--checkpoint", str(ck),
                     "--threads", str(a.threads)] + spec["cls_finetune"]
            if "--gamma-tpr" in extra:  # the gates keep the shares the family trained with
                fargv += ["--gamma-tpr", extra[extra.index("--gamma-tpr") + 1]]
            _log(f"{fam}: {kind} fine-tuned for int8 -> {onnx}")
            fp = FQ.add_args(argparse.ArgumentParser()).parse_args(fargv)
            fp.command = "python -m lidet_tools.train.finetune_q " + shlex.join(fargv)
            FQ.finetune(fp)
        timings[f"{fam} {kind}"] = time.perf_counter() - t
        out[kind] = ck
    t = time.perf_counter()
    dd = D.load(data)
    res = EV.evaluate(dd, 2, out["cls"], out["box"], w / f"{fam}_energy")
    res["val"] = EV.evaluate(dd, 1, out["cls"], out["box"])
    res["balance"] = D.balance_table(dd)
    res["dataset_meta"] = dd["meta"]
    res["onnx_parity"] = onnx_parity(dd, out, a.weights, fam)
    _histograms(fam, w / f"{fam}_energy", a)
    timings[f"{fam} evaluation"] = res["evaluation_seconds"] = time.perf_counter() - t
    (w / f"{fam}_test.json").write_text(json.dumps(res, indent=1, default=float))
    return res


def onnx_parity(dd: dict, cks: dict, wdir, fam: str) -> dict:
    """Max abs difference onnxruntime vs PyTorch over every test-split proposal, per output."""
    import numpy as np
    import onnxruntime as ort
    from .export import load_checkpoint, torch_forward
    from . import common as C
    te = C.split(dd, 2)
    feeds = {"points": te["points"].astype(np.float32), "voxel": te["voxel"].astype(np.float32)}
    oh = np.eye(M.N_CLASSES, dtype=np.float32)[np.maximum(te["label"], 0)]
    import copy
    import torch
    out = {}
    for kind, mk in (("cls", "classifier"), ("box", "box")):
        m, _ = load_checkpoint(cks[kind])
        f = dict(feeds, onehot=oh) if kind == "box" else feeds
        ref = torch_forward(m, mk, f["points"], f["voxel"], f.get("onehot"))
        sess = ort.InferenceSession(str(wdir / f"{kind}_{fam}.onnx"), providers=["CPUExecutionProvider"])
        got = dict(zip([o.name for o in sess.get_outputs()], sess.run(None, f)))
        # float64 PyTorch: how far float32 itself is from exact, for scale
        m64 = copy.deepcopy(m).double()
        with torch.no_grad():
            r = m64(*[torch.from_numpy(f[k]).double() for k in (["points", "voxel", "onehot"] if kind == "box" else ["points", "voxel"])])
        r64 = {"logits": r.numpy()} if kind == "cls" else {"center_tnet": r[0].numpy(), "box": r[1].numpy()}
        for k in got:
            out[f"{kind}.{k}"] = dict(ort_vs_torch=float(np.abs(got[k] - ref[k]).max()),
                                      torch32_vs_float64=float(np.abs(ref[k] - r64[k]).max()),
                                      max_abs_output=float(np.abs(ref[k]).max()))
    return out


def _histograms(fam, edir, a):
    from ..viz import cli as viz
    import numpy as np
    from .export import load_checkpoint
    for kind, title in (("cls", "gate 1 (classifier)"), ("box", "gate 2 (box net)")):
        if not (edir / f"{kind}_id.npy").exists():
            continue
        _, ck = load_checkpoint(a.work / f"{fam}_{kind}.pt")
        g = float(np.max(ck["meta"]["gamma"]))
        png = a.docs_img / f"energy_{kind}_{fam}.png"
        viz.main(["energy", "--id", str(edir / f"{kind}_id.npy"), "--ood", str(edir / f"{kind}_ood.npy"),
                  "--threshold", repr(g), "--title", f"{fam} test split, {title}", "--out", str(png)])


def run_real(a) -> dict:
    """The hdl64 classifier on the real scans: KITTI object frames (label_2, camera view only) and
    SemanticKITTI scans (per-point labels, 360 deg). Each skipped cleanly when absent."""
    out = {}
    for key, folder, opt in (("kitti", a.real, "--kitti"), ("semantickitti", a.real_semantickitti, "--semantickitti")):
        sub = "label_2" if key == "kitti" else "labels"
        if folder is None or not (folder / "velodyne").is_dir() or not (folder / sub).is_dir():
            _log(f"real {key} scans not found at {folder}: skipped")
            continue
        data = a.work / f"real_{key}.npz"
        if not data.exists():
            rc = D.main(["--sensor", "hdl64", opt, str(folder), "--split", "test", "--out", str(data), "--no-progress"])
            if rc:
                continue
        dd = D.load(data)
        res = EV.evaluate(dd, 2, a.work / "hdl64_cls.pt")
        res["balance"] = D.balance_table(dd)
        res["command"] = f"python -m lidet_tools.train.dataset --sensor hdl64 {opt} {folder} --split test --out {data}"
        (a.work / f"real_{key}_test.json").write_text(json.dumps(res, indent=1, default=float))
        out[key] = res
    return out


def c_models(a, fams, scan_dirs=None) -> list:
    """The C models of --weights after training: for each family trained, its two new ONNX files calibrated for
    int8 (`python -m lidet_tools.train.calibrate`, the classifier first: a box net is calibrated on the classes of the
    classifier beside it), the classifier's last layer refitted (`calibrate --refit`) unless it was fine-tuned for
    int8 (cls_finetune; a refit made the fine-tuned ones' gate decisions agree less, docs/journal/fixed-point.md,
    "Quantization-aware fine-tuning"); then
    every float and int8 C model of the folder and lidet_weights.{c,h} (lidet_codegen.regen.emit_all, the commands
    of the committed weights/ and of CI's drift check). scan_dirs: folders of scans (velodyne/*.bin) that replace
    the real KITTI scans of a.real in the calibration (`calibrate --scans`; lidet_tools.train.finetune passes the
    user's). Returns the emit commands."""
    from lidet_codegen import regen

    from . import calibrate as CB
    if scan_dirs:
        ra = [x for d in scan_dirs for x in ("--scans", str(d))]
    else:
        # calibrate takes the folder above kitti/ (its HDL-64 scans join the hdl64 calibration set when present)
        ra = ["--real", str(a.real.parents[1] if a.real.parent.name == "kitti" else a.real)]
    for fam in fams:
        cls, box = ((a.weights / f"{k}_{fam}.onnx").as_posix() for k in ("cls", "box"))
        _log(f"{fam}: int8 calibration -> {a.weights}/{{cls,box}}_{fam}.calib.json")
        CB.main([cls, box] + ra)
        if not FAMILIES[fam].get("cls_finetune"):
            CB.main(["--refit", cls] + ra)
    _log(f"C models -> {a.weights}/*.c, *_s8.c, lidet_weights.c")
    return regen.emit_all(a.weights)


def model_card(a, results: dict, real, timings: dict) -> str:
    from .export import load_checkpoint
    L = ["# lidet PointNet weights: model card", "",
         "Generated by `make weights` (`python -m lidet_tools.train.weights`); do not edit by hand. Method,",
         "choices and the ablation: docs/TRAINING.md.", ""]
    L += ["## Files", "", "| file | sensor family | kind | points | MACs | parameters | fp32 weights | gamma (Car, Cyclist, Pedestrian) | margins m_in / m_out | best epoch |",
          "|---|---|---|---:|---:|---:|---:|---|---|---:|"]
    shares = []  # gate-1 shares other than 95 % (`train_cls --gamma-tpr`; checkpoints made before it hold none)
    for fam in results:
        for kind in ("cls", "box"):
            p = a.weights / f"{kind}_{fam}.onnx"
            c = MC.count(p)
            _, ck = load_checkpoint(a.work / f"{fam}_{kind}.pt")
            mg = ck["meta"]["margins"] or {}
            tp = ck["meta"].get("gamma_tpr") if kind == "cls" else None
            if tp and any(abs(t - 0.95) > 1e-9 for t in tp):
                shares.append(f"; {fam}'s gate 1 keeps {', '.join(f'{100 * t:g} %' for t in tp)} (Car, Cyclist, "
                              "Pedestrian: `train_cls --gamma-tpr`)")
            L.append(f"| `{p.name}` | {fam} | {c['kind']} | {c['n_points']} | {c['macs']:,} | {c['params']:,} | "
                     f"{c['weight_bytes_fp32'] / 1024:.1f} KiB | {', '.join(f'{g:.3f}' for g in ck['meta']['gamma'])} | "
                     f"{mg.get('m_in', float('nan')):.2f} / {mg.get('m_out', float('nan')):.2f} | {ck['meta']['best_epoch']} |")
    small = [f for f in results if FAMILIES.get(f, {}).get("small")]
    L += ["", "Budgets per proposal at 64 points: classifier <= 1,000,000 MACs, box net <= 2,000,000 MACs "
          "(counted from the ONNX graphs by `python -m lidet_tools.train.macs`). At 128 points the same "
          "widths need about twice as many (classifier 1.33 M, box net 2.89 M: over budget), so the models use 64."
          + (f" {', '.join(small)}: a smaller pair for cores without an FPU (32 points per proposal, narrower layers: "
             "about 9x fewer multiply-adds), made for the integer firmware (docs/PORTING.md, \"The small VLP-16 pair\")."
             if small else ""), "",
          "Gates: gate 1 keeps a proposal when E = -logsumexp(logits) < gamma[predicted class]; gate 2 when "
          "E(heading scores) + E(size scores) < gamma[class] (T = 1). Each gamma keeps 95 % of that class's "
          "validation ID proposals" + "".join(shares) + ".", ""]
    L += ["## Data", ""]
    for fam, r in results.items():
        m = r["dataset_meta"]
        L += [f"**{fam}**: `{m.get('command', '')}` (simulator run seeds {m.get('seed')} train, "
              f"{m.get('seed', 0) + 1} val, {m.get('seed', 0) + 2} test; labels: purity >= {m.get('purity')}, "
              f"recall >= {m.get('recall')}, box margin {m.get('margin')} m; {m.get('n_excluded')} clusters excluded "
              "as ignored classes)", "", r["balance"], ""]
    L += ["## Training", "", f"Seed {a.seed}, {a.threads} thread(s), device {a.device}. Commands (from the checkpoints):", ""]
    for fam in results:
        for kind in ("cls", "box"):
            _, ck = load_checkpoint(a.work / f"{fam}_{kind}.pt")
            L.append(f"    {ck['meta']['command']}")
    L += ["", "Wall-clock seconds per step (training: the sum over its epochs, from the state history, so a "
          "resumed run still shows what the epochs cost; dataset: from its metadata when it was built):", "",
          "| step | seconds |", "|---|---:|"]
    steps = 0.0  # the steps' seconds listed: a run that found its datasets and checkpoints in --work took less
    for fam, r in results.items():
        ds = r["dataset_meta"].get("seconds")
        L.append(f"| {fam} dataset | {ds:.0f} |" if ds is not None else f"| {fam} dataset | (built before; not recorded) |")
        steps += float(ds or 0.0)
        for kind in ("cls", "box"):
            _, ck = load_checkpoint(a.work / f"{fam}_{kind}.pt")
            L.append(f"| {fam} {kind} training | {ck['meta'].get('train_seconds', float('nan')):.0f} |")
            steps += float(ck["meta"].get("train_seconds") or 0.0)
        L.append(f"| {fam} evaluation | {timings.get(f'{fam} evaluation', float('nan')):.0f} |")
    resumed = timings.get("total", 0.0) < steps
    L += [f"| int8 calibration and C models (all families) | {timings.get('C models', float('nan')):.0f} |",
          f"| this invocation, in all{' (it reused the datasets and checkpoints of ' + str(a.work) + ')' if resumed else ''}"
          f" | {timings.get('total', float('nan')):.0f} |", ""]
    L += ["## Figures on the test split (simulated, scans never seen in training or model selection)", ""]
    for fam, r in results.items():
        L.append(EV.markdown(r, f"{fam}, test split"))
        if "onnx_parity" in r:
            L += [f"ONNX parity on all {r['n']} test proposals (max abs difference; float32 PyTorch against float64 "
                  "PyTorch for scale):", "", "| output | onnxruntime vs PyTorch | PyTorch float32 vs float64 | largest |output| |",
                  "|---|---:|---:|---:|"]
            L += [f"| {k} | {v['ort_vs_torch']:.1e} | {v['torch32_vs_float64']:.1e} | {v['max_abs_output']:.1f} |"
                  for k, v in r["onnx_parity"].items()] + [""]
    if real:
        L += ["## Classifier on real scans", "",
              "The hdl64 classifier on ../shared/data/real: the three labelled KITTI object frames (only clusters "
              "inside the camera's view, as label_2 annotates only those) and the three labelled SemanticKITTI "
              "scans (360 deg; SemanticKITTI labels most vans as car, so some 'Car' samples are vans). Very few "
              "objects: the figures are anecdotes, not estimates.", ""]
        for k, r in real.items():
            L += [f"    {r['command']}", "", r["balance"], "", EV.markdown(r, f"real {k}")]
    tuned = []
    for fam in results:
        _, ck = load_checkpoint(a.work / f"{fam}_cls.pt")
        f = ck["meta"].get("finetune")
        if f:
            from .finetune_q import card_lines
            tuned += card_lines(f"cls_{fam}.onnx", f["command"], f["before"], f["after"])
    if tuned:
        from .finetune_q import CARD_SECTION
        L += [CARD_SECTION, ""] + tuned
    L += ["## Known limits", "",
          "- Trained on simulated scans only (lidet-sim); " + ("the real-frame figures above are the only check on real "
          "data." if real else "the real KITTI frames check only the hdl64 family (weights/MODEL_CARD_hdl64.md)."),
          "- The box net is evaluated with the true class as its one-hot; in the pipeline the classifier's class is used.",
          "- Heading error counts a box turned by 180 deg as an error (the IoU does not).",
          "- Gate-2 OOD figures use a random class one-hot for each OOD proposal.",
          "- One model family per sensor (and the small vlp16s pair for the integer firmware); other profiles "
          "(vlp32c, os1-*) are untested with these weights.",
          "- ONNX parity: the classifier logits agree within 1e-5; the box net's heading scores reach |20| and there "
          "the difference is about 1.3e-5, a few float32 ulps (float32 PyTorch is as far from float64).", ""]
    return "\n".join(L)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m lidet_tools.train.weights", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--work", type=pathlib.Path, default=pathlib.Path("data/train"))
    ap.add_argument("--weights", type=pathlib.Path, default=pathlib.Path("weights"))
    ap.add_argument("--docs-img", type=pathlib.Path, default=pathlib.Path("docs/img"))
    ap.add_argument("--families", default="hdl64,vlp16",
                    help="the families to train (FAMILIES); each invocation writes one card for its families")
    ap.add_argument("--card", type=pathlib.Path, default=None,
                    help="the model card to write (default: --weights/MODEL_CARD.md)")
    ap.add_argument("--jobs", type=int, default=max(1, min(2, os.cpu_count() or 1)))
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--device", default="cpu")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--real", type=pathlib.Path, default=pathlib.Path("../shared/data/real/kitti/training"))
    ap.add_argument("--real-semantickitti", type=pathlib.Path, default=pathlib.Path("../shared/data/real/semantickitti"))
    ap.add_argument("--no-progress", action="store_true")
    a = ap.parse_args(argv)
    fams = [f for f in a.families.split(",") if f]
    bad = [f for f in fams if f not in FAMILIES]
    if bad:
        ap.error(f"unknown family {bad} (known: {sorted(FAMILIES)})")
    a.work.mkdir(parents=True, exist_ok=True)
    a.weights.mkdir(parents=True, exist_ok=True)
    a.docs_img.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    timings, results = {}, {}
    try:
        for f in fams:
            results[f] = run_family(f, a, timings)
        real = run_real(a) if "hdl64" in fams else {}
        t = time.perf_counter()
        c_models(a, fams)
        timings["C models"] = time.perf_counter() - t
    except (FileNotFoundError, ValueError, RuntimeError) as e:
        print(f"weights: {e}", file=sys.stderr)
        return 2
    timings["total"] = time.perf_counter() - t0
    card = a.card or a.weights / "MODEL_CARD.md"
    card.write_text(model_card(a, results, real, timings))
    _log(f"done in {timings['total']:.0f} s: {card}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
