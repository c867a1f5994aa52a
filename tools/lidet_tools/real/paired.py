# SPDX-License-Identifier: MIT
"""Two runs of `python -m lidet_tools.eval_real` compared frame by frame: is a change's gain on a handful of real
frames more than which frames happen to be there?

    python -m lidet_tools.real.paired BASE/report.json NEW/report.json [--range 40] [--boot 10000] [--seed 0]
        [--json]
    python -m lidet_tools.real.paired BASE_DIR NEW_DIR ...    # folders of eval_real --seeds K

Both reports must hold the same frames (the same side and sources of split.txt) and each frame's tallies at the
loose overlaps (`counts` in report.json, written by eval_real since the paired comparison exists). Per class: the
objects, how many each run found and the difference; the false positives per frame of each run and the difference.
The interval beside each difference is a paired bootstrap over frames: `--boot` times, as many frames as there are
are drawn with replacement, each draw summing both runs' tallies over the same frames; the 5th and 95th percentiles
of the differences form the 90 % interval, and `P(gain)` is the share of draws in which the new run does better
(more found, fewer false positives) minus the share in which it does worse. Frames are the unit because objects of
one frame share its scene, sensor and clutter: on the 16 training frames a change that finds 2 more of 113 cars,
both on one frame, has an interval from 0 to 2 and says nothing about the next street.

Folders of `eval_real --seeds K` (OUT/seed_<S>/report.json) compare draw by draw: both must hold the same seeds.
Each frame's tallies are then the mean over the seeds (the bootstrap over frames as above, on those means), and
`seeds +/-` counts the seeds whose draw gains and loses (the same seed on both sides: the same draw of every
cluster the two runs share). The draw alone moves the figures of 16 frames by a few objects (docs/EVALUATION.md,
section 4); a change that gains on every seed is worth a look, one that gains on the default seed alone is not.

Exit status 0; 2 with a message for a missing or unreadable report, different frames, or a report without
per-frame tallies (made before them: run eval_real again).
"""
from __future__ import annotations

import argparse
import json
import pathlib
import sys

import numpy as np

CLASSES = ("Car", "Pedestrian", "Cyclist")


class PairedError(Exception):
    """A report that cannot be compared (the message says why)."""


def load(path) -> dict:
    """report.json -> {(source, frame): {range: {class: [objects, found, detections, right]}}}, in file order."""
    p = pathlib.Path(path)
    try:
        rep = json.loads(p.read_text())
    except (OSError, ValueError) as e:
        raise PairedError(f"{p}: cannot read an eval_real report ({e})") from None
    frames = rep.get("frames") if isinstance(rep, dict) else None
    if not isinstance(frames, list) or not frames:
        raise PairedError(f"{p}: no frames (not a report.json of python -m lidet_tools.eval_real)")
    out = {}
    for f in frames:
        if "counts" not in f:
            raise PairedError(f"{p}: frame {f.get('source')} {f.get('frame')} has no per-frame tallies (`counts`): "
                              "the report predates them, run python -m lidet_tools.eval_real again")
        out[(f["source"], f["frame"])] = f["counts"]
    return out


def tallies(rep: dict, rng: str) -> tuple[list, np.ndarray, np.ndarray, np.ndarray]:
    """(frame keys, objects (F, C), found (F, C), false positives (F,)) within range `rng` ('20' or '40')."""
    keys = list(rep)
    try:
        t = np.array([[rep[k][rng][c] for c in CLASSES] for k in keys], dtype=np.int64)  # (F, C, 4)
    except KeyError as e:
        raise PairedError(f"no tallies for range {rng} m (have {sorted(next(iter(rep.values())))})") from e
    fp = (t[:, :, 2] - t[:, :, 3]).sum(axis=1)
    return keys, t[:, :, 0], t[:, :, 1], fp


def _interval(v) -> list:
    """The 90 % interval (5th and 95th percentiles) of the bootstrap's differences."""
    lo, hi = np.percentile(v, [5.0, 95.0])
    return [float(lo), float(hi)]


def _paired(base: dict, new: dict, rng: str, keys=None):
    """(keys, objects, found and false positives of base, of new) of two loaded reports of the same frames, in the
    order of `keys` (default: base's); PairedError when they hold other frames or count other objects."""
    if set(base) != set(new):
        only_b = sorted(set(base) - set(new))
        only_n = sorted(set(new) - set(base))
        raise PairedError(f"the reports hold different frames: only in the first {only_b[:5]}"
                          f"{' ...' if len(only_b) > 5 else ''}, only in the second {only_n[:5]}"
                          f"{' ...' if len(only_n) > 5 else ''}")
    keys, obj_b, found_b, fp_b = tallies(base if keys is None else {k: base[k] for k in keys}, rng)
    _, obj_n, found_n, fp_n = tallies({k: new[k] for k in keys}, rng)
    if not np.array_equal(obj_b, obj_n):
        raise PairedError("the reports count different objects in the same frames (another --min-points, readers "
                          "or split): compare runs of the same evaluation")
    return keys, obj_b, found_b, fp_b, found_n, fp_n


