# SPDX-License-Identifier: MIT
"""One simulated scan: scene -> ray casting -> return model -> points, labels, boxes.

Seeding: scan `index` of run `seed` uses numpy.random.SeedSequence([seed, index]), split into a
scene stream and a sensor-noise stream; no global RNG state is touched, so the same (seed, index,
options) gives the same bytes on every machine with the same numpy.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .. import kitti
from ..sensors import get_sensor
from . import raycast as rc
from .objects import S
from .scene import SURF_ALB, SURF_ROUGH_DROP, SURF_SEM, Scene, make_scene
from .sensor_model import SensorModel

#: label_2 classes emitted (buses are 'Misc': KITTI has no bus class)
LABEL2_CLASSES = ("Car", "Van", "Truck", "Pedestrian", "Cyclist", "Misc", "DontCare")
DONTCARE_RANGE_M = 70.0
#: the primitives foliage_m applies to (SemanticKITTI's vegetation: canopies, bushes, hedges)
S_VEGETATION = S["vegetation"]
#: a foliage depth is capped at this many times its mean (a ray does not cross a whole canopy)
FOLIAGE_CAP = 3.0


@dataclass
class ScanResult:
    points: np.ndarray            # (N, 4) float32 x, y, z, remission (sensor frame)
    sem: np.ndarray               # (N,) uint16
    inst: np.ndarray              # (N,) uint16
    ring: np.ndarray              # (N,) uint16, ring order of sensors.py
    boxes: list                   # kitti.Box3D, sensor frame, objects with >= 1 point
    label2: list                  # kitti.KittiObject, camera frame
    calib: kitti.Calib
    scene: Scene = field(repr=False, default=None)
    n_points_obj: np.ndarray = field(repr=False, default=None)
    box_obj: list = field(repr=False, default=None)      # scene object index of each entry of boxes
    label2_obj: list = field(repr=False, default=None)   # scene object index of each entry of label2


def _robot(mount_height_m: float) -> bool:
    """Low mounts are robots: sensor on the sidewalk half of the time, 0.3 m minimum range."""
    return mount_height_m < 1.2


def simulate_scan(sensor, seed: int = 0, index: int = 0, mount_height_m: float | None = None,
                  pitch_deg: float | None = None, roll_deg: float | None = None,
                  scene_kind: str | None = None, range_noise_m: float = 0.02,
                  dropout: float = 0.015, keep_scene: bool = False, crowd: bool = False,
                  behind_cars: float = 0.0, foliage_m: float = 0.0) -> ScanResult:
    """Simulate scan `index` of run `seed` for a sensor profile (name or Sensor).

    mount_height_m defaults to the profile's; pitch/roll default to a random mounting tilt; scene_kind
    forces one of scene.SCENE_TYPES. keep_scene keeps the Scene (ground, primitives, objects) in the
    result for tests and plots. crowd: the crowded street content of crowd.py (issue 15) on top of the
    default scene (the default, False, gives the same bytes as before it existed). behind_cars: the mean number
    of people or rows of people standing behind parked cars (crowd.behind_cars; 0, the default, adds none and
    gives the same bytes as before it existed). foliage_m: the mean depth (m) a ray reaches into vegetation before
    it returns (cast_scene; 0, the default, returns at the vegetation's surface and gives the same bytes as before
    it existed)."""
    sensor = get_sensor(sensor) if isinstance(sensor, str) else sensor
    H = float(sensor.mount_height_m if mount_height_m is None else mount_height_m)
    ss = np.random.SeedSequence([int(seed), int(index)])
    scene_rng, noise_rng, mount_rng = (np.random.default_rng(s) for s in ss.spawn(3))
    pitch = np.radians(pitch_deg) if pitch_deg is not None else np.radians(
        np.clip(mount_rng.normal(0, 0.25), -0.6, 0.6))
    roll = np.radians(roll_deg) if roll_deg is not None else np.radians(
        np.clip(mount_rng.normal(0, 0.25), -0.6, 0.6))
    robot = _robot(H)
    scene = make_scene(scene_rng, H, sensor.max_range_m, scene_kind, robot, crowd=crowd, behind_cars=behind_cars)
    sm = SensorModel(sensor, H, float(pitch), float(roll), range_noise_m=range_noise_m, dropout=dropout,
                     min_range_m=0.3 if robot else 1.0)
    return cast_scene(scene, sm, noise_rng, keep_scene, foliage_m=foliage_m)


def cast_scene(scene: Scene, sm: SensorModel, noise_rng, keep_scene: bool = False,
               foliage_m: float = 0.0) -> ScanResult:
    """Ray cast a built scene (sensor at the origin of its level frame) with a sensor model; noise_rng draws
    the see-through surfaces, the foliage depths (foliage_m > 0 only) and the return model, in that order.

    foliage_m > 0: a ray that meets vegetation (canopies, bushes, hedges) returns from a depth inside it drawn
    from an exponential law of that mean, capped at FOLIAGE_CAP times it, instead of from its surface: real
    foliage scatters returns in depth. On the labelled SemanticKITTI training scan (spvnas_000000) the
    vegetation's points lie 3.8 cm (5-15 m) and 5.8 cm (15-30 m) from the plane of their 12 nearest neighbours
    (median rms), the simulated surfaces' 1.3 and 1.5 cm (`python -m lidet_tools.sim.foliage_report`).
    `simulate_scan` is make_scene + this; the sequences (sequence.py) call it once per scan with the scene moved into that scan's sensor frame."""
    sensor = sm.sensor
    grid, row2ring = sm.ray_grid()
    dirs = grid.dirs
    t_max = sensor.max_range_m + 1.0
    n_rays = len(dirs)

    # primitives
    prims = scene.prims
    ray, pidx = rc.cull_pairs(prims, grid)
    t, nrm = rc.intersect_pairs(prims, dirs, ray, pidx)
    m = t <= t_max
    ray, pidx, t, nrm = ray[m], pidx[m], t[m], nrm[m]
    obj = prims.obj[pidx]
    n_obj = len(scene.objects)
    # rays that meet each labelled object at all (for occlusion levels)
    labelled = np.array([bool(o.label) for o in scene.objects] + [False])
    lm = labelled[obj]
    key_any = np.unique(ray[lm].astype(np.int64) * (n_obj + 1) + obj[lm])
    any_cnt = np.bincount(key_any % (n_obj + 1), minlength=n_obj + 1)[:n_obj]
    # see-through surfaces (glass, leaves, spokes, mesh fences)
    through = noise_rng.random(len(t)) < prims.transp[pidx]
    m = ~through
    ray, pidx, t, nrm = ray[m], pidx[m], t[m], nrm[m]
    if foliage_m > 0.0:
        veg = np.nonzero(prims.sem[pidx] == S_VEGETATION)[0]
        t[veg] += np.minimum(noise_rng.exponential(foliage_m, len(veg)), FOLIAGE_CAP * foliage_m)
    t_best = np.full(n_rays, np.inf)
    np.minimum.at(t_best, ray, t)
    # ground, searched only up to the nearest object
    t_g = rc.intersect_ground(scene.ground, dirs, np.minimum(t_best, t_max), grid=grid)
    t_best = np.minimum(t_best, t_g)
    win = t <= t_best[ray]
    ray_w, pidx_w, nrm_w = ray[win], pidx[win], nrm[win]
    ray_w, first = np.unique(ray_w, return_index=True)
    pidx_w, nrm_w = pidx_w[first], nrm_w[first]
    hit_prim = np.full(n_rays, -1, np.int64)
    hit_prim[ray_w] = pidx_w

    valid = np.nonzero(np.isfinite(t_best))[0]
    tv = t_best[valid]
    hp = hit_prim[valid]
    dv = np.take(dirs, valid, axis=0)
    pts_level = dv * tv[:, None]
    is_g = hp < 0
    sem = np.zeros(len(valid), np.int32)
    alb = np.zeros(len(valid))
    drop = np.zeros(len(valid))
    normal = np.zeros((len(valid), 3))
    code = scene.ground.cls(pts_level[is_g, 0], pts_level[is_g, 1])
    sem[is_g] = SURF_SEM[code]
    alb[is_g] = SURF_ALB[code]
    drop[is_g] = SURF_ROUGH_DROP[code]
    normal[is_g] = scene.ground.normal(pts_level[is_g, 0], pts_level[is_g, 1])
    po = ~is_g
    hpo = hp[po]
    sem[po] = prims.sem[hpo]
    alb[po] = prims.albedo[hpo]
    drop[po] = prims.drop[hpo]
    normal[po] = rc.world_normals(prims, hpo, np.take(nrm_w, np.searchsorted(ray_w, valid[po]), axis=0))
    cos_inc = np.abs((normal * dv).sum(1))
    keep, tn, rem = sm.returns(noise_rng, tv, alb, cos_inc, drop)

    sel = valid[keep]
    row = sel // grid.cols
    col = sel % grid.cols
    ring = row2ring[row]
    order = np.lexsort((col, ring))          # ring by ring, columns in image order
    sdirs = sm.sensor_dirs()
    xyz = np.take(sdirs, sel, axis=0) * tn[keep][:, None]
    pts = np.empty((len(sel), 4), np.float32)
    pts[:, :3] = xyz
    pts[:, 3] = rem[keep]
    pts = np.take(pts, order, axis=0)
    sem_k = sem[keep][order].astype(np.uint16)
    hobj = np.where(hp[keep] >= 0, prims.obj[np.maximum(hp[keep], 0)], -1)[order]
    inst_of_obj = np.array([o.instance for o in scene.objects] + [0], np.int64)
    inst_k = inst_of_obj[hobj].astype(np.uint16)          # hobj == -1 -> last entry (0)
    ring_k = ring[order].astype(np.uint16)

    n_pts_obj = np.bincount(hobj[hobj >= 0], minlength=n_obj)
    # visible rays per object (first hits, before the return model)
    vis_cnt = np.bincount(prims.obj[pidx_w][prims.obj[pidx_w] >= 0], minlength=n_obj)

    calib = kitti.Calib()
    Rm = sm.R_mount
    boxes, label2, box_obj, label2_obj = [], [], [], []
    for o in scene.objects:
        if not o.label or n_pts_obj[o.obj] == 0:
            continue
        b = _to_sensor_box(o, Rm)
        boxes.append(b)
        box_obj.append(o.obj)
        vis = vis_cnt[o.obj] / max(any_cnt[o.obj], 1)
        ko = _label2(b, calib, vis)
        if ko is not None:
            label2.append(ko)
            label2_obj.append(o.obj)
    return ScanResult(pts, sem_k, inst_k, ring_k, boxes, label2, calib,
                      scene if keep_scene else None, n_pts_obj, box_obj, label2_obj)


