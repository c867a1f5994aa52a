# SPDX-License-Identifier: MIT
"""Training of lidet's PointNets (PyTorch): model definitions (models.py), proposal datasets and the
training loops; the ONNX export (export.py, `python -m lidet_tools.train.export`) and the int8 calibration on
scans (calibrate.py, `python -m lidet_tools.train.calibrate`) that lidet_codegen's C models are made from.
PyTorch is imported lazily by the modules that need it."""
