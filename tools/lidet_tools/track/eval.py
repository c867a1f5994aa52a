# SPDX-License-Identifier: MIT
"""Tracking evaluation (issue 38): CLEAR MOT and identity metrics with py-motmetrics, velocity errors.

    lidet-eval track --gt data/sim/seq/0000 data/sim/seq/0001 --pred PRED_DIR [--range 40] [--min-points 10] [--json]

Matching is in the bird's eye view by the distance of the box centres, per class, within `MATCH_DIST_M`
(Car 2 m, Pedestrian 1 m, Cyclist 1.5 m): py-motmetrics' accumulator gets, per scan and class, the ground truth
that counts and the predictions of that class, with the centre distance where it is within the class's threshold
(NaN otherwise), and keeps a match from one scan to the next while it stays within it (CLEAR MOT). MOTP is then
the mean centre distance of the matches, in metres (lower is better).

Ground truth that counts: its class, within `max_range_m` of the sensor (BEV distance of the centre), and with at
least `min_points` points in the scan. The rest is ignored, as KITTI's DontCare: ground truth of the class out of
range or with fewer points, and of the neighbouring class (Car: Van), is matched first (the same distance test,
optimal assignment) and the predictions it takes are dropped, as are unmatched predictions beyond max_range_m.

Velocity error: for every match of a prediction (a confirmed track: `state` != 0 where the prediction has a
state) with ground truth, |v_pred - v_gt| over the ground in the BEV (m/s); its median and 90th percentile per
class. Id switches per 100 ground-truth tracks: 100 num_switches / num_unique_objects.

A frame (ground truth or prediction) is a dict of arrays, a numpy structured array (the trackers' output) or a
list of dicts, with fields id, cls (a class name, or lidet_class_t's index: 0 Car, 1 Cyclist, 2 Pedestrian),
x, y, vx, vy; ground truth optionally npts, predictions optionally state. `evaluate` takes them in memory;
`evaluate_dirs` reads sequence folders (lidet-sim --sequence: tracks/<frame>.txt) and prediction folders
(the same lines, `id class x y z l w h yaw vx vy [score]`, PRED_DIR/<seq>/tracks/ or PRED_DIR/tracks/).
"""
from __future__ import annotations

import json
import os
import pathlib

import numpy as np

CLASSES = ("Car", "Pedestrian", "Cyclist")
#: lidet_class_t order (the trackers' integer classes)
NATIVE_CLASSES = ("Car", "Cyclist", "Pedestrian")
MATCH_DIST_M = {"Car": 2.0, "Pedestrian": 1.0, "Cyclist": 1.5}
#: ground truth of these classes is ignored (not missed, and predictions on it not false) for the key class
NEIGHBOURS = {"Car": ("Van",), "Pedestrian": ("Person_sitting",), "Cyclist": ()}
MAX_RANGE_M = 40.0
MIN_POINTS = 10
METRICS = ("num_frames", "mota", "motp", "idf1", "idp", "idr", "precision", "recall", "num_switches",
           "num_fragmentations", "mostly_tracked", "partially_tracked", "mostly_lost", "num_false_positives",
           "num_misses", "num_objects", "num_matches", "num_unique_objects")
FIELDS = ("id", "cls", "x", "y", "vx", "vy")


def _cls_name(c) -> str:
    if isinstance(c, (int, np.integer)):
        return NATIVE_CLASSES[int(c)] if 0 <= int(c) < len(NATIVE_CLASSES) else f"class{int(c)}"
    if isinstance(c, bytes):
        return c.decode()
    return str(c)


