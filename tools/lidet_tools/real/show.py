# SPDX-License-Identifier: MIT
"""Bird's-eye pictures of the real labelled frames (points + ground-truth boxes), to check a reader's conventions.

    python -m lidet_tools.real.show SOURCE FRAME_ID --png OUT.png [--root ../shared/data/real]
    python -m lidet_tools.real.show --all --out DIR [--root ../shared/data/real]   (sources absent there: skipped)
    add --crops for close-ups of every box (top and side views in the box frame, share of points inside)

Evaluated boxes (Car, Pedestrian, Cyclist) are drawn in green with their class, ignored ones (Van,
Person_sitting, DontCare, Other) in grey dashes; the labelled field of view (fov_half_rad) as two grey rays.
Points are coloured by height, or by object where the source has per-point labels (point_instance).
The title gives source, frame, point count and boxes per class.
"""
from __future__ import annotations

import argparse
import pathlib
import sys

import numpy as np

from . import EVAL_CLASSES, SOURCES, RealFrame, list_frames, load_frame

DEFAULT_ROOT = pathlib.Path(__file__).resolve().parents[3].parent / "shared" / "data" / "real"
IGNORED_COLOR = "#7f7f7f"


def frame_title(fr: RealFrame) -> str:
    counts = ", ".join(f"{k} {v}" for k, v in sorted(fr.class_counts().items()))
    approx = ", fitted boxes" if fr.approx_boxes else ""
    return (f"{fr.source} {fr.frame_id}: {len(fr.points)} points, {len(fr.boxes)} boxes ({counts or 'none'})"
            f"{approx}\nsensor {fr.sensor}, mount {fr.mount_height_m:.2f} m")


def save_frame_png(fr: RealFrame, png, view_m: float | None = None, xlim=None, ylim=None) -> str:
    """Write the BEV picture of one RealFrame to png; returns the path."""
    import matplotlib.pyplot as plt

    from ..viz.bev import box_outline, plot_bev

    if view_m is None:
        far = [np.hypot(b.x, b.y) for b in fr.boxes]
        view_m = float(np.clip(max(far, default=40.0) + 5.0, 30.0, 80.0))
    labels = None
    kw = {}
    if fr.point_instance is not None:
        labels = fr.point_instance.astype(np.int64) + 1
        kw["color_by"] = "cluster"
    ev = [b for b in fr.boxes if b.cls in EVAL_CLASSES]
    ign = [b for b in fr.boxes if b.cls not in EVAL_CLASSES]
    fig = plot_bev(fr.points, labels, gt_boxes=ev, view_m=view_m, xlim=xlim, ylim=ylim,
                   title=frame_title(fr), **kw)
    ax = fig.axes[0]
    for b in ign:
        o = box_outline(b)
        ax.plot(o[:, 0], o[:, 1], color=IGNORED_COLOR, lw=1.2, ls="--", zorder=4)
        ax.text(b.x, b.y + max(b.l, b.w) / 2 + 0.3, b.cls, fontsize=6, color=IGNORED_COLOR, ha="center",
                va="bottom", zorder=6, clip_on=True)
    if fr.fov_half_rad is not None:
        r = 2.0 * view_m
        for s in (-1.0, 1.0):
            ax.plot([0, r * np.cos(fr.fov_half_rad)], [0, s * r * np.sin(fr.fov_half_rad)], color="#555555",
                    lw=0.8, ls="-.", zorder=3)
    fig.savefig(png)
    plt.close(fig)
    return str(png)


