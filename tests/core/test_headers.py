"""The core's headers (cpp/include/epc_fast/, docs/internals.md "The core") keep the layout the
package keeps: each at most 400 lines, and no first word of a file name shared by two headers of
one folder, which would stand for a subsystem that wants a folder of its own (scan/, f50/,
exposure/); and the core's comments name only headers and files that exist."""

import re
from pathlib import Path

import pytest

from helpers.layout import shared_prefixes

ROOT = Path(__file__).resolve().parents[2]
HEADERS = ROOT / "cpp" / "include"
SOURCES = ROOT / "cpp" / "src"

#: Longest header, in lines (the binding files' limit too: tests/test_layout.py).
MAX_HEADER_LINES = 400


@pytest.mark.parametrize("path", sorted(HEADERS.rglob("*.h")),
                         ids=lambda p: p.relative_to(HEADERS).as_posix())
def test_no_header_is_over_400_lines(path):
    assert len(path.read_text().splitlines()) <= MAX_HEADER_LINES


@pytest.mark.parametrize("folder", sorted({p.parent for p in HEADERS.rglob("*.h")}),
                         ids=lambda p: p.relative_to(HEADERS).as_posix())
def test_no_header_name_prefix_stands_for_a_subsystem(folder):
    names = [p.stem for p in folder.glob("*.h")] + [p.name for p in folder.iterdir() if p.is_dir()]
    assert shared_prefixes(names) == {}



def _named_paths(text: str):
    """The headers (``f50/start.h``, ``kernel.h``) and repository files (``python/...py``,
    ``docs/...md``, ``scan/...py``) a source file's comments name; #include <...> lines are
    the system's."""
    text = "\n".join(line for line in text.splitlines() if not line.startswith("#include <"))
    headers = re.findall(r"(?<![\w/.<])((?:\w+/)*\w+\.h)\b", text)
    files = re.findall(r"\b((?:python|tests|tools|docs|bench|cmake)/[\w/.]+\.(?:py|md|cpp|csv))\b",
                       text)
    # the package's modules by their path under python/epc_fast/ (scan/sampling/qmc.py)
    modules = re.findall(r"(?<![\w/])((?:scan|reference)/[\w/]+\.py)\b", text)
    files += [f"python/epc_fast/{m}" for m in modules]
    return headers, files


@pytest.mark.parametrize("path", sorted([*HEADERS.rglob("*.h"), *SOURCES.glob("*")]),
                         ids=lambda p: p.relative_to(ROOT).as_posix())
def test_the_core_names_only_files_that_exist(path):
    headers, files = _named_paths(path.read_text())
    places = (path.parent, HEADERS / "epc_fast", HEADERS, SOURCES, ROOT / "tools")
    missing = [h for h in headers if not any((place / h).exists() for place in places)]
    missing += [f for f in files if not (ROOT / f).exists()]
    assert "MODEL.md" not in path.read_text()
    assert missing == []
