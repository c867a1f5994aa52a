# SPDX-License-Identifier: MIT
"""lidet codegen: PyTorch -> ONNX export, quantization and C array emission (later issues),
plus `lidet_codegen.ref`, the numpy reference of every library stage."""

__version__ = "0.1.0"
