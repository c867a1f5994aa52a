# SPDX-License-Identifier: MIT
"""Train the box net (T-Net + box PointNet with PVLE) and its energy gate (gate 2).

    python -m lidet_tools.train.train_box --data data/train/hdl64.npz --work data/train/hdl64_box \
        --out data/train/hdl64_box.pt --onnx weights/box_hdl64.onnx

Loss (Frustum PointNets v1, `get_loss`, without its two known bugs): centre Huber (delta 2) on the
distance of the final centre + T-Net centre Huber (delta 1) + heading-bin CE + 20 x Huber of the
normalised heading residual of the true bin + size-template CE + 20 x Huber of the norm of the
normalised size residual of the true template + 10 x corner loss. The corner loss takes the box built
from the true bin and template with the predicted residuals and centre, and the smaller of the summed
corner distances to the target box and to the target turned by pi, per box (F-PointNet takes the
minimum per corner, issue #60, and adds the size residual twice, issues #43/#49; neither is copied).
The one-hot input is the true class (as in F-PointNet training). Training samples are drawn with
probabilities proportional to n_c^-0.5 (cyclists are rare).

Phase 1 (`--epochs-box`): that loss, Adam lr 1e-3 cosine, selection on validation mean 3D IoU
(mean over the three classes). Phase 2 (`--epochs-energy`): the loss + `--lam` x squared energy hinge
on the gate-2 energy E = E(heading scores) + E(size scores); ID = the training targets with their true
class, OOD = the OOD proposals with a uniformly random class one-hot (at run time the classifier's
class goes into the box net, and an OOD proposal that passed gate 1 can carry any class). Margins as
for the classifier: the pre-trained model's mean ID / OOD energies, m_out >= m_in + `--min-gap`.
Selection: lowest validation (FPR95 of gate 2 - mean IoU). gamma_b per class: the energy that keeps
95 % of the validation ID targets of that class.
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

NH, NS = M.N_HEADING_BINS, M.N_SIZE_CLUSTERS
HALF_BIN = M.ANGLE_PER_BIN / 2


def huber(x, delta):
    a = x.abs()
    return torch.where(a <= delta, 0.5 * a * a, delta * (a - 0.5 * delta))


def corners(center, heading, size):
    """(B, 8, 3) corners of model-frame boxes: centre (B, 3), heading (B,), size (B, 3) l w h."""
    sx = torch.tensor([1, 1, -1, -1, 1, 1, -1, -1], dtype=center.dtype, device=center.device) * 0.5
    sy = torch.tensor([1, -1, -1, 1, 1, -1, -1, 1], dtype=center.dtype, device=center.device) * 0.5
    sz = torch.tensor([-1, -1, -1, -1, 1, 1, 1, 1], dtype=center.dtype, device=center.device) * 0.5
    x = size[:, 0:1] * sx
    y = size[:, 1:2] * sy
    z = size[:, 2:3] * sz
    c, s = torch.cos(heading)[:, None], torch.sin(heading)[:, None]
    return torch.stack([c * x - s * y, s * x + c * y, z], 2) + center[:, None, :]


class Targets:
    """Box targets of a batch as tensors: centre, heading bin + normalised residual, class, size residual."""

    def __init__(self, box: np.ndarray, cls: np.ndarray, dev):
        hb, hr = M.heading_to_bin(box[:, 6])
        ms = M.MEAN_SIZES[cls]
        t = lambda a, dt=torch.float32: torch.from_numpy(np.ascontiguousarray(a)).to(dev, dt)  # noqa: E731
        self.center = t(box[:, 0:3].astype(np.float32))
        self.heading = t(box[:, 6].astype(np.float32))
        self.size = t(box[:, 3:6].astype(np.float32))
        self.hb = t(hb.astype(np.int64), torch.int64)
        self.hr = t(hr.astype(np.float32))
        self.cls = t(cls.astype(np.int64), torch.int64)
        self.sr = t((box[:, 3:6] / ms - 1.0).astype(np.float32))
        self.ms = t(ms.astype(np.float32))


def box_loss(dc1, out, T: Targets, use_tnet=True):
    """Frustum PointNets loss; returns (total, parts dict)."""
    B = out.shape[0]
    ar = torch.arange(B, device=out.device)
    center = dc1 + out[:, 0:3]
    l_c = huber(torch.norm(center - T.center, dim=1), 2.0).mean()
    l_t = huber(torch.norm(dc1 - T.center, dim=1), 1.0).mean() if use_tnet else out.new_zeros(())
    hs, hr = out[:, 3:3 + NH], out[:, 3 + NH:3 + 2 * NH]
    o = 3 + 2 * NH
    ss, sr = out[:, o:o + NS], out[:, o + NS:].reshape(B, NS, 3)
    l_hc = F.cross_entropy(hs, T.hb)
    l_hr = huber(hr[ar, T.hb] - T.hr, 1.0).mean()
    l_sc = F.cross_entropy(ss, T.cls)
    sr_k = sr[ar, T.cls]
    l_sr = huber(torch.norm(sr_k - T.sr, dim=1), 1.0).mean()
    heading = T.hb.float() * M.ANGLE_PER_BIN + hr[ar, T.hb] * HALF_BIN
    size = T.ms * (1.0 + sr_k)
    pc = corners(center, heading, size)
    gc = corners(T.center, T.heading, T.size)
    gf = corners(T.center, T.heading + math.pi, T.size)
    d = torch.minimum(torch.norm(pc - gc, dim=2).sum(1), torch.norm(pc - gf, dim=2).sum(1))
    l_k = huber(d, 1.0).mean()
    total = l_c + l_t + l_hc + 20 * l_hr + l_sc + 20 * l_sr + 10 * l_k
    return total, dict(center=l_c.item(), tnet=l_t.item(), hcls=l_hc.item(), hres=l_hr.item(), scls=l_sc.item(),
                       sres=l_sr.item(), corner=l_k.item())


WIDTH_KEYS = ("tnet_point", "tnet_head", "point", "head", "pvle")


def widths_arg(text: str) -> dict:
    """--widths JSON -> BoxNet keyword arguments (lists of positive ints); a clear error otherwise."""
    w = C.json_object_arg(text, "--widths", WIDTH_KEYS)
    for k, v in w.items():
        if not isinstance(v, list) or not v or not all(isinstance(x, int) and 0 < x <= 1024 for x in v):
            raise ValueError(f"--widths: {k} must be a non-empty list of widths in [1, 1024], got {v!r}")
    return {k: tuple(v) for k, v in w.items()}


def add_args(ap):
    ap.add_argument("--data", type=pathlib.Path, required=True)
    ap.add_argument("--work", type=pathlib.Path, required=True)
    ap.add_argument("--out", type=pathlib.Path, required=True)
    ap.add_argument("--onnx", type=pathlib.Path)
    ap.add_argument("--epochs-box", type=int, default=40)
    ap.add_argument("--epochs-energy", type=int, default=15)
    ap.add_argument("--batch", type=int, default=64)
    ap.add_argument("--lam", type=float, default=0.1)
    ap.add_argument("--min-gap", type=float, default=3.0)
    ap.add_argument("--occlusion", type=float, default=0.0,
                    help="probability per training proposal of hiding a part of it (common.occlude); 0 = off")
    ap.add_argument("--no-pvle", action="store_true")
    ap.add_argument("--no-tnet", action="store_true")
    ap.add_argument("--widths", default="",
                    help='layer widths, JSON, any of tnet_point, tnet_head, point, head, pvle (e.g. \'{"point": [24, 48, '
                         '80], "head": [64, 32]}\'; default: models.BoxNet\'s (48, 96, 160) ...)')
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--device", default="cpu")
    ap.add_argument("--sensor", default=None)
    ap.add_argument("--no-progress", action="store_true")
    return ap


def train(a) -> dict:
    if not 0.0 <= a.occlusion <= 1.0:
        raise ValueError(f"--occlusion must be a probability in [0, 1], got {a.occlusion}")
    widths = widths_arg(a.widths)
    C.setup(a.seed, a.threads)
    dd = C.dist_from_env(a.device)  # None without torchrun: the single-process path below is unchanged
    main = dd is None or dd.main
    dev = dd.dev if dd else C.device(a.device)
    data = D.load(a.data)
    tr, va = C.split(data, 0), C.split(data, 1)
    ok = (tr["label"] >= 0) & ~np.isnan(tr["box"][:, 0])
    tr_id = np.nonzero(ok)[0]
    tr_ood = np.nonzero(tr["label"] < 0)[0]
    if len(tr_id) < a.batch or not ((va["label"] >= 0) & ~np.isnan(va["box"][:, 0])).any():
        raise ValueError(f"{a.data}: too few box targets to train ({len(tr_id)} training, none or few in validation)")
    if dd and len(tr_id) // dd.world < a.batch:
        raise ValueError(f"{a.data}: {len(tr_id)} box targets are too few for {dd.world} ranks of --batch {a.batch}")
    counts = np.bincount(tr["label"][tr_id], minlength=M.N_CLASSES).astype(np.float64)
    pw = 1.0 / np.sqrt(np.maximum(counts, 1))[tr["label"][tr_id]]
    pw /= pw.sum()
    cfg = dict(use_pvle=not a.no_pvle, use_tnet=not a.no_tnet, **widths)
    model = M.BoxNet(**cfg).to(dev)
    state_path = a.work / "state.pt"
    args_key = {k: (str(v) if isinstance(v, pathlib.Path) else v) for k, v in vars(a).items()
                if k not in ("no_progress", "threads", "device", "work", "out", "onnx", "command")}
    if not args_key.get("occlusion"):
        args_key.pop("occlusion", None)  # states made before the option resume as before
    if not args_key.get("widths"):
        args_key.pop("widths", None)  # the same for --widths at its default
    if dd:
        args_key["world_size"] = dd.world  # the shards depend on it: resume with the same number of ranks
    st = dict(epoch=0, history=[], best_box=None, best_en=None, margins=None, args=args_key)
    s = torch.load(state_path, map_location="cpu", weights_only=False) if main and state_path.exists() else None
    if dd:
        s = dd.bcast(s)  # rank 0 reads the state; --work need not be shared between machines
    if s is not None:
        if s.get("args") != args_key:
            raise ValueError(f"{state_path}: made with other arguments; remove {a.work} to start over")
        st = s
        model.load_state_dict(s["model"])
        if main:
            print(f"train_box: resuming after epoch {s['epoch']}", file=sys.stderr)
    net = dd.wrap(model) if dd else model  # trains through DDP; validation and export use `model`
    shards = []
    E1, E2 = a.epochs_box, a.epochs_energy
    t0 = time.perf_counter() - (st["history"][-1]["seconds"] if st["history"] else 0.0)
    for ep in range(st["epoch"], E1 + E2):
        phase = "box" if ep < E1 else "energy"
        if ep == E1 and E2 > 0:
            model.load_state_dict(st["best_box"]["state_dict"])
            if dd:
                dd.sync(model)
            if st["margins"] is None:
                r = MX.eval_box(model, tr, dev)
                ei, eo = r["energies"]["id"], r["energies"]["ood"]
                m_in = float(ei.mean())
                st["margins"] = dict(m_in=m_in, m_out=max(float(eo.mean()), m_in + a.min_gap),
                                     e_id_mean=float(ei.mean()), e_ood_mean=float(eo.mean()))
                if dd:
                    st["margins"] = dd.bcast(st["margins"])
        lr0, ne = (1e-3, E1) if phase == "box" else (5e-4, E2)
        k = ep if phase == "box" else ep - E1
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
            # this rank's shard of the targets (DistributedSampler, set_epoch), drawn from with the class
            # weights renormalised over the shard; the OOD rows are sharded too
            rng = np.random.default_rng([a.seed, ep, dd.rank])
            order = dd.shard(len(tr_id), ep, a.seed)
            ids, p_ids = tr_id[order], pw[order] / pw[order].sum()
            ood = tr_ood[dd.shard(len(tr_ood), ep, a.seed + 1, drop_last=False)] if len(tr_ood) else tr_ood
            shards.append(dict(epoch=ep + 1, id=ids.tolist(), ood=ood.tolist()))
            print(f"train_box: rank {dd.rank} of {dd.world}, epoch {ep + 1}: {len(ids)} box targets and "
                  f"{len(ood)} OOD proposals in this rank's shard", file=sys.stderr)
        else:
            rng = np.random.default_rng([a.seed, ep])
            ids, p_ids, ood = tr_id, pw, tr_ood
        nsteps = len(ids) // a.batch
        for _ in C.progress(range(nsteps), main and not a.no_progress, desc=f"box {phase} {ep + 1}/{E1 + E2}", leave=False):
            idx = ids[rng.choice(len(ids), a.batch, p=p_ids)]
            p, bx = C.augment(rng, tr["points"][idx], tr["box"][idx], a.occlusion)
            cls = tr["label"][idx].astype(np.int64)
            T = Targets(bx, cls, dev)
            if phase == "energy":
                oi = ood[rng.integers(0, len(ood), 2 * a.batch)]
                po, _ = C.augment(rng, tr["points"][oi], occlusion=a.occlusion)
                pts, vox = C.tensors(tr, np.concatenate([idx, oi]), dev, np.concatenate([p, po]))
                cls_all = np.concatenate([cls, rng.integers(0, M.N_CLASSES, len(oi))])
            else:
                pts, vox = C.tensors(tr, idx, dev, p)
                cls_all = cls
            oh = F.one_hot(torch.from_numpy(cls_all).to(dev), M.N_CLASSES).float()
            dc1, out = net(pts, vox, oh)
            n = len(idx)
            loss, _parts = box_loss(dc1[:n], out[:n], T, cfg["use_tnet"])
            if phase == "energy":
                e = C.box_energy(out)
                loss = loss + a.lam * C.hinge(e[:n], e[n:], st["margins"]["m_in"], st["margins"]["m_out"])
            opt.zero_grad()
            loss.backward()
            opt.step()
            tot += float(loss.detach())
            nb += 1
        if dd:
            tot, nb = dd.sum([tot, nb])  # the loss logged is the mean over all ranks' batches
            dd.sync(model)  # BN running statistics averaged over the ranks; one model everywhere
        r = MX.eval_box(model, va, dev)
        miou = MX.mean_iou(r)
        fpr = r["gate2"]["fpr95"]
        score = (fpr - miou) if phase == "energy" else -miou
        h = dict(epoch=ep + 1, phase=phase, lr=lr, loss=tot / max(nb, 1), val_mean_iou=miou, val_fpr95=fpr,
                 val_auroc=r["gate2"]["auroc"], score=score, seconds=time.perf_counter() - t0,
                 val_share=[r["box"][c].get("share_iou", float("nan")) for c in M.CLASSES])
        if dd:
            # every rank validates the same model on the whole validation split; rank 0's figures decide
            h = dd.bcast(h)
            miou, fpr, score = h["val_mean_iou"], h["val_fpr95"], h["score"]
        st["history"].append(h)
        key = "best_box" if phase == "box" else "best_en"
        if st[key] is None or score < st[key]["score"]:
            st[key] = dict(score=score, epoch=ep + 1, state_dict={k: v.detach().cpu().clone() for k, v in model.state_dict().items()})
        if main:
            print(f"box {phase} epoch {ep + 1}: loss {h['loss']:.3f} val mean IoU {miou:.3f} share>=thr "
                  f"{' '.join(f'{v:.2f}' for v in h['val_share'])} gate2 FPR95 {fpr:.3f} AUROC {h['val_auroc']:.3f}",
                  file=sys.stderr)
        st.update(epoch=ep + 1, model=model.state_dict(), opt=opt.state_dict(), opt_phase=phase)
        if main:
            C.save_atomic(st, state_path)  # state for resuming: rank 0 only
    C.dump_shards(dd, "box", shards)
    best = st["best_en"] if (E2 > 0 and st["best_en"] is not None) else st["best_box"]
    model.load_state_dict(best["state_dict"])
    model.eval()
    r = MX.eval_box(model, va, dev)
    gamma = C.per_class_gamma(r["energies"]["id"], r["energies"]["id_cls"])
    meta = dict(n_points=int(data["points"].shape[1]), gamma=gamma, energy_T=1.0, trained=1,
                sensor=a.sensor or data["meta"].get("sensor", ""), data=data["meta"].get("command", str(a.data)),
                z_origin=data["meta"].get("z_origin", "mean"),
                command=getattr(a, "command", None) or "python -m lidet_tools.train.train_box",
                margins=st["margins"], best_epoch=best["epoch"], seed=a.seed, history=st["history"],
                train_seconds=st["history"][-1]["seconds"] if st["history"] else 0.0)
    if dd:
        meta["world_size"] = dd.world
    ck = dict(kind="box", cfg=dict(model.cfg), state_dict=model.cpu().state_dict(), meta=meta)
    return C.write_outputs(ck, model, a, main, dd)  # checkpoint and ONNX from rank 0 only


def main(argv=None) -> int:
    return C.run_cli("train_box", add_args, train, __doc__, argv)


if __name__ == "__main__":
    sys.exit(main())
