"""The ``[reductions.NAME]`` tables of a scan config: each key checked, each size bounded.

The sizes a reduction allocates (its groups, its bins, its kept points) are computed from the
config alone and refused beyond the bounds of :mod:`epc_fast.jobs.schema` before any group key
or array is built.
"""

from __future__ import annotations

import math

import numpy as np

from ..reductions.best import TopK
from ..running.chunk import OUTPUTS
from ...jobs.errors import ConfigError
from ..reductions.groups import Binned, group_key
from ..reductions.histograms import Histogram, Quantiles
from ...jobs.schema import (boolean, check_size, choice, file_name, integer, number, number_list,
                            short, table_of, take, where_prefix, wrapped)
from .bounds import MAX_CELLS, MAX_EXACT_QUANTILE_POINTS, MAX_GROUPS, MAX_TOP_K
from ..reductions.replicates import REPLICATED
from ..reductions.summaries import FractionBelow, Summary
from ..reductions.targets import target_of

__all__ = ["parse_reductions", "check_reductions", "REDUCTIONS"]

REDUCTIONS = {"summary": Summary, "histogram": Histogram, "quantiles": Quantiles,
              "fraction_below": FractionBelow, "top_k": TopK}


def _of(where, value):
    return choice(where, "of", value, OUTPUTS)


def _q(where, value):
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        value = [value]
    return number_list(where, "q", value, 0.0, 1.0)


def _target(where, value):
    if not isinstance(value, dict):
        raise ConfigError(f"{where_prefix(where)}: target = {short(value)}: expected "
                          "{standard_error = ..., relative = ...}")
    return wrapped(where, lambda: target_of(dict(value)))


#: Each kind's keys and their checks (``by`` is checked apart: it needs the space).
KEYS = {
    "summary": {"of": _of, "target": _target},
    "fraction_below": {"of": _of, "threshold": lambda w, v: number(w, "threshold", v),
                       "target": _target},
    "top_k": {"of": _of, "k": lambda w, v: integer(w, "k", v, 1, MAX_TOP_K, size=True),
              "largest": lambda w, v: boolean(w, "largest", v)},
    "histogram": {"of": _of, "low": lambda w, v: number(w, "low", v),
                  "high": lambda w, v: number(w, "high", v),
                  "bins": lambda w, v: integer(w, "bins", v, 1, MAX_CELLS, size=True),
                  "log": lambda w, v: boolean(w, "log", v)},
    "quantiles": {"of": _of, "q": _q, "low": lambda w, v: number(w, "low", v, 0.0, low_open=True),
                  "high": lambda w, v: number(w, "high", v, 0.0, low_open=True),
                  "bins_per_decade": lambda w, v: integer(w, "bins_per_decade", v, 1, MAX_CELLS,
                                                              size=True),
                  "exact_up_to": lambda w, v: integer(w, "exact_up_to", v, 0,
                                                      MAX_EXACT_QUANTILE_POINTS, size=True),
                  "target": _target},
}
REQUIRED = {"fraction_below": ("threshold",), "histogram": ("low", "high")}


def _group_part(where: str, part):
    if isinstance(part, str):
        return part
    if not isinstance(part, dict):
        raise ConfigError(f"{where_prefix(where)}: by: {short(part)}: expected a name or "
                          "{parameter = ..., log_bins = [low, high, n]} or {parameter = ..., "
                          "edges = [...]}")
    take(part, where, required=("parameter",), optional=("log_bins", "edges"))
    if not isinstance(part["parameter"], str):
        raise ConfigError(f"{where_prefix(where)}: by: parameter = {short(part['parameter'])}: "
                          "expected a parameter name")
    if ("log_bins" in part) == ("edges" in part):
        raise ConfigError(f"{where_prefix(where)}: by: give log_bins = [low, high, n] or edges")
    if "edges" in part:
        edges = number_list(where, "edges", part["edges"], min_length=3)
        check_size(where, "a by part's bins", len(edges) - 1, MAX_GROUPS, 8)
        return wrapped(where, lambda: Binned(part["parameter"], edges))
    log_bins = part["log_bins"]
    if not isinstance(log_bins, list) or len(log_bins) != 3:
        raise ConfigError(f"{where_prefix(where)}: log_bins = {short(log_bins)}: expected "
                          "[low, high, n]")
    low = number(where, "log_bins low", log_bins[0], 0.0, low_open=True)
    high = number(where, "log_bins high", log_bins[1], low, low_open=True)
    count = log_bins[2]
    if isinstance(count, float) and count.is_integer() and count > MAX_GROUPS:
        count = int(count)
    if isinstance(count, int) and not isinstance(count, bool):
        check_size(where, "log_bins count", count, MAX_GROUPS, 8)
    count = integer(where, "log_bins n", count, 1, MAX_GROUPS)
    return Binned(part["parameter"], tuple(np.geomspace(low, high, count + 1)))


