# SPDX-License-Identifier: MIT
"""Estimate a sensor's mount height (its height above the ground) from scans.

    python -m lidet_tools.mount SCAN.bin [SCAN.bin ...] --sensor vlp16 [--json]
    python -m lidet_tools.mount KITTI_DIR --sensor hdl64          # every KITTI_DIR/velodyne/*.bin

The detector needs the real mount height (`lidet_sensor_t.mount_height_m`, `lidet detect --mount-height`): its
ground stage refuses a sector's plane lying more than `max_height_dev_m` (0.5 m on 16 beams, 1 m above) from it
(docs/DETECTOR.md, Mount height). This tool runs the library's own ground stage (through the bindings) with that
check opened to 10 m, so every sector keeps the plane its RANSAC finds, and takes the median of the fitted near
planes' offsets: a plane n.p + d = 0 with a unit normal lies d metres below the sensor. The median over the
scans is the estimate. Record a few scans where the robot stands on open, level ground.

Measured (20 simulated VLP-16 scans per mount; `lidet-sim --mount-height`): 0.31 / 0.53 / 0.74 / 1.04 m at 0.3 /
0.5 / 0.7 / 1.0 m mounts, single scans within 0.05 (0.3 m) to 0.2 m (0.7 m) of it; the 9 labelled KITTI / SemanticKITTI scans of
../shared/data/real give 1.67-1.81 m, median 1.80 m (KITTI's HDL-64 is mounted at 1.73 m); the real Ouster OS2-128
and OS1-32 captures of ../shared/data/packets (car roofs) 1.98 and 1.88 m. An estimate below 0.1 m comes with a
warning (and `"warning"` in the JSON): the planes lie at the sensor's own height, as in a real VLP-16 capture of an
office (0.00 m: desks and walls, the floor out of the beams' view), where no ground below the sensor was seen.
"""
from __future__ import annotations

import argparse
import json
import pathlib
import sys

import numpy as np

#: the ground stage's height check while estimating (the largest the configuration accepts is 20 m)
OPEN_HEIGHT_DEV_M = 10.0
#: an estimate below this is reported with a warning: the planes lie at the sensor's own height (a sensor standing on
#: the table it sees, or a room whose floor is out of the beams' view: a real VLP-16 capture in an office gives 0.00 m)
LOW_MOUNT_M = 0.1


#: more than this share of a scan's points outside the sensor's beams (the projection's n_out_of_fov) says the cloud
#: is not in lidet's frame or not from that sensor: the real labelled frames of ../shared/data/real put at most 0.5 %
#: there, a KITTI scan turned upside down 48 % (the rule of `native.frame_warning` and the CLI's cli_warn_frame,
#: which main applies)
OUT_OF_BEAMS_SHARE = 0.1


def out_of_beams(points, sensor: str = "hdl64") -> float:
    """The share of (N, >=3) points that the sensor's projection drops as outside its beams' elevations."""
    from . import native
    n = len(points)
    return float(native.project(points, sensor).stats["n_out_of_fov"]) / n if n else 0.0


def estimate(points, sensor: str = "hdl64") -> tuple[float, int]:
    """(height in m, fitted sectors it comes from) for one scan of (N, >=3) points; (nan, 0) when no sector got a
    plane of its own (an empty or tiny scan)."""
    from . import native
    g = native.ground(points, sensor, max_height_dev_m=OPEN_HEIGHT_DEV_M)
    ns = len(g.planes)
    d = g.planes[g.source[:ns] == 0][:, 3].astype(np.float64)
    d = d[np.isfinite(d)]
    return (float(np.median(d)), int(len(d))) if len(d) else (float("nan"), 0)


def _scans(paths) -> list[pathlib.Path]:
    out = []
    for p in map(pathlib.Path, paths):
        if p.is_dir():
            sub = p / "velodyne" if (p / "velodyne").is_dir() else p
            out += sorted(sub.glob("*.bin"))
        else:
            out.append(p)
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m lidet_tools.mount", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scans", nargs="+", help="KITTI .bin scans, or folders of them (FOLDER/velodyne/*.bin)")
    ap.add_argument("--sensor", default="hdl64", help="sensor profile (hdl64, vlp16, ...)")
    ap.add_argument("--json", action="store_true", help="print one JSON object")
    a = ap.parse_args(argv)
    from . import kitti, native
    presets = native.c_sensors()
    if a.sensor not in presets:
        print(f"lidet_tools.mount: error: unknown sensor '{a.sensor}' (known: {', '.join(presets)})",
              file=sys.stderr)
        return 1
    files = _scans(a.scans)
    if not files:
        print("lidet_tools.mount: error: no scans", file=sys.stderr)
        return 1
    per = []
    frame_warning = None
    for f in files:
        try:
            pts = kitti.read_bin(f)
        except (OSError, ValueError) as e:
            print(f"lidet_tools.mount: error: {f}: {e}", file=sys.stderr)
            return 1
        h, n = estimate(pts, a.sensor)
        per.append((str(f), h, n))
        w = native.frame_warning(native.project(pts, a.sensor).stats, a.sensor) if frame_warning is None else None
        if w is not None:
            frame_warning = f"{f}: {w}; its estimate means nothing"
            print(f"lidet_tools.mount: warning: {frame_warning}", file=sys.stderr)
    hs = np.array([h for _, h, _ in per])
    ok = np.isfinite(hs)
    if not ok.any():
        print("lidet_tools.mount: error: no ground plane found in any scan (empty scans, or no ground in view)",
              file=sys.stderr)
        return 1
    med = float(np.median(hs[ok]))
    profile = presets[a.sensor][3]
    warning = frame_warning
    if warning is None and med < LOW_MOUNT_M:
        warning = (f"the fitted planes lie within {LOW_MOUNT_M:g} m of the sensor's own height ({med:.2f} m): is the "
                   f"sensor standing on the surface it sees (a table), or is the floor out of view? Record scans on "
                   f"open, level ground, or give the height you measured")
        print(f"lidet_tools.mount: warning: {warning}", file=sys.stderr)
    if a.json:
        print(json.dumps({"sensor": a.sensor, "mount_height_m": round(med, 3), "profile_mount_height_m": profile,
                          "warning": warning,
                          "scans": [{"scan": s, "mount_height_m": None if not np.isfinite(h) else round(h, 3),
                                     "sectors": n} for s, h, n in per]}))
    else:
        for s, h, n in per:
            print(f"{s}: {h:.3f} m ({n} sectors)" if np.isfinite(h) else f"{s}: no ground plane")
        lo, hi = float(hs[ok].min()), float(hs[ok].max())
        advice = "no advice (see the warning)" if warning else f"lidet detect --mount-height {med:.2f}"
        print(f"mount height {med:.2f} m (median of {int(ok.sum())} scans, {lo:.2f}-{hi:.2f} m per scan; "
              f"the {a.sensor} profile says {profile:.2f} m): {advice}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
