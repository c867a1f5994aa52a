# SPDX-License-Identifier: MIT
"""Proposal datasets for the two PointNets, made by lidet's own C stages (bindings).

Every scan goes through projection -> ground stage -> depth clustering (with the ground stage's
per-sector planes for the height filter) -> `lidet_proposal_make` (64 resampled points, mean, PVLE
voxel), exactly what the detector (`lidet_detector_run`) does on the device. Each kept cluster is then labelled against
the scan's ground-truth boxes:

* **ID of class c** (Car, Cyclist, Pedestrian): the cluster is *mostly one object* and *holds most of
  it*: share = |cluster points inside the object's box| / |cluster| >= 0.8 (`--purity`), and
  recall = |cluster points inside the box| / |non-ground points inside the box| >= 0.5 (`--recall`).
  0.8 is the purity cluster_eval.py already uses for "under-segmented", so ID here means a cluster
  that the clustering report counts as one object; 0.5 is "most of it" (a majority of the object's
  points): below it the box target is mostly extrapolation and the cluster is a fragment. The box
  target is the object's box.
* **excluded**: the largest share (>= 0.5) of the cluster lies in a box of a class KITTI ignores
  for scoring (`Van`, `Person_sitting`; in the simulator vans are `Van`; in SemanticKITTI-only
  folders `other-vehicle` 20/259, which holds the vans). A detector that calls these a car or a
  pedestrian is not penalised by KITTI, so they must not be taught as negatives. Also excluded:
  clusters whose mean falls in a KITTI `DontCare` 2D region, and for KITTI folders clusters outside
  the camera's field of view (label_2 annotates only what the camera sees: an unlabelled car behind
  the vehicle must not become a negative), and for sensor-frame folders (`--boxes`) clusters outside
  their labelled azimuth field of view, clusters mostly in a `DontCare` box, and, in a scan that labels
  only some classes (KITTI-360: cars only), clusters in no labelled box.
* **OOD**: every other cluster (poles, trees, walls, bushes, trucks, buses, parked bicycles,
  fragments of road users, groups merged into one cluster, ...).

Points are assigned to boxes enlarged by `--margin` (0.1 m on every side) to absorb the real
annotators' tight boxes and the range noise; the simulator's boxes never overlap, and a point in
two enlarged boxes goes to the nearer box centre.

Splits are by scan, never by proposal: simulator scans of split s come from their own run seed
(`--seed` + 0 train, + 1 val, + 2 test), folder scans go to the split given by `--split` (or a
stable hash of the scan name: 70/15/15).

Output: one .npz with, per proposal, `points` (K, N, 3) float32 in the *model frame* (models.to_model_frame),
`xyz` (K, N, 3) centred sensor-frame points as the C code made them, `mean` (K, 3), `voxel` (K, 3)
int16, `label` (K,) int8 (0 Car, 1 Cyclist, 2 Pedestrian, -1 OOD; excluded clusters are not stored),
`box` (K, 7) float32 target in the model frame (x, y, z, l, w, h, heading; NaN when none),
`box_sensor` (K, 7) the same box in the sensor frame, `split` (K,) int8 (0 train, 1 val, 2 test),
`scan` (K,) int32 into `scan_names`, `share`, `recall` (K,) float32, `n_src` (K,) member pixels,
`sem` (K,) int16 dominant SemanticKITTI class of the cluster (-1 unknown), and the run's `meta`
(JSON string).

    python -m lidet_tools.train.dataset --sensor hdl64 --sim 160,40,40 --seed 1000 --out data/train/hdl64.npz
    python -m lidet_tools.train.dataset --sensor vlp16 --mounts 0.3,0.5,0.7,1.0 --sim 200,50,50 --out ...
    python -m lidet_tools.train.dataset --sensor hdl64 --kitti ../shared/data/real/kitti/training --split test --out real.npz
    python -m lidet_tools.train.dataset --sensor hdl64 --semantickitti DIR --out ...
    python -m lidet_tools.train.dataset --sensor hdl64 --boxes data/real_train --split train --out ...

Sensor-frame folders (`--boxes DIR`): lidet's own layout, `velodyne/<name>.bin` (float32 x, y, z, intensity) and
`boxes/<name>.txt` (`<class> x y z l w h yaw score` per line, `kitti.read_boxes`; what `lidet-sim` and
`python -m lidet_tools.real.export` write). Scans without a boxes file are skipped. An optional `DIR/meta.json`
gives per-folder defaults and per-scan values (`python -m lidet_tools.real.export` writes one):

    {"fov_half_deg": 45, "mount_height_m": 1.73, "sensor": "hdl64", "classes": ["Car", "Pedestrian", "Cyclist"],
     "frames": {"<name>": {"fov_half_deg": null, "mount_height_m": 2.05, ...}}}

fov_half_deg: labels exist where |azimuth| <= it (null or absent: all around); clusters outside are excluded, not
negatives. mount_height_m: the sensor's height above the road (the C stages run with it; absent: the profile's).
sensor: the profile of the C stages (absent: --sensor). classes: the classes labelled in the scan (absent: all
three). `--fov-deg` and `--mount-height` give the values for folders and scans that do not state them.
"""
from __future__ import annotations

