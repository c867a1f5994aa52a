# SPDX-License-Identifier: MIT
"""Real scans of a dense sensor thinned to the rings of a sparser one: the robot's sensor families (VLP-16,
VLP-32C) have no labelled real scans here, so real HDL-64 scans stand in for them (issue 36).

Each point takes the beam of the source profile nearest to its elevation (atan2(z, r) from the LiDAR), the way the
projection assigns rows; each beam of the target profile keeps the source beam nearest to it, if one lies within
`tol_deg`; the points of the kept beams are the thinned scan. An HDL-64 reaches +2.5 degrees, so of a VLP-16's
beams (-15 to +15 degrees, 2 apart) the 9 from -15 to +1 degrees exist: the result is a VLP-16 at the HDL-64's height
without its upper half, whose beams at that height hit only what is above the sensor beyond a few metres.
"""
from __future__ import annotations

import numpy as np

from ..sensors import get_sensor


def beam_map(from_sensor: str = "hdl64", to_sensor: str = "vlp16", tol_deg: float = 0.25) -> dict:
    """{source beam index (ring order): target beam index} for the target beams that have a source beam within
    tol_deg."""
    src = np.asarray(get_sensor(from_sensor).beam_elev_rad, dtype=np.float64)
    dst = np.asarray(get_sensor(to_sensor).beam_elev_rad, dtype=np.float64)
    out = {}
    for j, e in enumerate(dst):
        i = int(np.argmin(np.abs(src - e)))
        if abs(src[i] - e) <= np.radians(tol_deg):
            out[i] = j
    return out


def thin(points: np.ndarray, from_sensor: str = "hdl64", to_sensor: str = "vlp16",
         tol_deg: float = 0.25) -> np.ndarray:
    """The points of `points` (N, >=3, sensor frame of a `from_sensor`) on the beams a `to_sensor` shares with it."""
    p = np.asarray(points)
    src = np.asarray(get_sensor(from_sensor).beam_elev_rad, dtype=np.float64)
    order = np.argsort(src)
    s = src[order]
    el = np.arctan2(p[:, 2].astype(np.float64), np.hypot(p[:, 0], p[:, 1]).astype(np.float64))
    k = np.clip(np.searchsorted(s, el), 1, len(s) - 1)
    near = np.where(np.abs(el - s[k - 1]) <= np.abs(el - s[k]), k - 1, k)
    beam = order[near]
    keep = np.isin(beam, list(beam_map(from_sensor, to_sensor, tol_deg)))
    return p[keep]