def _to_sensor_box(o, Rm) -> kitti.Box3D:
    cx, cy, cz, l, w, h, yaw = o.box
    c = Rm.T @ np.array([cx, cy, cz])
    hd = Rm.T @ np.array([np.cos(yaw), np.sin(yaw), 0.0])
    yaw_s = float(np.arctan2(hd[1], hd[0]))
    return kitti.Box3D(o.label, float(c[0]), float(c[1]), float(c[2]), float(l), float(w), float(h), yaw_s, 1.0)


def _label2(b: kitti.Box3D, calib: kitti.Calib, vis: float):
    """label_2 object seen by the virtual front camera, or None when outside its image."""
    corners = calib.velo_to_cam_points(kitti.box_corners(b))
    if (corners[:, 2] < 0.5).any():
        return None
    uv = calib.project_rect_to_image(corners)
    W, Hh = calib.image_size
    x1, y1 = uv.min(0)
    x2, y2 = uv.max(0)
    cx1, cy1, cx2, cy2 = max(x1, 0.0), max(y1, 0.0), min(x2, W - 1.0), min(y2, Hh - 1.0)
    if cx2 <= cx1 or cy2 <= cy1:
        return None
    area = (x2 - x1) * (y2 - y1)
    trunc = float(np.clip(1.0 - (cx2 - cx1) * (cy2 - cy1) / max(area, 1e-9), 0.0, 1.0))
    bbox = np.array([cx1, cy1, cx2, cy2])
    dist = float(np.hypot(b.x, b.y))
    if dist > DONTCARE_RANGE_M:
        return kitti.KittiObject("DontCare", -1, -1, -10, bbox, -1, -1, -1, np.array([-1000.0] * 3), -10)
    occ = 0 if vis >= 0.8 else (1 if vis >= 0.4 else 2)
    return kitti.box_to_kitti(b, calib, truncated=round(trunc, 2), occluded=occ, bbox=bbox)