def frame_arrays(f) -> dict:
    """One frame (dict of arrays, structured array, list of dicts, or None) -> dict of arrays: id (int64), cls
    (object: names), x, y, vx, vy (float64), npts (int64, -1 unknown), state (int64, -1 unknown)."""
    if f is None:
        f = []
    if isinstance(f, np.ndarray) and f.dtype.names:
        d = {k: f[k] for k in f.dtype.names}
    elif isinstance(f, dict):
        d = f
    else:
        rows = list(f)
        d = {k: [r[k] for r in rows] for k in (rows[0].keys() if rows else FIELDS)}
    n = len(d["id"]) if "id" in d else 0
    out = {"id": np.asarray(d.get("id", []), dtype=np.int64).reshape(n),
           "cls": np.array([_cls_name(c) for c in (d["cls"] if n else [])], dtype=object).reshape(n)}
    for k in ("x", "y", "vx", "vy"):
        out[k] = np.asarray(d[k] if n else [], dtype=np.float64).reshape(n)
    for k in ("npts", "state"):
        out[k] = np.asarray(d[k], dtype=np.int64).reshape(n) if (n and k in d) else np.full(n, -1, np.int64)
    return out


def _take(f, m):
    return {k: v[m] for k, v in f.items()}


def _dist(g, p):
    return np.hypot(g["x"][:, None] - p["x"][None, :], g["y"][:, None] - p["y"][None, :])


def _class_frame(g, p, c, thr, max_range_m, min_points):
    """The ground truth that counts, the predictions kept, and their distance matrix (NaN beyond thr)."""
    from scipy.optimize import linear_sum_assignment
    rng_g = np.hypot(g["x"], g["y"])
    is_c = g["cls"] == c
    counts = is_c & (rng_g <= max_range_m) & ((g["npts"] < 0) | (g["npts"] >= min_points))
    ign = (is_c & ~counts) | np.isin(g["cls"], NEIGHBOURS.get(c, ()))
    pm = p["cls"] == c
    pc = _take(p, pm)
    drop = np.zeros(len(pc["id"]), bool)
    if ign.any() and len(pc["id"]):
        # ignored ground truth takes its predictions first (optimal, within thr, with the counting ground truth
        # competing, so a prediction on a counting object is never taken away from it)
        gg = _take(g, counts | ign)
        d = _dist(gg, pc)
        cost = np.where(d <= thr, d, 1e6)
        r, k = linear_sum_assignment(cost)
        ok = cost[r, k] < 1e6
        is_ign = ign[counts | ign]
        drop[k[ok & is_ign[r]]] = True
    far = np.hypot(pc["x"], pc["y"]) > max_range_m
    if far.any():
        gc = _take(g, counts)
        near_gt = (_dist(gc, pc) <= thr).any(0) if len(gc["id"]) else np.zeros(len(pc["id"]), bool)
        drop |= far & ~near_gt
    gk, pk = _take(g, counts), _take(pc, ~drop)
    d = _dist(gk, pk)
    d = np.where(d <= thr, d, np.nan)
    return gk, pk, d


