# SPDX-License-Identifier: MIT
"""Deterministic LiDAR scan simulator (numpy): street scenes of analytic primitives on a heightfield,
ray cast with a sensor profile's beams, written in KITTI's layout. Entry points: `simulate_scan`,
`write_scan`, and the `lidet-sim` CLI (cli.py)."""
from .simulate import LABEL2_CLASSES, ScanResult, simulate_scan  # noqa: F401
from .writer import SUBDIRS, read_ring, scan_paths, write_scan  # noqa: F401

__all__ = ["LABEL2_CLASSES", "ScanResult", "simulate_scan", "SUBDIRS", "read_ring", "scan_paths", "write_scan"]