def compare(base: dict, new: dict, rng: str = "40", boot: int = 10000, seed: int = 0) -> dict:
    """The paired comparison of two loaded reports (see the module's docstring) as a dict."""
    keys, obj_b, found_b, fp_b, found_n, fp_n = _paired(base, new, rng)
    if boot < 1:
        raise PairedError(f"--boot must be at least 1, got {boot}")
    n = len(keys)
    draws = np.random.default_rng(seed).integers(0, n, size=(boot, n))
    d_found = (found_n - found_b)[draws].sum(axis=1)          # (boot, C)
    d_fp = (fp_n - fp_b)[draws].sum(axis=1) / n               # (boot,): per frame
    res = {"range_m": float(rng), "frames": n, "boot": boot, "seed": seed, "classes": {}}

    for j, c in enumerate(CLASSES):
        v = d_found[:, j]
        res["classes"][c] = {
            "objects": int(obj_b[:, j].sum()), "found_base": int(found_b[:, j].sum()),
            "found_new": int(found_n[:, j].sum()), "diff": int((found_n - found_b)[:, j].sum()),
            "interval90": _interval(v), "p_gain": float((v > 0).mean() - (v < 0).mean()),
            "frames_changed": int(((found_n - found_b)[:, j] != 0).sum())}
    res["fp_per_frame"] = {
        "base": float(fp_b.sum() / n), "new": float(fp_n.sum() / n), "diff": float((fp_n - fp_b).sum() / n),
        "interval90": _interval(d_fp), "p_gain": float((d_fp < 0).mean() - (d_fp > 0).mean()),
        "frames_changed": int((fp_n != fp_b).sum())}
    return res


def load_runs(path) -> dict:
    """A report.json, or a folder of `eval_real --seeds` (seed_<S>/report.json): {seed name: load(report)} ('' for
    a single report)."""
    p = pathlib.Path(path)
    if p.is_dir():
        reps = sorted(p.glob("seed_*/report.json"))
        if not reps:
            if (p / "report.json").exists():
                return {"": load(p / "report.json")}
            raise PairedError(f"{p}: neither seed_*/report.json (eval_real --seeds) nor report.json inside")
        return {r.parent.name[len("seed_"):]: load(r) for r in reps}
    return {"": load(p)}


def compare_runs(base: dict, new: dict, rng: str = "40", boot: int = 10000, seed: int = 0) -> dict:
    """compare() over the draws of two load_runs() results with the same seeds: found and false positives per frame
    the mean over the seeds, the bootstrap over frames on those means, and per seed the difference. One run each
    (two report.json files): compare() itself."""
    if set(base) != set(new):
        raise PairedError(f"the two runs hold different seeds: {sorted(base)} against {sorted(new)}")
    seeds = sorted(base, key=lambda x: (len(x), x))
    if len(seeds) == 1:
        return compare(base[seeds[0]], new[seeds[0]], rng, boot, seed)
    if boot < 1:
        raise PairedError(f"--boot must be at least 1, got {boot}")
    keys = list(base[seeds[0]])
    for sd in seeds:
        if set(base[sd]) != set(keys):
            raise PairedError(f"seed {sd}: other frames than seed {seeds[0]}'s")
    per = [_paired(base[sd], new[sd], rng, keys) for sd in seeds]  # (keys, obj, found_b, fp_b, found_n, fp_n)
    obj = per[0][1]
    found_b, fp_b, found_n, fp_n = (np.mean([t[i] for t in per], axis=0) for i in (2, 3, 4, 5))
    n = len(keys)
    draws = np.random.default_rng(seed).integers(0, n, size=(boot, n))
    d_found = (found_n - found_b)[draws].sum(axis=1)
    d_fp = (fp_n - fp_b)[draws].sum(axis=1) / n
    res = {"range_m": float(rng), "frames": n, "boot": boot, "seed": seed, "seeds": seeds, "classes": {}}
    for j, c in enumerate(CLASSES):
        v = d_found[:, j]
        ds = [int((t[4] - t[2])[:, j].sum()) for t in per]
        res["classes"][c] = {
            "objects": int(obj[:, j].sum()), "found_base": float(found_b[:, j].sum()),
            "found_new": float(found_n[:, j].sum()), "diff": float((found_n - found_b)[:, j].sum()),
            "interval90": _interval(v), "p_gain": float((v > 0).mean() - (v < 0).mean()),
            "per_seed": ds, "seeds_gain": int(sum(x > 0 for x in ds)), "seeds_loss": int(sum(x < 0 for x in ds))}
    dfs = [float((t[5] - t[3]).sum() / n) for t in per]
    res["fp_per_frame"] = {
        "base": float(fp_b.sum() / n), "new": float(fp_n.sum() / n), "diff": float((fp_n - fp_b).sum() / n),
        "interval90": _interval(d_fp), "p_gain": float((d_fp < 0).mean() - (d_fp > 0).mean()),
        "per_seed": dfs, "seeds_gain": int(sum(x < 0 for x in dfs)), "seeds_loss": int(sum(x > 0 for x in dfs))}
    return res