def evaluate(sequences, classes=CLASSES, match_dist=None, max_range_m: float = MAX_RANGE_M,
             min_points: int = MIN_POINTS, names=None) -> dict:
    """CLEAR MOT / identity metrics and velocity errors.

    sequences: a list of (gt_frames, pred_frames) pairs (or one pair), each a list with one frame per scan (see
    the module doc). Returns {"classes": {cls: metrics}, "overall": metrics, "params": ...}; metrics: MOTA, MOTP
    (m), IDF1, ..., num_switches, ids_per_100 (per 100 ground-truth tracks), num_fragmentations, mostly_tracked,
    mostly_lost, num_false_positives, num_misses, vel_err {n, median, p90, mean} (m/s)."""
    import motmetrics as mm
    if isinstance(sequences, tuple) and len(sequences) == 2 and not isinstance(sequences[0], tuple):
        sequences = [sequences]
    thr = dict(MATCH_DIST_M, **(match_dist or {}))
    names = names or [f"seq{i}" for i in range(len(sequences))]
    accs = {c: [] for c in classes}
    vel = {c: [] for c in classes}
    dsum = {c: [0.0, 0] for c in classes}      # MOTP: distances of the matches, summed here (motmetrics' overall
    #                                            MOTP is NaN as soon as one accumulator has no match)
    for (gt_frames, pred_frames), nm in zip(sequences, names):
        gt_frames, pred_frames = list(gt_frames), list(pred_frames)
        if len(pred_frames) < len(gt_frames):
            pred_frames += [None] * (len(gt_frames) - len(pred_frames))
        for c in classes:
            acc = mm.MOTAccumulator(auto_id=False)
            gv, pv = {}, {}
            for k, (gf, pf) in enumerate(zip(gt_frames, pred_frames)):
                g, p = frame_arrays(gf), frame_arrays(pf)
                gk, pk, d = _class_frame(g, p, c, thr[c], max_range_m, min_points)
                acc.update(gk["id"].tolist(), pk["id"].tolist(), d, frameid=k)
                for i, oid in enumerate(gk["id"]):
                    gv[(k, int(oid))] = (gk["vx"][i], gk["vy"][i])
                for i, hid in enumerate(pk["id"]):
                    pv[(k, int(hid))] = (pk["vx"][i], pk["vy"][i], pk["state"][i])
            accs[c].append(acc)
            ev = acc.mot_events
            if len(ev):
                m = ev[ev["Type"].isin(["MATCH", "SWITCH"])]
                dsum[c][0] += float(m["D"].sum())
                dsum[c][1] += len(m)
                for (fr, _e), oid, hid in zip(m.index, m["OId"], m["HId"]):
                    a = gv[(int(fr), int(oid))]
                    b = pv[(int(fr), int(hid))]
                    if b[2] != 0:
                        vel[c].append(float(np.hypot(b[0] - a[0], b[1] - a[1])))
    mh = mm.metrics.create()
    out = {"classes": {}, "params": {"match_dist_m": {c: thr[c] for c in classes}, "max_range_m": max_range_m,
                                     "min_points": min_points, "neighbours_ignored": {c: list(NEIGHBOURS.get(c, ()))
                                                                                      for c in classes},
                                     "n_sequences": len(sequences)}}
    all_accs, all_names = [], []
    for c in classes:
        s = mh.compute_many(accs[c], metrics=list(METRICS), names=[f"{c}:{n}" for n in names], generate_overall=True)
        out["classes"][c] = _metrics(s.loc["OVERALL"], vel[c])
        out["classes"][c]["motp"] = dsum[c][0] / dsum[c][1] if dsum[c][1] else None
        all_accs += accs[c]
        all_names += [f"{c}:{n}" for n in names]
    s = mh.compute_many(all_accs, metrics=list(METRICS), names=all_names, generate_overall=True)
    out["overall"] = _metrics(s.loc["OVERALL"], [v for c in classes for v in vel[c]])
    nm = sum(dsum[c][1] for c in classes)
    out["overall"]["motp"] = sum(dsum[c][0] for c in classes) / nm if nm else None
    out["overall"]["num_frames"] = out["classes"][classes[0]]["num_frames"] if classes else 0
    return out


def _metrics(row, vel) -> dict:
    d = {}
    for k in METRICS:
        v = float(row[k])
        d[k] = v if np.isfinite(v) else None
    for k in ("num_frames", "num_switches", "num_fragmentations", "mostly_tracked", "partially_tracked",
              "mostly_lost", "num_false_positives", "num_misses", "num_objects", "num_matches", "num_unique_objects"):
        if d[k] is not None:
            d[k] = int(round(d[k]))
    n_gt = d["num_unique_objects"] or 0
    d["ids_per_100"] = 100.0 * d["num_switches"] / n_gt if n_gt else None
    v = np.asarray(vel, dtype=np.float64)
    d["vel_err"] = ({"n": int(v.size), "median": float(np.median(v)), "p90": float(np.percentile(v, 90)),
                     "mean": float(v.mean())} if v.size else {"n": 0, "median": None, "p90": None, "mean": None})
    return d


# ------------------------------------------------------------------------------------------------
# files


