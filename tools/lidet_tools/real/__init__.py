# SPDX-License-Identifier: MIT
"""Readers of the real labelled LiDAR frames in ``../shared/data/real`` (see its README.md), one module per
source, all giving lidet's sensor frame: x forward, y left, z up, metres, origin at the LiDAR; boxes are
:class:`lidet_tools.kitti.Box3D` with (x, y, z) the box centre, yaw about +z from +x, l along the heading.

    from lidet_tools import real
    for fid in real.list_frames(root, "pandaset"):
        fr = real.load_frame(root, "pandaset", fid)      # RealFrame

Evaluated classes are ``Car``, ``Pedestrian``, ``Cyclist``; ``Van``, ``Person_sitting``, ``DontCare`` and
``Other`` mark objects an evaluation must ignore (neither a hit nor a false positive). Labels exist only within
``fov_half_rad`` of the x axis (None: all around). ``approx_boxes`` marks boxes fitted to the visible points
(SemanticKITTI, SqueezeSeg: no annotated boxes), which are looser than annotated ones.

Every reader raises FileNotFoundError or ValueError naming the file and the problem on a missing, truncated or
malformed file. Each module's docstring states its conventions and what was checked with BEV pictures
(``python -m lidet_tools.real.show --all --out DIR``).
"""
from __future__ import annotations

import importlib
import os
import pathlib
from dataclasses import dataclass

import numpy as np

SOURCES = ("kitti", "kitti360", "pandaset", "argoverse", "semantickitti", "squeezeseg")

#: classes an evaluation scores; every other class name of a RealFrame box is ignored
#: presets of 64-beam sensors like KITTI's HDL-64E: their frames are the hdl64 family's kind of data (real.compare,
#: eval_real --as-sensor, real.export)
HDL64_LIKE = ("hdl64", "pandar64")
EVAL_CLASSES = ("Car", "Pedestrian", "Cyclist")
#: classes of objects that must be ignored (neither matched nor counted as false positives)
IGNORED_CLASSES = ("Van", "Person_sitting", "DontCare", "Other")

_MODULES = {"kitti": "kitti", "kitti360": "kitti360", "pandaset": "pandaset", "argoverse": "argoverse",
            "semantickitti": "semantickitti", "squeezeseg": "squeezeseg"}


@dataclass
class RealFrame:
    """One labelled scan in lidet's sensor frame (see the module docstring)."""
    source: str               # one of SOURCES
    frame_id: str             # file stem, unique within the source
    points: np.ndarray        # (N, 4) float32 x, y, z, intensity (sensor frame, finite only)
    boxes: list               # Box3D, sensor frame; cls in EVAL_CLASSES or IGNORED_CLASSES
    fov_half_rad: float | None  # labels exist where |atan2(y, x)| <= it; None = all 360 degrees
    sensor: str               # lidet sensor preset to run it with
    mount_height_m: float     # LiDAR height above the road
    point_instance: np.ndarray | None = None  # (N,) int32 index into boxes per point (-1 none), where labelled
    approx_boxes: bool = False  # boxes fitted to the visible points
    point_semantic: np.ndarray | None = None  # (N,) SemanticKITTI base class per point (lower 16 bits), where labelled

    def class_counts(self) -> dict[str, int]:
        """{class: number of boxes}."""
        out: dict[str, int] = {}
        for b in self.boxes:
            out[b.cls] = out.get(b.cls, 0) + 1
        return out


def _module(source: str):
    if source not in _MODULES:
        raise ValueError(f"unknown source {source!r}; known: {', '.join(SOURCES)}")
    return importlib.import_module(f".{_MODULES[source]}", __name__)


def list_frames(root, source: str) -> list[str]:
    """Sorted ids of the labelled frames of a source under root (.../shared/data/real). Raises
    FileNotFoundError when the source's folder is missing."""
    return _module(source).list_frames(pathlib.Path(root))


def load_frame(root, source: str, frame_id: str) -> RealFrame:
    """Read one labelled frame of a source in lidet's sensor frame."""
    return _module(source).load_frame(pathlib.Path(root), str(frame_id))


# --------------------------------------------------------------------------------------------
# helpers shared by the source modules


def need_file(path) -> pathlib.Path:
    """path as a Path; FileNotFoundError naming it when it is not an existing file."""
    p = pathlib.Path(path)
    if not p.is_file():
        raise FileNotFoundError(f"{p}: no such file")
    return p


def need_dir(path) -> pathlib.Path:
    p = pathlib.Path(path)
    if not p.is_dir():
        raise FileNotFoundError(f"{p}: no such folder")
    return p


def finite_points(points: np.ndarray, path) -> tuple[np.ndarray, np.ndarray]:
    """(finite rows as (N, 4) float32, boolean mask of the kept rows). Raises ValueError naming path when the
    array is not (N, 4)."""
    a = np.asarray(points)
    if a.ndim != 2 or a.shape[1] != 4:
        raise ValueError(f"{path}: expected (N, 4) points, got shape {a.shape}")
    keep = np.all(np.isfinite(a), axis=1)
    return np.ascontiguousarray(a[keep], dtype=np.float32), keep


def stems(folder, ext: str) -> set[str]:
    """File stems with extension ext (e.g. '.bin') in folder."""
    return {p[: -len(ext)] for p in os.listdir(need_dir(folder)) if p.endswith(ext)}
