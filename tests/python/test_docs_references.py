# SPDX-License-Identifier: MIT
"""Every file, function, option and command the docs name still exists (issue 39, item 4).

Reads README.md, docs/*.md, docs/journal/*.md, docs/benchmarks/*.md and every other README.md of the repository (outside build*/,
data/, out/, third_party/ and hidden folders such as .venv/) and checks code spans (`...`), code blocks (fenced
or indented), links and, for the first two rules, the plain text:

1. paths. A word with a '/' whose first part is a top-level entry of the repository (`lib/...`, `tools/...`,
   `weights/MODEL_CARD.md`, also in plain text: docs/X.md) exists in the tree (tracked or not ignored); a link
   target ([text](X.md), (../lib/...)) exists relative to the doc's own folder. In code: a shorter path of a
   source file that starts with a folder name of the tree (`internal/x.h`, `lidet_ref/track.py`) is the end of some path
   of the tree, and a bare file name with a source extension (`lidet_refine.c`, `peer.py`) is the name of some
   file (other projects' files: EXTERNAL_FILES). A glob (`*`, `{a,b}`) matches at least one path. Not checked:
   outputs and user data (out/, data/, build*/, /tmp, ~, ../shared or anything else outside the repository, the
   value of --out / -o), URLs, placeholders (`<name>`, `{fam}`, `...`, upper-case parts such as DIR, SCAN,
   NNNNNN).
2. C names. Every `lidet_*` / `LIDET_*` word occurs in a C/C++ source, a CMakeLists.txt or a *.cmake file of the
   tree (CMake cache variables and compile options count), or is the name of a file or folder (`lidet_tools`);
   an upper-case `LIDET_*` may also be an environment variable of the Makefile, a script or the Python tools.
3. `make TARGET` (a command at the start of a code span or shell line): a target of the top-level Makefile
   (with -C / -f another Makefile runs: not checked).
4. `python -m MODULE` of the project (lidet_*; torchrun's -m too): the module's file exists under tools/ or
   codegen/ (found, not imported), and every --flag after it occurs as a string in that file, the files it
   imports from the project, or (a package run with -m) the package; the same for `python tools/x.py --flag`
   and for the console scripts of pyproject.toml (lidet-sim, lidet-eval, lidet-viz: their package).
   `FILE::test_name` names a test function of that file.
5. `lidet SUBCOMMAND` (the host CLI, at the start of a code span or shell line): a command of the table in
   ports/host/cli_main.c, and every --option of that command line (usage lines continued with indented
   [--options] included) is a string of ports/host/*.c ("--name", or "name" in a getopt_long table).
6. Python names of the project: `lidet_tools.x.y`, `lidet_codegen.x`, `lidet_ref.x` and `module.name` for a module
   of theirs (`native.detect`, `sensors.load_sensor_file`): the module exists and the name occurs in it.

Journal pages (docs/journal/) are history and may name old functions, options and commands on purpose: there
only paths (1) and make targets (3) are checked. Commands (3-5) are not looked for in blocks of another language
(```c, ```python): a C comment's "lidet would ..." is no command.

Every stale reference is reported at once, with its doc, line and name. About a second: no build, no import of
the tools, no ../shared.
"""
import fnmatch
import os
import re
import shlex
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]

SKIP_TOP = ("out", "data")  # outputs and user data at the top, as build*/ (tests/data/ is checked)
SKIP_ANY = ("third_party", "node_modules", "__pycache__")  # vendored code, caches, and hidden folders


def _skipped_top(name):
    return name in SKIP_TOP or name.startswith("build") or _skipped_any(name)


def _skipped_any(name):
    return name in SKIP_ANY or name.startswith(".")


# ---------------------------------------------------------------------------------------------------- the tree

def _tree_files():
    """Paths (posix, relative) of the files a checkout has: tracked plus untracked-but-not-ignored (what CI gets
    once committed), present in the working tree; a walk without git."""
    try:
        out = subprocess.run(["git", "ls-files", "-z", "-c", "-o", "--exclude-standard"], cwd=ROOT, check=True,
                             capture_output=True).stdout
        rels = {p for p in out.decode("utf-8", "surrogateescape").split("\0") if p}
        return sorted(p for p in rels if (ROOT / p).is_file())
    except (OSError, subprocess.CalledProcessError):
        files = []
        for dirpath, dirnames, filenames in os.walk(ROOT):
            rel = Path(dirpath).relative_to(ROOT)
            dirnames[:] = [d for d in dirnames if not (_skipped_any(d) or (rel == Path(".") and _skipped_top(d)))]
            files += [(rel / f).as_posix() for f in filenames]
        return sorted(files)