def save_box_crops(fr: RealFrame, png, max_boxes: int = 30, margin_m: float = 1.5) -> str:
    """Write close-ups of up to max_boxes boxes (nearest first) to png: per box a top view and a side view in
    the box's own frame (u along l, v along w; the box is the rectangle), points within margin_m of the box
    coloured by height above the box bottom, with the share of those points inside the box."""
    import matplotlib.pyplot as plt

    from .fit import box_point_share, points_in_box

    boxes = sorted(fr.boxes, key=lambda b: np.hypot(b.x, b.y))[:max_boxes]
    n = max(len(boxes), 1)
    cols = 6
    rows = (n + cols - 1) // cols
    fig, axs = plt.subplots(2 * rows, cols, figsize=(3.2 * cols, 2.8 * 2 * rows), dpi=80, squeeze=False)
    for ax in axs.ravel():
        ax.set_axis_off()
    for i, b in enumerate(boxes):
        near = points_in_box(fr.points, b, margin=margin_m)
        near &= fr.points[:, 2] >= b.z - b.h / 2 + 0.15     # no road in the close-up
        n_in, n_near = box_point_share(fr.points, b)
        d = fr.points[near, :3].astype(np.float64) - np.array([b.x, b.y, b.z])
        c, s = np.cos(b.yaw), np.sin(b.yaw)
        u, v, z = c * d[:, 0] + s * d[:, 1], -s * d[:, 0] + c * d[:, 1], d[:, 2]
        top, side = axs[2 * (i // cols), i % cols], axs[2 * (i // cols) + 1, i % cols]
        for ax, (a1, a2, e1, e2) in ((top, (u, v, b.l, b.w)), (side, (u, z, b.l, b.h))):
            ax.set_axis_on()
            ax.scatter(a1, a2, c=z + b.h / 2, s=3, cmap="viridis", vmin=0, vmax=max(b.h, 0.5), linewidths=0)
            ax.plot([-e1 / 2, e1 / 2, e1 / 2, -e1 / 2, -e1 / 2], [-e2 / 2, -e2 / 2, e2 / 2, e2 / 2, -e2 / 2],
                    color="#2ca02c" if b.cls in EVAL_CLASSES else IGNORED_COLOR, lw=1.2)
            ax.set_aspect("equal")
            ax.tick_params(labelsize=6)
        top.set_title(f"{b.cls} r={np.hypot(b.x, b.y):.0f}m {b.l:.1f}x{b.w:.1f}x{b.h:.1f}\n"
                      f"{n_in}/{n_near} in ({n_in / max(n_near, 1):.0%})", fontsize=7)
        top.plot([0, b.l / 2], [0, 0], color="#d62728", lw=1)   # heading
    fig.suptitle(frame_title(fr) + " - close-ups (top: u along l, v along w; below: u, z)", fontsize=8)
    fig.tight_layout()
    fig.savefig(png)
    plt.close(fig)
    return str(png)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m lidet_tools.real.show", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("source", nargs="?", choices=SOURCES, help="source of the frame")
    ap.add_argument("frame_id", nargs="?", help="frame id (file stem)")
    ap.add_argument("--png", help="output picture of one frame")
    ap.add_argument("--all", action="store_true", help="one picture per labelled frame of every source")
    ap.add_argument("--out", help="output folder with --all")
    ap.add_argument("--root", default=str(DEFAULT_ROOT), help=f"data folder (default {DEFAULT_ROOT})")
    ap.add_argument("--crops", action="store_true", help="also write close-ups of the boxes (OUT_crops.png)")
    ap.add_argument("--view-m", type=float, default=None, help="half width of the view (default: fit the boxes)")
    a = ap.parse_args(argv)
    import matplotlib
    matplotlib.use("Agg")
    try:
        if a.all:
            if not a.out or a.source or a.frame_id:
                ap.error("--all takes --out DIR and no SOURCE / FRAME_ID")
            out = pathlib.Path(a.out)
            out.mkdir(parents=True, exist_ok=True)
            for src in SOURCES:
                try:
                    ids = list_frames(a.root, src)
                except FileNotFoundError as e:
                    print(f"{src}: skipped ({e})")
                    continue
                for fid in ids:
                    fr = load_frame(a.root, src, fid)
                    p = save_frame_png(fr, out / f"{src}_{fid}.png", a.view_m)
                    if a.crops:
                        save_box_crops(fr, out / f"{src}_{fid}_crops.png")
                    print(f"{p}: {len(fr.boxes)} boxes {fr.class_counts()}")
            return 0
        if not (a.source and a.frame_id and a.png):
            ap.error("give SOURCE FRAME_ID --png OUT.png, or --all --out DIR")
        fr = load_frame(a.root, a.source, a.frame_id)
        print(save_frame_png(fr, a.png, a.view_m))
        if a.crops:
            print(save_box_crops(fr, str(pathlib.Path(a.png).with_suffix("")) + "_crops.png"))
        return 0
    except (OSError, ValueError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
