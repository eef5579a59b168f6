"""Global sensitivity over a space: Sobol' first- and total-order indices of EPC or log EPC.

SALib (the ``sensitivity`` extra) lays out Saltelli's design on a scrambled Sobol' sequence in
the unit hypercube, one coordinate per random parameter, and estimates the indices and their
bootstrap confidence intervals from the outputs; the core evaluates the model at every point.

- **Coordinates to values.** A random parameter's value at coordinate u is its distribution's
  inverse CDF at u (``from_uniform``, the same function a scan draws with), for every
  distribution of :mod:`epc_fast.scan.sampling.distributions`. A :class:`Choice` takes value index
  ``indices_from_uniform(u)`` (its weights respected); a :class:`Grid` on a parameter is a
  random input whose values are equally likely, as a scan visits each equally often. A
  discrete parameter's indices are those of u, exactly: the output depends on u only through
  the parameter's value.
- **Designs.** The indices are computed per design of the space's design axis (grid or
  choice), on the same points for every design: how each parameter drives EPC for that
  design. The design is never an input of the analysis.
- **Points that are not OK.** An out-of-domain value (a distribution reaching below a
  parameter's domain) raises, naming the parameter and value. Points that cannot meet the SNR
  target (EPC NaN) raise unless ``not_ok="zero"`` counts them as 0 effective pixels, which
  only EPC itself can take (the log of 0 is -inf). A blur that is unbounded gives EPC = 0 in
  the model: a value for EPC, a -inf for log EPC, which raises. The result counts both kinds.
"""

from __future__ import annotations

import operator
import warnings

import numpy as np

from ...api import evaluate
from ...params import PARAMETER_NAMES, PARAMETERS, SIZE_PARAMETERS, in_domain
from ...status import Cause, Status
from ..sampling.distributions import Choice, Grid
from .result import SobolResult
from ..running.readout_modes import readout_kwargs
from ..sampling.space import Space

__all__ = ["sobol_indices", "random_parameters", "unit_design", "design_inputs", "OUTPUTS",
           "NOT_OK_POLICIES", "MIN_POINTS", "MAX_BOOTSTRAP_VALUES", "MAX_DESIGN_VALUES",
           "design_rows"]

#: The outputs whose indices can be asked for: EPC (pixels) and its natural log.
OUTPUTS = ("epc", "log_epc")
#: What to do with points whose EPC is NaN because the SNR target is unreachable.
NOT_OK_POLICIES = ("raise", "zero")
#: Fewest base points: fewer leave the bootstrap too few points to resample.
MIN_POINTS = 16
#: Most base points x bootstrap resamples: SALib's bootstrap holds several arrays of that many
#: float64 and int64 values at once, 64 MB each at this bound.
MAX_BOOTSTRAP_VALUES = 1 << 23
#: Most values of the design's inputs (rows x random parameters): 256 MB of float64 a copy.
MAX_DESIGN_VALUES = 1 << 25
#: The design's coordinates are multiples of 2^-30 in [0, 1) (SciPy's Sobol' sequence, 30 bits);
#: half a step moves each to the middle of its cell, inside (0, 1), where every inverse CDF is
#: finite.
HALF_STEP = 2.0**-31


def _salib():
    """SALib's Sobol' sampler and analyser, imported here only: the ``sensitivity`` extra."""
    try:
        from SALib.analyze import sobol as analyze
        from SALib.sample import sobol as sample
    except ImportError:
        raise ImportError("Sobol' indices need SALib: pip install 'epc-fast[sensitivity]'"
                          ) from None
    return sample, analyze


def random_parameters(space: Space) -> tuple[str, ...]:
    """The inputs of the analysis: every parameter of ``space`` that is drawn (a
    distribution or a :class:`Choice`) or on a :class:`Grid`, in the space's order; the
    design axis is not one of them."""
    return tuple(name for name, axis in space.axes.items()
                 if name != "design" and not isinstance(axis, float))


def design_rows(points: int, parameters: int, second_order: bool = False) -> int:
    """Rows (model evaluations per design) of Saltelli's design: N (D + 2), or N (2 D + 2) with
    second-order indices."""
    return points * ((2 * parameters if second_order else parameters) + 2)