def markdown(res: dict, base_name: str, new_name: str) -> str:
    """The comparison as markdown tables: compare()'s, or compare_runs()'s over several seeds (found and false
    positives the mean over the draws, and the per-seed columns)."""
    r = res
    many = "seeds" in r
    if many:
        head = (f"Paired comparison over {r['frames']} frames within {r['range_m']:g} m and {len(r['seeds'])} draws "
                f"(seeds {', '.join(r['seeds'])}; first: `{base_name}`, second: `{new_name}`; found and false positives "
                "the mean over the draws; bootstrap over frames")
        last, rule = "seeds +/- | per seed", "---:|---|"
    else:
        head = (f"Paired comparison over {r['frames']} frames within {r['range_m']:g} m (first: `{base_name}`, "
                f"second: `{new_name}`; bootstrap over frames")
        last, rule = "frames changed", "---:|"
    L = [head + f", {r['boot']} draws, seed {r['seed']}; 90 % interval of the difference; P(gain): share of draws "
         "where the second does better minus where it does worse" +
         ("; seeds +/-: the seeds whose draw gains / loses, then each seed's difference):" if many else "):"), "",
         f"| class | objects | found, first | found, second | difference | 90 % interval | P(gain) | {last} |",
         "|---|---:|---:|---:|---:|---|---:|" + rule]

    def tail(v, fmt):
        if many:
            return f"{v['seeds_gain']} / {v['seeds_loss']} | " + ", ".join(format(x, fmt) for x in v["per_seed"])
        return str(v["frames_changed"])
    for c, v in r["classes"].items():
        if v["objects"] == 0 and v["diff"] == 0:
            continue
        lo, hi = v["interval90"]
        n, d, i = (".1f", "+.1f", "+.1f") if many else ("d", "+d", "+.0f")
        L.append(f"| {c} | {v['objects']} | {v['found_base']:{n}} | {v['found_new']:{n}} | {v['diff']:{d}} | "
                 f"[{lo:{i}}, {hi:{i}}] | {v['p_gain']:+.2f} | {tail(v, '+d')} |")
    f = r["fp_per_frame"]
    lo, hi = f["interval90"]
    L += ["", f"| false positives per frame | first | second | difference | 90 % interval | P(gain) | {last} |",
          "|---|---:|---:|---:|---|---:|" + rule,
          f"| all classes | {f['base']:.2f} | {f['new']:.2f} | {f['diff']:+.2f} | [{lo:+.2f}, {hi:+.2f}] | "
          f"{f['p_gain']:+.2f} | {tail(f, '+.2f')} |"]
    return "\n".join(L)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m lidet_tools.real.paired", description=__doc__.split("\n\n")[0])
    ap.add_argument("base", help="the first run's report.json (eval_real --out DIR writes DIR/report.json), or a "
                                 "folder of eval_real --seeds K")
    ap.add_argument("new", help="the second run's report.json, on the same frames (a folder: the same seeds)")
    ap.add_argument("--range", choices=("20", "40"), default="40", help="within 20 or 40 m (default 40)")
    ap.add_argument("--boot", type=int, default=10000, help="bootstrap draws (default 10000)")
    ap.add_argument("--seed", type=int, default=0, help="the draws' seed (default 0)")
    ap.add_argument("--json", action="store_true", help="print the comparison as JSON")
    a = ap.parse_args(argv)
    try:
        res = compare_runs(load_runs(a.base), load_runs(a.new), a.range, a.boot, a.seed)
    except PairedError as e:
        print(f"lidet_tools.real.paired: {e}", file=sys.stderr)
        return 2
    print(json.dumps(res, indent=1) if a.json else markdown(res, a.base, a.new))
    return 0


if __name__ == "__main__":
    sys.exit(main())