def _by(where: str, value):
    if isinstance(value, list):
        if len(value) > 16:
            raise ConfigError(f"{where_prefix(where)}: by = {short(value)}: expected at most 16 "
                              "parts")
        return tuple(_group_part(where, part) for part in value)
    return _group_part(where, value)


def _part_size(space, part) -> int:
    """Groups of one ``by`` part, from the space alone (1 for a part the space cannot group
    by: :func:`group_key` names it afterwards)."""
    if isinstance(part, Binned):
        return len(part.edges) - 1
    if part in space.discrete_axes:
        return len(space.axis_values(part))
    if part in space.design_table:
        return len(np.unique(space.design_table[part]))
    return 1


def _check_sizes(where: str, reduction, space, replicates: int) -> None:
    by = reduction.by
    parts = () if by is None else (by,) if isinstance(by, (str, Binned)) else tuple(by)
    groups = math.prod(_part_size(space, part) for part in parts)
    if isinstance(reduction, REPLICATED):  # folded per replicate
        groups *= replicates
    check_size(where, "groups (the cells of its by parts crossed)", groups, MAX_GROUPS, 64)
    if isinstance(reduction, Histogram):
        check_size(where, "groups x bins", groups * (reduction.bins + 2), MAX_CELLS, 16)
    if isinstance(reduction, Quantiles):
        slots = reduction.bin_layout.slots
        check_size(where, "groups x streamed histogram bins", groups * slots, MAX_CELLS, 16)


def _reduction(name: str, table):
    where = f"reductions.{name}"
    table = dict(table_of(where, table))
    kind = table.pop("kind", None)
    if kind not in REDUCTIONS:
        raise ConfigError(f"{where_prefix(where)}: kind = {short(kind)}: expected one of "
                          f"{', '.join(REDUCTIONS)}")
    checks = KEYS[kind]
    by_allowed = kind != "top_k"
    take(table, where, required=REQUIRED.get(kind, ()),
         optional=tuple(checks) + (("by",) if by_allowed else ()))
    arguments = {key: checks[key](where, value) for key, value in table.items() if key != "by"}
    if "by" in table:
        arguments["by"] = _by(where, table["by"])
    return wrapped(where, lambda: REDUCTIONS[kind](**arguments))


def parse_reductions(tables: dict) -> dict:
    """{name: reduction} of the ``[reductions]`` table; each name becomes a file name, so it
    is letters, digits, ``_``, ``-`` and ``.``."""
    reductions = {}
    for name, table in tables.items():
        file_name("reductions", "a reduction's name", name)
        reductions[name] = _reduction(name, table)
    return reductions


def check_reductions(reductions: dict, space, replicates: int = 1) -> None:
    """Refuse a reduction whose sizes on ``space`` (in ``replicates``, which multiply the
    groups of those folded per replicate) pass their bounds, or whose ``by`` the space cannot
    group by, before any group key is built for the scan."""
    for name, reduction in reductions.items():
        where = f"reductions.{name}"
        _check_sizes(where, reduction, space, replicates)
        wrapped(where, lambda: group_key(space, reduction.by))
