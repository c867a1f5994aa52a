# SPDX-License-Identifier: MIT
"""Python flows one way (issue 39, item 3): lidet_tools -> lidet_codegen -> lidet_ref.

- lidet_ref (codegen/lidet_ref/, the numpy oracle the C tests compare with) imports numpy and the standard library
  only: never lidet_codegen, lidet_tools or torch;
- lidet_codegen (codegen/lidet_codegen/: ONNX -> C, int8 quantization, generated tables) imports lidet_ref, numpy and
  onnx, never lidet_tools (the PyTorch export and the calibration on scans are lidet_tools.train.export and
  lidet_tools.train.calibrate);
- lidet_tools may import both.

Every .py under codegen/ and tools/ is parsed (ast, nothing imported): `import X`, `from X import Y` (relative ones
resolved), at module level or inside functions, classes and conditionals, and importlib.import_module / __import__
of a constant name. The oracle's old path, lidet_codegen.ref, is gone: nothing under codegen/, tools/ or tests/
imports it. Every offending import is listed at once, with its file and line.
"""
import ast
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]

#: package -> the packages of this repository it must not import
FORBIDDEN = {"lidet_ref": ("lidet_codegen", "lidet_tools"), "lidet_codegen": ("lidet_tools",)}
#: what lidet_ref may import besides the standard library and itself
REF_ALLOWED = ("numpy",)
#: the oracle's old package (before lidet_ref)
OLD_PATH = "lidet_codegen.ref"


def _package(rel):
    """The package a file belongs to (lidet_ref, lidet_codegen, lidet_tools), else None (scripts, tests)."""
    parts = rel.split("/")
    if len(parts) > 2 and (parts[0], parts[1]) in (("codegen", "lidet_ref"), ("codegen", "lidet_codegen"),
                                                   ("tools", "lidet_tools")):
        return parts[1]
    return None


def _module_name(rel):
    """codegen/lidet_codegen/ref/__init__.py -> (lidet_codegen.ref, True): the dotted name and whether a package."""
    parts = rel[:-3].split("/")[1:]
    is_pkg = parts[-1] == "__init__"
    if is_pkg:
        parts = parts[:-1]
    return ".".join(parts), is_pkg


def imports(source, rel="x.py"):
    """[(line, module, where)] of every import in `source`: `from a.b import c` gives a.b and a.b.c (c may be a
    module); relative imports resolved against rel's package; where is 'module level' or 'inside a function'."""
    tree = ast.parse(source, filename=rel)
    name, is_pkg = _module_name(rel) if _package(rel) else ("", False)
    here = name.split(".") if is_pkg else name.split(".")[:-1]
    out = []

    def visit(node, in_def):
        for child in ast.iter_child_nodes(node):
            inner = in_def or isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda))
            where = "inside a function" if in_def else "module level"
            if isinstance(child, ast.Import):
                out.extend((child.lineno, a.name, where) for a in child.names)
            elif isinstance(child, ast.ImportFrom):
                if child.level:
                    base = here[:len(here) - (child.level - 1)] if child.level > 1 else here
                    mod = ".".join(base + ([child.module] if child.module else []))
                else:
                    mod = child.module
                out.append((child.lineno, mod, where))
                out.extend((child.lineno, f"{mod}.{a.name}", where) for a in child.names if a.name != "*")
            elif (isinstance(child, ast.Call) and child.args and isinstance(child.args[0], ast.Constant)
                  and isinstance(child.args[0].value, str)
                  and ((isinstance(child.func, ast.Attribute) and child.func.attr == "import_module")
                       or (isinstance(child.func, ast.Name) and child.func.id in ("__import__", "import_module")))):
                out.append((child.lineno, child.args[0].value, where))
            visit(child, inner)

    visit(tree, False)
    return out


def _top(mod):
    return mod.split(".")[0]


def _py_files(*tops):
    files = []
    for top in tops:
        for p in sorted((ROOT / top).rglob("*.py")):
            rel = p.relative_to(ROOT).as_posix()
            if "__pycache__" not in rel and not any(part.startswith(".") for part in rel.split("/")):
                files.append(rel)
    return files


