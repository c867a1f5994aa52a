"""The repository speaks of the project as it is: no "stop N" markers of the development history in tracked
text (docs state today's behaviour and numbers; history lives in git log and docs/journal/)."""
import re
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
PATTERN = re.compile(r"\bstops? \d+\b", re.IGNORECASE)
SKIP_DIRS = ("docs/journal/", "weights/", "third_party/")


def _tracked_files():
    try:
        out = subprocess.run(["git", "ls-files", "-z"], cwd=ROOT, check=True, capture_output=True).stdout
    except (OSError, subprocess.CalledProcessError):
        pytest.skip("not a git checkout")
    return [p for p in out.decode("utf-8", "surrogateescape").split("\0") if p and not p.startswith(SKIP_DIRS)]


def _text(path):
    try:
        data = path.read_bytes()
    except OSError:  # listed by git but missing in the working tree (deleted, not yet staged)
        return None
    if b"\0" in data[:8192]:
        return None  # binary
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError:
        return None


def test_no_stop_markers_in_tracked_text():
    hits = []
    for rel in _tracked_files():
        text = _text(ROOT / rel)
        if text is None:
            continue
        for n, line in enumerate(text.splitlines(), 1):
            if PATTERN.search(line):
                hits.append(f"{rel}:{n}: {line.strip()[:160]}")
    assert not hits, "development-history markers (\"stop N\") in tracked files; state today's behaviour " \
                     "instead (history belongs in git log / docs/journal/):\n" + "\n".join(hits)