import argparse
import dataclasses
import functools
import json
import os
import pathlib
import sys
import time
import zlib

import numpy as np
from lidet_codegen.emit import Z_ORIGINS  # lidet_proposal_z_origin_t names (ONNX lidet.z_origin)

from .. import kitti
from ..sensors import get_sensor
from . import models as M

ID_CLASSES = {c: i for i, c in enumerate(M.CLASSES)}      # Car 0, Cyclist 1, Pedestrian 2
IGNORED_CLASSES = ("Van", "Person_sitting")
SPLITS = ("train", "val", "test")
#: SemanticKITTI ids -> role for folders without boxes (labels/ only)
SEMKITTI_ID = {10: 0, 252: 0, 31: 1, 253: 1, 30: 2, 254: 2}
SEMKITTI_IGNORED = (20, 259)
GROUND_IDS = (40, 44, 48, 49, 60, 72)

DEFAULTS = dict(purity=0.8, recall=0.5, ignored_share=0.5, margin=0.1, n_points=64, z_origin="mean")


# ---- geometry -------------------------------------------------------------------------------------

def points_in_box(xyz: np.ndarray, box, margin: float = 0.0) -> np.ndarray:
    """Boolean mask of points (N, 3) inside the sensor-frame box (x, y, z, l, w, h, yaw) enlarged by margin."""
    x, y, z, l, w, h, yaw = [float(v) for v in box]
    d = xyz[:, :3].astype(np.float64) - np.array([x, y, z])
    c, s = np.cos(yaw), np.sin(yaw)
    u = c * d[:, 0] + s * d[:, 1]
    v = -s * d[:, 0] + c * d[:, 1]
    return (np.abs(u) <= l / 2 + margin) & (np.abs(v) <= w / 2 + margin) & (np.abs(d[:, 2]) <= h / 2 + margin)


def box_to_model_frame(box_sensor: np.ndarray, mean: np.ndarray) -> np.ndarray:
    """(K, 7) sensor-frame boxes -> model frame of proposals with means (K, 3): centre relative to the
    mean rotated by minus the mean's azimuth, heading = yaw - azimuth, wrapped to [-pi, pi)."""
    b = np.asarray(box_sensor, np.float32)
    mean = np.asarray(mean, np.float32)
    rel = (b[:, 0:3] - mean)[:, None, :]
    out = b.copy()
    out[:, 0:3] = M.to_model_frame(rel, mean)[:, 0, :]
    az = np.arctan2(*M.azimuth_cos_sin(mean)[::-1]).astype(np.float32)
    out[:, 6] = (b[:, 6] - az + np.pi) % (2 * np.pi) - np.pi
    return out


def box_from_model_frame(box_model: np.ndarray, mean: np.ndarray) -> np.ndarray:
    """Inverse of box_to_model_frame (float64)."""
    b = np.asarray(box_model, np.float64)
    mean = np.asarray(mean, np.float64)
    c, s = M.azimuth_cos_sin(mean)
    c, s = c.astype(np.float64), s.astype(np.float64)
    out = b.copy()
    out[:, 0] = c * b[:, 0] - s * b[:, 1] + mean[:, 0]
    out[:, 1] = s * b[:, 0] + c * b[:, 1] + mean[:, 1]
    out[:, 2] = b[:, 2] + mean[:, 2]
    out[:, 6] = b[:, 6] + np.arctan2(s, c)
    return out


# ---- scans -----------------------------------------------------------------------------------------

