"""The checks of an optimisation's arguments: the bounds against the space, the objective,
the point count and the search's settings; each error names the argument and its value."""

from __future__ import annotations

import math

from .._validation import integer, threads_of
from ..params import PARAMETERS, SIZE_PARAMETERS, in_domain
from ..scan.sampling.space import POINT_PARAMETERS, Space
from .objectives import Mean, ProbabilityAtLeast, Quantile

__all__ = ["checked_bounds", "whole_numbers_only", "checked_objective", "checked_points", "checked_search",
           "checked_threads", "unit_of", "size_name"]


def _param(name: str):
    slot = "size" if name in SIZE_PARAMETERS else name
    return next(p for p in PARAMETERS if p.name == slot)


def unit_of(name: str) -> str:
    """A parameter's unit: ``"um"``, ``"1"``, ``"pixels"``, ``"mm^2"``."""
    if name in SIZE_PARAMETERS:
        return "pixels" if name == "pixel_count" else "mm^2"
    return _param(name).unit


def size_name(space: Space) -> str:
    """How ``space`` gives the sensor's size: ``"sensor_area_mm2"`` or ``"pixel_count"``."""
    given = set(space.axes) | set(space.design_table)
    return next(name for name in SIZE_PARAMETERS if name in given)


def whole_numbers_only(name: str) -> str | None:
    """Why ``name`` cannot be optimised when it takes whole numbers only (``binning``,
    ``frames``); None for a parameter with a continuous range."""
    inside = _param(name)
    if not inside.integer:
        return None
    return (f"{name} takes whole numbers only ({inside.domain_text()}): the optimiser searches "
            f"a continuous range; compare a few values of {name} by fixing each, or give a "
            "design readout modes")


def checked_bounds(space: Space, bounds) -> dict:
    """``bounds`` ({name: (low, high)} in each parameter's unit) checked against ``space``:
    each name a per-point parameter of :func:`epc_fast.evaluate` that the space does not vary,
    each bound finite and inside the parameter's domain, low < high. A ValueError or TypeError
    names the parameter and its value."""
    if not isinstance(space, Space):
        raise TypeError(f"space must be an epc_fast.scan.Space, got {space!r}")
    if not isinstance(bounds, dict) or not bounds:
        raise TypeError(f"bounds must be a non-empty dict {{name: (low, high)}}, got {bounds!r}")
    checked = {}
    for name, pair in bounds.items():
        if name not in POINT_PARAMETERS:
            raise ValueError(f"bounds: {name!r} is not a parameter of epc_fast.evaluate; the "
                             f"parameters are {', '.join(POINT_PARAMETERS)}")
        try:
            low, high = (float(v) for v in pair)
        except (TypeError, ValueError):
            raise TypeError(f"bounds[{name!r}] = {pair!r}: expected (low, high), two numbers in "
                            f"{unit_of(name)}") from None
        if whole_numbers_only(name):
            raise ValueError(f"bounds: {whole_numbers_only(name)}")
        inside = _param(name)
        if not (math.isfinite(low) and math.isfinite(high) and low < high
                and in_domain(inside, [low, high]).all()):
            raise ValueError(f"bounds[{name!r}] = {pair!r}: expected finite low < high, both in "
                             f"{name}'s domain {inside.domain_text()} ({unit_of(name)})")
        _check_fixed(space, name)
        checked[name] = (low, high)
    return checked


def _check_fixed(space: Space, name: str) -> None:
    """A ValueError when the space varies ``name`` or gives the sensor another way, or when
    ``name`` is the focal length of a design that meets its SNR target at the image corner
    (whose field angle was fixed with the design's focal length)."""
    if name in space.axes and not isinstance(space.axes[name], float):
        how = repr(space.axes[name])
    elif name in space.design_varying:
        how = "its designs give " + ", ".join(f"{v:g}" for v in space.design_table[name])
    else:
        how = None
    if how is not None:
        raise ValueError(f"bounds: {name} varies in the space ({how}); an optimised parameter "
                         "is fixed in the space and set per candidate")
    if name in SIZE_PARAMETERS and name != size_name(space):
        raise ValueError(f"bounds: the space gives the sensor as {size_name(space)}, not "
                         f"{name}: optimise {size_name(space)}")
    if name == "focal_length_mm" and any(t.startswith("corner") for t in space.design_snr_at):
        raise ValueError("bounds: focal_length_mm of a design that meets its SNR target at the "
                         "image corner: the corner's field angle follows the focal length, but "
                         "the design fixed it; give the design field_angle_deg or "
                         "snr_at='axis' to optimise the focal length")


def checked_points(space: Space, points) -> int:
    """Draws of the scene: ``points`` (>= 1), or one pass over the grid of a space without
    random parameters when None."""
    if points is None:
        if space.is_random:
            raise TypeError("a space with random parameters needs points= (draws of the scene)")
        return space.grid_size
    count = integer("points", points)
    if count < 1:
        raise ValueError(f"points must be >= 1, got {points!r}")
    return count


def checked_threads(threads):
    """``threads`` (None: the core's default), or an error naming it, before any draw."""
    return None if threads is None else threads_of(threads)


def checked_objective(objective):
    """``objective`` when it is one of the objectives; :class:`Mean` for None."""
    if objective is None:
        return Mean()
    if not isinstance(objective, (Mean, Quantile, ProbabilityAtLeast)):
        raise TypeError(f"objective must be epc_fast.optimize.Mean(), Quantile(q) or "
                        f"ProbabilityAtLeast(target_pixels), got {objective!r}")
    return objective


def checked_search(batches, start_grid, xtol, dimensions: int, points: int,
                   is_random: bool, min_batch_points: int) -> tuple[int, int, float]:
    """(batches, start grid, xtol) of a search, checked; a space without random parameters
    runs no batch (it has no Monte Carlo error)."""
    from .search import default_grid

    batches = integer("batches", batches)
    if not is_random:
        batches = 0
    elif batches == 1 or batches < 0 or (batches and points // batches < min_batch_points):
        raise ValueError(f"batches={batches}: expected 0 or 2 and more, each of at least "
                         f"{min_batch_points} of the {points:,} draws")
    grid = (default_grid(dimensions) if start_grid is None
            else integer("start_grid", start_grid))
    if grid < 2:
        raise ValueError(f"start_grid={start_grid!r}: expected an integer >= 2")
    if isinstance(xtol, bool) or not isinstance(xtol, (int, float)) or not 0 < xtol <= 0.1:
        raise ValueError(f"xtol={xtol!r}: expected a number in (0, 0.1] (a fraction of each "
                         "bound's range)")
    return batches, grid, float(xtol)
