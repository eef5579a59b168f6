"""How much a rounding of the inputs may move an output: the condition numbers of T_MPE, f50 and
EPC at each point, by differences of the NumPy reference (docs/numerics.md), for tolerances
that follow each point's conditioning."""

from __future__ import annotations

import math
import warnings

import numpy as np

import epc_fast
from epc_fast import params

#: The outputs whose condition numbers are estimated.
OUTPUTS = ("t_mpe_s", "f50_cyc_per_mm", "epc")


def evaluate_quietly(**kwargs):
    """epc_fast.evaluate without the reference's overflow warnings."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # the reference's overflow warnings
        return epc_fast.evaluate(**kwargs)


def condition_numbers(points, h=1e-7):
    """kappa of T_MPE, f50 and EPC at each point: sum over the inputs of |d ln out / d ln x|.

    Differences of the reference over steps of h |x| either way, h times the distance to an
    open end of the domain where that is nearer (where the model is singular: a threshold
    near 1, a field angle near 90 deg) but never under 64 ulp of x, one way where the other
    leaves the domain (reflectance 1): the estimate is good to ~10%, plenty for a tolerance.
    inf where a step changes a status (the point sits on a boundary, where no tolerance is
    meaningful).
    """
    table = {p.name: p for p in params.PARAMETERS}
    base = evaluate_quietly(**points, backend="reference")
    kappa = {name: np.zeros(base.status.shape) for name in OUTPUTS}
    with np.errstate(all="ignore"):
        for name, value in points.items():
            if name == "full_well_e":  # only decides a status
                continue
            param = table["size" if name in params.SIZE_PARAMETERS else name]
            scale = np.abs(value)
            for end, closed in ((param.lo, param.lo_closed), (param.hi, param.hi_closed)):
                if not closed and math.isfinite(end):
                    scale = np.minimum(scale, np.abs(value - end))
            delta = np.maximum(h * scale, 64 * np.spacing(np.abs(value)))  # >= 64 ulp of x
            steps = [np.where(params.in_domain(param, value + sign * delta),
                              value + sign * delta, value) for sign in (1.0, -1.0)]
            up = evaluate_quietly(**{**points, name: steps[0]}, backend="reference")
            down = evaluate_quietly(**{**points, name: steps[1]}, backend="reference")
            flips = (up.status != base.status) | (down.status != base.status)
            for out in OUTPUTS:
                slope = (np.abs(np.log(getattr(up, out)) - np.log(getattr(down, out)))
                         / np.abs(np.log(np.abs(steps[0])) - np.log(np.abs(steps[1]))))
                slope = np.where(np.isfinite(slope), slope, 0.0)  # 0/0: an input at 0
                kappa[out] += np.where(flips, np.inf, slope)
    return kappa