class Scan:
    """One labelled scan: points (N, 4), boxes [(class, (x, y, z, l, w, h, yaw))] in the sensor frame,
    optional per-point SemanticKITTI labels, ring, camera (for KITTI field-of-view and DontCare)."""

    def __init__(self, name, points, boxes, sem=None, inst=None, ring=None, calib=None, dontcare=(), fov_only=False,
                 mount=None, fov_half=None, labelled=None, sensor=None):
        self.name, self.points, self.boxes = name, points, boxes
        self.sem, self.inst, self.ring, self.calib = sem, inst, ring, calib
        self.dontcare, self.fov_only = list(dontcare), fov_only
        self.mount = mount  # the sensor's height above the ground when it is not the profile's (m), else None
        self.fov_half = fov_half  # labels exist where |azimuth| <= it (rad); None: all around
        self.labelled = labelled  # the ID classes the scan labels (None: all); other clusters in no box are excluded
        self.sensor = sensor  # the C stages' sensor profile when it is not the dataset's, else None


def sim_scan(sensor: str, seed: int, index: int, mount: float | None, behind_cars: float = 0.0,
             foliage_m: float = 0.0) -> Scan:
    """Simulated scan `index` of run `seed`; behind_cars: `lidet-sim --behind-cars` (people standing behind parked
    cars, seen from the waist up; 0 = the default scenes); foliage_m: `lidet-sim --foliage` (the mean depth rays
    reach into vegetation; 0 = returns from its surface)."""
    from ..sim.simulate import simulate_scan
    r = simulate_scan(sensor, seed, index, mount, behind_cars=behind_cars, foliage_m=foliage_m)
    boxes = [(b.cls, (b.x, b.y, b.z, b.l, b.w, b.h, b.yaw)) for b in r.boxes]
    name = (f"sim:{sensor}:{seed}:{index}:{mount}" + (f":behind{behind_cars:g}" if behind_cars > 0 else "")
            + (f":foliage{foliage_m:g}" if foliage_m > 0 else ""))
    return Scan(name, r.points, boxes, sem=r.sem.astype(np.int64),
                inst=r.inst, ring=r.ring, mount=mount)


def kitti_scans(folder) -> list[str]:
    """Scan names of a KITTI-format folder (velodyne/ + label_2/ + calib/). Raises on a bad folder."""
    folder = pathlib.Path(folder)
    for sub in ("velodyne", "label_2", "calib"):
        if not (folder / sub).is_dir():
            raise FileNotFoundError(f"{folder}: no {sub}/ folder (a KITTI folder holds velodyne/, label_2/, calib/)")
    names = sorted(f.stem for f in (folder / "velodyne").glob("*.bin") if (folder / "label_2" / (f.stem + ".txt")).exists())
    if not names:
        raise ValueError(f"{folder}: no velodyne/*.bin with a label_2/*.txt")
    return names


def kitti_scan(folder, name: str) -> Scan:
    folder = pathlib.Path(folder)
    pts = kitti.read_bin(folder / "velodyne" / f"{name}.bin")
    calib = kitti.read_calib(folder / "calib" / f"{name}.txt")
    boxes, dc = [], []
    for o in kitti.read_label2(folder / "label_2" / f"{name}.txt"):
        if o.type == "DontCare":
            dc.append(np.asarray(o.bbox, np.float64))
            continue
        b = kitti.kitti_to_box(o, calib)
        boxes.append((o.type, (b.x, b.y, b.z, b.l, b.w, b.h, b.yaw)))
    sem = inst = None
    lab = folder / "labels" / f"{name}.label"
    if lab.exists():
        s, i = kitti.read_label(lab, len(pts))
        sem, inst = kitti.semantic_base(s).astype(np.int64), i
    return Scan(f"kitti:{folder}:{name}", pts, boxes, sem=sem, inst=inst, calib=calib, dontcare=dc, fov_only=True)


def boxes_meta(folder) -> dict:
    """The optional DIR/meta.json of a sensor-frame folder ({} without one); ValueError naming it when malformed."""
    p = pathlib.Path(folder) / "meta.json"
    if not p.exists():
        return {}
    try:
        m = json.loads(p.read_text())
    except json.JSONDecodeError as e:
        raise ValueError(f"{p}: not JSON ({e})") from None
    if not isinstance(m, dict) or not isinstance(m.get("frames", {}), dict):
        raise ValueError(f"{p}: expected an object with optional per-scan values in 'frames'")
    return m


