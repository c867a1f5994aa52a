# SPDX-License-Identifier: MIT
"""lidet tools: scan simulator, KITTI/SemanticKITTI readers and writers, evaluation, plots, bindings."""

__version__ = "0.1.0"
