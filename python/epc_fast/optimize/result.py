"""What :mod:`epc_fast.optimize` returns: the objective at a candidate (:class:`Estimate`),
along a parameter (:class:`Curve`), and at the optimum with its uncertainty (:class:`Optimum`),
with the optimum as a JSON-ready dict and a Markdown table."""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, fields, is_dataclass

import numpy as np

__all__ = ["Estimate", "Curve", "Optimum"]


@dataclass(frozen=True)
class Estimate:
    """The objective at one candidate.

    Attributes
    ----------
    value : the objective's unit (pixels, or 1 for a probability).
    standard_error : the same unit, its Monte Carlo standard error (0 for a space without
        random parameters: the value is exact).
    not_ok_fraction : 1, the fraction of draws whose status is not OK (unreachable SNR target
        or unbounded blur), each counted as 0 pixels.
    """

    value: float
    standard_error: float
    not_ok_fraction: float


@dataclass(frozen=True)
class Curve:
    """The objective along one optimised parameter, the others held at ``at``.

    Attributes
    ----------
    parameter : str, the parameter's name (with its unit).
    values : float64 array, the parameter's values (its unit).
    objective, standard_error : float64 arrays, the objective and its Monte Carlo standard
        error at each value (the objective's unit).
    at : {name: value}, the other optimised parameters.
    """

    parameter: str
    values: np.ndarray
    objective: np.ndarray
    standard_error: np.ndarray
    at: dict


@dataclass(frozen=True)
class Optimum:
    """The maximum of an objective over the optimised parameters, with its uncertainty.

    Attributes
    ----------
    x : {name: value}, the optimum, each parameter in its unit.
    x_standard_error : {name: value}, each parameter's Monte Carlo standard error, in its unit,
        from batch means: the spread of the optima of ``batches`` disjoint batches of the
        draws over sqrt(batches) (NaN without batches; 0 for a space without random
        parameters).
    batch_x : {name: tuple}, the optimum of each batch, in the parameter's unit.
    value : the objective at ``x`` over every draw (pixels, or 1 for a probability).
    value_standard_error : the same unit, its Monte Carlo standard error at ``x``.
    not_ok_fraction : 1, the fraction of draws not OK at ``x`` (counted as 0 pixels).
    at_bound : {name: bool}, whether the optimum is within ``xtol`` of a bound (then the
        bound, not the objective, stops it, and the batch spread understates the uncertainty).
    objective : Mean, Quantile or ProbabilityAtLeast.
    unit : str, the objective's unit: ``"pixels"`` or ``"1"``.
    bounds : {name: (low, high)}, in each parameter's unit.
    held : str, what stays fixed of the sensor (the pixel count or the area).
    points, seed, batches : int, the draws, their seed, the batches.
    evaluations : int, candidates evaluated on all the draws (the batches' not counted).
    batch_evaluations : int, candidates evaluated on one batch, over every batch.
    wall_s : s, the search's time, the batches' included (the scene's draws not
        counted: :attr:`Problem.draw_s`).
    """

    x: dict
    x_standard_error: dict
    batch_x: dict
    value: float
    value_standard_error: float
    not_ok_fraction: float
    at_bound: dict
    objective: object
    unit: str
    bounds: dict
    held: str
    points: int
    seed: int
    batches: int
    evaluations: int
    batch_evaluations: int
    wall_s: float

    def as_dict(self) -> dict:
        """Every field as JSON-ready values (the objective as its kind and arguments, NaN as
        None)."""
        def plain(value):
            if is_dataclass(value):
                return {"kind": type(value).__name__, **asdict(value), "label": value.label}
            if isinstance(value, dict):
                return {k: plain(v) for k, v in value.items()}
            if isinstance(value, (tuple, list, np.ndarray)):
                return [plain(v) for v in value]
            if isinstance(value, (float, np.floating)):
                return None if math.isnan(value) else float(value)
            if isinstance(value, np.integer):
                return int(value)
            return value
        return {f.name: plain(getattr(self, f.name)) for f in fields(self)}

    def markdown(self) -> str:
        """The optimum as a Markdown table: one row per parameter, then the objective."""
        rows = ["| quantity | optimum | standard error | bounds |", "|---|---|---|---|"]
        for name, value in self.x.items():
            low, high = self.bounds[name]
            mark = " (at a bound)" if self.at_bound[name] else ""
            rows.append(f"| {name} | {value:.6g}{mark} | {self.x_standard_error[name]:.2g} | "
                        f"[{low:g}, {high:g}] |")
        label = f"{self.objective.label} ({self.unit})"
        rows.append(f"| {label} | {self.value:,.6g} | {self.value_standard_error:.2g} | |")
        rows.append(f"| draws not OK (counted as 0 pixels) | {self.not_ok_fraction:.4g} | | |")
        return "\n".join(rows)