def boxes_scans(folder) -> list[str]:
    """Scan names of a sensor-frame folder (velodyne/ + boxes/). Raises on a bad folder."""
    folder = pathlib.Path(folder)
    for sub in ("velodyne", "boxes"):
        if not (folder / sub).is_dir():
            raise FileNotFoundError(f"{folder}: no {sub}/ folder (a sensor-frame folder holds velodyne/ and boxes/)")
    names = sorted(f.stem for f in (folder / "velodyne").glob("*.bin") if (folder / "boxes" / (f.stem + ".txt")).exists())
    if not names:
        raise ValueError(f"{folder}: no velodyne/*.bin with a boxes/*.txt")
    return names


def boxes_settings(folder, name: str, defaults: dict | None = None) -> dict:
    """fov_half_deg, mount_height_m, sensor, classes of one scan of a sensor-frame folder: its meta.json entry, else
    the file's folder-level values, else `defaults` (the command line's), else None."""
    m = boxes_meta(folder)
    f = m.get("frames", {}).get(name, {})
    out = {}
    for k in ("fov_half_deg", "mount_height_m", "sensor", "classes"):
        out[k] = f[k] if k in f else m[k] if k in m else (defaults or {}).get(k)
    bad = [c for c in out["classes"] or () if c not in ID_CLASSES]
    if bad:
        raise ValueError(f"{folder}/meta.json: {name}: unknown classes {bad} (labelled classes among {list(ID_CLASSES)})")
    return out


def boxes_scan(folder, name: str, defaults: dict | None = None) -> Scan:
    """One scan of a sensor-frame folder: boxes as written (sensor frame), the folder's settings (boxes_settings)."""
    folder = pathlib.Path(folder)
    pts = kitti.read_bin(folder / "velodyne" / f"{name}.bin")
    boxes = [(b.cls, (b.x, b.y, b.z, b.l, b.w, b.h, b.yaw)) for b in kitti.read_boxes(folder / "boxes" / f"{name}.txt")]
    s = boxes_settings(folder, name, defaults)
    fov = None if s["fov_half_deg"] is None else np.radians(float(s["fov_half_deg"]))
    lab = None if s["classes"] is None or set(s["classes"]) == set(ID_CLASSES) else tuple(s["classes"])
    return Scan(f"boxes:{folder}:{name}", pts, boxes, mount=None if s["mount_height_m"] is None else float(s["mount_height_m"]),
                fov_half=fov, labelled=lab, sensor=s["sensor"])


def semkitti_scans(folder) -> list[str]:
    folder = pathlib.Path(folder)
    for sub in ("velodyne", "labels"):
        if not (folder / sub).is_dir():
            raise FileNotFoundError(f"{folder}: no {sub}/ folder (a SemanticKITTI folder holds velodyne/ and labels/)")
    names = sorted(f.stem for f in (folder / "velodyne").glob("*.bin") if (folder / "labels" / (f.stem + ".label")).exists())
    if not names:
        raise ValueError(f"{folder}: no velodyne/*.bin with a labels/*.label")
    return names


def semkitti_scan(folder, name: str) -> Scan:
    """SemanticKITTI folder: objects are (class, instance) groups; no boxes (box target NaN)."""
    folder = pathlib.Path(folder)
    pts = kitti.read_bin(folder / "velodyne" / f"{name}.bin")
    s, i = kitti.read_label(folder / "labels" / f"{name}.label", len(pts))
    return Scan(f"semantickitti:{folder}:{name}", pts, [], sem=s.astype(np.int64), inst=i)


# ---- labelling --------------------------------------------------------------------------------------

