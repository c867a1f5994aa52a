# SPDX-License-Identifier: MIT
"""Sensor profiles, mirrored from lib/src/lidet_sensors.c (tests/python/test_bindings_proj.py keeps the
two identical through the bindings).

Frame: x forward, y left, z up, metres, radians, origin at the sensor's optical centre.
Beam elevations are listed in the sensor's *ring order* (the ring index its driver reports);
the projection sorts them top to bottom to get image rows (row 0 = highest beam).

Column convention (same as the SemanticKITTI API): col = floor(0.5 * (1 - azimuth / pi) * cols),
azimuth = atan2(y, x); so +x (forward) is the middle column, azimuth decreases to the right, and
the seam (col 0 / cols-1) is straight behind the sensor.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


def _deg(a):
    return np.radians(np.asarray(a, dtype=np.float64))


@dataclass(frozen=True)
class Sensor:
    name: str
    rows: int
    cols: int
    #: per-beam elevation in radians, ring order (len == rows)
    beam_elev_rad: np.ndarray = field(repr=False)
    mount_height_m: float
    max_range_m: float
    #: (fov_up, fov_down) in microradians for a uniform sensor (the integer presets give the fov, not a
    #: table, as lib/src/lidet_sensor_q.c); None for a sensor with a beam table
    fov_urad: tuple | None = None

    @property
    def beam_elev_urad(self) -> np.ndarray:
        """Beam elevations in ring order, integer microradians (the integer path's profile,
        lidet_sensor_q_elevations): the table rounded, or the uniform beams computed in integers."""
        if self.fov_urad is not None:
            up, down = self.fov_urad
            span = up - down
            i = np.arange(self.rows, dtype=np.int64)
            n = (2 * i + 1) * span  # > 0: round half away from zero = floor(n / d + 1/2)
            return (up - (n + self.rows) // (2 * self.rows)).astype(np.int32)
        return np.round(self.beam_elev_rad * 1e6).astype(np.int32)

    @property
    def mount_height_mm(self) -> int:
        return int(round(self.mount_height_m * 1000.0))

    @property
    def max_range_mm(self) -> int:
        return int(round(self.max_range_m * 1000.0))

    #: horizontal angular resolution in radians
    @property
    def az_step_rad(self) -> float:
        return 2.0 * np.pi / self.cols

    @property
    def elev_sorted_desc(self) -> np.ndarray:
        """Beam elevations in row order (row 0 = top)."""
        return np.sort(self.beam_elev_rad)[::-1]

    @property
    def ring_to_row(self) -> np.ndarray:
        """Row of each ring (stable: equal elevations keep ring order)."""
        order = np.argsort(-self.beam_elev_rad, kind="stable")
        r2r = np.empty(self.rows, dtype=np.int64)
        r2r[order] = np.arange(self.rows)
        return r2r


def uniform_beams(fov_up_deg: float, fov_down_deg: float, rows: int) -> np.ndarray:
    """Beam centres of a uniform fov split into `rows` bins, top to bottom (radians).

    Bin i spans [fov_up - (i+1)*step, fov_up - i*step]; its beam sits at the bin centre, so the
    nearest-beam rule reproduces the uniform formula row = floor((fov_up - pitch) / step).
    """
    step = (fov_up_deg - fov_down_deg) / rows
    return _deg(fov_up_deg - (np.arange(rows) + 0.5) * step)


# KITTI HDL-64E. The datasheet gives +2.0 .. -24.8 deg; in KITTI's own (calibrated, motion-
# compensated) scans the beams sit higher. We recovered each point's ring from the scan order of 11
# real KITTI scans (a new ring starts where the azimuth wraps) and took each ring's median
# elevation: upper block +2.5 .. -7.7 deg (~0.33 deg apart), lower block -8.25 .. -23.5 deg
# (~0.49 deg apart). Ring order = top to bottom, as KITTI's scan order.
_HDL64 = np.concatenate([np.linspace(2.5, -7.7, 32), np.linspace(-8.25, -23.5, 32)])

# Velodyne VLP-16: -15..+15 deg every 2 deg. Ring order as velodyne_pointcloud reports it:
# ring 0 = lowest beam.
_VLP16 = np.arange(-15.0, 15.0 + 1e-9, 2.0)

# Velodyne VLP-32C: its real non-uniform table (dense around the horizon), ring 0 = lowest.
_VLP32C = np.array([
    -25.0, -15.639, -11.31, -8.843, -7.254, -6.148, -5.333, -4.667,
    -4.0, -3.667, -3.333, -3.0, -2.667, -2.333, -2.0, -1.667,
    -1.333, -1.0, -0.667, -0.333, 0.0, 0.333, 0.667, 1.0,
    1.333, 1.667, 2.333, 3.333, 4.667, 7.0, 10.333, 15.0,
])

def _urad_fov(up_deg: float, down_deg: float) -> tuple:
    return int(round(np.radians(up_deg) * 1e6)), int(round(np.radians(down_deg) * 1e6))


SENSORS: dict[str, Sensor] = {
    "hdl64": Sensor("hdl64", 64, 2048, _deg(_HDL64), 1.73, 120.0),
    "vlp16": Sensor("vlp16", 16, 1800, _deg(_VLP16), 0.5, 100.0),
    "vlp32c": Sensor("vlp32c", 32, 1800, _deg(_VLP32C), 1.0, 200.0),
    # Ouster OS1: uniform +-22.5 deg; ring 0 = top beam (Ouster's convention).
    "os1-64": Sensor("os1-64", 64, 2048, uniform_beams(22.5, -22.5, 64), 1.0, 120.0, _urad_fov(22.5, -22.5)),
    "os1-128": Sensor("os1-128", 128, 2048, uniform_beams(22.5, -22.5, 128), 1.0, 120.0, _urad_fov(22.5, -22.5)),
}


def get_sensor(name: str) -> Sensor:
    try:
        return SENSORS[name]
    except KeyError:
        raise ValueError(f"unknown sensor {name!r}; known: {', '.join(SENSORS)}") from None


def custom_sensor(name: str, cols: int, beam_elev_deg=None, fov_up_deg=None, fov_down_deg=None,
                  rows=None, mount_height_m=1.0, max_range_m=100.0) -> Sensor:
    """A custom profile from a per-beam table (ring order, degrees) or a uniform fov."""
    fov = None
    if beam_elev_deg is not None:
        elev = _deg(beam_elev_deg)
    else:
        if fov_up_deg is None or fov_down_deg is None or rows is None:
            raise ValueError("custom sensor needs beam_elev_deg or fov_up_deg, fov_down_deg and rows")
        elev = uniform_beams(fov_up_deg, fov_down_deg, rows)
        fov = _urad_fov(fov_up_deg, fov_down_deg)
    return Sensor(name, len(elev), int(cols), elev, float(mount_height_m), float(max_range_m), fov)
