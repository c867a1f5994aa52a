# SPDX-License-Identifier: MIT
"""The float and the integer detector on the same real frames, proposal by proposal: do they draw the same points
and give them the same energies?

    python -m lidet_tools.real.agree [--root ../shared/data/real] [--side train|val|all] [--model hdl64]
        [--min-members 65] [--json]

For each frame of the split: the float detector's classified candidates (`native.candidates_float`, the scan as it
comes) and the integer detector's (`native.candidates_q`, the scan rounded to millimetres), both with the frame's
sensor preset and its default mount height, the classifier of `--model` (float and int8). Candidates are matched
by their means (within 5 cm); clusters of at most 64 members give every member to their proposal either way, so
only larger ones (`--min-members`) are compared. Per matched pair: whether the two clusters have the same member
count, the share of the float proposal's points that the integer proposal holds too (a point within 1.5 cm: the
4 mm steps of the integer image), and the difference of the two classifiers' energies. The table splits the pairs
by equal and different member counts: a pixel more or less in a cluster is where the proposals' draw matters
(docs/journal/real-streets.md, "Kept: a draw the pixels decide").

Exit status 0; 2 with a message when the folder is not there.
"""
from __future__ import annotations

import argparse
import json
import pathlib
import sys

import numpy as np

from .. import native

SHARE_M = 0.015  # a float proposal point is shared when the integer proposal has one this close
MATCH_M = 0.05   # candidates match when their means are this close


def frame_pairs(points: np.ndarray, sensor: str, model: str = "hdl64", min_members: int = 65) -> list[dict]:
    """The matched candidates of one scan (N, 4) float32: [{'members_float', 'members_int', 'shared', 'energy_float',
    'energy_int'}] for clusters of at least min_members members."""
    cf = native.candidates_float(points, sensor, model=model)
    cq = native.candidates_q(np.round(points[:, :3] * 1000.0).astype(np.int32), sensor, model=model)
    if len(cf["mean"]) == 0 or len(cq["mean"]) == 0:
        return []
    ef = native.pn_classify(f"cls_{model}", cf["xyz"], cf["mean"], cf["voxel"])["energy"]
    eq = native.pnq_classify(f"cls_{model}_s8", cq["xyz"], cq["mean"], cq["voxel"])["energy"] / 65536.0
    mq = cq["mean"].astype(np.float64) * 0.004
    out = []
    for i in range(len(cf["mean"])):
        d = np.linalg.norm(mq - cf["mean"][i], axis=1)
        j = int(np.argmin(d))
        if d[j] > MATCH_M or int(cf["n_points"][i]) < min_members:
            continue
        pf = cf["xyz"][i].astype(np.float64) + cf["mean"][i]
        pq = cq["xyz"][j].astype(np.float64) * 0.004 + mq[j]
        near = np.linalg.norm(pf[:, None, :] - pq[None, :, :], axis=2).min(1) < SHARE_M
        out.append(dict(members_float=int(cf["n_points"][i]), members_int=int(cq["n_points"][j]),
                        shared=float(near.mean()), energy_float=float(ef[i]), energy_int=float(eq[j])))
    return out


def summary(pairs: list[dict]) -> dict:
    """Per group (all, same member count, other member count): pairs, mean shared share, the energy difference's
    mean and 90th percentile of its size, and how many differ by more than 0.3 nats."""
    out = {}
    same = np.array([p["members_float"] == p["members_int"] for p in pairs], bool)
    for name, m in (("all", np.ones(len(pairs), bool)), ("same member count", same),
                    ("other member count", ~same)):
        sel = [p for p, k in zip(pairs, m) if k]
        if not sel:
            out[name] = dict(pairs=0)
            continue
        de = np.abs([p["energy_int"] - p["energy_float"] for p in sel])
        out[name] = dict(pairs=len(sel), shared=float(np.mean([p["shared"] for p in sel])),
                         energy_diff_mean=float(de.mean()), energy_diff_p90=float(np.percentile(de, 90)),
                         over_0_3_nats=int((de > 0.3).sum()))
    return out


def markdown(s: dict, what: str) -> str:
    L = [f"Float against integer candidates, {what} (clusters of more than 64 members, matched by their means):", "",
         "| pairs | number | points shared | energy difference, mean / 90th pct. (nats) | more than 0.3 nats |",
         "|---|---:|---:|---|---:|"]
    for name, v in s.items():
        if v["pairs"] == 0:
            L.append(f"| {name} | 0 | - | - | - |")
            continue
        L.append(f"| {name} | {v['pairs']} | {v['shared']:.3f} | {v['energy_diff_mean']:.3f} / "
                 f"{v['energy_diff_p90']:.3f} | {v['over_0_3_nats']} |")
    return "\n".join(L) + "\n"


def main(argv=None) -> int:
    from .. import eval_real as ER
    from .. import real
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--root", default=str(ER.ROOT.parent / "shared" / "data" / "real"))
    ap.add_argument("--side", choices=("train", "val", "all"), default="train")
    ap.add_argument("--model", default="hdl64", help="model family (float and int8 classifiers)")
    ap.add_argument("--min-members", type=int, default=65)
    ap.add_argument("--json", action="store_true", help="print the summary as JSON")
    a = ap.parse_args(argv)
    root = pathlib.Path(a.root)
    if not root.is_dir():
        print(f"agree: {root} not found (the real frames live in ../shared/data/real)", file=sys.stderr)
        return 2
    pairs = []
    for src, fid, side in ER.read_split(ER.SPLIT):
        if a.side != "all" and side != a.side:
            continue
        fr = real.load_frame(root, src, fid)
        pairs += frame_pairs(fr.points, fr.sensor, a.model, a.min_members)
    s = summary(pairs)
    print(json.dumps(s, indent=1) if a.json else markdown(s, f"side {a.side} of split.txt, models {a.model}"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
