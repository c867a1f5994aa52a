# SPDX-License-Identifier: MIT
"""numpy references of the library's stages (the oracle of the golden and binding tests)."""
