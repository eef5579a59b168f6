"""A scan's results as tables: one row per group, as columns for the CSV and markdown
writers of :mod:`epc_fast.jobs.table_formats`.
"""

from __future__ import annotations

import numpy as np

from .running.runner import ScanResult

__all__ = ["grouped_tables", "grouping_units", "table_groupings", "file_stem", "top_k_columns",
           "histogram_tables", "HISTOGRAM_BINS", "partial_note", "marked_partial",
           "SNR_TARGET_COLUMN", "OUTPUT_UNITS", "PARTIAL_COLUMN"]

#: The column, after ``design``, that says where each design meets its SNR target.
SNR_TARGET_COLUMN = "SNR target"
#: The unit of each output a reduction may summarise.
OUTPUT_UNITS = {"electron_rate_e_per_s": "e-/s", "electrons": "e-", "t_mpe_s": "s",
                "blur_mm": "mm", "f50_cyc_per_mm": "cycles/mm", "epc": "pixels",
                "f50_across_cyc_per_mm": "cycles/mm"}

#: The column every table of a partial scan ends with: the points done of those asked for.
PARTIAL_COLUMN = "partial: points done"

#: The ``bin`` column of a histogram's table: the slots around the numbered bins.
HISTOGRAM_BINS = ("below", "above", "not finite")


def _same_groups(a: dict, b: dict) -> bool:
    return a.keys() == b.keys() and all(list(a[k]) == list(b[k]) for k in a)


def table_groupings(labels_by_reduction: dict) -> dict:
    """{reduction name: grouping} for reductions given as {name: their group labels}, in order:
    the grouping is the label columns joined (``"design"``, ``"all"`` for a single group), and
    a grouping already taken by other groups gets `` (n)``, n the tables before it."""
    groupings, labels_of = {}, {}
    for reduction_name, labels in labels_by_reduction.items():
        name = ", ".join(labels) or "all"
        if name in labels_of and not _same_groups(labels_of[name], labels):
            name = f"{name} ({len(labels_of)})"
        labels_of.setdefault(name, labels)
        groupings[reduction_name] = name
    return groupings


def grouped_tables(result: ScanResult) -> dict:
    """{grouping: {column: list}}: one table per grouping (e.g. ``"design"``), joining the
    columns of every per-group result on it (summary, quantiles, fractions below), in the
    order the reductions were given; a column name already taken is prefixed with its
    reduction's name. The grouping of a single group is ``"all"``."""
    tabled = {name: r for name, r in result.results.items()
              if hasattr(r, "labels") and hasattr(r, "columns")}
    groupings = table_groupings({name: r.labels for name, r in tabled.items()})
    tables = {}
    for reduction_name, reduction in tabled.items():
        name = groupings[reduction_name]
        table = tables.setdefault(name, _label_columns(reduction.labels, result.space))
        for column, values in reduction.columns().items():
            if column not in reduction.labels:
                table[f"{reduction_name} {column}" if column in table else column] = list(values)
    return tables


def grouping_units(result: ScanResult) -> dict:
    """{grouping: text}: the unit of each table's values (its means, extremes and quantiles),
    e.g. ``"epc in pixels"``; fractions below a threshold are fractions (1)."""
    tabled = {name: r for name, r in result.results.items()
              if hasattr(r, "labels") and hasattr(r, "columns")}
    groupings = table_groupings({name: r.labels for name, r in tabled.items()})
    units = {}
    for name, reduction in tabled.items():
        if hasattr(reduction, "threshold"):
            continue
        outputs = units.setdefault(groupings[name], [])
        text = f"{reduction.of} in {OUTPUT_UNITS[reduction.of]}"
        if text not in outputs:
            outputs.append(text)
    return {grouping: ", ".join(texts) for grouping, texts in units.items()}


