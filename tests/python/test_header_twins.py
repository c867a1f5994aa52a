# SPDX-License-Identifier: MIT
"""The integer path never includes the float path's headers; the umbrella header names every public header.

A float header is a public header lib/include/lidet/lidet_X.h whose integer twin lidet_X_q.h exists (lidet_proj.h,
lidet_ground.h, lidet_cluster.h, ...; also the umbrella lidet.h, beside lidet_q.h, which includes everything). What
both twins need (the range image, the stages' counts, enums, the clock type) lives in headers that neither twin
owns (lidet_image.h, lidet_proj_stats.h, lidet_ground_common.h, lidet_cluster_stats.h, lidet_detector_common.h,
lidet_pointnet_common.h, lidet_track_common.h), which the float headers include as well.

1. No integer header includes a float header, directly or through other headers: every lib/include/lidet/*_q.h.
2. No integer source does: the files of the integer-only build (the LIDET_SRC_<FOLDER>_INT lists of
   cmake/lidet_sources.cmake) and every private header they reach (lib/src/internal/). One exception: the umbrella
   in lib/src/common/lidet_status.c, which defines lidet_version().
3. Each integer header compiles alone with the float headers taken away (a copy of lib/include/lidet without
   them), in C99 with -Wall -Wextra -Wpedantic -Werror, as do the integer sources (skipped without a C compiler).
4. lidet.h includes every other public header directly.

Includes are read from the text (comments removed; `#include "..."` only: the system headers and the port's
lidet_port.h / lidet_user_config.h are not the library's). Every offender is listed at once with its chain of
includes. Under a second without the compiles, a few seconds with them; no build needed.
"""
import os
import re
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
PUBLIC = ROOT / "lib" / "include" / "lidet"
SRC = ROOT / "lib" / "src"
SOURCES_CMAKE = ROOT / "cmake" / "lidet_sources.cmake"

#: integer sources allowed to include the umbrella lidet.h (and with it the float headers)
UMBRELLA_USERS = {"lib/src/common/lidet_status.c": "defines lidet_version(), declared in lidet.h"}

_COMMENT = re.compile(r"/\*.*?\*/|//[^\n]*", re.S)
_INCLUDE = re.compile(r'^[ \t]*#[ \t]*include[ \t]*"([^"]+)"', re.M)


def _rel(path):
    return path.resolve().relative_to(ROOT).as_posix()


def includes(path):
    """The quoted includes of a file, resolved as the compiler would with lib/include and lib/src on the path:
    the including file's folder first, then lib/include, then lib/src. Unresolved names (the port's headers)
    are left out."""
    text = _COMMENT.sub("", path.read_text(encoding="utf-8", errors="replace"))
    out = []
    for name in _INCLUDE.findall(text):
        for base in (path.parent, ROOT / "lib" / "include", SRC):
            cand = base / name
            if cand.is_file():
                out.append(cand.resolve())
                break
    return out


def float_headers():
    """Public headers whose name + _q is another public header: the float twins (and the umbrella lidet.h)."""
    names = {p.name for p in PUBLIC.glob("*.h")}
    return {PUBLIC / n for n in names if not n.endswith("_q.h") and n[:-2] + "_q.h" in names}


def reached_floats(start, floats):
    """[(float header, chain of includes from start)] of the float headers start reaches (breadth first: the
    shortest chain to each)."""
    start = start.resolve()
    parent = {start: None}
    queue = [start]
    found = []
    while queue:
        f = queue.pop(0)
        for g in includes(f):
            if g in parent:
                continue
            parent[g] = f
            if g in floats:
                chain = [g]
                while parent[chain[-1]] is not None:
                    chain.append(parent[chain[-1]])
                found.append((g, " -> ".join(_rel(c) for c in reversed(chain))))
                continue  # what a float header includes in turn is its own business
            queue.append(g)
    return found