class Tree:
    def __init__(self):
        self.files = _tree_files()
        self.file_set = set(self.files)
        self.dirs = {str(p.as_posix()) for f in self.files for p in Path(f).parents if str(p) != "."}
        self.paths = self.file_set | self.dirs
        self.top = {p.split("/")[0] for p in self.paths}
        self.dir_names = {d.rsplit("/", 1)[-1] for d in self.dirs}
        self.basenames = {f.rsplit("/", 1)[-1] for f in self.files}
        self.stems = {n.split(".")[0] for n in self.basenames | self.dir_names}
        self._text = {}
        self.memo = {}

    def exists(self, rel):
        return rel.rstrip("/") in self.paths  # not an ignored file that happens to be here: CI would not have it

    def glob(self, pattern):
        pattern = pattern.rstrip("/")
        rx = re.compile(fnmatch.translate(pattern).replace(".*", "[^/]*"))
        return any(rx.match(p) for p in self.paths)

    def suffix(self, tail):
        tail = "/" + tail.rstrip("/")
        if "*" in tail:
            rx = re.compile(r"(?:.*)" + fnmatch.translate(tail).replace(".*", "[^/]*"))
            return any(rx.match(p) for p in self.paths)
        return any(p.endswith(tail) for p in self.paths)

    def read(self, rel):
        if rel not in self._text:
            try:
                self._text[rel] = (ROOT / rel).read_text(encoding="utf-8", errors="replace")
            except OSError:
                self._text[rel] = ""
        return self._text[rel]


def _doc_files(tree):
    docs = ["README.md", "lib/src/README.md"]
    docs += sorted(f for f in tree.files if re.fullmatch(r"docs/(journal/|benchmarks/)?[^/]+\.md", f))
    for f in tree.files:  # every other README.md outside outputs, data and vendored code
        parts = f.split("/")
        if parts[-1] == "README.md" and len(parts) > 1 and not _skipped_top(parts[0]) \
                and not any(_skipped_any(p) for p in parts[:-1]):
            docs.append(f)
    return list(dict.fromkeys(d for d in docs if (ROOT / d).is_file()))


# ------------------------------------------------------------------------------------------- reading the docs

FENCE = re.compile(r"^( {0,3})(```+|~~~+)")
SHELL_LANGS = ("", "sh", "bash", "shell", "console", "text")


class Doc:
    """A markdown file cut into code blocks (line by line, `\\` continuations joined), code spans and links,
    each with its line number."""

    def __init__(self, rel):
        self.rel = rel
        self.dir = Path(rel).parent
        self.journal = rel.startswith("docs/journal/")
        text = (ROOT / rel).read_text(encoding="utf-8")
        lines = text.split("\n")
        self.block_lines = []  # (lineno, text, shell): shell = the block may hold commands (not C, Python, ...)
        prose = []
        fence = None
        prev_blank = True
        in_indented = False
        in_list = False  # an indented paragraph after a list item is the item's text, not code
        for n, line in enumerate(lines, 1):
            m = FENCE.match(line)
            if fence:
                if m and m.group(2)[0] == fence[0] and len(m.group(2)) >= len(fence):
                    fence = None
                else:
                    self.block_lines.append((n, line, shell))
                prose.append("")
                continue
            if m:
                fence = m.group(2)
                shell = line[m.end():].strip().lower() in SHELL_LANGS
                prose.append("")
                continue
            indented = line.startswith("    ") and line.strip() and (prev_blank or in_indented)
            if indented and (in_indented or not in_list):
                in_indented = True
                self.block_lines.append((n, line, True))
                prose.append("")
            else:
                in_indented = in_indented and not line.strip()
                if line.strip():
                    in_list = bool(re.match(r"\s*([-*+]|\d+\.)\s", line)) or (in_list and line[:1] == " ")
                prose.append(line)
            prev_blank = not line.strip()
        self.block_lines = _join_continuations(self.block_lines)
        prose = "\n".join(prose)
        self.spans = []
        for m in re.finditer(r"(`+)(?!`)((?:(?!\n[ \t]*\n).)+?)(?<!`)\1(?!`)", prose, re.S):
            self.spans.append((_lineno(prose, m.start()), " ".join(m.group(2).split())))
        no_spans = re.sub(r"(`+)(?!`)((?:(?!\n[ \t]*\n).)+?)(?<!`)\1(?!`)",
                          lambda m: re.sub(r"[^\n]", " ", m.group(0)), prose, flags=re.S)
        link = re.compile(r"\]\(\s*<?([^()\s<>]+)>?(?:\s+\"[^\"]*\")?\s*\)")
        self.links = [(_lineno(no_spans, m.start()), m.group(1)) for m in link.finditer(no_spans)]
        plain = link.sub(lambda m: "]" + " " * (len(m.group(0)) - 1), no_spans)
        self.prose = [(n, line) for n, line in enumerate(plain.split("\n"), 1) if line.strip()]

    def code(self, commands=False):
        """(lineno, text, kind) of every code span and code-block line; with commands=True, without the lines of
        blocks in a programming language (a C comment's "lidet would..." is no command)."""
        return [(n, t, "span") for n, t in self.spans] + \
               [(n, t, "block") for n, t, shell in self.block_lines if shell or not commands]


