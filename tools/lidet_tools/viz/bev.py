# SPDX-License-Identifier: MIT
"""Bird's-eye view of a scan: points coloured by height, ground, cluster or semantic class, ground-truth
and predicted boxes (with headings and scores), range rings, the sensor at the origin.

The picture is in the sensor frame: x forward (to the right in the picture), y left (up), metres,
equal aspect. Use :func:`plot_bev` from Python and ``lidet-viz bev`` from the shell.
"""
from __future__ import annotations

import numpy as np

from ..kitti import Box3D

#: box colours per class (predictions); ground truth is drawn in GT_COLOR
CLASS_COLORS = {"car": "#ff7f0e", "van": "#ffbb78", "truck": "#8c564b", "pedestrian": "#d62728",
                "person_sitting": "#ff9896", "cyclist": "#9467bd", "misc": "#7f7f7f"}
GT_COLOR = "#2ca02c"
GROUND_COLOR = "#b59b6d"
OTHER_COLOR = "#5a5a5a"
NO_CLUSTER_COLOR = "#c8c8c8"

#: SemanticKITTI classes -> (name, colour) for the legend (ground classes in earthy tones)
SEMANTIC_COLORS = {
    0: ("unlabeled", "#d0d0d0"), 1: ("outlier", "#d0d0d0"),
    10: ("car", "#1f77b4"), 11: ("bicycle", "#17becf"), 13: ("bus", "#393b79"),
    15: ("motorcycle", "#17becf"), 16: ("on-rails", "#393b79"), 18: ("truck", "#393b79"),
    20: ("other-vehicle", "#6b6ecf"), 30: ("person", "#d62728"), 31: ("bicyclist", "#e377c2"),
    32: ("motorcyclist", "#e377c2"), 40: ("road", "#8c6d31"), 44: ("parking", "#bd9e39"),
    48: ("sidewalk", "#ad494a"), 49: ("other-ground", "#843c39"), 50: ("building", "#ffbb78"),
    51: ("fence", "#e7969c"), 52: ("other-structure", "#ffbb78"), 60: ("lane-marking", "#e7cb94"),
    70: ("vegetation", "#2ca02c"), 71: ("trunk", "#637939"), 72: ("terrain", "#b5cf6b"),
    80: ("pole", "#7f7f7f"), 81: ("traffic-sign", "#bcbd22"), 99: ("other-object", "#9c9ede"),
}
_MOVING = {252: 10, 253: 31, 254: 30, 255: 32, 256: 16, 257: 13, 258: 18, 259: 20}


def _as_boxes(boxes) -> list:
    """Box3D list, or an (N, 7|8) array [x y z l w h yaw (score)], -> list of Box3D."""
    if boxes is None:
        return []
    if isinstance(boxes, np.ndarray):
        a = np.atleast_2d(boxes)
        return [Box3D("object", *map(float, r[:7]), float(r[7]) if len(r) > 7 else 1.0) for r in a]
    return list(boxes)


def box_outline(b: Box3D) -> np.ndarray:
    """(5, 2) closed BEV outline of a box (front-left, rear-left, rear-right, front-right, front-left)."""
    c, s = np.cos(b.yaw), np.sin(b.yaw)
    dx = np.array([1, -1, -1, 1, 1]) * b.l / 2
    dy = np.array([1, 1, -1, -1, 1]) * b.w / 2
    return np.stack([b.x + c * dx - s * dy, b.y + s * dx + c * dy], 1)


