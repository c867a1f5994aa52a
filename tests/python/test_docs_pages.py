# SPDX-License-Identifier: MIT
"""The handbook stays a handbook: every page of docs/ and docs/benchmarks/ states today's behaviour in at most
MAX_LINES lines (history, superseded figures and experiments go to docs/journal/, which is exempt), and the
benchmark pages written by tools/bench/run_bench.py keep their shape: a section cut over several pages joins
again byte for byte, an --update replaces one section and nothing else, and every figure of the index's headline
table is on the page it links. No build, no benchmark run: a second."""
import importlib.util
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"
MAX_LINES = 320  # run_bench.PAGE_LINES (300) for the pages it writes, and a little room for hand-written ones


@pytest.fixture(scope="module")
def rb():
    spec = importlib.util.spec_from_file_location("run_bench", ROOT / "tools" / "bench" / "run_bench.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _handbook_pages():
    return sorted(DOCS.glob("*.md")) + sorted((DOCS / "benchmarks").glob("*.md"))


def test_handbook_pages_are_short():
    pages = _handbook_pages()
    assert len(pages) > 10
    long = [f"{p.relative_to(ROOT)}: {n} lines" for p in pages
            if (n := len(p.read_text(encoding="utf-8").splitlines())) > MAX_LINES]
    assert not long, (f"handbook pages over {MAX_LINES} lines; keep today's behaviour, usage and numbers there and "
                      "move history, derivations and experiments to docs/journal/ (or split the page by topic):\n"
                      + "\n".join(long))


def test_benchmark_pages_are_the_runners(rb, tmp_path):
    """Each benchmark's pages, joined and written again by the runner, are the same files: the cut is the runner's
    own, every page within run_bench.PAGE_LINES, continuation pages linked from the first."""
    pages = DOCS / rb.PAGES_DIR
    names = sorted(p.stem for p in pages.glob("*.md") if not re.search(r"-\d+$", p.stem))
    assert "firmware" in names and "cluster" in names
    for name in names:
        files = rb.page_files(pages, name)
        assert files, name
        body = rb.read_pages(pages, name)
        assert body.startswith("## "), f"{name}: the page's text after its head is no '## ' section"
        again = rb.write_pages(tmp_path, name, body)
        assert [p.name for p in again] == [p.name for p in files], name
        for mine, theirs in zip(again, files):
            assert mine.read_text() == theirs.read_text(), f"{theirs.name} is not as run_bench writes it"
            assert len(theirs.read_text().splitlines()) <= rb.PAGE_LINES, theirs.name
    orphans = [p.name for p in pages.glob("*-*.md")
               if re.fullmatch(r"(.+)-(\d+)", p.stem) and p not in rb.page_files(pages, p.stem.rsplit("-", 1)[0])]
    assert not orphans, f"continuation pages without the pages before them: {orphans}"


def test_update_replaces_one_section(rb, tmp_path):
    pages = tmp_path / rb.PAGES_DIR
    index = tmp_path / "BENCHMARKS.md"
    rows = lambda n: "\n".join(f"| row {i} | {i} |" for i in range(n))  # noqa: E731
    body = (f"## Alpha (a)\n\nintro\n\n| a | b |\n|---|---|\n| 1 | 2 |\n\n### Part two\n\n| x | y |\n|---|---|\n"
            f"{rows(200)}\n\n### Part three\n\n**caption**\n\n| x | y |\n|---|---|\n{rows(150)}\n\ntail\n\n"
            "## Kept by hand\n\nmeasured once")
    written = rb.write_pages(pages, "alpha", body)
    assert len(written) == 2 and all(len(p.read_text().splitlines()) <= rb.PAGE_LINES for p in written)
    assert rb.read_pages(pages, "alpha") == body
    assert written[1].read_text().split("\n\n", 2)[2].startswith("### Part three\n\n**caption**\n\n| x | y |")
    new = rb.splice(rb.read_pages(pages, "alpha"), "## Alpha (a)\n\nremeasured\n")
    written = rb.write_pages(pages, "alpha", new)
    assert len(written) == 1 and not (pages / "alpha-2.md").exists()
    assert rb.read_pages(pages, "alpha") == "## Alpha (a)\n\nremeasured\n\n## Kept by hand\n\nmeasured once"
    index.write_text(f"# Benchmarks\n\n{rb.RUN_LINE} on 2000-01-01.\n\nhand text\n\n## Pages\n\n"
                     f"{rb.PAGES_BEGIN}\nold\n{rb.PAGES_END}\n\nafter\n")
    rb.update_index(index, pages, f"{rb.RUN_LINE} on 2001-01-01.")
    text = index.read_text()
    assert "2001-01-01" in text and "2000-01-01" not in text and "hand text" in text and "after" in text
    assert "[alpha](benchmarks/alpha.md)" in text and "Alpha (a); Kept by hand" in text and "old" not in text


def test_headline_figures_are_on_their_pages(rb):
    """Every number of a row of the index's headline table occurs on the pages that row links."""
    text = (DOCS / "BENCHMARKS.md").read_text(encoding="utf-8")
    section = text.split("## Headline figures", 1)[1].split("\n## ", 1)[0]
    rows = [ln for ln in section.splitlines() if ln.startswith("| ") and "](benchmarks/" in ln]
    assert len(rows) >= 10
    missing = []
    for row in rows:
        links = re.findall(r"\]\(benchmarks/([\w-]+)\.md\)", row)
        pages = "\n".join(rb.read_pages(DOCS / rb.PAGES_DIR, name) for name in links)
        figures = re.sub(r"\[[^\]]*\]\([^)]*\)", "", row)
        for num in re.findall(r"\d+(?:,\d{3})*(?:\.\d+)?", figures):
            if not re.search(r"(?<![\d.])" + re.escape(num) + r"(?![\d])", pages):
                missing.append(f"{num} ({', '.join(links)}): {row[:80]}")
    assert not missing, "headline figures not on their pages:\n" + "\n".join(missing)
