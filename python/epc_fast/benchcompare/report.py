"""A comparison's reports: Markdown for people (and a CI job's summary), JSON for tools."""

from __future__ import annotations

import json
from dataclasses import asdict

from .worker import WORKLOADS

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