def _lineno(text, offset):
    return text.count("\n", 0, offset) + 1


def _join_continuations(lines):
    """One line per command: a line ending in '\\', or followed by indented lines of more [--options], is joined
    with them (the usage blocks' layout)."""
    out = []
    last = None
    for n, line, shell in lines:
        if out and last == n - 1 and (out[-1][1].endswith("\\") or re.match(r"\s+\[", line)):
            out[-1] = (out[-1][0], out[-1][1].rstrip("\\") + " " + line.strip(), shell)
        else:
            out.append((n, line, shell))
        last = n
    return out


def _strip_comment(line):
    """A shell line without its trailing `# comment` (a '#' at a word start that is not an #include)."""
    m = re.search(r"(?:^|\s)#(?!include|define|if|endif|else|elif|pragma)", line)
    return line[:m.start()] if m else line


# ----------------------------------------------------------------------------------------------------- paths

# Files of other projects the docs cite by bare name (the KITTI devkit, the ROS Velodyne driver).
EXTERNAL_FILES = {"evaluate_object_3d_offline.cpp", "gen_calibration.py"}
PLACEHOLDER_PART = re.compile(r"^(?:[A-Z][A-Z0-9_]*|N+(?:\.\w+)?|X+(?:\.\w+)?|\.\.\.)$")
SOURCE_EXT = ("c", "h", "cpp", "py", "cmake", "sh", "ld", "md")
BARE_FILE = re.compile(r"^[A-Za-z0-9_][\w.-]*\.(?:%s)$" % "|".join(SOURCE_EXT))
OUTPUT_OPTION = re.compile(r"-o|--[\w-]*out[\w-]*")


def _expand_braces(word):
    """['weights/cls_a.onnx', 'weights/box_a.onnx'] for 'weights/{cls,box}_a.onnx'; None when a {group} has no
    comma (a placeholder such as {fam})."""
    m = re.search(r"\{([^{}]*)\}", word)
    if not m:
        return [word]
    if "," not in m.group(1):
        return None
    out = []
    for alt in m.group(1).split(","):
        sub = _expand_braces(word[:m.start()] + alt + word[m.end():])
        if sub is None:
            return None
        out += sub
    return out


def _words(text):
    """Path-like candidates of a piece of code: whitespace words, trimmed of quotes and punctuation, the value of
    VAR=value / --opt=value, each side of '|' and the file of FILE::test / FILE:line; not the value of an output
    option (--out, -o, --kitti-out: what the command writes, e.g. weights/cls_mysensor.onnx)."""
    prev = ""
    for raw in text.split():
        prev, is_output = raw, OUTPUT_OPTION.fullmatch(prev) is not None
        if is_output or ("=" in raw and OUTPUT_OPTION.fullmatch(raw.split("=", 1)[0])):
            continue
        w = raw.lstrip("\"'`([")
        if w.endswith("'s"):
            w = w[:-2]
        w = w.rstrip("\"'`,;:.!?)]")
        if "/" not in w and "." not in w:
            continue  # neither a path nor a file name
        if w.startswith("<") and w.endswith(">") and "/" in w and w.endswith(".h>"):
            w = w[1:-1]  # #include <lidet/lidet.h>
        if "=" in w:
            w = w.rsplit("=", 1)[1]
        for part in w.split("|") if "{" not in w else [w]:
            part = re.sub(r"::.*$", "", part)
            part = re.sub(r":\d+(?::\d+)?$", "", part)
            part = part.rstrip(".:")
            if part:
                yield part


