# SPDX-License-Identifier: MIT
"""KITTI and SemanticKITTI file formats, and lidet's sensor-frame box lines.

* velodyne .bin: float32 records (x, y, z, remission), sensor frame (x fwd, y left, z up, metres).
* SemanticKITTI .label: uint32 per point; lower 16 bits semantic class, upper 16 bits instance id.
* KITTI label_2 .txt: one object per line in the rectified camera frame
  `type trunc occ alpha x1 y1 x2 y2 h w l tx ty tz ry [score]`; (tx, ty, tz) is the *bottom* centre.
* KITTI calib .txt: `P0..P3` (3x4), `R0_rect` (3x3), `Tr_velo_to_cam` (3x4), `Tr_imu_to_velo` (3x4).
* lidet box lines (sensor frame): `<class> <x> <y> <z> <l> <w> <h> <yaw> <score>`, (x, y, z) the box
  *centre*, yaw about +z from +x (radians), l along the heading, w across, h vertical.

Every reader raises ValueError with the file name on malformed input (never silently truncates).
"""
from __future__ import annotations

import os
from dataclasses import dataclass, field

import numpy as np

# --------------------------------------------------------------------------------------------
# Point clouds and per-point labels


def read_bin(path, dims: int = 4) -> np.ndarray:
    """Read a KITTI velodyne .bin as an (N, dims) float32 array. Raises ValueError when the
    file size is not a multiple of dims * 4 bytes (truncated or not a scan)."""
    size = os.path.getsize(path)
    if size % (4 * dims):
        raise ValueError(f"{path}: size {size} B is not a multiple of {4 * dims} B "
                         f"({dims} float32 per point): truncated or not a KITTI scan")
    return np.fromfile(path, dtype="<f4").reshape(-1, dims)


def write_bin(path, points: np.ndarray) -> None:
    """Write (N, 4) points (x, y, z, remission) as little-endian float32."""
    pts = np.asarray(points)
    if pts.ndim != 2 or pts.shape[1] != 4:
        raise ValueError(f"write_bin: expected (N, 4) points, got {pts.shape}")
    _ensure_dir(path)
    pts.astype("<f4").tofile(path)


