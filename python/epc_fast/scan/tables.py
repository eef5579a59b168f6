"""A scan's results as tables: one row per group, written as CSV or markdown."""

from __future__ import annotations

import csv
import numbers

import numpy as np

from .runner import ScanResult

__all__ = ["grouped_tables", "file_stem", "top_k_columns", "write_csv", "markdown"]


def _same_groups(a: dict, b: dict) -> bool:
    return a.keys() == b.keys() and all(list(a[k]) == list(b[k]) for k in a)


def grouped_tables(result: ScanResult) -> dict:
    """{grouping: {column: list}}: one table per grouping (e.g. ``"design"``), joining the
    columns of every per-group result on it (summary, quantiles, fractions below), in the
    order the reductions were given; a column name already taken is prefixed with its
    reduction's name. The grouping of a single group is ``"all"``."""
    tables = {}
    labels_of = {}
    for reduction_name, reduction in result.results.items():
        if not (hasattr(reduction, "labels") and hasattr(reduction, "columns")):
            continue
        name = ", ".join(reduction.labels) or "all"
        if name in labels_of and not _same_groups(labels_of[name], reduction.labels):
            name = f"{name} ({len(tables)})"
        labels_of.setdefault(name, reduction.labels)
        table = tables.setdefault(name, {k: list(v) for k, v in reduction.labels.items()})
        for column, values in reduction.columns().items():
            if column not in reduction.labels:
                table[f"{reduction_name} {column}" if column in table else column] = list(values)
    return tables


def file_stem(grouping: str) -> str:
    """A file name for a grouping's table: ``summary_by_<grouping>`` in letters, digits and
    underscores."""
    slug = "".join(c if c.isalnum() else "_" for c in grouping)
    return "summary_by_" + "_".join(part for part in slug.split("_") if part)


def top_k_columns(result: ScanResult) -> dict:
    """{reduction name: {column: list}} for every :class:`~epc_fast.scan.TopK` result."""
    return {name: {c: list(v) for c, v in r.columns().items()}
            for name, r in result.results.items() if hasattr(r, "index")}


def write_csv(path, columns: dict) -> None:
    """One header row, then one row per entry; floats at full precision."""
    with open(path, "w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(columns)
        writer.writerows(zip(*(map(_csv_value, v) for v in columns.values())))


def _csv_value(value):
    if isinstance(value, numbers.Integral):
        return int(value)
    if isinstance(value, numbers.Real):
        return repr(float(value))
    return value


def _cell(value) -> str:
    if isinstance(value, numbers.Integral):
        return f"{int(value):,}"
    if isinstance(value, numbers.Real):
        value = float(value)
        if not np.isfinite(value):
            return str(value)
        return f"{value:,.0f}" if abs(value) >= 1000 else f"{value:.4g}"
    return str(value).replace("|", "\\|")


def markdown(columns: dict) -> str:
    """A markdown table: integers and values >= 1000 with thousands separators, others to 4
    significant digits."""
    if not columns:
        return ""
    header = "| " + " | ".join(columns) + " |"
    rule = "|" + "|".join("---" for _ in columns) + "|"
    rows = ["| " + " | ".join(_cell(v) for v in row) + " |" for row in zip(*columns.values())]
    return "\n".join([header, rule, *rows])
