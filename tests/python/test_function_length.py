# SPDX-License-Identifier: MIT
"""No function of the library is longer than MAX_BODY_LINES lines (lib/src, .c and .h files).

A long function is split at its passes into static functions named for what each pass does (the compiler inlines
a static function called once, so the hot loops keep their code). A function here is what clang-format's style
of the repository writes: its head ends with `)` on the lines just above a `{` at column 0, and its body ends at
the next `}` at column 0; the count is the lines between the two braces. Struct and table definitions (`{` at
column 0 after `typedef struct` or `=`, closed by `} name;` or `};`) are not functions. Every offender is listed
at once, with its file, line, name and length.
"""
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
SRC = ROOT / "lib" / "src"
MAX_BODY_LINES = 150

_COMMENT = re.compile(r"/\*.*?\*/")
_NAME = re.compile(r"([A-Za-z_]\w*)\s*\(")
_TEMPLATE_NAME = re.compile(r"([A-Z][A-Z0-9_]*)\s*\(\s*(\w+)\s*\)\s*\(")  # GROW_FN(search)(...)
_NOT_NAMES = {"__attribute__", "defined", "sizeof"}


def _head(lines, brace):
    """The text of the lines above line `brace` that belong to its head (up to a blank line, a preprocessor line,
    or the end of the previous declaration), comments removed."""
    head = []
    i = brace - 1
    while i >= 0:
        ln = _COMMENT.sub("", lines[i]).rstrip()
        s = ln.strip()
        if not s or s.startswith("#") or s.endswith(";") or s.endswith("}") or s.startswith("*") or \
                s.endswith("*/"):
            break
        head.insert(0, s)
        i -= 1
    return " ".join(head)


def _name(head):
    m = _TEMPLATE_NAME.search(head)
    if m:
        return f"{m.group(1)}({m.group(2)})"
    for m in _NAME.finditer(head):
        if m.group(1) not in _NOT_NAMES:
            return m.group(1)
    return head[:60]


def functions(path):
    """(name, line of the opening brace (1-based), body lines) of every function defined in path"""
    lines = path.read_text(encoding="utf-8").splitlines()
    out = []
    i = 0
    while i < len(lines):
        if not lines[i].startswith("{"):
            i += 1
            continue
        end = i + 1
        while end < len(lines) and not lines[end].startswith("}"):
            end += 1
        head = _head(lines, i)
        closes_function = end < len(lines) and lines[end].rstrip() == "}"
        if closes_function and head.endswith(")") and "(" in head and "=" not in head.split("(")[0]:
            out.append((_name(head), i + 1, end - i - 1))
        i = end + 1
    return out


def _sources():
    return sorted(p for p in SRC.rglob("*") if p.suffix in (".c", ".h") and p.is_file())


def test_the_scan_sees_the_library():
    """the scan finds the functions it is meant to measure (a parser that found none would pass anything)"""
    found = {(p.name, name) for p in _sources() for name, _, _ in functions(p)}
    assert len(found) > 300, len(found)
    for expected in (("lidet_proj.c", "lidet_proj_run_buffers"), ("lidet_velodyne.c", "lidet_velodyne_packet"),
                     ("lidet_track_q.c", "lidet_tracker_q_update"), ("lidet_ground_ransac_q.c", "fit_cell_q"),
                     ("lidet_ground_ransac.c", "fit_sector"), ("lidet_refine_body.h", "refine_split_one"),
                     ("lidet_cluster_grow_body.h", "GROW_FN(grow)"), ("lidet_ground_ransac_q.c", "far_meets"),
                     ("lidet_proj.c", "round_block")):
        assert expected in found, expected


def test_no_function_longer_than_the_limit():
    long = []
    for path in _sources():
        for name, line, n in functions(path):
            if n > MAX_BODY_LINES:
                long.append(f"{path.relative_to(ROOT)}:{line}: {name}: {n} lines")
    assert not long, (f"functions longer than {MAX_BODY_LINES} lines (split them at their passes into static "
                      "functions):\n" + "\n".join(long))


def test_the_scan_measures_a_function():
    """a synthetic file: a function, a struct and a table; only the function is counted, with its body lines"""
    import tempfile
    text = ("typedef struct\n{\n    int a;\n} s_t;\n\nstatic const int k[] =\n{\n    1,\n};\n\n"
            "#if defined(__GNUC__)\n__attribute__((noinline))\n#endif\nstatic int\n"
            "far(const s_t *s, /* a comment (with parentheses) */\n    int b)\n{\n"
            + "    b += 1;\n" * 151 + "    return b;\n}\n")
    with tempfile.TemporaryDirectory() as d:
        p = Path(d) / "x.c"
        p.write_text(text)
        assert functions(p) == [("far", 17, 152)]