def _path_problem(tree, doc, word, link=False):
    """None when `word` is fine or not checkable; else a reason."""
    if "://" in word or word.startswith(("mailto:", "#")):
        return None
    if link:
        word = word.split("#", 1)[0]
        if not word:
            return None
    if any(c in word for c in "<>$~") or "..." in word or word.startswith("/"):
        return None  # placeholder, variable, home or absolute path (/tmp, /work/shared)
    variants = _expand_braces(word)
    if variants is None:
        return None
    for v in variants:
        bare = "/" not in v.rstrip("/")
        base = doc.dir if link else Path(".")
        rel = os.path.normpath((base / v).as_posix()) if not bare or link else v
        rel = rel.replace(os.sep, "/")
        if rel.startswith(".."):
            return None  # outside the repository (../shared, a peer's checkout)
        parts = [p for p in rel.split("/") if p not in ("", ".")]
        if not parts:
            return None
        if _skipped_top(parts[0]) and parts[0] != "third_party":
            return None  # outputs and user data
        if any(PLACEHOLDER_PART.match(p) for p in parts[:-1]) or PLACEHOLDER_PART.match(parts[-1]):
            return None
        rel = "/".join(parts)
        if link:
            if not tree.exists(rel):
                return "missing link target"
            continue
        if bare:
            if BARE_FILE.match(rel) and "*" not in rel and rel not in tree.basenames | EXTERNAL_FILES:
                return "no file of that name"
            continue
        if parts[0] in tree.top:
            if "*" in rel:
                if not tree.glob(rel):
                    return "glob matches nothing"
            elif not (tree.exists(rel) or (doc.dir / rel).as_posix() in tree.paths):
                return "missing path"
        elif parts[0] in tree.dir_names and BARE_FILE.match(parts[-1]):  # a dataset's velodyne/0000/: not ours
            if not tree.suffix(rel):
                return "no path of the tree ends so"
    return None


def _check_paths(tree, doc, problems):
    for n, text in doc.prose:  # plain text: only paths from the top (docs/X.md, lib/...), not "float/integer"
        for w in _words(text):
            if "/" in w and w.split("/", 1)[0] in tree.top:
                why = _path_problem(tree, doc, w)
                if why:
                    problems.append(f"{doc.rel}:{n}: {why}: {w}")
    for n, text, kind in doc.code():
        for w in _words(text):  # a block's comments included: they name paths too
            if "/" not in w and not BARE_FILE.match(w):
                continue
            why = _path_problem(tree, doc, w)
            if why:
                problems.append(f"{doc.rel}:{n}: {why}: {w}")
    for n, target in doc.links:
        why = _path_problem(tree, doc, target, link=True)
        if why:
            problems.append(f"{doc.rel}:{n}: {why}: {target}")


# ----------------------------------------------------------------------------------------------- C names

FILE_EXT = r"(?:elf|bin|hex|so|a|o|c|h|py|cpp|cmake|onnx|md|json|txt|png|ld|sh|npz|npy|pt|csv|yaml|xml|pcap)\b"
IDENT = re.compile(r"(?<![\w./-])(lidet_[a-z0-9_]*[a-z0-9]|LIDET_[A-Z0-9_]*[A-Z0-9])(?![\w*<{]|\." + FILE_EXT + ")")
C_SOURCE = re.compile(r".*\.(?:c|h|cpp|hpp|cc|inc|ld|cmake)$|(?:.*/)?CMakeLists\.txt$")
ENV_SOURCE = re.compile(r".*\.(?:py|sh|toml|yml|yaml)$|(?:.*/)?Makefile$|\.ci/.*")


def _identifiers(tree):
    c_names, env_names = set(), set()
    word = re.compile(r"\b(?:lidet|LIDET)_\w+")
    for f in tree.files:
        if f.startswith(("docs/", "third_party/")) or f.endswith(".md"):
            continue
        if C_SOURCE.match(f):
            c_names.update(word.findall(tree.read(f)))
        elif ENV_SOURCE.match(f):
            env_names.update(w for w in word.findall(tree.read(f)) if w.isupper())
    return c_names, env_names