def _point_colors(points, labels, color_by, ground):
    """-> (colors or scalar values, legend handles info, colorbar flag)."""
    import matplotlib.colors as mcolors

    n = len(points)
    legend = []
    if color_by == "auto":
        if labels is None:
            color_by = "ground" if ground is not None else "height"
        else:
            lab = np.asarray(labels)
            color_by = "ground" if (lab.dtype == bool or lab.max(initial=0) <= 1) else "cluster"
    if color_by == "height":
        return points[:, 2], [], True
    cols = np.empty((n, 4))
    if color_by == "ground":
        g = np.asarray(labels if labels is not None else ground).astype(bool)
        cols[:] = mcolors.to_rgba(OTHER_COLOR)
        cols[g] = mcolors.to_rgba(GROUND_COLOR)
        legend = [("ground", GROUND_COLOR), ("not ground", OTHER_COLOR)]
        return cols, legend, False
    if color_by == "cluster":
        ids = np.asarray(labels).astype(np.int64)
        cmap = __import__("matplotlib").colormaps["tab20"]
        pal = np.array([cmap(i) for i in range(20)])
        # stable shuffle so neighbouring ids get different colours
        cols[:] = pal[(ids * 7) % 20]
        none = ids <= 0
        cols[none] = mcolors.to_rgba(NO_CLUSTER_COLOR)
        legend = [(f"clusters ({len(np.unique(ids[~none]))}, one colour each)", pal[7]),
                  ("no cluster", NO_CLUSTER_COLOR)]
        if ground is not None:
            gm = np.asarray(ground).astype(bool)
            cols[gm] = mcolors.to_rgba(GROUND_COLOR)
            legend.insert(0, ("ground", GROUND_COLOR))
        return cols, legend, False
    if color_by in ("semantic", "class"):
        sem = (np.asarray(labels).astype(np.uint32) & 0xFFFF).astype(np.int64)
        for m, s in _MOVING.items():
            sem[sem == m] = s
        cols[:] = mcolors.to_rgba("#d0d0d0")
        for cid in np.unique(sem):
            name, c = SEMANTIC_COLORS.get(int(cid), (f"class {cid}", "#9c9ede"))
            cols[sem == cid] = mcolors.to_rgba(c)
            legend.append((name, c))
        return cols, legend, False
    raise ValueError(f"color_by must be auto, height, ground, cluster or semantic, got {color_by!r}")


