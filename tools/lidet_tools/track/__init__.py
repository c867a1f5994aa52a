# SPDX-License-Identifier: MIT
"""Tracking across scans (docs/TRACKING.md): the C trackers' bindings (native: Tracker, float or fixed=True)."""
from .native import Tracker

__all__ = ["Tracker"]
