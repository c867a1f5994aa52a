# SPDX-License-Identifier: MIT
"""Pictures: bird's-eye views (bev), precision-recall curves and energy histograms (curves), a synthetic
demo scene (demo) and the lidet-viz CLI (cli)."""
