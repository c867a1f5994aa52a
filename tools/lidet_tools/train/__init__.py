# SPDX-License-Identifier: MIT
"""Training of lidet's PointNets (PyTorch): model definitions (models.py), proposal datasets and the
training loops. PyTorch is imported lazily by the modules that need it."""
