# SPDX-License-Identifier: MIT
"""Train the proposal classifier (PointNet + PVLE) and its energy gate (gate 1).

    python -m lidet_tools.train.train_cls --data data/train/hdl64.npz --work data/train/hdl64_cls \
        --out data/train/hdl64_cls.pt --onnx weights/cls_hdl64.onnx

Two phases, as energy_ood (wetliu/energy_ood) fine-tunes a pre-trained net:
1. `--epochs-ce` epochs of cross-entropy on the ID proposals (Car, Cyclist, Pedestrian), class weights
   (n / (3 n_c))^0.5 against the car-heavy balance, Adam (lr 1e-3, cosine to 1e-5). Model selection:
   best validation balanced accuracy.
2. margins from that model, as the energy_ood maintainers advise (issues #13, #21: near the pre-trained
   model's average ID and OOD energies): m_in = mean training ID energy, m_out = mean training OOD
   energy, but at least m_in + `--min-gap` (so the hinge opens a gap even when the plain model gives
   OOD the same low energies as ID). Then `--epochs-energy` epochs of CE(ID) + 0.1 x squared hinge on
   batches of 64 ID + 128 OOD proposals, Adam lr 5e-4 cosine. Model selection on validation only:
   lowest FPR at 95 % TPR + (1 - balanced accuracy).
gamma_c (gate 1 keeps E < gamma_c, c the predicted class) is the energy that keeps 95 % of the
validation ID proposals predicted as c (pooled when a class has fewer than 20); `--gamma-tpr` sets that share,
one value or one per class (Car, Cyclist, Pedestrian). It is applied after training, so a finished state
resumes with another share at once.

Fixed seeds; one thread by default (`--threads`); a state file in --work after every epoch makes the
run resumable (the same command continues where it stopped, with the same result).
"""
from __future__ import annotations

import math
import pathlib
import sys
import time

import numpy as np
import torch
import torch.nn.functional as F

from . import common as C
from . import dataset as D
from . import metrics as MX
from . import models as M


def balanced_acc(res: dict) -> float:
    v = [a["acc"] for a in res["acc"].values() if a["n"]]
    return float(np.mean(v)) if v else float("nan")


def add_args(ap):
    ap.add_argument("--data", type=pathlib.Path, required=True, help="dataset .npz (lidet_tools.train.dataset)")
    ap.add_argument("--work", type=pathlib.Path, required=True, help="folder for the resumable state")
    ap.add_argument("--out", type=pathlib.Path, required=True, help="checkpoint .pt (export contract)")
    ap.add_argument("--onnx", type=pathlib.Path, help="also export the ONNX here")
    ap.add_argument("--epochs-ce", type=int, default=30)
    ap.add_argument("--epochs-energy", type=int, default=15)
    ap.add_argument("--batch", type=int, default=64)
    ap.add_argument("--lam", type=float, default=0.1, help="weight of the energy hinge")
    ap.add_argument("--min-gap", type=float, default=3.0, help="least m_out - m_in")
    ap.add_argument("--gamma-tpr", default="0.95",
                    help="share of the validation ID proposals each class's gate-1 gamma keeps: one value, or three "
                         "(Car, Cyclist, Pedestrian)")
    ap.add_argument("--occlusion", type=float, default=0.0,
                    help="probability per training proposal, road user or not, of hiding a part of it "
                         "(common.occlude, as train_box --occlusion); 0 = off")
    ap.add_argument("--aug", default="",
                    help="augmentation settings changed from common.SIM_AUG, JSON (e.g. '{\"jitter\": 0.02}')")
    ap.add_argument("--no-pvle", action="store_true", help="ablation: no PVLE branch")
    ap.add_argument("--point", default="32,64,128", help="shared MLP widths")
    ap.add_argument("--head", default="64", help="FC widths")
    ap.add_argument("--pvle", default="32,32", help="PVLE widths")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--device", default="cpu")
    ap.add_argument("--sensor", default=None, help="sensor name stored in the metadata (default: the dataset's)")
    ap.add_argument("--no-progress", action="store_true")
    return ap


def _ints(s):
    return tuple(int(v) for v in s.split(",") if v)


def gamma_tprs(s: str) -> list:
    """--gamma-tpr as one share per class (Car, Cyclist, Pedestrian), each in (0, 1]."""
    try:
        v = [float(x) for x in str(s).split(",")]
    except ValueError:
        raise ValueError(f"--gamma-tpr {s!r}: one number or three, comma-separated") from None
    if len(v) == 1:
        v = v * M.N_CLASSES
    if len(v) != M.N_CLASSES or not all(0.0 < x <= 1.0 for x in v):
        raise ValueError(f"--gamma-tpr {s!r}: one share or {M.N_CLASSES} (Car, Cyclist, Pedestrian), each in (0, 1]")
    return v