def _check_identifiers(tree, doc, names, problems):
    c_names, env_names = names
    for n, text, _ in doc.code() + [(n, t, "prose") for n, t in doc.prose]:
        for m in IDENT.finditer(text):
            name = m.group(1)
            if name in c_names or name in tree.stems or (name.isupper() and name in env_names):
                continue
            problems.append(f"{doc.rel}:{n}: C name not in the sources: {name}")


# -------------------------------------------------------------------------------------------- commands

ENV_PREFIX = r"(?:[A-Za-z_][A-Za-z0-9_]*=\S*\s+)*(?:sudo\s+|time\s+)?"
CMD_START = r"(?:^\s*(?:\$\s+)?|&&\s*|;\s*|\|\|?\s*|\(\s*)"


def _commands(text, kind, program):
    """The rest of the line after each invocation of `program` (a regex) that starts a command: at the start of a
    code span or a block's line, or after &&, ;, |, (, a prompt, VAR=value assignments, sudo."""
    rx = re.compile(CMD_START + ENV_PREFIX + program + r"(?=\s|$)(.*)$")
    out = []
    if kind == "block":
        text = _strip_comment(text)
    pos = 0
    while True:
        m = rx.search(text, pos)
        if not m:
            return out
        out.append(m.group(1))
        pos = m.start() + 1


def _cut_command(rest):
    """The arguments of one command: up to &&, ;, or a '|' outside [...] (a pipe into the next program)."""
    depth = 0
    for i, c in enumerate(rest):
        if c == "[":
            depth += 1
        elif c == "]":
            depth -= 1
        elif depth <= 0 and (c in ";" or rest.startswith("&&", i) or (c == "|" and rest[i - 1:i] == " ")):
            return rest[:i]
    return rest


def _split(args):
    try:
        return shlex.split(args)
    except ValueError:  # an unbalanced quote of a shortened command
        return args.split()


def _makefile_targets():
    text = (ROOT / "Makefile").read_text(encoding="utf-8")
    targets = set()
    for m in re.finditer(r"^([^\s#=:][^#=:]*?)\s*::?(?!=)", text, re.M):
        targets.update(t for t in m.group(1).split() if "$" not in t)
    for m in re.finditer(r"^\.PHONY\s*:(.*)$", text, re.M):
        targets.update(m.group(1).split())
    return {t for t in targets if not t.startswith(".")}


def _check_make(doc, targets, problems):
    for n, text, kind in doc.code(commands=True):
        for rest in _commands(text, kind, r"make"):
            args = _split(_cut_command(rest))
            if any(a in ("-C", "-f") or a.startswith(("-C", "-f", "--directory", "--file")) for a in args):
                continue
            for a in args:
                if re.match(r"-{1,2}[A-Za-z]", a) or re.match(r"[A-Za-z_]\w*=", a):
                    continue
                if not re.fullmatch(r"[a-z][\w.-]*", a):
                    break  # prose, a placeholder or something else: the targets end here
                if a not in targets:
                    problems.append(f"{doc.rel}:{n}: make target not in the Makefile: make {a}")


def _py_module_file(tree, module):
    """The file `python -m module` runs (tools/... or codegen/...), and the folder whose files count for its
    flags; (None, None) if none exists."""
    parts = module.split(".")
    for top in ("tools", "codegen"):
        base = "/".join([top] + parts)
        if base + ".py" in tree.file_set:
            return base + ".py", None
        if base + "/__main__.py" in tree.file_set:
            return base + "/__main__.py", base
    return None, None


def _flags(args):
    return [m.group(0) for m in re.finditer(r"(?<![\w-])--[a-z][\w-]*", args)]


def _with_imports(tree, files):
    """The files and the project modules they import (one level: a script that takes its options from a shared
    parser, tools/sim_report.py -> lidet_tools.sim.report)."""
    out = list(files)
    for f in files:
        here = f.rsplit("/", 1)[0]
        for m in re.finditer(r"^\s*(?:from\s+([\w.]+)\s+import\s+([\w, ]+)|import\s+([\w.]+))", tree.read(f), re.M):
            mod = m.group(1) or m.group(3)
            names = [n.strip() for n in (m.group(2) or "").split(",") if n.strip()]
            for cand in [mod] + [mod + "." + n for n in names]:
                path = cand.replace(".", "/")
                for base in (here, "tools", "codegen"):
                    for f2 in (f"{base}/{path}.py", f"{base}/{path}/__init__.py"):
                        if f2 in tree.file_set and f2 not in out:
                            out.append(f2)
    return out


