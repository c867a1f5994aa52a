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


@pytest.fixture(scope="session")
def bench_mod():
    """load(name): tools/bench/bench_<name>.py as a module (its folder on sys.path, for its run_bench imports)."""
    import importlib.util
    import sys

    def load(name):
        sys.path.insert(0, str(ROOT / "tools" / "bench"))
        spec = importlib.util.spec_from_file_location(f"bench_{name}", ROOT / "tools" / "bench" / f"bench_{name}.py")
        m = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(m)
        return m
    return load


@pytest.fixture(scope="session")
def cli():
    """The host CLI `lidet` of the build under test ($LIDET_BUILD_DIR, else build/); skips if not built."""
    exe = pathlib.Path(os.environ.get("LIDET_BUILD_DIR", ROOT / "build")) / "ports" / "host" / "lidet"
    if not exe.exists():
        pytest.skip(f"{exe} not built")
    return exe


@pytest.fixture(scope="session")
def pcli(cli):
    """The CLI, when it was built with libpcap (else a skip; the message of a CLI without it is checked by
    tests/cli_pcap.cmake)."""
    import subprocess
    r = subprocess.run([str(cli), "detect", "--pcap", "/nonexistent.pcap"], capture_output=True, text=True)
    if "built without libpcap" in r.stderr:
        pytest.skip("lidet was built without libpcap (apt-get install libpcap-dev)")
    return cli


@pytest.fixture(scope="session")
def need_lib():
    """Skips when the bindings' shared library (liblidet_py.so) is not built."""
    from lidet_tools import native
    try:
        native.lib()
    except FileNotFoundError as e:
        pytest.skip(str(e))


@pytest.fixture(scope="session")
def nd():
    """lidet_tools.native with its models loaded; skips when the bindings are not built."""
    from lidet_tools import native
    try:
        native.pn_models()
    except (OSError, FileNotFoundError) as e:  # pragma: no cover - bindings not built
        pytest.skip(f"bindings not built: {e}")
    return native
