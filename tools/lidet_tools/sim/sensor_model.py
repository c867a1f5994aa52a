# SPDX-License-Identifier: MIT
"""Sensor model: the ray grid of a profile and what happens to a return (noise, dropout, remission).

Rays: one per (beam, column); the beam elevations are the profile's table (sensors.py), the column
azimuths follow the project's column convention (col = floor(0.5 * (1 - az / pi) * cols)), with each
ray at its column centre. A small mounting pitch/roll rotates every ray of the level frame.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..sensors import Sensor
from .raycast import RayGrid, rot_x, rot_y


_DIRS_CACHE: dict = {}


def _sensor_dirs(s: Sensor):
    key = (s.name, s.cols, s.beam_elev_rad.tobytes())
    if key not in _DIRS_CACHE:
        order = np.argsort(-s.beam_elev_rad, kind="stable")     # row -> ring
        elev = s.beam_elev_rad[order]
        az = np.pi * (1.0 - 2.0 * (np.arange(s.cols) + 0.5) / s.cols)
        ce, se = np.cos(elev)[:, None], np.sin(elev)[:, None]
        d = np.stack([ce * np.cos(az)[None, :], ce * np.sin(az)[None, :],
                      np.broadcast_to(se, (len(elev), s.cols))], -1).reshape(-1, 3)
        if len(_DIRS_CACHE) > 8:
            _DIRS_CACHE.clear()
        _DIRS_CACHE[key] = (d, elev, order)
    return _DIRS_CACHE[key]


@dataclass
class SensorModel:
    sensor: Sensor
    mount_height_m: float
    pitch_rad: float = 0.0
    roll_rad: float = 0.0
    range_noise_m: float = 0.02      # 1-sigma, clipped at 2.5 sigma
    dropout: float = 0.015           # random loss of any return
    min_range_m: float = 1.0
    far_dropout: float = 0.35        # extra loss at max range (grows with (t / max_range)^2)
    weak_return: float = 0.0015      # returns with remission / t^2 * 100 below this are lost

    @property
    def R_mount(self) -> np.ndarray:
        """Sensor frame -> level frame rotation."""
        return rot_y(self.pitch_rad) @ rot_x(self.roll_rad)

    def ray_grid(self) -> tuple[RayGrid, np.ndarray]:
        """Level-frame ray grid (rows top to bottom) and the ring index of each row."""
        d, elev, order = _sensor_dirs(self.sensor)
        d_level = d @ self.R_mount.T
        tilt = abs(self.pitch_rad) + abs(self.roll_rad) + 1e-4
        return RayGrid(d_level, len(elev), self.sensor.cols, elev, tilt), order

    def sensor_dirs(self) -> np.ndarray:
        """Unit ray directions in the sensor frame, row-major (rows top to bottom)."""
        return _sensor_dirs(self.sensor)[0]

    def returns(self, rng, t, albedo, cos_inc, extra_drop):
        """Apply the return model to first hits. Returns (keep mask, noisy range, remission)."""
        n = len(t)
        noise = np.clip(rng.standard_normal(n), -2.5, 2.5) * self.range_noise_m
        tn = t + noise
        rem = albedo * (0.7 + 0.3 * np.clip(cos_inc, 0.0, 1.0))
        rem = np.clip(rem + rng.normal(0.0, 0.025, n), 0.0, 0.99)
        u = rng.random(n)
        frac = t / self.sensor.max_range_m
        p_drop = self.dropout + extra_drop + self.far_dropout * frac ** 2
        weak = rem / np.maximum(t, 1.0) ** 2 * 100.0 < self.weak_return
        keep = (u >= p_drop) & ~weak & (tn >= self.min_range_m) & (t <= self.sensor.max_range_m)
        return keep, tn, rem
