"""The statements table (:mod:`epc_fast.paper`) as CSV, at full precision, and as Markdown."""

from __future__ import annotations

import csv
import math

__all__ = ["CSV_COLUMNS", "write_csv", "markdown_table", "simulated_markdown_table"]

CSV_COLUMNS = ("id", "kind", "statement", "unit", "relation", "paper_value", "tolerance",
               "preset_value", "on_axis_30db_value", "on_axis_33db_value", "deviation", "holds",
               "simulated_value", "simulated_holds")


def _csv_row(s) -> dict:
    holds = "" if s.holds is None else str(s.holds).lower()
    return {"id": s.id, "kind": s.kind, "statement": s.text, "unit": s.unit,
            "relation": s.relation, "paper_value": repr(s.paper_value),
            "tolerance": repr(s.tolerance), "preset_value": repr(s.preset_value),
            "on_axis_30db_value": repr(s.on_axis_30db_value),
            "on_axis_33db_value": repr(s.on_axis_33db_value),
            "deviation": repr(s.deviation), "holds": holds,
            "simulated_value": repr(s.simulated_value),
            "simulated_holds": "" if s.simulated_holds is None else str(s.simulated_holds).lower()}


def write_csv(statements, path) -> None:
    """Write ``statements`` to ``path`` (UTF-8): floats as Python reprs ("nan" where none)."""
    with open(path, "w", newline="", encoding="utf-8") as f:
        writer = csv.DictWriter(f, fieldnames=CSV_COLUMNS)
        writer.writeheader()
        writer.writerows(_csv_row(s) for s in statements)


def _number(value: float) -> str:
    """4 significant digits, whole numbers from 1000 up (thousands separated)."""
    if math.isnan(value):
        return "—"
    return f"{value:,.0f}" if abs(value) >= 1000.0 else f"{value:.4g}"


def _paper(s) -> str:
    if math.isnan(s.paper_value):
        return "—"
    tolerance = f" ±{100 * s.tolerance:.2g}%" if s.relation == "≈" else ""
    return f"{s.relation} {_number(s.paper_value)}{tolerance}"


def _deviation(s) -> str:
    """Percent to two decimals; adding 0.0 turns a rounded -0.0 into +0.0."""
    return "—" if math.isnan(s.deviation) else f"{round(100 * s.deviation, 2) + 0.0:+.2f}%"


def markdown_table(statements) -> str:
    """A Markdown table: one row per statement, values to 4 significant digits or whole."""
    lines = ["| id | kind | statement | unit | paper | preset (30 dB, corner) | 30 dB on axis "
             "| 33 dB on axis | deviation | holds |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for s in statements:
        holds = {None: "—", True: "yes", False: "**no**"}[s.holds]
        lines.append(f"| {s.id} | {s.kind} | {s.text} | {s.unit} | {_paper(s)} "
                     f"| {_number(s.preset_value)} | {_number(s.on_axis_30db_value)} "
                     f"| {_number(s.on_axis_33db_value)} | {_deviation(s)} | {holds} |")
    return "\n".join(lines) + "\n"


def simulated_markdown_table(statements) -> str:
    """A Markdown table of the statements checked on simulated captures: the paper's value, the
    model's (the preset), the simulated one, its deviation from the model and whether it holds
    against the paper."""
    lines = ["| id | statement | unit | paper | model (preset) | simulated captures "
             "| simulated vs model | holds (simulated) |",
             "|---|---|---|---|---|---|---|---|"]
    for s in statements:
        holds = {None: "—", True: "yes", False: "**no**"}[s.simulated_holds]
        deviation = ("—" if math.isnan(s.simulated_deviation)
                     else f"{round(100 * s.simulated_deviation, 1) + 0.0:+.1f}%")
        lines.append(f"| {s.id} | {s.text} | {s.unit} | {_paper(s)} | {_number(s.preset_value)} "
                     f"| {_number(s.simulated_value)} | {deviation} | {holds} |")
    return "\n".join(lines) + "\n"
