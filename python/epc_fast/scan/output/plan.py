"""The files a scan will write, named before its first point: tables, histograms' tables, top-k
lists, plots, the
Sobol' indices, the Parquet directory and the manifest.

Names come from the reductions' names and groupings, the same functions the writers use, so a
collision (a top-k reduction named ``summary_by_design`` beside the summary table by design) is
refused before any work rather than one file silently replacing the other.
"""

from __future__ import annotations

from ..config.indices import SOBOL_FILES
from ...jobs.errors import OutputError
from ..reductions.groups import group_key
from ..reductions.histograms import Histogram, Quantiles
from ...jobs.output.manifest import MANIFEST_NAME
from ..plot import bands_parameter_of
from ..running.runner import default_reductions
from ..tables import file_stem, table_groupings

__all__ = ["plan_outputs", "TABLE_KINDS"]

#: Reductions whose results join the per-grouping tables (those with labels and columns).
TABLE_KINDS = ("Summary", "Quantiles", "FractionBelow")


def plan_outputs(space, reductions: dict | None, plots: bool, parquet: str | None,
                 sobol: bool = False) -> dict:
    """{file name: what writes it}, in the order they are written, the manifest last;
    ``sobol``: the config's ``[sobol]`` indices too (sobol.csv, sobol.md)."""
    reductions = default_reductions(space) if reductions is None else reductions
    labels = {name: group_key(space, r.by).columns for name, r in reductions.items()
              if type(r).__name__ in TABLE_KINDS}
    planned = {}

    def add(file, what):
        if file in planned:
            raise OutputError(f"{what} and {planned[file]} would both write {file}: rename "
                              "the reduction")
        planned[file] = what

    for grouping in dict.fromkeys(table_groupings(labels).values()):
        for suffix in (".csv", ".md"):
            add(file_stem(grouping) + suffix, f"the table by {grouping}")
    for name, reduction in reductions.items():
        if isinstance(reduction, Histogram):
            for suffix in (".csv", ".md"):
                add(f"{name}{suffix}", f"reduction {name!r} (histogram)")
    for name, reduction in reductions.items():
        if type(reduction).__name__ == "TopK":
            add(f"{name}.csv", f"reduction {name!r} (top_k)")
    if plots:
        for name, reduction in reductions.items():
            plotted = isinstance(reduction, Histogram) or (
                isinstance(reduction, Quantiles) and bands_parameter_of(labels.get(name, {})))
            if plotted:
                add(f"{name}.png", f"reduction {name!r}'s plot")
    if sobol:
        for file in SOBOL_FILES:
            add(file, "the [sobol] indices")
    if parquet is not None:
        add(parquet, "[output] parquet")
    add(MANIFEST_NAME, "the manifest")
    return planned
