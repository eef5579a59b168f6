"""Standard errors from replicates, and the stopping rules that read them.

A scan in ``R`` replicates (:mod:`epc_fast.scan.sampling.qmc`) folds each of its summaries,
fractions below and quantiles per replicate and group (the replicate is the key's first part,
:func:`epc_fast.scan.reductions.groups.replicated`). :func:`finish` pools the replicates' states
into the reduction's own (its estimate is the statistic of every point, as with one replicate) and
gives each statistic the standard error of the replicates' spread,
``std(estimate_r, ddof=1) / sqrt(R)``: the ``R`` replicates are independent randomisations of
the same kind of sample, so their spread measures the error under Sobol' sampling, whose error
no variance formula gives. Under Monte Carlo the mean's and the fraction's standard errors are
their variances' (``std / sqrt(count)``, ``sqrt(p (1 - p) / count)``), the quantiles' in one
replicate the order statistics'
(:func:`~epc_fast.scan.reductions.histograms.finish_with_order_statistics`), the std's and, with
replicates, the quantiles' the replicates'.

A reduction's ``target`` (:class:`Target`) holds when, in every group, each of its statistics
(a summary's mean, a fraction, every quantile) has a standard error within the target.

A scan that may stop early gives the numbers of a scan of the points where it stopped: quantiles
streamed at the cap (more than ``exact_up_to`` points) but exact at an earlier stopping point
are also kept exactly (:func:`exact_companions`) until the scan passes ``exact_up_to`` points,
and :func:`finish_plan` gives them exact while it has not.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from .histograms import Quantiles, QuantilesResult, finish_with_order_statistics
from .summaries import FractionBelow, FractionBelowResult, Summary, SummaryResult, Moments
from .targets import Target, target_of

__all__ = ["Target", "target_of", "finish", "unmet_targets", "REPLICATED", "exact_companions",
           "stage_plan", "finish_plan"]

#: The reductions folded per replicate: those whose statistics take a standard error.
REPLICATED = (Summary, FractionBelow, Quantiles)


# -- pooling the replicates' states ------------------------------------------------------------

def _pool_summary(state: dict, r: int, g: int) -> dict:
    moments = state["moments"]
    pooled = Moments(np.zeros(g, np.int64), np.zeros(g), np.zeros(g))
    for k in range(r):
        rows = slice(k * g, (k + 1) * g)
        pooled.add(moments.count[rows], moments.mean[rows], moments.m2[rows])
    result = {"status": state["status"].reshape(r, g, -1).sum(axis=0), "moments": pooled,
              "min": state["min"].reshape(r, g).min(axis=0),
              "max": state["max"].reshape(r, g).max(axis=0)}
    if "modes" in state:
        result["modes"] = state["modes"].reshape(r, g, -1).sum(axis=0)
    return result


def _pool_quantiles(state: dict, r: int, g: int) -> dict:
    if state["exact"]:
        return {"exact": True, "values": list(state["values"]),
                "groups": [groups % g for groups in state["groups"]]}
    return {"exact": False, "counts": state["counts"].reshape(r, g, -1).sum(axis=0),
            "min": state["min"].reshape(r, g).min(axis=0),
            "max": state["max"].reshape(r, g).max(axis=0)}


def _pool(reduction, state: dict, r: int, g: int) -> dict:
    if isinstance(reduction, Summary):
        return _pool_summary(state, r, g)
    if isinstance(reduction, FractionBelow):
        return {name: state[name].reshape(r, g).sum(axis=0) for name in ("count", "below")}
    return _pool_quantiles(state, r, g)


# -- standard errors ---------------------------------------------------------------------------

def _spread(per_replicate: np.ndarray) -> np.ndarray:
    """The standard error of the mean of the replicates' estimates (axis 0): NaN where a
    replicate has none (an empty group)."""
    r = per_replicate.shape[0]
    with np.errstate(invalid="ignore"):
        return np.std(per_replicate, axis=0, ddof=1) / math.sqrt(r)


def finish(item, state: dict, space):
    """The result of a plan item's reduction over its state: pooled over the replicates, with
    the standard errors (:mod:`epc_fast.scan.reductions.replicates`); the state is left as it
    was."""
    reduction, key, base = item.reduction, item.key, item.base_key
    if base is None or key is base:
        return _one_replicate(reduction, state, key, space)
    r, g = key.size // base.size, base.size
    result = reduction.finish(_pool(reduction, state, r, g), base, space)
    per = reduction.finish(state, key, space)
    sobol = space.sampling.sobol
    if isinstance(result, SummaryResult):
        result = _with_variance_errors(result, space)
        mean_error = _spread(per.mean.reshape(r, g)) if sobol else result.mean_error
        return replace(result, mean_error=mean_error, std_error=_spread(per.std.reshape(r, g)))
    if isinstance(result, FractionBelowResult):
        if sobol:
            result = replace(result, standard_error=_spread(per.fraction.reshape(r, g)))
        return result
    if isinstance(result, QuantilesResult):
        return replace(result, standard_error=_spread(per.estimate.reshape(r, g, -1)))
    return result


def _one_replicate(reduction, state: dict, key, space):
    """A result in one replicate: under Monte Carlo the mean's, the fraction's and the
    quantiles' errors from their own formulas; under Sobol' sampling NaN (no formula gives
    them)."""
    sobol = space.sampling.sobol
    if isinstance(reduction, Quantiles) and not sobol:
        return finish_with_order_statistics(reduction, state, key)
    result = reduction.finish(state, key, space)
    if isinstance(result, SummaryResult):
        return _with_variance_errors(result, space)
    if isinstance(result, FractionBelowResult) and sobol:
        return replace(result, standard_error=np.full(result.fraction.shape, np.nan))
    if isinstance(result, QuantilesResult):
        return replace(result, standard_error=np.full(result.estimate.shape, np.nan))
    return result


def _with_variance_errors(result: SummaryResult, space) -> SummaryResult:
    """A Monte Carlo summary's mean error std / sqrt(count); NaN under Sobol' sampling in one
    replicate (no formula gives it)."""
    if space.sampling.sobol:
        return replace(result, mean_error=np.full(result.mean.shape, np.nan))
    with np.errstate(invalid="ignore", divide="ignore"):
        error = result.std / np.sqrt(result.count)
    return replace(result, mean_error=np.where(result.count > 0, error, np.nan))


# -- exact quantiles of a scan that stops early -------------------------------------------------

def _companion_name(name: str) -> str:
    return f"{name}\0exact"


def exact_companions(plan: tuple, stages: list, points: int) -> tuple:
    """The plan items that keep exactly the values of each Quantiles streamed at the cap
    (``points`` above its ``exact_up_to``) that a scan stopping at one of ``stages`` would
    have exact: the same reduction, exact up to ``points``, under a name of its own."""
    companions = []
    for item in plan:
        reduction = item.reduction
        if (isinstance(reduction, Quantiles) and reduction.exact_up_to < points
                and stages[0] <= reduction.exact_up_to):
            companions.append(replace(item, name=_companion_name(item.name),
                                      reduction=replace(reduction, exact_up_to=points)))
    return tuple(companions)


def stage_plan(plan: tuple, companions: tuple, stage: int, states: dict) -> tuple:
    """The plan items of the scan's points up to ``stage``: ``plan`` and the companions of the
    quantiles still exact at ``stage`` points; the states of the others are dropped."""
    limits = {_companion_name(item.name): item.reduction.exact_up_to for item in plan
              if isinstance(item.reduction, Quantiles)}
    kept = []
    for companion in companions:
        if stage <= limits[companion.name]:
            kept.append(companion)
        else:
            states.pop(companion.name, None)
    return plan + tuple(kept) if kept else plan


def finish_plan(plan: tuple, companions: tuple, states: dict, space,
                targeted: bool = False) -> dict:
    """{name: result} of each item of ``plan`` (``targeted``: of each with a target, all
    :func:`unmet_targets` reads); a Quantiles from its exact companion while its state is
    kept."""
    exact = {companion.name: companion for companion in companions
             if companion.name in states}
    results = {}
    for item in plan:
        if targeted and getattr(item.reduction, "target", None) is None:
            continue
        companion = exact.get(_companion_name(item.name))
        if companion is None:
            results[item.name] = finish(item, states[item.name], space)
        else:
            results[item.name] = finish(companion, states[companion.name], space)
    return results


# -- stopping rules ----------------------------------------------------------------------------

def _statistics(result) -> list[tuple[str, np.ndarray, np.ndarray]]:
    """(name, estimate, standard error) of each statistic a target bounds, per group."""
    if isinstance(result, SummaryResult):
        return [("mean", result.mean, result.mean_error)]
    if isinstance(result, FractionBelowResult):
        return [(result.name, result.fraction, result.standard_error)]
    error = result.standard_error
    if error is None:
        error = np.full(result.estimate.shape, np.nan)
    return [(f"q{100 * q:g}", result.estimate[:, i], error[:, i]) for i, q in enumerate(result.q)]


def _label(result, group: int) -> str:
    labels = getattr(result, "labels", {})
    return ", ".join(f"{name}={values[group]}" for name, values in labels.items())


def unmet_targets(plan: tuple, results: dict) -> list[str]:
    """One line per reduction whose target does not hold: the statistic, its worst group's
    standard error and the target; empty when every target holds."""
    lines = []
    for item in plan:
        target = getattr(item.reduction, "target", None)
        if target is None:
            continue
        result = results[item.name]
        for name, estimate, error in _statistics(result):
            holds = target.holds(estimate, error)
            if holds.all():
                continue
            worst = int(np.argmin(holds))  # the first group where it fails
            where = _label(result, worst)
            lines.append(f"{item.name}: {name}{' (' + where + ')' if where else ''} has "
                         f"standard error {error[worst]:.4g} (estimate {estimate[worst]:.6g}), "
                         f"target {target}")
            break
    return lines