def plot_bev(points, point_labels=None, gt_boxes=None, pred_boxes=None, *, color_by: str = "auto",
             ground=None, ax=None, xlim=None, ylim=None, view_m: float = 50.0, ring_step_m: float = 10.0,
             title: str | None = None, point_size: float | None = None, min_score: float | None = None,
             show_scores: bool = True, show_gt_class: bool = True, legend: bool = True,
             figsize=(9.0, 9.0)):
    """Draw a bird's-eye view and return the matplotlib Figure (save it with ``fig.savefig(png)``).

    points: (N, >=3) sensor-frame x, y, z[, ...] in metres.
    point_labels: None, or one value per point: a ground mask (bool / 0-1), cluster ids (0 or
        negative: no cluster) or SemanticKITTI labels (uint32, lower 16 bits), as chosen by color_by.
    gt_boxes, pred_boxes: lists of :class:`kitti.Box3D` (sensor frame) or (N, 7|8) arrays.
    color_by: "auto" (ground for 0/1 labels, cluster for other ids, height without labels),
        "height", "ground", "cluster" or "semantic". ground: optional mask drawn over cluster colours.
    xlim, ylim: view in metres (default: +-view_m around the sensor). min_score: hide weaker predictions.
    show_scores / show_gt_class: write each prediction's score / each ground-truth box's class beside it.
    """
    import matplotlib.pyplot as plt
    from matplotlib.lines import Line2D
    from matplotlib.patches import Circle

    pts = np.asarray(points, dtype=np.float64)
    if pts.ndim != 2 or pts.shape[1] < 3:
        raise ValueError(f"points must be (N, >=3), got {pts.shape}")
    if point_labels is not None and len(point_labels) != len(pts):
        raise ValueError(f"{len(point_labels)} point labels for {len(pts)} points")
    xlim = tuple(xlim) if xlim is not None else (-view_m, view_m)
    ylim = tuple(ylim) if ylim is not None else (-view_m, view_m)
    if ax is None:
        fig, ax = plt.subplots(figsize=figsize, dpi=120, layout="constrained")
    else:
        fig = ax.figure
    vals, leg_pts, colorbar = _point_colors(pts, point_labels, color_by, ground)
    inview = ((pts[:, 0] >= xlim[0]) & (pts[:, 0] <= xlim[1]) & (pts[:, 1] >= ylim[0])
              & (pts[:, 1] <= ylim[1]))
    area = (xlim[1] - xlim[0]) * (ylim[1] - ylim[0])
    s = point_size if point_size is not None else float(np.clip(3000.0 / max(area, 1.0), 0.15, 4.0))
    if colorbar:
        sc = ax.scatter(pts[inview, 0], pts[inview, 1], c=np.clip(vals[inview], -2.5, 2.5), s=s,
                        cmap="viridis", linewidths=0, vmin=-2.5, vmax=2.5, zorder=4.5)
        fig.colorbar(sc, ax=ax, shrink=0.6, label="z [m] (height above the sensor)")
    else:
        ax.scatter(pts[inview, 0], pts[inview, 1], c=vals[inview], s=s, linewidths=0, zorder=4.5)

    # points above the ground-truth outlines (an object's returns lie on its box's edges),
    # below the predictions; range rings and the sensor
    rmax = float(np.hypot(max(abs(xlim[0]), abs(xlim[1])), max(abs(ylim[0]), abs(ylim[1]))))
    for r in np.arange(ring_step_m, rmax + 1e-9, ring_step_m):
        ax.add_patch(Circle((0, 0), r, fill=False, lw=0.6, ls=":", color="#888888", zorder=1))
        a = np.deg2rad(40.0)
        tx, ty = r * np.cos(a), r * np.sin(a)
        if xlim[0] < tx < xlim[1] and ylim[0] < ty < ylim[1]:
            ax.text(tx, ty, f"{r:g} m", fontsize=7, color="#666666", ha="left", va="bottom", zorder=1)
    ax.plot([0], [0], marker=">", ms=9, color="black", zorder=6, ls="none")

    handles = []
    gts = _as_boxes(gt_boxes)
    for b in gts:
        o = box_outline(b)
        ax.plot(o[:, 0], o[:, 1], color=GT_COLOR, lw=2.0, zorder=4)
        ax.plot([b.x, b.x + np.cos(b.yaw) * b.l / 2], [b.y, b.y + np.sin(b.yaw) * b.l / 2],
                color=GT_COLOR, lw=2.0, zorder=4)
        if show_gt_class and xlim[0] < b.x < xlim[1] and ylim[0] < b.y < ylim[1]:
            ax.text(b.x, b.y - max(b.l, b.w) / 2 - 0.4, b.cls, fontsize=7, color=GT_COLOR, ha="center",
                    va="top", zorder=6, clip_on=True)
    if gts:
        handles.append(Line2D([], [], color=GT_COLOR, lw=2.0, label=f"ground truth ({len(gts)})"))
    preds = [b for b in _as_boxes(pred_boxes) if min_score is None or b.score >= min_score]
    seen = {}
    for b in preds:
        c = CLASS_COLORS.get(b.cls.lower(), "#1f1f1f")
        o = box_outline(b)
        ax.plot(o[:, 0], o[:, 1], color=c, lw=1.3, ls="--", zorder=5)
        ax.plot([b.x, b.x + np.cos(b.yaw) * b.l / 2], [b.y, b.y + np.sin(b.yaw) * b.l / 2],
                color=c, lw=1.3, zorder=5)
        if show_scores and xlim[0] < b.x < xlim[1] and ylim[0] < b.y < ylim[1]:
            ax.text(b.x + max(b.l, b.w) / 2 + 0.3, b.y, f"{b.score:.2f}", fontsize=7, color=c,
                    va="center", zorder=6, clip_on=True)
        seen[b.cls] = seen.get(b.cls, 0) + 1
    for cls, n in seen.items():
        handles.append(Line2D([], [], color=CLASS_COLORS.get(cls.lower(), "#1f1f1f"), lw=1.3, ls="--",
                              label=f"predicted {cls} ({n}), score"))
    for name, c in leg_pts:
        handles.append(Line2D([], [], marker="o", ls="none", color=c, ms=5, label=name))
    handles.append(Line2D([], [], marker=">", ls="none", color="black", ms=7,
                          label=f"sensor (rings every {ring_step_m:g} m)"))
    ax.set_xlim(*xlim)
    ax.set_ylim(*ylim)
    ax.set_aspect("equal")
    ax.set_xlabel("x [m] (forward)")
    ax.set_ylabel("y [m] (left)")
    ax.grid(False)
    if title:
        ax.set_title(title)
    if legend:
        ax.legend(handles=handles, loc="upper left", fontsize=8, framealpha=0.85)
    return fig


def save_bev(path, *args, **kw):
    """plot_bev(...) then save it as a PNG at path; returns path."""
    import matplotlib.pyplot as plt

    fig = plot_bev(*args, **kw)
    fig.savefig(path)
    plt.close(fig)
    return path
