# SPDX-License-Identifier: MIT
"""lidet codegen: ONNX -> C models (emit, regen), int8 quantization (quant) and the generated integer tables
(qtables, pnq_tables). It imports lidet_ref (the numpy reference, codegen/lidet_ref/), numpy and onnx, never
lidet_tools: the PyTorch export and the int8 calibration on scans are lidet_tools.train.export and
lidet_tools.train.calibrate (tests/python/test_package_flow.py)."""

__version__ = "0.1.0"