def unit_design(parameters: tuple, points: int, seed: int,
                second_order: bool = False) -> np.ndarray:
    """Saltelli's design in (0, 1)^D: SALib's ``sample.sobol`` (scrambled Sobol' sequence,
    seeded with ``seed``) moved half a step to the middle of each cell.

    Returns
    -------
    float64 array of shape (points (D + 2), D), or (points (2 D + 2), D) with
    ``second_order``; D = len(parameters), one column per parameter, in (0, 1).
    """
    sample, _ = _salib()
    problem = {"num_vars": len(parameters), "names": list(parameters),
               "bounds": [[0.0, 1.0]] * len(parameters)}
    return sample.sample(problem, points, calc_second_order=second_order, seed=seed) + HALF_STEP


def design_inputs(space: Space, parameters: tuple, unit: np.ndarray) -> dict:
    """{name: float64 array}: each random parameter's values at the design's coordinates
    ``unit`` (column j for ``parameters[j]``), in the parameter's unit."""
    inputs = {}
    for name, u in zip(parameters, unit.T):
        axis = space.axes[name]
        if isinstance(axis, (Grid, Choice)):
            choice = axis if isinstance(axis, Choice) else Choice(axis.values)
            inputs[name] = np.asarray(axis.values, dtype=np.float64)[
                choice.indices_from_uniform(u)]
        else:
            inputs[name] = axis.from_uniform(u)
    return inputs


def _design_values(space: Space, design: int) -> dict:
    """The fixed parameters of one design: the space's numbers and the design's parameters."""
    values = {name: axis for name, axis in space.axes.items() if isinstance(axis, float)}
    values.update({name: float(column[design]) for name, column in space.design_table.items()})
    return values


def _checked(points, seed, of, confidence, resamples, not_ok) -> tuple:
    count = operator.index(points) if isinstance(points, (int, np.integer)) else None
    if count is None or count < MIN_POINTS or count & (count - 1):
        raise ValueError(f"points must be a power of 2, at least {MIN_POINTS} (Saltelli's design "
                         f"on a Sobol' sequence), got {points!r}")
    if not isinstance(seed, (int, np.integer)) or isinstance(seed, bool) \
            or not 0 <= seed < 2**64:
        raise ValueError(f"seed must be an integer in [0, 2**64), got {seed!r}")
    outputs = (of,) if isinstance(of, str) else tuple(of) if isinstance(of, (tuple, list)) else ()
    if (not outputs or not all(isinstance(o, str) for o in outputs)
            or len(set(outputs)) != len(outputs) or not set(outputs) <= set(OUTPUTS)):
        raise ValueError(f"of must be one of {', '.join(map(repr, OUTPUTS))} or a sequence of "
                         f"them, got {of!r}")
    if isinstance(confidence, bool) or not isinstance(confidence, (int, float)) \
            or not 0.0 < confidence < 1.0:
        raise ValueError(f"confidence must be a number in (0, 1), got {confidence!r}")
    if not isinstance(resamples, (int, np.integer)) or isinstance(resamples, bool) \
            or resamples < 2:
        raise ValueError(f"resamples must be an integer >= 2, got {resamples!r}")
    if count * resamples > MAX_BOOTSTRAP_VALUES:
        raise ValueError(f"points x resamples = {count:,} x {resamples:,} exceeds "
                         f"{MAX_BOOTSTRAP_VALUES:,}, the bootstrap's memory bound (~64 MB an "
                         "array): use fewer points or resamples")
    if not_ok not in NOT_OK_POLICIES:
        raise ValueError(f"not_ok must be one of {', '.join(map(repr, NOT_OK_POLICIES))}, got "
                         f"{not_ok!r}")
    if not_ok == "zero" and "log_epc" in outputs:
        raise ValueError("not_ok='zero' counts unreachable points as EPC 0, whose log is -inf: "
                         f"it cannot go with of={of!r}; use of='epc', or not_ok='raise'")
    return count, int(seed), outputs, float(confidence), int(resamples)


