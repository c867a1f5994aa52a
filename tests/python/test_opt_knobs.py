# SPDX-License-Identifier: MIT
"""Every compile-time option lives in lib/include/lidet/lidet_opt.h with its #error check, its CMake variable
(cmake/lidet_options.cmake, or one of the four CMake options), a bad-value case in tests/opt/check_opt.cmake and
a row in docs/OPTIONS.md; no other file of lib/ defaults a LIDET_ macro, and no selector compares one with a bare
number (kernel variants are named). Reads the sources only; no build needed."""
import re

import pytest

# include guards end in _H; the port hooks are defined by a target's lidet_port.h (lidet_opt.h documents them)
PORT_HOOKS = {"LIDET_ASSERT", "LIDET_ALIGN", "LIDET_WORKSPACE_SECTION", "LIDET_RODATA"}
# switches of the configuration mechanism itself, not options: the user header, the port header
MECHANISM = {"LIDET_USER_CONFIG", "LIDET_PORT"}
# CMake option() (ON/OFF) rather than a cache string: they also choose sources or per-source flags
CMAKE_OPTIONS = {"LIDET_FIXED_POINT", "LIDET_NN_CLONES", "LIDET_NN_FMA", "LIDET_NN_NEON"}

IFNDEF = re.compile(r"^\s*#\s*ifndef\s+(LIDET_\w+)", re.M)
DEFINED = re.compile(r"(?:#\s*ifdef\s+|defined\s*\(?\s*)(LIDET_\w+)")


def _text(p):
    return p.read_text(encoding="utf-8")


def _lib_sources(root):
    lib = root / "lib"
    return sorted(p for p in lib.rglob("*") if p.suffix in (".c", ".h"))


@pytest.fixture(scope="module")
def opt(root):
    return _text(root / "lib" / "include" / "lidet" / "lidet_opt.h")


@pytest.fixture(scope="module")
def options(opt):
    """The options of lidet_opt.h: every LIDET_X it both tests with `#ifndef` and defines, guard and hooks aside."""
    defined = set(re.findall(r"^\s*#\s*define\s+(LIDET_\w+)", opt, re.M))
    names = set(IFNDEF.findall(opt)) & defined
    names -= PORT_HOOKS | {"LIDET_OPT_H"}
    assert len(names) >= 30, sorted(names)
    return names


def _is_guard(name):
    return name.endswith("_H")


def test_no_option_defaults_outside_lidet_opt_h(root, options):
    """Every LIDET_ macro a lib/ file tests with #ifndef is an option of lidet_opt.h (include guards and the
    LIDET_ASSERT port hook aside): its default lives there, nowhere else."""
    stray = []
    for p in _lib_sources(root):
        if p.name == "lidet_opt.h":
            continue
        for name in IFNDEF.findall(_text(p)):
            if _is_guard(name) or name in PORT_HOOKS:
                continue
            stray.append(f"{p.relative_to(root)}: #ifndef {name}")
    assert not stray, "defaults outside lidet_opt.h (move them there): " + "; ".join(stray)


def test_defined_checks_name_known_macros(root, options, opt):
    """A lib/ file asks `defined(LIDET_X)` / `#ifdef LIDET_X` only of options, guards, port hooks, the
    configuration switches, or macros that lib/ itself defines (internal LIDET__ names): no hidden knob that is
    set by being defined."""
    defined_in_lib = set()
    for p in _lib_sources(root):
        defined_in_lib |= set(re.findall(r"^\s*#\s*define\s+(LIDET_\w+)", _text(p), re.M))
    stray = []
    for p in _lib_sources(root):
        for name in DEFINED.findall(_text(p)):
            if _is_guard(name) or name in options or name in PORT_HOOKS or name in MECHANISM:
                continue
            if name in defined_in_lib:
                continue
            stray.append(f"{p.relative_to(root)}: {name}")
    assert not stray, "knobs tested with defined() that lidet_opt.h does not declare: " + "; ".join(stray)


