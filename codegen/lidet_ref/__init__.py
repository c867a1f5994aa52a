# SPDX-License-Identifier: MIT
"""lidet_ref: the numpy references of the library's stages, the oracle of the golden and binding tests (float64
for the float stages, Python integers bit for bit for the integer ones; docs/ARCHITECTURE.md, "Where each stage
lives: reference, tests, docs").

numpy and the standard library only: lidet_codegen (which generates the C tables and models from the same
functions) and lidet_tools (bindings, simulator, training) import this package, never the other way
(tests/python/test_package_flow.py)."""