def read_label(path, n_points: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Read a SemanticKITTI .label file. Returns (semantic uint16, instance uint16).
    With n_points, checks that the file has exactly one label per point."""
    size = os.path.getsize(path)
    if size % 4:
        raise ValueError(f"{path}: size {size} B is not a multiple of 4 (uint32 per point)")
    raw = np.fromfile(path, dtype="<u4")
    if n_points is not None and raw.size != n_points:
        raise ValueError(f"{path}: {raw.size} labels for {n_points} points")
    return (raw & 0xFFFF).astype(np.uint16), (raw >> 16).astype(np.uint16)


def write_label(path, semantic: np.ndarray, instance: np.ndarray) -> None:
    sem = np.asarray(semantic, dtype=np.uint32)
    ins = np.asarray(instance, dtype=np.uint32)
    if sem.shape != ins.shape or sem.ndim != 1:
        raise ValueError("write_label: semantic and instance must be 1-D arrays of equal length")
    if (sem > 0xFFFF).any() or (ins > 0xFFFF).any():
        raise ValueError("write_label: ids must fit in 16 bits")
    _ensure_dir(path)
    ((ins << 16) | sem).astype("<u4").tofile(path)


# SemanticKITTI class ids used across the project
SEMKITTI = {
    "unlabeled": 0, "outlier": 1, "car": 10, "bicycle": 11, "bus": 13, "motorcycle": 15,
    "on-rails": 16, "truck": 18, "other-vehicle": 20, "person": 30, "bicyclist": 31,
    "motorcyclist": 32, "road": 40, "parking": 44, "sidewalk": 48, "other-ground": 49,
    "building": 50, "fence": 51, "other-structure": 52, "lane-marking": 60, "vegetation": 70,
    "trunk": 71, "terrain": 72, "pole": 80, "traffic-sign": 81, "other-object": 99,
}
#: ground classes of the Seppänen benchmark and of the Ground-Segmentation-Benchmark
GROUND_IDS = (40, 44, 48, 49, 60, 72)
GROUND_IDS_NO_TERRAIN = (40, 44, 48, 49, 60)


def semantic_base(sem: np.ndarray) -> np.ndarray:
    """Map SemanticKITTI moving classes (252..259) onto their static counterparts."""
    sem = np.asarray(sem).astype(np.uint16, copy=True)
    moving = {252: 10, 253: 31, 254: 30, 255: 32, 256: 16, 257: 13, 258: 18, 259: 20}
    for m, s in moving.items():
        sem[sem == m] = s
    return sem


# --------------------------------------------------------------------------------------------
# Calibration


@dataclass
class Calib:
    """KITTI calibration. Matrices are float64. Defaults give a KITTI-like front camera."""
    P2: np.ndarray = field(default_factory=lambda: np.array(
        [[721.5377, 0.0, 609.5593, 44.85728], [0.0, 721.5377, 172.854, 0.2163791],
         [0.0, 0.0, 1.0, 0.002745884]]))
    R0_rect: np.ndarray = field(default_factory=lambda: np.eye(3))
    Tr_velo_to_cam: np.ndarray = field(default_factory=lambda: np.array(
        [[0.0, -1.0, 0.0, 0.0], [0.0, 0.0, -1.0, -0.08], [1.0, 0.0, 0.0, -0.27]]))
    P0: np.ndarray | None = None
    P1: np.ndarray | None = None
    P3: np.ndarray | None = None
    Tr_imu_to_velo: np.ndarray | None = None
    image_size: tuple[int, int] = (1242, 375)  # (width, height), not stored in the file

    # -- transforms ------------------------------------------------------------------------
    def velo_to_rect(self) -> np.ndarray:
        """4x4 transform from the sensor frame to the rectified camera frame."""
        T = np.eye(4)
        T[:3, :4] = self.Tr_velo_to_cam
        R = np.eye(4)
        R[:3, :3] = self.R0_rect
        return R @ T

    def velo_to_cam_points(self, xyz: np.ndarray) -> np.ndarray:
        xyz = np.asarray(xyz, dtype=np.float64).reshape(-1, 3)
        T = self.velo_to_rect()
        return xyz @ T[:3, :3].T + T[:3, 3]

    def cam_to_velo_points(self, xyz: np.ndarray) -> np.ndarray:
        xyz = np.asarray(xyz, dtype=np.float64).reshape(-1, 3)
        Ti = np.linalg.inv(self.velo_to_rect())
        return xyz @ Ti[:3, :3].T + Ti[:3, 3]

    def project_rect_to_image(self, xyz_rect: np.ndarray) -> np.ndarray:
        """(N,3) rectified camera points -> (N,2) pixel coordinates through P2."""
        xyz = np.asarray(xyz_rect, dtype=np.float64).reshape(-1, 3)
        h = np.hstack([xyz, np.ones((len(xyz), 1))]) @ self.P2.T
        return h[:, :2] / h[:, 2:3]


def read_calib(path) -> Calib:
    vals: dict[str, np.ndarray] = {}
    with open(path) as f:
        for ln, line in enumerate(f, 1):
            line = line.strip()
            if not line:
                continue
            if ":" not in line:
                raise ValueError(f"{path}:{ln}: expected 'KEY: values'")
            k, v = line.split(":", 1)
            try:
                vals[k.strip()] = np.array([float(x) for x in v.split()], dtype=np.float64)
            except ValueError:
                raise ValueError(f"{path}:{ln}: non-numeric value") from None
            if not np.all(np.isfinite(vals[k.strip()])):
                raise ValueError(f"{path}:{ln}: non-finite value (nan or inf)")
    need = {"P2": 12, "Tr_velo_to_cam": 12}
    for k, n in need.items():
        if k not in vals or vals[k].size != n:
            raise ValueError(f"{path}: missing or malformed {k} ({n} values expected)")
    r0 = vals.get("R0_rect", vals.get("R_rect"))
    c = Calib(P2=vals["P2"].reshape(3, 4), Tr_velo_to_cam=vals["Tr_velo_to_cam"].reshape(3, 4),
              R0_rect=np.eye(3) if r0 is None else r0.reshape(3, 3))
    for k in ("P0", "P1", "P3", "Tr_imu_to_velo"):
        if k in vals and vals[k].size == 12:
            setattr(c, k, vals[k].reshape(3, 4))
    return c


def write_calib(path, calib: Calib) -> None:
    def fmt(m):
        return " ".join(f"{x:.12e}" for x in np.asarray(m, dtype=np.float64).ravel())
    eye34 = np.hstack([np.eye(3), np.zeros((3, 1))])
    lines = [
        f"P0: {fmt(calib.P0 if calib.P0 is not None else calib.P2)}",
        f"P1: {fmt(calib.P1 if calib.P1 is not None else calib.P2)}",
        f"P2: {fmt(calib.P2)}",
        f"P3: {fmt(calib.P3 if calib.P3 is not None else calib.P2)}",
        f"R0_rect: {fmt(calib.R0_rect)}",
        f"Tr_velo_to_cam: {fmt(calib.Tr_velo_to_cam)}",
        f"Tr_imu_to_velo: {fmt(calib.Tr_imu_to_velo if calib.Tr_imu_to_velo is not None else eye34)}",
    ]
    _ensure_dir(path)
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


# --------------------------------------------------------------------------------------------
# Boxes


@dataclass
class Box3D:
    """A box in the sensor frame: centre (x, y, z), size (l, w, h), yaw about +z."""
    cls: str
    x: float
    y: float
    z: float
    l: float
    w: float
    h: float
    yaw: float
    score: float = 1.0


@dataclass
class KittiObject:
    """One label_2 line (camera frame)."""
    type: str
    truncated: float
    occluded: int
    alpha: float
    bbox: np.ndarray  # x1, y1, x2, y2 (pixels)
    h: float
    w: float
    l: float
    loc: np.ndarray  # tx, ty, tz: bottom centre in the rectified camera frame
    ry: float
    score: float | None = None

    def to_line(self) -> str:
        s = (f"{self.type} {self.truncated:.2f} {int(self.occluded)} {self.alpha:.2f} "
             f"{self.bbox[0]:.2f} {self.bbox[1]:.2f} {self.bbox[2]:.2f} {self.bbox[3]:.2f} "
             f"{self.h:.3f} {self.w:.3f} {self.l:.3f} {self.loc[0]:.3f} {self.loc[1]:.3f} "
             f"{self.loc[2]:.3f} {self.ry:.4f}")
        if self.score is not None:
            s += f" {self.score:.4f}"
        return s


def read_label2(path) -> list[KittiObject]:
    objs = []
    with open(path) as f:
        for ln, line in enumerate(f, 1):
            p = line.split()
            if not p:
                continue
            if len(p) not in (15, 16):
                raise ValueError(f"{path}:{ln}: expected 15 or 16 fields, got {len(p)}")
            try:
                v = [float(x) for x in p[1:]]
            except ValueError:
                raise ValueError(f"{path}:{ln}: non-numeric field") from None
            if not np.all(np.isfinite(v)):
                raise ValueError(f"{path}:{ln}: non-finite field (nan or inf)")
            objs.append(KittiObject(p[0], v[0], int(v[1]), v[2], np.array(v[3:7]), v[7], v[8],
                                    v[9], np.array(v[10:13]), v[13],
                                    v[14] if len(v) == 15 else None))
    return objs


def write_label2(path, objs: list[KittiObject]) -> None:
    _ensure_dir(path)
    with open(path, "w") as f:
        for o in objs:
            f.write(o.to_line() + "\n")


def truncation_level(truncated: float) -> int:
    """label_2's truncation (a fraction) -> KITTI tracking's level: 0 (<= 0.1), 1 (<= 0.5), 2 (more)."""
    t = float(truncated)
    return 0 if t <= 0.1 else (1 if t <= 0.5 else 2)


def write_label02(path, rows) -> None:
    """KITTI tracking labels (label_02/<seq>.txt): one line per (frame, track id, KittiObject) row,
    `frame id type truncated occluded alpha x1 y1 x2 y2 h w l tx ty tz ry [score]` in the rectified camera frame,
    truncation as the tracking benchmark's integer level (`truncation_level`), DontCare with id -1."""
    _ensure_dir(path)
    with open(path, "w") as f:
        for frame, tid, o in rows:
            rest = o.to_line().split(" ", 2)[2]           # the fields after type and truncated
            f.write(f"{int(frame)} {int(tid)} {o.type} {truncation_level(o.truncated)} {rest}\n")


def read_label02(path) -> list[tuple[int, int, KittiObject]]:
    """Read a KITTI tracking label file: [(frame, track id, KittiObject)] (17 fields, 18 with a score)."""
    out = []
    with open(path) as f:
        for ln, line in enumerate(f, 1):
            p = line.split()
            if not p:
                continue
            if len(p) not in (17, 18):
                raise ValueError(f"{path}:{ln}: expected 17 or 18 fields, got {len(p)}")
            try:
                frame, tid = int(p[0]), int(p[1])
                v = [float(x) for x in p[3:]]
            except ValueError:
                raise ValueError(f"{path}:{ln}: non-numeric field") from None
            if not np.all(np.isfinite(v)):
                raise ValueError(f"{path}:{ln}: non-finite field (nan or inf)")
            out.append((frame, tid, KittiObject(p[2], v[0], int(v[1]), v[2], np.array(v[3:7]), v[7], v[8], v[9],
                                                np.array(v[10:13]), v[13], v[14] if len(v) == 15 else None)))
    return out


def _wrap(a):
    return (a + np.pi) % (2.0 * np.pi) - np.pi


def _rect_rotation(calib: Calib) -> np.ndarray:
    return calib.velo_to_rect()[:3, :3]


def kitti_to_box(obj: KittiObject, calib: Calib) -> Box3D:
    """label_2 object (camera frame, bottom centre) -> sensor-frame Box3D (centre)."""
    # centre = bottom centre moved up by h/2 along camera -y (rectified camera y points down)
    c_rect = np.asarray(obj.loc, dtype=np.float64) + np.array([0.0, -obj.h / 2.0, 0.0])
    c = calib.cam_to_velo_points(c_rect)[0]
    # heading: object x axis in the camera frame is (cos ry, 0, -sin ry)
    d_rect = np.array([np.cos(obj.ry), 0.0, -np.sin(obj.ry)])
    d = np.linalg.inv(_rect_rotation(calib)) @ d_rect
    yaw = float(np.arctan2(d[1], d[0]))
    return Box3D(obj.type, float(c[0]), float(c[1]), float(c[2]), obj.l, obj.w, obj.h, yaw,
                 1.0 if obj.score is None else obj.score)


def box_corners(b: Box3D) -> np.ndarray:
    """(8, 3) corners in the sensor frame: bottom 4 (counter-clockwise from front-left) then top 4."""
    c, s = np.cos(b.yaw), np.sin(b.yaw)
    dx = np.array([1, -1, -1, 1]) * b.l / 2.0
    dy = np.array([1, 1, -1, -1]) * b.w / 2.0
    x = b.x + c * dx - s * dy
    y = b.y + s * dx + c * dy
    zb = np.full(4, b.z - b.h / 2.0)
    bottom = np.stack([x, y, zb], 1)
    top = bottom.copy()
    top[:, 2] += b.h
    return np.vstack([bottom, top])


def box_to_kitti(b: Box3D, calib: Calib, truncated: float = 0.0, occluded: int = 0,
                 bbox=None, score=None) -> KittiObject:
    """Sensor-frame box -> label_2 object. The 2D bbox defaults to the min/max of the 8 corners
    projected through P2, clipped to calib.image_size."""
    # inverse of kitti_to_box: the box's vertical axis is the camera's y axis (KITTI convention)
    loc = calib.velo_to_cam_points(np.array([[b.x, b.y, b.z]]))[0] + np.array([0.0, b.h / 2.0, 0.0])
    d = _rect_rotation(calib) @ np.array([np.cos(b.yaw), np.sin(b.yaw), 0.0])
    ry = float(_wrap(np.arctan2(-d[2], d[0])))
    alpha = float(_wrap(ry - np.arctan2(loc[0], loc[2])))
    if bbox is None:
        uv = calib.project_rect_to_image(calib.velo_to_cam_points(box_corners(b)))
        W, H = calib.image_size
        bbox = np.array([np.clip(uv[:, 0].min(), 0, W - 1), np.clip(uv[:, 1].min(), 0, H - 1),
                         np.clip(uv[:, 0].max(), 0, W - 1), np.clip(uv[:, 1].max(), 0, H - 1)])
    return KittiObject(b.cls, truncated, occluded, alpha, np.asarray(bbox, dtype=np.float64),
                       b.h, b.w, b.l, loc, ry, score)


def read_boxes(path) -> list[Box3D]:
    """Read lidet sensor-frame box lines (9 fields; '#' starts a comment)."""
    out = []
    with open(path) as f:
        for ln, line in enumerate(f, 1):
            line = line.split("#", 1)[0].strip()
            if not line:
                continue
            p = line.split()
            if len(p) != 9:
                raise ValueError(f"{path}:{ln}: expected 9 fields "
                                 f"'<class> <x> <y> <z> <l> <w> <h> <yaw> <score>', got {len(p)}")
            try:
                v = [float(x) for x in p[1:]]
            except ValueError:
                raise ValueError(f"{path}:{ln}: non-numeric field") from None
            if not np.all(np.isfinite(v)):
                raise ValueError(f"{path}:{ln}: non-finite field (nan or inf)")
            if min(v[3:6]) < 0:
                raise ValueError(f"{path}:{ln}: negative box size")
            out.append(Box3D(p[0], *v))
    return out


def write_boxes(path, boxes: list[Box3D]) -> None:
    _ensure_dir(path)
    with open(path, "w") as f:
        for b in boxes:
            f.write(f"{b.cls} {b.x:.4f} {b.y:.4f} {b.z:.4f} {b.l:.4f} {b.w:.4f} {b.h:.4f} "
                    f"{b.yaw:.5f} {b.score:.4f}\n")


def _ensure_dir(path) -> None:
    d = os.path.dirname(os.fspath(path))
    if d:
        os.makedirs(d, exist_ok=True)