def read_tracks(path, gt: bool = True) -> dict:
    """tracks/<frame>.txt -> frame arrays. Lines `id class x y z l w h yaw vx vy [npts | score]` ('#' starts a
    comment); the 12th field is npts in ground truth (gt=True), a score in predictions."""
    ids, cls, vals, extra = [], [], [], []
    with open(path) as f:
        for ln, line in enumerate(f, 1):
            line = line.split("#", 1)[0].strip()
            if not line:
                continue
            p = line.split()
            if len(p) not in (11, 12):
                raise ValueError(f"{path}:{ln}: expected 11 or 12 fields 'id class x y z l w h yaw vx vy [npts|score]',"
                                 f" got {len(p)}")
            try:
                ids.append(int(p[0]))
                vals.append([float(x) for x in p[2:11]])
                extra.append(float(p[11]) if len(p) == 12 else np.nan)
            except ValueError:
                raise ValueError(f"{path}:{ln}: non-numeric field") from None
            if not np.all(np.isfinite(vals[-1])):
                raise ValueError(f"{path}:{ln}: non-finite field (nan or inf)")
            cls.append(p[1])
    v = np.asarray(vals, dtype=np.float64).reshape(-1, 9)
    e = np.asarray(extra, dtype=np.float64)
    d = {"id": np.asarray(ids, np.int64), "cls": np.array(cls, dtype=object), "x": v[:, 0], "y": v[:, 1],
         "z": v[:, 2], "box": v[:, :7], "vx": v[:, 7], "vy": v[:, 8]}
    if gt:
        d["npts"] = np.where(np.isfinite(e), e, -1).astype(np.int64)
    else:
        d["score"] = e
    return d


def write_tracks(path, frame, score_field: str = "score") -> None:
    """Prediction lines `id class x y z l w h yaw vx vy score` from a tracker's output (structured array with
    fields id, cls, x, y, z, l, w, h, yaw, vx, vy[, score]) or a dict of arrays."""
    os.makedirs(os.path.dirname(os.fspath(path)) or ".", exist_ok=True)
    f = frame
    n = len(f["id"])
    with open(path, "w") as fh:
        fh.write("# id class x y z l w h yaw vx vy score (sensor frame; velocity over the ground, m/s)\n")
        for i in range(n):
            sc = float(f[score_field][i]) if (score_field in (f.dtype.names if isinstance(f, np.ndarray) else f)) \
                else 1.0
            fh.write(f"{int(f['id'][i])} {_cls_name(f['cls'][i])} {f['x'][i]:.4f} {f['y'][i]:.4f} {f['z'][i]:.4f} "
                     f"{f['l'][i]:.4f} {f['w'][i]:.4f} {f['h'][i]:.4f} {f['yaw'][i]:.5f} {f['vx'][i]:.4f} "
                     f"{f['vy'][i]:.4f} {sc:.4f}\n")


def _frames_of(d: pathlib.Path) -> list:
    t = d / "tracks"
    if not t.is_dir():
        raise FileNotFoundError(f"{t}: no tracks/ folder")
    return sorted(t.glob("*.txt"))


def load_gt(seq_dir) -> list:
    """A sequence folder's ground truth, one frame per scan. Without an npts column, points are counted in each
    box (where_lost.points_in_box, 0.1 m margin) from velodyne/<frame>.bin."""
    d = pathlib.Path(seq_dir)
    out = []
    for p in _frames_of(d):
        f = read_tracks(p, gt=True)
        if len(f["id"]) and (f["npts"] < 0).any():
            from .. import kitti
            from ..where_lost import points_in_box
            pts = kitti.read_bin(d / "velodyne" / f"{p.stem}.bin")
            f["npts"] = np.array([int(points_in_box(pts, b).sum()) for b in f["box"]], np.int64)
        out.append(f)
    return out


