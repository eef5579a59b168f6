"""A table's columns ({name: values}) written as CSV or as markdown.

Text cells come from users (design names): a CSV cell starting with ``=``, ``+``, ``-``, ``@``,
a tab or a carriage return gets a leading ``'`` so that a spreadsheet shows it as text instead
of running it as a formula; a markdown cell has its pipes escaped and line breaks as spaces.
"""

from __future__ import annotations

import csv
import numbers

import numpy as np

__all__ = ["write_csv", "markdown", "NO_VALUE"]

#: What a Markdown cell shows for a statistic with no value (NaN: a group with no finite value).
NO_VALUE = "–"

#: First characters that make a spreadsheet read a CSV cell as a formula.
FORMULA_STARTS = ("=", "+", "-", "@", "\t", "\r")


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
    text = str(value)
    return "'" + text if text.startswith(FORMULA_STARTS) else text


def _cell(value) -> str:
    if isinstance(value, numbers.Integral):
        return f"{int(value):,}"
    if isinstance(value, numbers.Real):
        value = float(value)
        if np.isnan(value):
            return NO_VALUE
        if not np.isfinite(value):
            return str(value)
        return f"{value:,.0f}" if abs(value) >= 1000 else f"{value:.4g}"
    return " ".join(str(value).replace("|", "\\|").splitlines())


def markdown(columns: dict) -> str:
    """A markdown table: integers and values >= 1000 with thousands separators, others to 4
    significant digits, a statistic with no value (NaN) a dash."""
    if not columns:
        return ""
    header = "| " + " | ".join(map(_cell, columns)) + " |"
    rule = "|" + "|".join("---" for _ in columns) + "|"
    rows = ["| " + " | ".join(_cell(v) for v in row) + " |" for row in zip(*columns.values())]
    return "\n".join([header, rule, *rows])