def _label_columns(labels: dict, space) -> dict:
    """A table's label columns; after ``design``, the column :data:`SNR_TARGET_COLUMN`: each
    design's SNR target and where it is met (its field angle moves EPC several-fold)."""
    columns = {}
    for name, values in labels.items():
        columns[name] = list(values)
        if name == "design" and space.design_names:
            target = dict(zip(space.design_names, space.snr_target_text()))
            columns[SNR_TARGET_COLUMN] = [target[design] for design in values]
    return columns


def file_stem(grouping: str) -> str:
    """A file name for a grouping's table: ``summary_by_<part>_and_<part>`` in letters, digits
    and underscores, a binned parameter's ``low`` and ``high`` columns named once as its
    ``band`` (``"design, illuminance_lux low, illuminance_lux high"`` gives
    ``summary_by_design_and_illuminance_lux_band``). The groupings of one scan are distinct,
    and so are their stems: the parts are parameter names, which hold no ``_and_``."""
    grouping, _, number = grouping.partition(" (")
    parts = []
    for part in grouping.split(", "):
        for end in (" low", " high"):
            if part.endswith(end):
                part = part[:-len(end)] + " band"
        if not parts or parts[-1] != part:
            parts.append(part)
    slug = "".join(c if c.isalnum() else "_" for c in "_and_".join(parts)
                   + (f"_{number.rstrip(')')}" if number else ""))
    return "summary_by_" + "_".join(piece for piece in slug.split("_") if piece)


def top_k_columns(result: ScanResult) -> dict:
    """{reduction name: {column: list}} for every :class:`~epc_fast.scan.TopK` result."""
    return {name: {c: list(v) for c, v in r.columns().items()}
            for name, r in result.results.items() if hasattr(r, "index")}


def histogram_tables(result: ScanResult) -> dict:
    """{reduction name: {column: list}} for every :class:`~epc_fast.scan.Histogram` result: per
    group (its label columns, and the SNR target after ``design``), one row a slot: ``below``
    the first edge (-inf to it), the bins ``1`` .. ``n``, ``above`` (the last edge to +inf) and
    ``not finite`` (no edges: NaN), with the output's edges ``<of> low`` and ``<of> high`` and
    the ``points`` in each. A group's rows sum to its points, the table's to the scan's."""
    found = {}
    for name, r in result.results.items():
        if not hasattr(r, "edges"):
            continue
        groups, bins = r.counts.shape
        below, above, nonfinite = HISTOGRAM_BINS
        slots = [below, *map(str, range(1, bins + 1)), above, nonfinite]
        low = [-np.inf, *r.edges[:-1], r.edges[-1], np.nan]
        high = [r.edges[0], *r.edges[1:], np.inf, np.nan]
        table = {column: [value for value in values for _ in slots]
                 for column, values in _label_columns(r.labels, result.space).items()}
        table["bin"] = slots * groups
        table[f"{r.of} low"] = [float(v) for v in low] * groups
        table[f"{r.of} high"] = [float(v) for v in high] * groups
        table["points"] = [int(c) for g in range(groups) for c in (
            r.below[g], *r.counts[g], r.above[g], r.nonfinite[g])]
        found[name] = table
    return found


def partial_note(result: ScanResult) -> str:
    """What marks every file of a partial scan: ``"PARTIAL RESULTS: 120,000 of 1,000,000
    points"``; empty for a complete one."""
    if not result.partial:
        return ""
    return f"PARTIAL RESULTS: {result.points:,} of {result.points_requested:,} points"


def marked_partial(columns: dict, result: ScanResult) -> dict:
    """``columns`` with :data:`PARTIAL_COLUMN` last, the points done of those asked for on every
    row, when ``result`` is partial; ``columns`` as they are for a complete scan."""
    if not result.partial:
        return columns
    rows = len(next(iter(columns.values()))) if columns else 0
    done = f"{result.points} of {result.points_requested}"
    return {**columns, PARTIAL_COLUMN: [done] * rows}
