"""The examples of README.md and docs/*.md run as written and print what the pages show.

Conventions of the pages, which this test enforces:

- Every fenced ```python block runs. The blocks of one page run in order in one namespace, as
  a reader who pastes them one after another into one session would; each page starts in a
  fresh temporary directory (its cwd), where ``examples`` links to the repository's examples.
- A ```text block that is the next fenced block after a ```python, ```toml or ```console
  block (prose may come between) is the expected output of that block: stdout, and for
  commands stdout and stderr. A block whose next fenced block is not ```text must run without
  error; its output is not checked.
- A ```toml block is a scan config: saved as ``scan.toml`` in a directory of its own, it runs
  as ``epc-fast scan scan.toml --out scan-out``, the command the pages give.
- A ```console block holds commands, each on a line starting with ``$ ``; they run in the
  page's directory, in order, and must exit with 0. ```bash blocks (installs, benchmarks that
  take minutes, the shell of a cluster) are shown, never run.
- ``<!-- docs-test: skip (reason) -->`` on the line before a block keeps it from running; the
  reason is part of the marker and must be given. Used only where running the block is not
  possible here (a Dask cluster).

Comparing outputs: whitespace runs count as one space; ``...`` in the expected text matches
any text (timings, elided lines), as doctest's ELLIPSIS does; every number is compared as a
number, equal within a relative 1e-9. The pages show the output of the x86-64-v4 build; the
x86-64-v3 build gives the same bits and the baseline build agrees with them to a few ulp
(docs/numerics.md), which moves a value printed in full (17 digits) by about 1e-15 relative.
1e-9 is far above that and far below any change an example is meant to show: every value the
pages print has at most ten significant digits that mean something, so a drift in the model
or an edited example still fails.
"""

from __future__ import annotations

import contextlib
import io
import math
import os
import re
import shlex
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import pytest

#: Every page's examples run: about four minutes on 2 cores (a scan, the paper, captures).
pytestmark = pytest.mark.heavy

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md"] + sorted((ROOT / "docs").glob("*.md"))
#: Relative tolerance of printed numbers (the module docstring gives the reason).
RTOL = 1e-9
SKIP_MARKER = re.compile(r"<!--\s*docs-test:\s*skip\s*\((?P<reason>[^)]+)\)\s*-->")
FENCE = re.compile(r"^```(?P<info>[^\n`]*)\n(?P<body>.*?)^```[ \t]*$", re.S | re.M)
NUMBER = r"[-+]?(?:\d{1,3}(?:,\d{3})+|\d+)(?:\.\d+)?(?:[eE][-+]?\d+)?"
RUN_LANGUAGES = ("python", "toml", "console")


@dataclass
class Block:
    page: Path
    line: int
    language: str
    body: str
    expected: str | None = None
    skip: str | None = None

    def where(self) -> str:
        return f"{self.page.relative_to(ROOT)}:{self.line}"


def blocks_of(page: Path) -> list[Block]:
    """The fenced blocks of a page that run, each with its expected output, in page order."""
    text = page.read_text(encoding="utf-8")
    fences = list(FENCE.finditer(text))
    blocks = []
    for i, match in enumerate(fences):
        language = match["info"].strip().split(" ")[0]
        if language not in RUN_LANGUAGES:
            continue
        before = text[:match.start()].rstrip().rsplit("\n", 1)[-1]
        skip = SKIP_MARKER.search(before)
        block = Block(page, text.count("\n", 0, match.start()) + 1, language, match["body"],
                      skip=skip["reason"] if skip else None)
        following = fences[i + 1] if i + 1 < len(fences) else None
        if following is not None and following["info"].strip() == "text":
            block.expected = following["body"]
        blocks.append(block)
    return blocks


def _squash(text: str) -> str:
    return " ".join(text.split())


def output_mismatch(expected: str, actual: str) -> str | None:
    """None when ``actual`` matches ``expected`` (the module docstring's rules), else why not."""
    expected, actual = _squash(expected), _squash(actual)
    literal, pattern, numbers = [], [], []
    for piece in re.split(rf"(\.\.\.|{NUMBER})", expected):
        if piece == "...":
            literal.append(".*?")
            pattern.append(".*?")
        elif piece and re.fullmatch(NUMBER, piece):
            literal.append(re.escape(piece))
            pattern.append(f"({NUMBER})")
            numbers.append(piece)
        else:
            literal.append(re.escape(piece))
            pattern.append(re.escape(piece))
    # The same digits first: with numbers as wildcards, "..." could align a row with another.
    if re.fullmatch("".join(literal), actual, re.S):
        return None
    match = re.fullmatch("".join(pattern), actual, re.S)
    if match is None:
        return f"the text differs:\nexpected: {expected}\nactual:   {actual}"
    for want, got in zip(numbers, match.groups()):
        a, b = float(want.replace(",", "")), float(got.replace(",", ""))
        if not math.isclose(a, b, rel_tol=RTOL, abs_tol=0.0):
            return f"{got} printed where the page shows {want}\nactual: {actual}"
    return None


#: NumPy's default print options, which a reader's fresh session has (another test may have
#: changed them in this process).
NUMPY_PRINT_DEFAULTS = dict(edgeitems=3, infstr="inf", linewidth=75, nanstr="nan", precision=8,
                            suppress=False, threshold=1000, formatter=None, sign="-",
                            floatmode="maxprec", legacy=False)