def flow_problems(files, read=lambda rel: (ROOT / rel).read_text(encoding="utf-8")):
    """The imports against the flow, one line each: file:line: what imports what."""
    problems = []
    for rel in files:
        pkg = _package(rel)
        if pkg is None:
            continue
        seen = set()
        for line, mod, where in imports(read(rel), rel):
            top = _top(mod)
            bad = top in FORBIDDEN.get(pkg, ())
            if pkg == "lidet_ref" and not bad:
                bad = not (top in sys.stdlib_module_names or top in REF_ALLOWED or top in ("lidet_ref", "__future__"))
            if bad and (line, top) not in seen:
                seen.add((line, top))
                problems.append(f"{rel}:{line}: {pkg} imports {top} ({mod}, {where})")
    return problems


def old_path_problems(files, read=lambda rel: (ROOT / rel).read_text(encoding="utf-8")):
    problems = []
    for rel in files:
        seen = set()
        for line, mod, where in imports(read(rel), rel):
            if (mod == OLD_PATH or mod.startswith(OLD_PATH + ".")) and line not in seen:
                seen.add(line)
                problems.append(f"{rel}:{line}: imports the old path {mod} ({where}): import lidet_ref instead")
    return problems


def test_python_flows_one_way():
    files = _py_files("codegen", "tools")
    by_pkg = {p: [f for f in files if _package(f) == p] for p in ("lidet_ref", "lidet_codegen", "lidet_tools")}
    assert all(len(v) >= 5 for v in by_pkg.values()), {k: len(v) for k, v in by_pkg.items()}  # the tree is there
    problems = flow_problems(files)
    assert not problems, "imports against lidet_tools -> lidet_codegen -> lidet_ref:\n  " + "\n  ".join(problems)


def test_nothing_else_imports_the_old_path():
    problems = old_path_problems(_py_files("codegen", "tools", "tests"))
    assert not problems, "\n  ".join(["lidet_codegen.ref is gone (the oracle is lidet_ref):"] + problems)


def test_the_checks_find_what_they_look_for():
    """Each kind of import the checks must see, in sources of their own: module level, inside a function,
    relative, importlib; stdlib and numpy pass in lidet_ref, torch does not."""
    src = {
        "codegen/lidet_ref/a.py": "import math\nimport numpy as np\nfrom . import qmath\ndef f():\n"
                                  "    from lidet_codegen import quant\n    import torch\n",
        "codegen/lidet_codegen/b.py": "from lidet_ref import proj_q\nimport onnx\nclass K:\n    def g(self):\n"
                                      "        if 1:\n            from lidet_tools.train import models\n"
                                      "import importlib\nm = importlib.import_module('lidet_tools.native')\n",
        "codegen/lidet_codegen/sub/c.py": "from ...lidet_tools import kitti\nfrom .. import emit\n",
        "tools/lidet_tools/d.py": "from lidet_codegen import quant\nfrom lidet_ref import qmath\n",
        "tests/python/test_e.py": "from lidet_codegen.ref import proj_q\nfrom lidet_codegen import ref\n",
    }
    got = flow_problems(list(src), src.get)
    assert got == ["codegen/lidet_ref/a.py:5: lidet_ref imports lidet_codegen (lidet_codegen, inside a function)",
                   "codegen/lidet_ref/a.py:6: lidet_ref imports torch (torch, inside a function)",
                   "codegen/lidet_codegen/b.py:6: lidet_codegen imports lidet_tools (lidet_tools.train, inside a "
                   "function)",
                   "codegen/lidet_codegen/b.py:8: lidet_codegen imports lidet_tools (lidet_tools.native, module level)",
                   "codegen/lidet_codegen/sub/c.py:1: lidet_codegen imports lidet_tools (lidet_tools, module "
                   "level)"], got
    old = old_path_problems(list(src), src.get)
    assert [p.split(":")[:2] for p in old] == [["tests/python/test_e.py", "1"], ["tests/python/test_e.py", "2"]], old
