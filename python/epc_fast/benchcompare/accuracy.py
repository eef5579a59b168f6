"""Accuracy tables against committed ones: a change of the outputs fails unless declared.

Per build (``EPC_FAST_ISA`` = x86-64, x86-64-v3, x86-64-v4) a table holds the core against
the 50-digit mpmath model on random designs (``tools/mpmath_check.py --backend core``: status
mismatches and the largest relative error of T_MPE, f50 and EPC) and a digest of
``evaluate``'s outputs (``tools/output_digest.py``: a hash of every output of every setting);
``reference.txt`` holds the NumPy reference against mpmath. Both tools live in the source
checkout (the mpmath model beside the tests), so this runs from one.

A change is declared by the commit that makes it: it rewrites the tables
(``epc-fast bench accuracy --update``) and says why in its message, on a line of its own
starting ``Accuracy-change:`` (tests/benchcompare/test_tables.py holds every commit that
touches the tables to that).
"""

from __future__ import annotations

import difflib
import subprocess
from pathlib import Path

from .sides import split_command

ISAS = ("x86-64", "x86-64-v3", "x86-64-v4")
#: glibc's libm picks FMA variants of sin, cos, exp and pow on CPUs with FMA, which differ from
#: its other variants in the last bits. The tables are measured with the variants without FMA on
#: every CPU (glibc's hwcaps tunable; other C libraries have one variant), so that one build
#: gives the same table on any x86-64 CPU. The inputs are the same bits on every CPU
#: (epc_fast.portable_math); docs/performance.md states what the tables assume.
LIBM_PINNED = "GLIBC_TUNABLES=glibc.cpu.hwcaps=-AVX2,-FMA,-FMA4"
MPMATH_POINTS = 200
TRAILER = "Accuracy-change:"


def _run(words: list, script: Path, *args) -> list[str]:
    done = subprocess.run([*words, str(script), *args], capture_output=True, text=True)
    if done.returncode != 0:
        tail = " | ".join(done.stderr.strip().splitlines()[-3:])
        raise RuntimeError(f"{script.name} failed ({' '.join(words)}): {tail}")
    return done.stdout.strip().splitlines()


def lines_for(python: str, repo: Path, isa: str | None) -> list[str]:
    """The table of one build (``isa``), or of the reference (``isa`` None)."""
    words = split_command(python, "--python")
    tools = repo / "tools"
    if isa is None:
        return _run(words, tools / "mpmath_check.py", "--points", str(MPMATH_POINTS))
    words = ["env", LIBM_PINNED, f"EPC_FAST_ISA={isa}", *words]
    mp = _run(words, tools / "mpmath_check.py", "--points", str(MPMATH_POINTS), "--backend",
              "core")
    return [*mp, *_run(words, tools / "output_digest.py")]


def cpu_runs(python: str, isa: str) -> bool:
    """Whether this CPU (and the install) runs the build ``isa``."""
    words = ["env", f"EPC_FAST_ISA={isa}", *split_command(python, "--python")]
    done = subprocess.run([*words, "-c", "import epc_fast._core"], capture_output=True)
    return done.returncode == 0


def check(python: str, repo: Path, tables: Path, isas=ISAS, update: bool = False,
          progress=None) -> tuple[bool, list[str]]:
    """(all equal, report lines): each table measured and held against ``tables/<name>.txt``,
    the difference shown as a unified diff; with ``update``, the tables written instead."""
    say = progress or (lambda line: None)
    report, equal = [], True
    targets = [("reference", None)] + [(isa, isa) for isa in isas]
    for name, isa in targets:
        if isa is not None and not cpu_runs(python, isa):
            report.append(f"{name}: skipped, this CPU or install does not run it")
            continue
        say(f"accuracy: {name}")
        measured = lines_for(python, repo, isa)
        path = tables / f"{name}.txt"
        committed = path.read_text().splitlines() if path.exists() else None
        if update:
            tables.mkdir(parents=True, exist_ok=True)
            path.write_text("\n".join(measured) + "\n")
            state = "unchanged" if committed == measured else "written"
            report.append(f"{name}: {state} {path}")
            continue
        if committed == measured:
            report.append(f"{name}: same as {path}")
            continue
        equal = False
        if committed is None:
            report.append(f"{name}: CHANGED: {path} is missing (write it with --update)")
            continue
        report.append(f"{name}: CHANGED against {path}:")
        report += list(difflib.unified_diff(committed, measured, "committed", "measured",
                                            lineterm="", n=0))
    if not equal:
        report.append(f"an output or an error changed: if that is meant, rewrite the tables "
                      f"(epc-fast bench accuracy --update) and commit them with a line "
                      f"'{TRAILER} <why>' in the commit message")
    return equal, report