def _run_python(block: Block, namespace: dict) -> str:
    import numpy as np

    stdout = io.StringIO()
    with contextlib.redirect_stdout(stdout), np.printoptions(**NUMPY_PRINT_DEFAULTS):
        exec(compile(block.body, block.where(), "exec"), namespace)
    return stdout.getvalue()


def _run_command(command: str, cwd: Path) -> str:
    words = shlex.split(command)
    if words[0] == "epc-fast":  # the installed entry point is this interpreter's package
        words = [sys.executable, "-m", "epc_fast"] + words[1:]
    elif words[0] == "python":
        words[0] = sys.executable
    done = subprocess.run(words, cwd=cwd, capture_output=True, text=True, timeout=300,
                          env={**os.environ, "PYTHONWARNINGS": "ignore"})
    assert done.returncode == 0, f"{command!r} exited with {done.returncode}:\n{done.stderr}"
    return done.stdout + done.stderr


def _run_console(block: Block, cwd: Path) -> str:
    commands = [line[2:] for line in block.body.splitlines() if line.startswith("$ ")]
    assert commands, f"{block.where()}: a console block without a '$ ' command"
    return "".join(_run_command(command, cwd) for command in commands)


def _run_toml(block: Block, cwd: Path, index: int) -> str:
    folder = cwd / f"toml-{index}"
    folder.mkdir()
    (folder / "scan.toml").write_text(block.body, encoding="utf-8")
    return _run_command("epc-fast scan scan.toml --out scan-out", folder)


def run_page(page: Path, cwd: Path) -> list[str]:
    """Run every block of a page in ``cwd``; the list of failures, each naming its block."""
    (cwd / "examples").symlink_to(ROOT / "examples")
    namespace = {"__name__": "__main__"}
    failures = []
    previous = Path.cwd()
    os.chdir(cwd)
    try:
        for index, block in enumerate(blocks_of(page)):
            if block.skip:
                continue
            if block.language == "python":
                actual = _run_python(block, namespace)
            elif block.language == "toml":
                actual = _run_toml(block, cwd, index)
            else:
                actual = _run_console(block, cwd)
            if block.expected is not None:
                why = output_mismatch(block.expected, actual)
                if why is not None:
                    failures.append(f"{block.where()}: {why}")
    finally:
        os.chdir(previous)
    return failures


@pytest.mark.parametrize("page", PAGES, ids=[str(p.relative_to(ROOT)) for p in PAGES])
def test_page_examples_print_what_the_page_shows(page, tmp_path):
    failures = run_page(page, tmp_path)
    assert not failures, "\n\n".join(failures)


def test_every_skipped_block_gives_its_reason():
    for page in PAGES:
        text = page.read_text(encoding="utf-8")
        for marker in re.findall(r"<!--\s*docs-test[^>]*-->", text):
            assert SKIP_MARKER.fullmatch(marker), f"{page.name}: malformed marker {marker}"


def test_output_comparison_fails_on_a_drifted_number():
    assert output_mismatch("EPC 370628.39 pixels", "EPC 370628.39  pixels\n") is None
    assert output_mismatch("scan: ... 1,235,303 mean", "scan: 0.1 s, 8 M/s 1,235,303 mean") is None
    assert output_mismatch("EPC 370628.39 pixels", "EPC 370628.40 pixels") is not None
    assert output_mismatch("mean 1,235,303", "mean 1,235,304") is not None
    assert output_mismatch("OK NONE", "OK PRNU") is not None


LINK = re.compile(r"(?<!!)\[[^\]]*\]\((?P<target>[^)\s]+)\)|!\[[^\]]*\]\((?P<image>[^)\s]+)\)")


@pytest.mark.parametrize("page", PAGES, ids=[str(p.relative_to(ROOT)) for p in PAGES])
def test_relative_links_point_at_files_of_the_repository(page):
    text = FENCE.sub("", page.read_text(encoding="utf-8"))
    for match in LINK.finditer(text):
        target = match["target"] or match["image"]
        if re.match(r"[a-z]+:", target) or target.startswith("#"):
            continue
        path = (page.parent / target.split("#")[0]).resolve()
        assert path.exists(), f"{page.name}: {target} does not exist"
        assert ROOT in path.parents, f"{page.name}: {target} is outside the repository"


def test_no_page_links_to_the_contract_outside_the_repository():
    for page in PAGES:
        text = page.read_text(encoding="utf-8")
        assert "shared/spec" not in text and "MODEL.md" not in text, page.name


def test_performance_page_script_prints_one_markdown_row_per_build():
    # docs/performance.md's table comes from this script; a small run checks its shape only.
    done = subprocess.run(
        [sys.executable, str(ROOT / "bench" / "performance_page.py"), "--isa", "x86-64",
         "--points", "65536", "--reference-points", "2000", "--rounds", "1"],
        capture_output=True, text=True, timeout=300, check=True)
    lines = done.stdout.splitlines()
    assert lines[0].startswith("CPU: ") and "Command: `python bench/performance_page.py" in lines[1]
    header = next(line for line in lines if line.startswith("| build |"))
    rows = [line for line in lines if line.startswith("| x86-64")]
    assert len(rows) == 1 and rows[0].startswith("| x86-64 (SSE2, no FMA) | ")
    assert rows[0].count("|") == header.count("|") == 11
    assert "M" in rows[0] and "x |" in rows[0]