def _flag_in(tree, flag, files):
    key = ("imports",) + tuple(files)
    if key not in tree.memo:
        tree.memo[key] = "\n".join(tree.read(f) for f in _with_imports(tree, files))
    return re.search(r"[\"']" + re.escape(flag) + r"(?![\w-])", tree.memo[key]) is not None


def _console_scripts():
    text = (ROOT / "pyproject.toml").read_text(encoding="utf-8")
    sect = re.search(r"^\[project\.scripts\]\s*$(.*?)(?=^\[|\Z)", text, re.M | re.S)
    return dict(re.findall(r"^\s*([\w-]+)\s*=\s*\"([\w.]+):\w+\"", sect.group(1), re.M)) if sect else {}


def _check_python(tree, doc, scripts, problems):
    for n, text, kind in doc.code(commands=True):
        code = _strip_comment(text) if kind == "block" else text
        for m in re.finditer(r"(?:^|\s)-m\s+(lidet[\w.]*)(.*)$", code):  # python -m, torchrun ... -m
            module, rest = m.group(1), _cut_command(m.group(2))
            path, pkg = _py_module_file(tree, module)
            if path is None:
                problems.append(f"{doc.rel}:{n}: no module file under tools/ or codegen/: -m {module}")
                continue
            files = [f for f in tree.files if f.startswith(pkg + "/") and f.endswith(".py")] if pkg else [path]
            for flag in _flags(rest):
                if flag not in ("--help",) and not _flag_in(tree, flag, files):
                    problems.append(f"{doc.rel}:{n}: option not in {pkg or path}: -m {module} {flag}")
        for m in re.finditer(r"(?:^|[\s/])python3?\s+((?:tools|codegen|tests)/[\w/.-]+\.py)(.*)$", code):
            path, rest = m.group(1), _cut_command(m.group(2))
            if path not in tree.file_set:
                continue  # reported by the path check
            for flag in _flags(rest):
                if flag != "--help" and not _flag_in(tree, flag, [path]):
                    problems.append(f"{doc.rel}:{n}: option not in {path}: {flag}")
        for script, module in scripts.items():
            for rest in _commands(code, kind, re.escape(script)):
                path, _ = _py_module_file(tree, module)
                if path is None:
                    problems.append(f"{doc.rel}:{n}: {script}: entry module {module} missing")
                    continue
                pkg = path.rsplit("/", 1)[0]
                files = [f for f in tree.files if f.startswith(pkg + "/") and f.endswith(".py")]
                for flag in _flags(_cut_command(rest)):
                    if flag != "--help" and not _flag_in(tree, flag, files):
                        problems.append(f"{doc.rel}:{n}: option not in {pkg}/: {script} ... {flag}")
        for m in re.finditer(r"(?:^|\s)((?:tests/python/)?test_\w+\.py)::(\w+)", code):
            f = m.group(1) if "/" in m.group(1) else "tests/python/" + m.group(1)
            if f in tree.file_set and not re.search(r"^\s*def " + m.group(2) + r"\b", tree.read(f), re.M):
                problems.append(f"{doc.rel}:{n}: no test {m.group(2)} in {f}")


def _py_modules(tree):
    """{'lidet_tools.track.eval': [its files], ...} for every module and package of tools/ and codegen/."""
    mods = {}
    for top in ("tools/lidet_tools", "codegen/lidet_codegen", "codegen/lidet_ref"):
        for f in tree.files:
            if f.startswith(top + "/") and f.endswith(".py") and not f.endswith("/__main__.py"):
                parts = [top.split("/")[1]] + f[len(top) + 1:-3].split("/")
                if parts[-1] == "__init__":
                    parts.pop()
                    pkg = f.rsplit("/", 1)[0] + "/"
                    mods[".".join(parts)] = [g for g in tree.files if g.startswith(pkg) and g.endswith(".py")]
                else:
                    mods[".".join(parts)] = [f]
    return mods


