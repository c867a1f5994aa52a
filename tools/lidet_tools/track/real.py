# SPDX-License-Identifier: MIT
"""The tracker on real consecutive scans (issue 38): SemanticKITTI sequence 00, scans 0-5 of ../shared/data/real
(scans 0-2 carry per-point instance labels whose ids persist across scans; 3-5 have none).

    python -m lidet_tools.track.real [--root ../shared/data/real] [--json]

lidet's float detector (the hdl64 models) on each scan, lidet's tracker and the AB3DMOT-style peer on the same
detections, dt 0.1 s (KITTI's 10 Hz) and no ego motion (the sequence's poses are not in the folder: velocities
are relative to the car, which drives here). Ground truth of scans 0-2: the labelled objects
(`lidet_tools.real.semantickitti`, boxes fitted to their points) with their instance id as the track id; objects
of a class without instance ids (split by clustering) count as ignored ground truth. Scored by
`lidet_tools.track.eval` (within 40 m, >= 10 points); with three labelled scans and confirmation after two hits,
the figures say whether ids hold, not how good the tracker is.
"""
from __future__ import annotations

import argparse
import json
import pathlib
import sys

import numpy as np

from . import eval as tev

FRAMES = [f"00_{i:06d}" for i in range(6)]
LABELLED = 3
DT_S = 0.1
CLS_INDEX = {"Car": 0, "Cyclist": 1, "Pedestrian": 2}


def _gt_frame(root: pathlib.Path, stem: str) -> dict:
    from ..kitti import read_bin, read_label
    from ..real import semantickitti as sk
    fr = sk.load_frame(root, stem)
    raw = read_bin(root / sk.SUBDIR / "velodyne" / f"{stem}.bin")
    _sem, ins = read_label(root / sk.SUBDIR / "labels" / f"{stem}.label", len(raw))
    keep = np.isfinite(raw[:, :3]).all(axis=1)
    ins = ins[keep]
    rows = []
    for k, b in enumerate(fr.boxes):
        members = fr.point_instance == k
        ids = ins[members]
        ids = ids[ids > 0]
        # an object without an instance id (split by clustering) has no identity to keep: ignored ground truth
        oid = int(np.bincount(ids).argmax()) if ids.size else -1 - k
        cls = b.cls if (ids.size and b.cls in CLS_INDEX) else "Van"
        rows.append({"id": oid, "cls": cls, "x": float(b.x), "y": float(b.y), "vx": 0.0, "vy": 0.0,
                     "npts": int(members.sum())})
    return {k: [r[k] for r in rows] for k in ("id", "cls", "x", "y", "vx", "vy", "npts")}


def run(root) -> dict:
    from .. import native
    from ..kitti import read_bin
    from .native import Tracker
    from .peer import PeerTracker
    root = pathlib.Path(root)
    scans = [root / "semantickitti" / "velodyne" / f"{s}.bin" for s in FRAMES]
    missing = [str(p) for p in scans if not p.exists()]
    if missing:
        raise FileNotFoundError(f"not found: {', '.join(missing)}")
    dets = []
    for p in scans:
        det = native.detect(read_bin(p), "hdl64")
        d = np.zeros((len(det.cls), 9), np.float32)
        d[:, 0], d[:, 1:8], d[:, 8] = det.cls, det.box, det.score
        dets.append(d)
    gt = [_gt_frame(root, s) for s in FRAMES[:LABELLED]]
    res = {"frames": FRAMES, "labelled": LABELLED, "detections_per_scan": [len(d) for d in dets], "trackers": {}}
    for name, make in (("lidet", Tracker), ("peer", PeerTracker)):
        trk = make()
        outs = [trk.update(d, DT_S, None, 0) for d in dets]
        ev = tev.evaluate([(gt, outs[:LABELLED])], names=["00"])
        o = ev["overall"]
        res["trackers"][name] = {
            "num_switches": o["num_switches"], "num_matches": o["num_matches"], "num_objects": o["num_objects"],
            "num_unique_objects": o["num_unique_objects"], "num_false_positives": o["num_false_positives"],
            "mota": o["mota"], "idf1": o["idf1"],
            "tracks_per_scan": [int(len(x)) for x in outs],
            "ids_kept_scans_3_5": _ids_kept(outs)}
    return res


def _ids_kept(outs) -> dict:
    """Of the confirmed tracks in scan 2 (the last labelled one), how many still have their id in scan 5."""
    a = {int(i) for i in outs[LABELLED - 1]["id"]}
    b = {int(i) for i in outs[-1]["id"]}
    return {"tracks_scan_2": len(a), "still_there_scan_5": len(a & b)}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m lidet_tools.track.real", description=__doc__.split("\n\n")[0])
    ap.add_argument("--root", default="../shared/data/real")
    ap.add_argument("--json", action="store_true")
    a = ap.parse_args(argv)
    try:
        res = run(a.root)
    except FileNotFoundError as e:
        print(f"lidet_tools.track.real: {e}", file=sys.stderr)
        return 2
    if a.json:
        print(json.dumps(res, indent=1))
        return 0
    print(f"SemanticKITTI 00, scans 0-5 (0-{LABELLED - 1} labelled); detections per scan "
          f"{res['detections_per_scan']}")
    for name, r in res["trackers"].items():
        print(f"{name:6s} matches {r['num_matches']} of {r['num_objects']} (objects {r['num_unique_objects']}), "
              f"id switches {r['num_switches']}, false positives {r['num_false_positives']}, tracks per scan "
              f"{r['tracks_per_scan']}, ids of scan 2 still there in scan 5: {r['ids_kept_scans_3_5']}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
