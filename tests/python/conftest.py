# SPDX-License-Identifier: MIT
import os
import pathlib

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
REAL = pathlib.Path(os.environ.get("LIDET_REAL_DATA", ROOT.parent / "shared" / "data" / "real"))


@pytest.fixture(scope="session")
def root():
    return ROOT


@pytest.fixture(scope="session")
def real_dir():
    """../shared/data/real (KITTI / SemanticKITTI scans); tests using it skip when it is absent."""
    if not (REAL / "README.md").exists():
        pytest.skip(f"real scans not available at {REAL}")
    return REAL