def _check_py_names(tree, doc, mods, problems):
    """`lidet_tools.real.split`, `native.detect`, `eval.write_tracks`: the module exists and the name after it
    occurs in its files (a short module name: in any module of that name)."""
    short = {}
    for m in mods:
        if "." in m:
            short.setdefault(m.rsplit(".", 1)[1], []).append(m)
    rx = re.compile(r"(?<![\w./-])((?:lidet_tools|lidet_codegen|lidet_ref|%s)(?:\.[A-Za-z_]\w*)+)"
                    % "|".join(map(re.escape, short)))
    for n, text, _ in doc.code():
        for m in rx.finditer(text):
            if re.search(r"\." + FILE_EXT + r"$", m.group(1)):
                continue  # a file name (report.json, qmath.py): the path rules check those
            parts = m.group(1).split(".")
            full = parts[0] in ("lidet_tools", "lidet_codegen", "lidet_ref")
            found = False
            for base in ([parts[0]] if full else short[parts[0]]):
                p = base.split(".") + parts[1:]
                k = len(p)
                while k > 1 and ".".join(p[:k]) not in mods:
                    k -= 1
                mod = ".".join(p[:k])
                if mod not in mods or (full and k < len(base.split("."))):
                    continue
                rest = p[k:]
                text_of = "".join(tree.read(f) for f in mods[mod])
                if not rest or re.search(r"\b%s\b" % re.escape(rest[0]), text_of):
                    found = True
                    break
            if not found:
                problems.append(f"{doc.rel}:{n}: Python name not in tools/ or codegen/: {m.group(1)}")


def _cli_commands(tree):
    text = tree.read("ports/host/cli_main.c")
    return set(re.findall(r"\{\s*\"([a-z][\w-]*)\"\s*,\s*cli_\w+", text))


def _cli_options(tree):
    """Every "--name" literal of ports/host/*.c, and every name of a getopt_long table ({"name", x_argument})."""
    opts = set()
    for f in tree.files:
        if f.startswith("ports/host/") and f.endswith(".c"):
            text = tree.read(f)
            opts.update(re.findall(r"\"(--[a-z][\w-]*)", text))
            opts.update("--" + o for o in
                        re.findall(r"\{\s*\"([a-z][\w-]*)\"\s*,\s*(?:no|required|optional)_argument", text))
    return opts


def _check_cli(doc, commands, options, problems):
    for n, text, kind in doc.code(commands=True):
        for rest in _commands(text, kind, r"(?:\S*/)?lidet"):
            rest = _cut_command(rest)
            words = rest.split()
            subs = []
            if words and not words[0].startswith("-"):
                subs = words[0].split("|")
                if len(words) > 2 and words[1] in ("/", "|"):
                    subs.append(words[2])
            for sub in subs:
                if re.fullmatch(r"[a-z][\w-]*", sub) and sub not in commands:
                    problems.append(f"{doc.rel}:{n}: not a command of the CLI (ports/host/cli_main.c): lidet {sub}")
            for flag in _flags(rest):
                if flag not in options:
                    problems.append(f"{doc.rel}:{n}: option not in ports/host/*.c: lidet ... {flag}")


# ------------------------------------------------------------------------------------------------- the test

def stale_references():
    tree = Tree()
    names = _identifiers(tree)
    targets = _makefile_targets()
    scripts = _console_scripts()
    commands, options = _cli_commands(tree), _cli_options(tree)
    mods = _py_modules(tree)
    assert commands, "no command table found in ports/host/cli_main.c"
    problems = []
    for rel in _doc_files(tree):
        doc = Doc(rel)
        _check_paths(tree, doc, problems)
        _check_make(doc, targets, problems)
        if doc.journal:
            continue
        _check_identifiers(tree, doc, names, problems)
        _check_python(tree, doc, scripts, problems)
        _check_cli(doc, commands, options, problems)
        _check_py_names(tree, doc, mods, problems)

    def where(problem):
        f, n = problem.split(":", 2)[:2]
        return f, int(n)
    return sorted(dict.fromkeys(problems), key=where)


def test_docs_name_what_exists():
    problems = stale_references()
    assert not problems, (f"{len(problems)} stale reference(s) in the docs; name what exists today (or reword "
                          "the sentence if the thing is gone):\n" + "\n".join(problems))


if __name__ == "__main__":
    print("\n".join(stale_references()) or "ok")