def _evaluated_epc(space: Space, design: int, inputs: dict, not_ok: str, threads,
                   label: str) -> tuple[np.ndarray, int, int]:
    """EPC (pixels) at every point of one design, with the unreachable points as the policy
    says, and the counts of unreachable and blur-unbounded points."""
    values = {**_design_values(space, design), **inputs}
    readout = {}
    if space.has_modes:  # the best of the design's modes per point
        readout, set_by_modes = readout_kwargs(space.design_readout[design],
                                               space.design_modes[design])
        values = {k: v for k, v in values.items() if k not in set_by_modes}
    result = evaluate(**values, threads=threads, outputs=("epc", "status", "cause"),
                      **readout, **space.evaluate_options)
    epc = np.asarray(result.epc, dtype=np.float64)
    status = np.asarray(result.status)
    if (status == Status.INVALID).any():
        raise ValueError(f"Sobol' indices{label}: {_outside_domain(values)}")
    # a frame the camera cannot take (a frame cap, EXPOSURE_LIMIT, cause NONE) is no image too
    unreachable = (status == Status.UNREACHABLE) | (status == Status.EXPOSURE_LIMIT)
    count = int(unreachable.sum())
    if count and not_ok == "raise":
        causes = np.unique(np.asarray(result.cause)[unreachable])
        names = ", ".join(Cause(c).name.lower().replace("_", " ") if c else "the frame cap"
                          for c in causes)
        raise ValueError(f"Sobol' indices{label}: {count:,} of {epc.size:,} points cannot meet "
                         f"the SNR target ({names}), where EPC is NaN; narrow the space (e.g. "
                         "truncate the distribution that reaches them) or pass not_ok='zero' "
                         "to count them as 0 effective pixels")
    if count:
        epc = np.where(unreachable, 0.0, epc)
    return epc, count, int((status == Status.BLUR_UNBOUNDED).sum())


def _outside_domain(values: dict) -> str:
    """Which parameter has a value outside its domain, and the value."""
    for name, value in values.items():
        param = PARAMETERS[PARAMETER_NAMES.index("size" if name in SIZE_PARAMETERS else name)]
        outside = ~in_domain(param, value)
        if outside.any():
            first = float(np.broadcast_to(value, outside.shape)[np.argmax(outside)])
            return (f"{name}={first!r} is outside its domain {param.domain_text()} "
                    f"({param.meaning}) at {int(outside.sum()):,} of the design's points; "
                    + ("truncate its distribution" if np.ndim(value) else "change its value"))
    return "a point is INVALID though each parameter is inside its domain"


def _output(epc: np.ndarray, of: str, label: str) -> np.ndarray:
    """The analysed output: EPC, or its natural log (refusing EPC = 0, whose log is -inf)."""
    if of == "epc":
        values = epc
    else:
        zeros = int(np.count_nonzero(epc == 0.0))
        if zeros:
            raise ValueError(f"Sobol' indices{label}: {zeros:,} points have EPC = 0 (the blur "
                             "is unbounded: the shake angle during the exposure reaches 90 "
                             "deg), whose log is -inf; use of='epc', or narrow the space")
        values = np.log(epc)
    if np.ptp(values) == 0.0:
        raise ValueError(f"Sobol' indices{label}: {of} is {values[0]!r} at every point; there "
                         "is no variance to apportion")
    return values


def _analysed(analyze, parameters, y, second_order, resamples, confidence, seed) -> dict:
    problem = {"num_vars": len(parameters), "names": list(parameters),
               "bounds": [[0.0, 1.0]] * len(parameters)}
    with warnings.catch_warnings():
        # A parameter the output ignores has a constant bootstrap: its interval is 0 wide, and
        # NumPy warns of the degrees of freedom of a standard deviation of equal values.
        warnings.simplefilter("ignore", RuntimeWarning)
        # SALib takes a seed of 0 as "no seed" (global state): seed + 1 is never 0.
        return analyze.analyze(problem, y, calc_second_order=second_order,
                               num_resamples=resamples, conf_level=confidence, seed=seed + 1)


