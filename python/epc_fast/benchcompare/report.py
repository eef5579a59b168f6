"""A comparison's reports: Markdown for people (and a CI job's summary), JSON for tools; the
folder they go to is checked before the first round (:func:`check_out`), and each is written
whole or not at all (:func:`write_reports`)."""

from __future__ import annotations

import json
from dataclasses import asdict
from pathlib import Path

from .worker import WORKLOADS

#: The reports' file names in ``--out``.
REPORTS = ("compare.md", "compare.json")

CLOCK_TEXT = {"cpu": "the process's CPU time, all its threads", "wall": "wall time"}
VERDICT_TEXT = {"slower": "**SLOWER**", "faster": "faster", "same": "same",
                "unclear": "unclear"}


def _side_line(label: str, side: dict) -> str:
    return (f"- {label}: `{side['command']}`: epc_fast {side['version']} ({side['isa']}, "
            f"OpenMP {'on' if side['openmp'] else 'off'}, Python {side['python']}) from "
            f"`{side['module']}`")


def _ms(seconds_list) -> str:
    ordered = sorted(seconds_list)
    return f"{ordered[len(ordered) // 2] * 1e3:.3g}"


def markdown(comparison) -> str:
    """The verdict, both sides, a table of the workloads and the conditions."""
    c = comparison
    pct = f"{c.threshold:.0%}"
    slower = [w.name for w in c.workloads if w.ratio.verdict(c.threshold) == "slower"]
    head = (f"**FAIL**: a slowdown beyond {pct} is significant in {', '.join(slower)}"
            if slower else f"**PASS**: no workload is significantly more than {pct} slower")
    rows = ["| workload | points | threads | calls a sample | baseline ms | candidate ms | "
            "ratio | 95% interval | verdict |", "|---|---:|---:|---:|---:|---:|---:|---|---|"]
    for w in c.workloads:
        r = w.ratio
        rows.append(f"| {w.name} | {w.points:,} | {w.threads} | {w.reps} | "
                    f"{_ms(w.baseline_s)} | {_ms(w.candidate_s)} | {r.estimate:.3f} | "
                    f"[{r.low:.3f}, {r.high:.3f}] | {VERDICT_TEXT[r.verdict(c.threshold)]} |")
    cond = c.conditions
    lines = [f"# epc-fast bench compare: {head}", "",
             _side_line("baseline", c.baseline), _side_line("candidate", c.candidate), "",
             *rows, "",
             f"Times: {CLOCK_TEXT[cond['clock']]}; ms: the median time of one call. Ratio: "
             f"candidate time / baseline time (above 1: the candidate is slower), the "
             f"10%-trimmed geometric mean of {cond['rounds']} paired rounds in "
             f"{cond['blocks']} blocks of fresh processes, with a 95% bootstrap interval. A "
             f"workload fails when its whole interval lies above 1 + {pct}; 'unclear' when it "
             f"reaches past that but not wholly (more rounds, or a quieter machine, can "
             f"tell).", ""]
    for name, why in c.unavailable.items():
        sides = "; ".join(f"{side}: {text}" for side, text in why.items() if text)
        lines.append(f"- not compared, {name}: {sides}")
    lines.append(f"- {'quick' if cond['quick'] else 'full'} set, {cond['rounds']} rounds, "
                 f"{cond['seconds']:.0f} s; {cond['cpus']} CPUs, 1-minute load average "
                 f"{cond['load_before']} before and {cond['load_after']} after")
    lines.append("- workloads: " + "; ".join(f"{name}: {WORKLOADS[name][3]}"
                                             for name in (w.name for w in c.workloads)))
    return "\n".join(lines) + "\n"


def as_json(comparison) -> str:
    """Everything measured, the times of every round included."""
    c = comparison
    data = {"passed": not c.failed, "threshold": c.threshold, "baseline": c.baseline,
            "candidate": c.candidate, "conditions": c.conditions,
            "unavailable": c.unavailable,
            "workloads": [{**{k: v for k, v in asdict(w).items() if k != "ratio"},
                           "ratio": asdict(w.ratio),
                           "verdict": w.ratio.verdict(c.threshold)} for w in c.workloads]}
    return json.dumps(data, indent=1) + "\n"


def check_out(folder: Path) -> None:
    """Makes ``folder`` ready for the reports, or refuses it with an OutputError naming it: a
    path that is not a folder, one that cannot be created, a report's name taken by a folder,
    or a folder that cannot be written (a probe file is written and removed)."""
    from ..jobs.atomic import probe_writable
    from ..jobs.errors import OutputError

    def refuse(why: str):
        raise OutputError(f"--out {str(folder)!r}: {why}")

    if folder.exists() and not folder.is_dir():
        refuse("exists and is not a folder")
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        refuse(f"cannot create it: {error.strerror}")
    for name in REPORTS:
        if (folder / name).is_dir() and not (folder / name).is_symlink():
            refuse(f"{name} is a folder; the comparison writes a file of that name")
    try:
        probe_writable(folder)
    except OSError as error:
        refuse(f"is not writable: {error.strerror}")


def write_reports(folder: Path, comparison, text: str | None = None) -> list:
    """compare.md (``text``, else :func:`markdown`) and compare.json in ``folder``, each
    written to a temporary file beside it and renamed into place
    (:func:`~epc_fast.jobs.atomic.atomic_write`): a report is the previous one, or none, until
    the new one is whole. An OSError naming the file when one cannot be written."""
    from ..jobs.atomic import atomic_write

    texts = {"compare.md": markdown(comparison) if text is None else text,
             "compare.json": as_json(comparison)}
    written = []
    for name, text in texts.items():
        target = folder / name
        try:
            atomic_write(target, lambda path, text=text: path.write_text(text, encoding="utf-8"))
        except OSError as error:
            raise OSError(error.errno, f"cannot write {target}: "
                          f"{error.strerror or error}") from error
        written.append(target)
    return written