def load_pred(pred_dir, seq_name: str | None = None, n_frames: int | None = None, names=None,
              flat_ok: bool = True) -> list:
    """Predictions of a sequence: PRED_DIR/<seq_name>/tracks/<frame>.txt, else (flat_ok) PRED_DIR/tracks/. Frames
    are aligned by file name with the ground truth's (names); a missing file is an empty frame."""
    d = pathlib.Path(pred_dir)
    if seq_name is not None and (d / seq_name / "tracks").is_dir():
        d = d / seq_name
    elif seq_name is not None and not flat_ok:
        raise FileNotFoundError(f"{d / seq_name / 'tracks'}: no predictions for sequence {seq_name}")
    t = d / "tracks"
    if not t.is_dir():
        raise FileNotFoundError(f"{t}: no predictions for sequence {seq_name}")
    names = names or [p.stem for p in sorted(t.glob("*.txt"))][:n_frames]
    return [read_tracks(t / f"{n}.txt", gt=False) if (t / f"{n}.txt").exists() else None for n in names]


def evaluate_dirs(gt_dirs, pred_dir, **kw) -> dict:
    seqs, names = [], []
    for g in gt_dirs:
        g = pathlib.Path(g)
        gt = load_gt(g)
        fn = [p.stem for p in _frames_of(g)]
        seqs.append((gt, load_pred(pred_dir, g.name, names=fn, flat_ok=len(gt_dirs) == 1)))
        names.append(g.name)
    return evaluate(seqs, names=names, **kw)


# ------------------------------------------------------------------------------------------------
# tables

ROWS = (("MOTA", "mota", "{:.3f}"), ("MOTP (m)", "motp", "{:.3f}"), ("IDF1", "idf1", "{:.3f}"),
        ("id switches", "num_switches", "{:d}"), ("id sw. / 100 GT tracks", "ids_per_100", "{:.1f}"),
        ("fragmentations", "num_fragmentations", "{:d}"), ("mostly tracked", "mostly_tracked", "{:d}"),
        ("partially tracked", "partially_tracked", "{:d}"), ("mostly lost", "mostly_lost", "{:d}"),
        ("false positives", "num_false_positives", "{:d}"), ("misses", "num_misses", "{:d}"),
        ("GT tracks", "num_unique_objects", "{:d}"), ("GT boxes", "num_objects", "{:d}"),
        ("vel. err. median (m/s)", ("vel_err", "median"), "{:.3f}"),
        ("vel. err. p90 (m/s)", ("vel_err", "p90"), "{:.3f}"))


def _get(m, key):
    if isinstance(key, tuple):
        return m[key[0]][key[1]]
    return m[key]


def _fmt(v, f):
    if v is None:
        return "-"
    return f.format(int(v)) if f == "{:d}" else f.format(v)


def format_table(res: dict, title: str = "") -> str:
    cols = list(res["classes"]) + ["overall"]
    per = dict(res["classes"], overall=res["overall"])
    w = max(len(r[0]) for r in ROWS) + 2
    lines = [title] if title else []
    lines.append("".ljust(w) + "".join(c.rjust(12) for c in cols))
    for name, key, f in ROWS:
        lines.append(name.ljust(w) + "".join(_fmt(_get(per[c], key), f).rjust(12) for c in cols))
    return "\n".join(lines)


def compare_table(results: dict, title: str = "", classes=None) -> str:
    """Side by side: {name: evaluate() result}; with two names, the ratio first / second per row."""
    names = list(results)
    classes = classes or (list(next(iter(results.values()))["classes"]) + ["overall"])
    w = max(len(r[0]) for r in ROWS) + 2
    lines = [title] if title else []
    for c in classes:
        hdr = f"[{c}]".ljust(w) + "".join(n.rjust(12) for n in names) + ("ratio".rjust(9) if len(names) == 2 else "")
        lines.append(hdr)
        for name, key, f in ROWS:
            vals = [_get(results[n]["overall"] if c == "overall" else results[n]["classes"][c], key) for n in names]
            row = name.ljust(w) + "".join(_fmt(v, f).rjust(12) for v in vals)
            if len(names) == 2:
                a, b = vals
                row += (f"{a / b:9.2f}" if (a is not None and b not in (None, 0)) else "-".rjust(9))
            lines.append(row)
        lines.append("")
    return "\n".join(lines).rstrip()


def to_json(res: dict) -> str:
    return json.dumps(res, indent=1, sort_keys=False)
