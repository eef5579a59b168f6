"""A scan parameter's values against its domain (:mod:`epc_fast.params`): a fixed value, every
value of a grid, a choice or an empirical distribution, a distribution's bounds and the
probability that it draws inside; ``binning``, ``frames`` and ``lens`` take whole numbers only,
``lens`` those below the space's number of lens tables."""

from __future__ import annotations

import math

import numpy as np

from ...params import SIZE_PARAMETERS, in_domain, parameters
from .distributions import (MIN_TRUNCATED_PROBABILITY, Choice, Empirical, Grid, LogNormal,
                            LogUniform, Truncated, Uniform)

__all__ = ["domain_problem", "domain_of", "inside_probability"]


def domain_of(name: str, lens_count: int = 1):
    """The :class:`~epc_fast.params.Param` of a point parameter (the size slot for
    ``pixel_count`` and ``sensor_area_mm2``), with ``lens_count`` lens tables."""
    slot = "size" if name in SIZE_PARAMETERS else name
    return next(p for p in parameters(lens_count) if p.name == slot)


def _expected(name: str, what: str = "a value", lens_count: int = 1) -> str:
    """``"expected <what> in <domain> (<unit>, <meaning>)"`` of point parameter ``name``."""
    param = domain_of(name, lens_count)
    if name in SIZE_PARAMETERS:
        unit, meaning = ("pixels", "pixel count") if name == "pixel_count" else \
            ("mm^2", "sensor area")
    else:
        unit, meaning = param.meaning.split(": ", 1)
    return f"expected {what} in {param.domain_text()} ({unit}: {meaning})"


def _outside(param, values) -> list:
    values = np.asarray(values, dtype=np.float64).reshape(-1)
    return [float(v) for v in values[~in_domain(param, values)]]


def _inside_closure(param, value: float) -> bool:
    return param.lo <= value <= param.hi


def domain_problem(name: str, axis, lens_count: int = 1):
    """What is wrong with parameter ``name`` set to ``axis`` (a number, a :class:`Grid`, a
    :class:`Choice` or a distribution) against its domain (:mod:`epc_fast.params`, with
    ``lens_count`` lens tables), as ``"<value>: expected ..."``; None when nothing is.

    A number, and every value of a grid, a choice or an empirical distribution, is drawn as
    it is, so each must lie in the domain. A uniform or log-uniform distribution's bounds, and
    a truncation's finite bounds, must lie in the domain or on its ends (draws never reach an
    open end). A distribution whose draws fall in the domain with a probability below
    :data:`~epc_fast.scan.sampling.distributions.MIN_TRUNCATED_PROBABILITY` is refused (its points
    would all be INVALID); one whose tail only reaches outside keeps its draws there, which are
    INVALID points, counted as such (``truncate`` avoids them).
    """
    param = domain_of(name, lens_count)

    def expected(what="a value"):
        return _expected(name, what, lens_count)

    if isinstance(axis, (Grid, Choice)):
        bad = _outside(param, axis.values)
        kind = "grid" if isinstance(axis, Grid) else "choice"
        return (None if not bad else
                f"{kind} value {bad[0]:g}: {expected('every value')}")
    if isinstance(axis, (int, float)) and not isinstance(axis, bool):
        return None if in_domain(param, axis) else f"{float(axis):g}: {expected()}"
    parent = axis.distribution if isinstance(axis, Truncated) else axis
    if param.integer and not isinstance(parent, Empirical):
        # a continuous distribution draws whole numbers with probability 0
        return (f"{axis!r}: {expected('whole numbers')}; draw them with "
                f"{{grid = [...]}}, {{choice = [...]}} or an empirical distribution")
    if isinstance(parent, Empirical):
        bad = _outside(param, parent.samples if parent is axis else
                       parent.samples[(parent.samples >= axis.low)
                                      & (parent.samples <= axis.high)])
        if bad:
            return f"empirical sample {bad[0]:g}: {expected('every sample')}"
        return None
    # The support's ends, and whether the user wrote each (a bound or a truncation).
    if isinstance(parent, (Uniform, LogUniform)):
        (low, low_given), (high, high_given) = (parent.low, True), (parent.high, True)
    else:
        low, low_given = (0.0 if isinstance(parent, LogNormal) else -math.inf), False
        high, high_given = math.inf, False
    if isinstance(axis, Truncated):
        if axis.low > low:
            low, low_given = axis.low, True
        if axis.high < high:
            high, high_given = axis.high, True
    bad = [v for v, given in ((low, low_given), (high, high_given))
           if given and not _inside_closure(param, v)]
    if bad:
        return f"{axis!r} reaches {bad[0]:g}: {expected('its bounds')}"
    inside = inside_probability(name, axis)
    if inside < MIN_TRUNCATED_PROBABILITY:
        return (f"{axis!r} draws in the domain with a probability of {inside:.2g}: "
                f"{expected('draws')}")
    return None


def inside_probability(name: str, axis) -> float:
    """1: the probability that a distribution's draw of parameter ``name`` falls inside its
    domain; 1 for a number, a grid, a choice and an empirical distribution, whose values are
    checked one by one."""
    param = domain_of(name)
    parent = axis.distribution if isinstance(axis, Truncated) else axis
    if not hasattr(parent, "probability_within") or isinstance(parent, Empirical):
        return 1.0
    low, high = (max(param.lo, axis.low), min(param.hi, axis.high)) \
        if isinstance(axis, Truncated) else (param.lo, param.hi)
    inside = parent.probability_within(low, high) / getattr(axis, "probability", 1.0) \
        if low < high else 0.0
    return min(max(inside, 0.0), 1.0)