def integer_sources():
    """The integer-only build's sources: every file of the LIDET_SRC_<FOLDER>_INT lists."""
    text = _COMMENT.sub("", SOURCES_CMAKE.read_text())
    text = re.sub(r"#[^\n]*", "", text)
    out = []
    for _, body in re.findall(r"set\(\s*(LIDET_SRC_\w+_INT)\b([^)]*)\)", text):
        out += [SRC / f for f in body.split()]
    assert out, f"no LIDET_SRC_<FOLDER>_INT list found in {_rel(SOURCES_CMAKE)}"
    return out


def _resolved(path):
    return {p.resolve() for p in path}


def test_float_headers_found():
    """The rule sees the pairs it is about (a renamed folder or twin would silently empty it)."""
    floats = {p.name for p in float_headers()}
    for name in ("lidet.h", "lidet_proj.h", "lidet_ground.h", "lidet_cluster.h", "lidet_detector.h",
                 "lidet_pointnet.h", "lidet_track.h", "lidet_sensor.h"):
        assert name in floats, f"{name} is no longer seen as a float header (its _q twin is missing?)"


def test_integer_headers_include_no_float_header():
    floats = _resolved(float_headers())
    bad = []
    for h in sorted(PUBLIC.glob("*_q.h")):
        bad += [chain for _, chain in reached_floats(h, floats)]
    assert not bad, ("integer headers that include a float header (move what they need into a header neither "
                     "twin owns, e.g. lidet_image.h or lidet_<stage>_common.h):\n  " + "\n  ".join(bad))


def test_integer_sources_include_no_float_header():
    floats = _resolved(float_headers())
    umbrella = (PUBLIC / "lidet.h").resolve()
    bad = []
    for src in integer_sources():
        assert src.is_file(), f"{_rel(src)} is listed in {_rel(SOURCES_CMAKE)} but missing"
        for g, chain in reached_floats(src, floats):
            if g == umbrella and _rel(src) in UMBRELLA_USERS:
                continue
            bad.append(chain)
    assert not bad, ("integer sources that include a float header (private headers shared by both twins take "
                     "the shared public headers only):\n  " + "\n  ".join(bad))


def test_umbrella_includes_every_public_header():
    direct = {p.name for p in includes(PUBLIC / "lidet.h") if p.parent == PUBLIC.resolve()}
    missing = sorted(p.name for p in PUBLIC.glob("*.h") if p.name != "lidet.h" and p.name not in direct)
    assert not missing, f"lib/include/lidet/lidet.h does not include: {', '.join(missing)}"


def _cc():
    for cc in (os.environ.get("CC"), "cc", "gcc", "clang"):
        if cc and shutil.which(cc):
            return cc
    return None


def test_integer_side_compiles_without_float_headers(tmp_path):
    cc = _cc()
    if cc is None:
        pytest.skip("no C compiler")
    inc = tmp_path / "include" / "lidet"
    inc.mkdir(parents=True)
    floats = {p.name for p in float_headers()}
    for p in PUBLIC.glob("*.h"):
        if p.name not in floats:
            shutil.copy(p, inc / p.name)
    flags = ["-std=c99", "-Wall", "-Wextra", "-Wpedantic", "-Werror", "-fsyntax-only",
             "-I", str(tmp_path / "include"), "-I", str(SRC)]
    failures = []

    def compile_one(label, path):
        r = subprocess.run([cc, *flags, str(path)], capture_output=True, text=True)
        if r.returncode != 0:
            failures.append(label + ":\n    " + "\n    ".join(r.stderr.strip().splitlines()[:6]))

    for h in sorted(PUBLIC.glob("*_q.h")):
        probe = tmp_path / f"probe_{h.stem}.c"
        probe.write_text(f'#include "lidet/{h.name}"\ntypedef int lidet_probe_t;\n')
        compile_one(_rel(h), probe)
    for src in integer_sources():
        if _rel(src) not in UMBRELLA_USERS:
            compile_one(_rel(src), src)
    assert not failures, "compiled without the float headers:\n" + "\n".join(failures)