def _objects(scan: Scan, nonground: np.ndarray, margin: float):
    """Per-point object index (-1 none) and per object (role, class, box or None, n non-ground points).
    role: 'id', 'ignored' or 'other'."""
    n = len(scan.points)
    owner = np.full(n, -1, np.int64)
    objs = []
    if scan.boxes:
        best = np.full(n, np.inf)
        for j, (cls, box) in enumerate(scan.boxes):
            m = points_in_box(scan.points, box, margin)
            d = np.sum((scan.points[m, :3] - np.asarray(box[:3])) ** 2, axis=1)
            idx = np.nonzero(m)[0]
            closer = d < best[idx]
            owner[idx[closer]] = j
            best[idx[closer]] = d[closer]
            # DontCare boxes (sensor-frame folders: regions an evaluation ignores) are ignored as Van is
            role = "id" if cls in ID_CLASSES else ("ignored" if cls in IGNORED_CLASSES or cls == "DontCare" else "other")
            objs.append([role, ID_CLASSES.get(cls, -1), np.asarray(box, np.float64), 0])
    elif scan.sem is not None:
        key = scan.sem.astype(np.int64) * 65536 + scan.inst.astype(np.int64)
        groups = {}
        for k in np.unique(key[scan.inst > 0]):
            s = int(k // 65536)
            if s in SEMKITTI_ID:
                role, c = "id", SEMKITTI_ID[s]
            elif s in SEMKITTI_IGNORED:
                role, c = "ignored", -1
            else:
                continue
            groups[int(k)] = len(objs)
            objs.append([role, c, None, 0])
        if groups:
            ks = np.array(list(groups)), np.array(list(groups.values()))
            pos = np.searchsorted(ks[0], key)
            pos = np.clip(pos, 0, len(ks[0]) - 1)
            hit = ks[0][pos] == key
            owner[hit] = ks[1][pos[hit]]
    counts = np.bincount(owner[(owner >= 0) & nonground], minlength=len(objs))
    for j, o in enumerate(objs):
        o[3] = int(counts[j])
    return owner, objs


def _in_camera(calib, xyz: np.ndarray) -> np.ndarray:
    """Points (K, 3) in front of the camera and inside its image."""
    cam = calib.velo_to_cam_points(xyz)
    uv = calib.project_rect_to_image(cam)
    W, H = calib.image_size
    return (cam[:, 2] > 0.5) & (uv[:, 0] >= 0) & (uv[:, 0] < W) & (uv[:, 1] >= 0) & (uv[:, 1] < H)


def _in_dontcare(calib, xyz: np.ndarray, regions) -> np.ndarray:
    out = np.zeros(len(xyz), bool)
    if not regions:
        return out
    uv = calib.project_rect_to_image(calib.velo_to_cam_points(xyz))
    for r in regions:
        out |= (uv[:, 0] >= r[0]) & (uv[:, 0] <= r[2]) & (uv[:, 1] >= r[1]) & (uv[:, 1] <= r[3])
    return out


def process_scan(scan: Scan, sensor: str, cfg: dict) -> dict:
    """C stages + labels for one scan -> dict of per-proposal arrays (excluded clusters dropped)."""
    from .. import native
    pts = np.ascontiguousarray(scan.points, np.float32)
    # no ring indices: the clustering bindings project from the elevation table (as KITTI scans must).
    # A simulated robot mount runs the stages with that height, as the detector on that robot is configured
    # (lidet detect --mount-height): with the profile's, the ground of a 1.0 m VLP-16 mount is refused
    # sector by sector and stays in the clusters (docs/DETECTOR.md, Mount height)
    s = get_sensor(scan.sensor or sensor) if isinstance(scan.sensor or sensor, str) else sensor
    if scan.mount is not None:
        s = dataclasses.replace(s, mount_height_m=float(scan.mount))
    gr = native.ground(pts, s)
    cl = native.cluster(pts, s, ground=gr.mask_point, planes=gr.planes)
    k = len(cl)
    pr = native.proposals(cl, n_points=cfg["n_points"], z_origin=Z_ORIGINS.index(cfg.get("z_origin", "mean")))
    nonground = (gr.mask_point == 0) & (gr.image.point_pixel >= 0)
    owner, objs = _objects(scan, nonground, cfg["margin"])
    lab = cl.point_labels.astype(np.int64)
    label = np.full(k, -1, np.int8)
    keep = np.ones(k, bool)
    box = np.full((k, 7), np.nan, np.float32)
    share = np.zeros(k, np.float32)
    recall = np.zeros(k, np.float32)
    sem_dom = np.full(k, -1, np.int16)
    if k:
        in_cl = lab > 0
        cid = lab[in_cl] - 1
        own = owner[in_cl]
        size = np.bincount(cid, minlength=k)
        for c in range(k):
            o = own[cid == c]
            o = o[o >= 0]
            if scan.sem is not None:
                sc = scan.sem[in_cl][cid == c]
                vals, cnt = np.unique(sc, return_counts=True)
                sem_dom[c] = int(vals[np.argmax(cnt)])
            if len(o) == 0:
                if scan.labelled is not None:
                    keep[c] = False  # in no box of a scan that labels only some classes: it may be an unlabelled one
                continue
            vals, cnt = np.unique(o, return_counts=True)
            j = int(vals[np.argmax(cnt)])
            sh = float(cnt.max()) / float(size[c])
            role, cls, bx, nobj = objs[j]
            rc = float(cnt.max()) / max(nobj, 1)
            share[c], recall[c] = sh, min(rc, 1.0)
            if role == "ignored" and sh >= cfg["ignored_share"]:
                keep[c] = False
            elif role == "id" and sh >= cfg["purity"] and rc >= cfg["recall"]:
                label[c] = cls
                if bx is not None:
                    box[c] = bx
        if scan.calib is not None:
            if scan.fov_only:
                keep &= _in_camera(scan.calib, pr.mean.astype(np.float64))
            keep &= ~_in_dontcare(scan.calib, pr.mean.astype(np.float64), scan.dontcare)
        if scan.fov_half is not None:
            keep &= np.abs(np.arctan2(pr.mean[:, 1].astype(np.float64), pr.mean[:, 0].astype(np.float64))) <= scan.fov_half
    box_model = np.full((k, 7), np.nan, np.float32)
    ok = ~np.isnan(box[:, 0])
    if ok.any():
        box_model[ok] = box_to_model_frame(box[ok], pr.mean[ok])
    sel = keep
    return dict(points=M.to_model_frame(pr.xyz, pr.mean)[sel], xyz=pr.xyz[sel], mean=pr.mean[sel],
                voxel=pr.voxel[sel], label=label[sel], box=box_model[sel], box_sensor=box[sel],
                share=share[sel], recall=recall[sel], n_src=pr.n_src[sel].astype(np.int32), sem=sem_dom[sel],
                n_excluded=int((~keep).sum()),
                n_objects=np.bincount([o[1] for o in objs if o[0] == "id" and o[3] >= 10], minlength=3))


# ---- jobs -------------------------------------------------------------------------------------------

def _job(task, sensor, cfg, behind_cars=0.0, foliage_m=0.0):
    kind, split, a, b, c = task[:5]
    sensor = task[5] if len(task) > 5 else sensor  # a simulated scan of a mixed set names its own sensor
    if kind == "sim":
        scan = sim_scan(sensor, a, b, c, behind_cars, foliage_m)
    elif kind == "kitti":
        scan = kitti_scan(a, b)
    elif kind == "boxes":
        scan = boxes_scan(a, b, c)
    else:
        scan = semkitti_scan(a, b)
    out = process_scan(scan, sensor, cfg)
    out["split"] = np.full(len(out["label"]), split, np.int8)
    out["name"] = scan.name
    return out


def hash_split(name: str) -> int:
    """Stable split of a folder scan by its name: 70 % train, 15 % val, 15 % test."""
    h = zlib.crc32(name.encode()) % 100
    return 0 if h < 70 else (1 if h < 85 else 2)


def build_tasks(a) -> list:
    tasks = []
    if a.sim:
        counts = [int(v) for v in a.sim.split(",")]
        if len(counts) != 3 or min(counts) < 0:
            raise ValueError("--sim takes three counts: train,val,test")
        mounts = [float(v) for v in a.mounts.split(",")] if a.mounts else [None]
        sensors = [v for v in (a.sim_sensors or "").split(",") if v]
        for s, n in enumerate(counts):
            for i in range(n):
                if sensors:  # every sensor at every mount: sensors cycle fastest, then the mounts
                    k = len(sensors)
                    tasks.append(("sim", s, a.seed + s, i, mounts[(i // k) % len(mounts)], sensors[i % k]))
                else:
                    tasks.append(("sim", s, a.seed + s, i, mounts[i % len(mounts)]))
    split_of = (lambda n: SPLITS.index(a.split)) if a.split else hash_split
    for folder in a.kitti or []:
        for n in kitti_scans(folder):
            tasks.append(("kitti", split_of(n), str(folder), n, None))
    for folder in a.semantickitti or []:
        for n in semkitti_scans(folder):
            tasks.append(("semantickitti", split_of(n), str(folder), n, None))
    defaults = dict(fov_half_deg=getattr(a, "fov_deg", None), mount_height_m=getattr(a, "mount_height", None))
    for folder in getattr(a, "boxes", None) or []:
        for n in boxes_scans(folder):
            boxes_settings(folder, n, defaults)  # a malformed meta.json fails here, not in a worker
            tasks.append(("boxes", split_of(n), str(folder), n, defaults))
    return tasks


def concat(parts: list) -> dict:
    keys = ["points", "xyz", "mean", "voxel", "label", "box", "box_sensor", "share", "recall", "n_src", "sem", "split"]
    out = {k: np.concatenate([p[k] for p in parts]) if parts else np.zeros(0) for k in keys}
    out["scan"] = np.concatenate([np.full(len(p["label"]), i, np.int32) for i, p in enumerate(parts)]) \
        if parts else np.zeros(0, np.int32)
    out["scan_names"] = np.array([p["name"] for p in parts])
    return out


def balance_table(d: dict) -> str:
    """Markdown table: proposals per split and label."""
    names = list(M.CLASSES) + ["OOD"]
    lines = ["| split | scans | " + " | ".join(names) + " | ID share |", "|---|---:|" + "---:|" * (len(names) + 1)]
    for s, sn in enumerate(SPLITS):
        m = d["split"] == s
        if not m.any():
            continue
        lab = d["label"][m]
        cnt = [int((lab == c).sum()) for c in range(3)] + [int((lab < 0).sum())]
        nscan = len(np.unique(d["scan"][m]))
        lines.append(f"| {sn} | {nscan} | " + " | ".join(map(str, cnt)) + f" | {100 * sum(cnt[:3]) / max(1, sum(cnt)):.1f} % |")
    return "\n".join(lines)


def load(path) -> dict:
    """Load a dataset .npz as a dict of arrays (+ meta dict)."""
    path = pathlib.Path(path)
    if not path.exists():
        raise FileNotFoundError(f"{path}: no such dataset (make it with python -m lidet_tools.train.dataset)")
    with np.load(path, allow_pickle=False) as z:
        d = {k: z[k] for k in z.files}
    d["meta"] = json.loads(str(d["meta"])) if "meta" in d else {}
    return d


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m lidet_tools.train.dataset", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--sensor", default="hdl64", help="sensor profile of the C stages (hdl64, vlp16, ...)")
    ap.add_argument("--sim", help="simulated scans per split: TRAIN,VAL,TEST (e.g. 160,40,40)")
    ap.add_argument("--seed", type=int, default=1000, help="simulator run seed of the train split (val +1, test +2)")
    ap.add_argument("--mounts", help="simulator mount heights in m, cycled over scans (e.g. 0.3,0.5,0.7,1.0)")
    ap.add_argument("--sim-sensors", metavar="A,B,...",
                    help="simulated scans of several sensor presets (e.g. vlp32c,hdl32,os1-32), cycled over the scans "
                         "(every sensor at every --mounts height), each through its own C stages; default: --sensor")
    ap.add_argument("--sim-behind-cars", type=float, default=0.0, metavar="RATE",
                    help="simulated scans: mean number of people (or rows of people) standing behind parked cars "
                         "per scan (`lidet-sim --behind-cars`; default 0)")
    ap.add_argument("--sim-foliage", type=float, default=0.0, metavar="M",
                    help="simulated scans: the mean depth in m that rays reach into vegetation before they return "
                         "(`lidet-sim --foliage`; default 0: from its surface)")
    ap.add_argument("--kitti", action="append", type=pathlib.Path, help="KITTI folder (velodyne/ label_2/ calib/)")
    ap.add_argument("--semantickitti", action="append", type=pathlib.Path, help="SemanticKITTI folder (velodyne/ labels/)")
    ap.add_argument("--boxes", action="append", type=pathlib.Path,
                    help="sensor-frame folder (velodyne/ boxes/, optional meta.json; see above)")
    ap.add_argument("--fov-deg", type=float, default=None,
                    help="--boxes folders: half the labelled azimuth field of view, degrees, where meta.json does not say "
                         "(default: all around)")
    ap.add_argument("--mount-height", type=float, default=None,
                    help="--boxes folders: the sensor's height above the road, m, where meta.json does not say "
                         "(default: the profile's)")
    ap.add_argument("--split", choices=SPLITS, help="split of every folder scan (default: hash of the scan name)")
    ap.add_argument("--purity", type=float, default=DEFAULTS["purity"])
    ap.add_argument("--recall", type=float, default=DEFAULTS["recall"])
    ap.add_argument("--margin", type=float, default=DEFAULTS["margin"])
    ap.add_argument("--n-points", type=int, default=DEFAULTS["n_points"])
    ap.add_argument("--z-origin", choices=Z_ORIGINS, default=DEFAULTS["z_origin"],
                    help="where the proposals' z is measured from: the cluster mean (default) or the ground under it "
                         "(lidet_proposal_z_origin_t; the models trained on the set carry it as lidet.z_origin)")
    ap.add_argument("--jobs", type=int, default=1, help="worker processes")
    ap.add_argument("--out", type=pathlib.Path, required=True)
    ap.add_argument("--no-progress", action="store_true")
    a = ap.parse_args(argv)
    if not a.sim and not a.kitti and not a.semantickitti and not a.boxes:
        ap.error("give at least one source: --sim, --kitti, --semantickitti or --boxes")
    if a.jobs < 1:
        ap.error("--jobs must be >= 1")
    if a.sim_sensors:
        from ..sensors import SENSORS
        bad = [v for v in a.sim_sensors.split(",") if v not in SENSORS]
        if bad or not a.sim:
            ap.error(f"--sim-sensors: presets ({', '.join(SENSORS)}) with --sim" + (f"; unknown: {', '.join(bad)}" if bad else ""))
    if not 0.0 <= a.sim_behind_cars <= 50.0:
        ap.error("--sim-behind-cars must be in [0, 50]")
    if not 0.0 <= a.sim_foliage <= 2.0:
        ap.error("--sim-foliage must be in [0, 2] m")
    try:
        tasks = build_tasks(a)
    except (FileNotFoundError, ValueError) as e:
        print(f"dataset: {e}", file=sys.stderr)
        return 2
    cfg = dict(DEFAULTS, purity=a.purity, recall=a.recall, margin=a.margin, n_points=a.n_points, z_origin=a.z_origin)
    job = functools.partial(_job, sensor=a.sensor, cfg=cfg, behind_cars=a.sim_behind_cars,
                            foliage_m=a.sim_foliage)
    t0 = time.perf_counter()
    parts = [None] * len(tasks)
    bar = None
    if not a.no_progress:
        from tqdm import tqdm
        bar = tqdm(total=len(tasks), desc=f"proposals {a.sensor}", unit="scan")
    if a.jobs > 1:
        import multiprocessing as mp
        with mp.get_context("spawn").Pool(a.jobs) as pool:
            for i, r in enumerate(pool.imap(job, tasks, chunksize=2)):
                parts[i] = r
                if bar:
                    bar.update(1)
    else:
        for i, t in enumerate(tasks):
            parts[i] = job(t)
            if bar:
                bar.update(1)
    if bar:
        bar.close()
    d = concat(parts)
    if len(d["label"]) == 0:
        print("dataset: no proposals (empty scans?)", file=sys.stderr)
        return 1
    meta = dict(sensor=a.sensor, sim_sensors=a.sim_sensors, sim=a.sim, seed=a.seed, mounts=a.mounts, sim_behind_cars=a.sim_behind_cars,
                sim_foliage=a.sim_foliage, kitti=[str(p) for p in a.kitti or []],
                semantickitti=[str(p) for p in a.semantickitti or []], boxes=[str(p) for p in a.boxes or []], n_excluded=int(sum(p["n_excluded"] for p in parts)),
                n_objects=[int(v) for v in np.sum([p["n_objects"] for p in parts], axis=0)], **cfg,
                command="python -m lidet_tools.train.dataset " + " ".join(argv if argv is not None else sys.argv[1:]))
    meta["seconds"] = time.perf_counter() - t0
    meta["jobs"] = a.jobs
    a.out.parent.mkdir(parents=True, exist_ok=True)
    tmp = a.out.with_name(a.out.name + ".tmp.npz")
    np.savez_compressed(tmp, meta=json.dumps(meta), **d)
    os.replace(tmp, a.out)
    dt = time.perf_counter() - t0
    print(balance_table(d))
    print(f"excluded (ignored classes, DontCare, outside the camera): {meta['n_excluded']}; "
          f"labelled ID objects with >= 10 non-ground points: {dict(zip(M.CLASSES, meta['n_objects']))}")
    print(f"dataset: {len(tasks)} scans -> {len(d['label'])} proposals in {dt:.1f} s -> {a.out}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
