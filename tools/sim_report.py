#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Realism report of the scan simulator: writes docs/img/sim_*.png and the numbers in docs/SIMULATOR.md.

    .venv/bin/python tools/sim_report.py --real ../shared/data/real --scans 24 --seed 1000
"""
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__))))

from lidet_tools.sim.report import main  # noqa: E402

if __name__ == "__main__":
    sys.exit(main())