def train(a) -> dict:
    tprs = gamma_tprs(a.gamma_tpr)
    if not 0.0 <= a.occlusion <= 1.0:
        raise ValueError(f"--occlusion must be a probability in [0, 1], got {a.occlusion}")
    aug = C.json_object_arg(a.aug, "--aug", C.SIM_AUG)  # settings of common.SIM_AUG
    C.setup(a.seed, a.threads)
    dd = C.dist_from_env(a.device)  # None without torchrun: the single-process path below is unchanged
    main = dd is None or dd.main
    dev = dd.dev if dd else C.device(a.device)
    data = D.load(a.data)
    tr, va = C.split(data, 0), C.split(data, 1)
    tr_id = np.nonzero(tr["label"] >= 0)[0]
    tr_ood = np.nonzero(tr["label"] < 0)[0]
    if len(tr_id) < a.batch or len(va["label"]) == 0:
        raise ValueError(f"{a.data}: too few proposals to train ({len(tr_id)} training ID, {len(va['label'])} validation)")
    if dd and len(tr_id) // dd.world < a.batch:
        raise ValueError(f"{a.data}: {len(tr_id)} training ID proposals are too few for {dd.world} ranks of --batch {a.batch}")
    counts = np.bincount(tr["label"][tr_id], minlength=M.N_CLASSES).astype(np.float64)
    w = np.sqrt(counts.sum() / (M.N_CLASSES * np.maximum(counts, 1)))
    cw = torch.tensor(w, dtype=torch.float32, device=dev)
    cfg = dict(point=_ints(a.point), head=_ints(a.head), pvle=_ints(a.pvle), use_pvle=not a.no_pvle)
    model = M.ClassifierNet(**cfg).to(dev)
    state_path = a.work / "state.pt"
    args_key = {k: (str(v) if isinstance(v, pathlib.Path) else v) for k, v in vars(a).items()
                if k not in ("no_progress", "threads", "device", "work", "out", "onnx", "command", "gamma_tpr")}
    if args_key.get("pvle") == "32,32":
        args_key.pop("pvle")  # states made before --pvle (at its default) resume as before
    for k in ("occlusion", "aug"):
        if not args_key.get(k):
            args_key.pop(k, None)  # the same for --occlusion and --aug at their defaults
    if dd:
        args_key["world_size"] = dd.world  # the shards depend on it: resume with the same number of ranks
    st = dict(epoch=0, history=[], best_ce=None, best_en=None, margins=None, args=args_key)
    s = torch.load(state_path, map_location="cpu", weights_only=False) if main and state_path.exists() else None
    if dd:
        s = dd.bcast(s)  # rank 0 reads the state; --work need not be shared between machines
    if s is not None:
        if s.get("args") != args_key:
            raise ValueError(f"{state_path}: made with other arguments; remove {a.work} to start over")
        st = s
        model.load_state_dict(s["model"])
        if main:
            print(f"train_cls: resuming after epoch {s['epoch']}", file=sys.stderr)
    net = dd.wrap(model) if dd else model  # trains through DDP; validation and export use `model`
    shards = []
    E1, E2 = a.epochs_ce, a.epochs_energy
    t0 = time.perf_counter() - (st["history"][-1]["seconds"] if st["history"] else 0.0)
    for ep in range(st["epoch"], E1 + E2):
        phase = "ce" if ep < E1 else "energy"
        if ep == E1 and E2 > 0:
            # phase 2 starts from the best CE model; margins from its training energies
            model.load_state_dict(st["best_ce"]["state_dict"])
            if dd:
                dd.sync(model)
            if st["margins"] is None:
                lg = MX.cls_logits(model, tr, dev)
                e = MX.energy_np(lg)
                m_in = float(e[tr["label"] >= 0].mean())
                m_out = max(float(e[tr["label"] < 0].mean()), m_in + a.min_gap)
                st["margins"] = dict(m_in=m_in, m_out=m_out, e_id_mean=float(e[tr["label"] >= 0].mean()),
                                     e_ood_mean=float(e[tr["label"] < 0].mean()))
                if dd:
                    st["margins"] = dd.bcast(st["margins"])
        lr0, ne = (1e-3, E1) if phase == "ce" else (5e-4, E2)
        k = ep if phase == "ce" else ep - E1
        opt = torch.optim.Adam(model.parameters(), lr=lr0)
        if "opt" in st and st.get("opt_phase") == phase:
            opt.load_state_dict(st["opt"])
        lr = 1e-5 + 0.5 * (lr0 - 1e-5) * (1 + math.cos(math.pi * k / max(ne, 1)))
        for g in opt.param_groups:
            g["lr"] = lr
        torch.manual_seed(a.seed * 1000 + ep)
        net.train()
        tot, nb = 0.0, 0
        if dd:
            # this rank's shard of the ID rows (DistributedSampler, set_epoch) and of the OOD rows
            rng = np.random.default_rng([a.seed, ep, dd.rank])
            order = dd.shard(len(tr_id), ep, a.seed)
            it = [order[i:i + a.batch] for i in range(0, len(order) - len(order) % a.batch, a.batch)]
            ood = tr_ood[dd.shard(len(tr_ood), ep, a.seed + 1, drop_last=False)] if len(tr_ood) else tr_ood
            shards.append(dict(epoch=ep + 1, id=tr_id[order].tolist(), ood=ood.tolist()))
            print(f"train_cls: rank {dd.rank} of {dd.world}, epoch {ep + 1}: {len(order)} training ID and "
                  f"{len(ood)} OOD proposals in this rank's shard", file=sys.stderr)
        else:
            rng = np.random.default_rng([a.seed, ep])
            it = C.batches(rng, len(tr_id), a.batch)
            ood = tr_ood
        for bi in C.progress(list(it), main and not a.no_progress, desc=f"cls {phase} {ep + 1}/{E1 + E2}", leave=False):
            idx = tr_id[bi]
            p, _ = C.augment(rng, tr["points"][idx], occlusion=a.occlusion, **aug)
            if phase == "energy":
                oi = ood[rng.integers(0, len(ood), 2 * a.batch)]
                po, _ = C.augment(rng, tr["points"][oi], occlusion=a.occlusion, **aug)
                pts, vox = C.tensors(tr, np.concatenate([idx, oi]), dev, np.concatenate([p, po]))
            else:
                pts, vox = C.tensors(tr, idx, dev, p)
            y = torch.from_numpy(tr["label"][idx].astype(np.int64)).to(dev)
            logits = net(pts, vox)
            loss = F.cross_entropy(logits[:len(idx)], y, weight=cw)
            if phase == "energy":
                e = C.energy(logits)
                loss = loss + a.lam * C.hinge(e[:len(idx)], e[len(idx):], st["margins"]["m_in"], st["margins"]["m_out"])
            opt.zero_grad()
            loss.backward()
            opt.step()
            tot += float(loss.detach())
            nb += 1
        if dd:
            tot, nb = dd.sum([tot, nb])  # the loss logged is the mean over all ranks' batches
            dd.sync(model)  # BN running statistics averaged over the ranks; one model everywhere
        res = MX.cls_figures(MX.cls_logits(model, va, dev), va["label"])
        bal = balanced_acc(res)
        score = res["gate1"]["fpr95"] + (1 - bal) if phase == "energy" else -bal
        h = dict(epoch=ep + 1, phase=phase, lr=lr, loss=tot / max(nb, 1), val_bal_acc=bal,
                 val_fpr95=res["gate1"]["fpr95"], val_auroc=res["gate1"]["auroc"], score=score,
                 seconds=time.perf_counter() - t0)
        if dd:
            # every rank validates the same model on the whole validation split; rank 0's figures decide
            h = dd.bcast(h)
            bal, score = h["val_bal_acc"], h["score"]
        st["history"].append(h)
        key = "best_ce" if phase == "ce" else "best_en"
        if st[key] is None or score < st[key]["score"]:
            st[key] = dict(score=score, epoch=ep + 1, state_dict={k: v.detach().cpu().clone() for k, v in model.state_dict().items()})
        if main:
            print(f"cls {phase} epoch {ep + 1}: loss {h['loss']:.4f} val bal.acc {bal:.3f} FPR95 {h['val_fpr95']:.3f} "
                  f"AUROC {h['val_auroc']:.3f}", file=sys.stderr)
        st.update(epoch=ep + 1, model=model.state_dict(), opt=opt.state_dict(), opt_phase=phase)
        if main:
            C.save_atomic(st, state_path)  # state for resuming: rank 0 only
    C.dump_shards(dd, "cls", shards)
    best = st["best_en"] if (E2 > 0 and st["best_en"] is not None) else st["best_ce"]
    model.load_state_dict(best["state_dict"])
    model.eval()
    lg = MX.cls_logits(model, va, dev)
    idm = va["label"] >= 0
    gamma = C.per_class_gamma(MX.energy_np(lg)[idm], lg.argmax(1)[idm], tprs)
    meta = dict(n_points=int(data["points"].shape[1]), gamma=gamma, gamma_tpr=tprs, energy_T=1.0, trained=1,
                sensor=a.sensor or data["meta"].get("sensor", ""), data=data["meta"].get("command", str(a.data)),
                z_origin=data["meta"].get("z_origin", "mean"),
                command=getattr(a, "command", None) or "python -m lidet_tools.train.train_cls",
                margins=st["margins"], best_epoch=best["epoch"], seed=a.seed, history=st["history"],
                train_seconds=st["history"][-1]["seconds"] if st["history"] else 0.0)
    if dd:
        meta["world_size"] = dd.world
    ck = dict(kind="classifier", cfg={k: v for k, v in model.cfg.items()}, state_dict=model.cpu().state_dict(), meta=meta)
    return C.write_outputs(ck, model, a, main, dd)  # checkpoint and ONNX from rank 0 only


def main(argv=None) -> int:
    return C.run_cli("train_cls", add_args, train, __doc__, argv)


if __name__ == "__main__":
    sys.exit(main())