def sobol_indices(space: Space, points: int = 4096, *, seed: int = 0, of="epc",
                  confidence: float = 0.95, resamples: int = 100, not_ok: str = "raise",
                  second_order: bool = False, threads: int | None = None) -> SobolResult:
    """First- and total-order Sobol' indices of EPC (or log EPC) for each random parameter of
    ``space``, per design, with bootstrap confidence intervals (needs SALib: the
    ``sensitivity`` extra).

    S1 is the fraction of the output's variance a parameter explains alone (by which the
    variance drops, on average, once it is known), ST the fraction it explains with all its
    interactions (the variance left, on average, once every other parameter is known): one with
    ST near 0 can be fixed at any of its values without changing the spread. The module
    docstring (:mod:`epc_fast.scan.indices`) says how coordinates become values, what a design and
    a discrete parameter mean, and what happens at points that are not OK.

    Parameters
    ----------
    space : Space
        At least one parameter drawn or on a grid (the design axis does not count).
    points : int
        Base points N of Saltelli's design, a power of 2 >= 16. Each design costs N (D + 2)
        model evaluations (N (2 D + 2) with ``second_order``), D the random parameters.
    seed : int in [0, 2**64)
        Seeds the design's scrambling and the bootstrap: the same seed, the same numbers.
    of : {"epc", "log_epc"} or a sequence of both
        The output: EPC in pixels, or its natural log (the indices of log EPC do not depend on
        the log's base). Both come from the same evaluations.
    confidence : 1, in (0, 1)
        Level of the confidence intervals.
    resamples : int >= 2
        Bootstrap resamples; points x resamples is at most :data:`MAX_BOOTSTRAP_VALUES`.
    not_ok : {"raise", "zero"}
        Points whose SNR target is unreachable (EPC NaN): raise a ValueError (the default), or
        count them as 0 effective pixels (``of="epc"`` only).
    second_order : bool
        Also estimate the second-order indices S2 (each pair of parameters).
    threads : int, optional
        Core threads; default ``OMP_NUM_THREADS`` or every core.

    Returns
    -------
    SobolResult
    """
    count, seed, outputs, confidence, resamples = _checked(points, seed, of, confidence,
                                                           resamples, not_ok)
    if not isinstance(space, Space):
        raise TypeError(f"space must be an epc_fast.scan.Space, got {space!r}")
    parameters = random_parameters(space)
    if not parameters:
        raise ValueError("the space has no random parameter (a distribution, a Choice or a "
                         "Grid besides the design axis): there is nothing to apportion")
    values = design_rows(count, len(parameters), second_order) * len(parameters)
    if values > MAX_DESIGN_VALUES:
        raise ValueError(f"points={count:,} with {len(parameters)} random parameters makes a "
                         f"design of {values:,} values, more than {MAX_DESIGN_VALUES:,} (256 MB):"
                         " use fewer points")
    _, analyze = _salib()
    inputs = design_inputs(space, parameters, unit_design(parameters, count, seed, second_order))
    designs = space.design_names or ("",)
    shape = (len(outputs), len(designs), len(parameters))
    arrays = {key: np.full(shape, np.nan) for key in ("S1", "S1_conf", "ST", "ST_conf")}
    pairs = {key: np.full(shape + (len(parameters),), np.nan) for key in ("S2", "S2_conf")}
    moments = np.full((2,) + shape[:2], np.nan)
    unreachable = np.zeros(len(designs), dtype=np.int64)
    blur_unbounded = np.zeros(len(designs), dtype=np.int64)
    for d, design in enumerate(designs):
        label = f" of design {design!r}" if design else ""
        epc, unreachable[d], blur_unbounded[d] = _evaluated_epc(space, d, inputs, not_ok,
                                                                threads, label)
        for o, output in enumerate(outputs):
            y = _output(epc, output, label)
            moments[:, o, d] = y.mean(), y.std()
            found = _analysed(analyze, parameters, y, second_order, resamples, confidence, seed)
            for key, values in arrays.items():
                values[o, d] = found[key]
            if second_order:
                for key, values in pairs.items():
                    values[o, d] = found[key]
    evaluations = design_rows(count, len(parameters), second_order)
    return SobolResult(outputs, designs, parameters, count, evaluations, seed, confidence,
                       not_ok, arrays["S1"], arrays["S1_conf"], arrays["ST"], arrays["ST_conf"],
                       pairs["S2"] if second_order else None,
                       pairs["S2_conf"] if second_order else None, moments[0], moments[1],
                       unreachable, blur_unbounded)