def test_no_magic_number_selectors(root):
    """Outside lidet_opt.h's range checks no #if compares a LIDET_ option with a bare number: variants are named."""
    pat = re.compile(r"^\s*#\s*(?:el)?if\b.*\b(LIDET_(?!\w*_H\b)\w+)\s*[=!]=\s*-?\d", re.M)
    bad = []
    for p in _lib_sources(root):
        if p.name == "lidet_opt.h":
            continue
        bad += [f"{p.relative_to(root)}: {m.group(0).strip()}" for m in pat.finditer(_text(p))]
    assert not bad, "; ".join(bad)


def test_every_option_has_an_error_check(opt, options):
    errors = "\n".join(re.findall(r"^#error\s+\"[^\"]*\"", opt, re.M))
    missing = sorted(n for n in options if not re.search(rf"\b{n}\b", errors))
    assert not missing, f"options without an #error check in lidet_opt.h: {missing}"


def test_cmake_variables_match_the_options(root, options):
    text = _text(root / "cmake" / "lidet_options.cmake")
    listed = set()
    for body in re.findall(r"set\(LIDET_(?:CAPACITY|LAYOUT|TARGET)_OPTIONS\s+([^)]*)\)", text):
        listed |= set(body.split())
    assert listed, "no option lists in cmake/lidet_options.cmake"
    main = _text(root / "CMakeLists.txt")
    cmake_opts = set(re.findall(r"^option\((LIDET_\w+)", main, re.M))
    assert CMAKE_OPTIONS <= cmake_opts, CMAKE_OPTIONS - cmake_opts
    assert not listed & CMAKE_OPTIONS
    assert sorted(options - CMAKE_OPTIONS - listed) == [], "options without a CMake cache variable"
    assert sorted(listed - options) == [], "CMake variables that are no option of lidet_opt.h"
    # the firmware project takes the same variables
    fw = _text(root / "ports" / "firmware" / "CMakeLists.txt")
    assert "lidet_options.cmake" in fw and "lidet_opt_definitions(fw_lidet" in fw


def test_every_option_has_a_compile_fail_case(root, options):
    text = _text(root / "tests" / "opt" / "check_opt.cmake")
    cases = set(re.findall(r"\"(LIDET_\w+)=[^|\"]*\|\1 must", text))
    assert sorted(options - cases) == [], "options without a bad-value case in tests/opt/check_opt.cmake"


def test_every_option_is_documented(root, options):
    doc = _text(root / "docs" / "OPTIONS.md")
    rows = set(re.findall(r"^\| `(LIDET_\w+)` \|", doc, re.M))
    assert sorted(options - rows) == [], "options missing from docs/OPTIONS.md's option table"
    assert sorted(rows - options) == [], "rows of docs/OPTIONS.md's option table that are no option"


def test_kernel_variants_are_named(root, opt):
    """LIDET_NN_S8_KERNEL's values are the LIDET_NN_S8_KERNEL_* names, distinct, non-zero (an unknown word
    evaluates to 0 in #if, so 0 must not name a kernel); the selector in lidet_nn_s8.c reads each name and ends in
    an #error; lidet_opt.h's check names every one."""
    names = dict(re.findall(r"^#define\s+(LIDET_NN_S8_KERNEL_\w+)\s+(\d+)\s*$", opt, re.M))
    assert set(names) == {f"LIDET_NN_S8_KERNEL_{k}" for k in ("ROWS4", "COLS", "DSP", "R2O2", "R4O2", "LIST")}
    values = [int(v) for v in names.values()]
    assert len(set(values)) == len(values) and 0 not in values
    # the values these names replaced, so that an old command line fails instead of picking another kernel
    assert not set(values) & {0, 1, 2, 22, 42}
    src = _text(root / "lib" / "src" / "nn" / "lidet_nn_s8.c")
    for n in names:
        assert re.search(rf"#\s*(?:el)?if\s+LIDET_NN_S8_KERNEL\s*==\s*{n}\b", src), n
    assert re.search(r"#else\s*\n#error[^\n]*LIDET_NN_S8_KERNEL", src)
    check = re.search(r"#error \"LIDET_NN_S8_KERNEL must be one of ([^\"]*)\"", opt)
    assert check, "no #error for LIDET_NN_S8_KERNEL"
    for n in names:
        assert n.replace("LIDET_NN_S8_KERNEL", "") in check.group(1), n
