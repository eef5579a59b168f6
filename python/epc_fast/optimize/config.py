"""Optimiser configurations in TOML, for ``epc-fast optimize``.

The scene and the fixed design are a scan config's ``[design]``, ``[parameters]`` and
``[evaluate]`` tables, read by the scan's own parser (:func:`epc_fast.scan.config.parse_space`,
its messages naming the optimize config);
``[optimize]`` replaces ``[scan]`` and ``[reductions]``::

    [optimize]                   # points (required), seed, batches, threads, start_grid,
                                 #   xtol, curve_points, sampling = "monte_carlo" | "sobol"
    [optimize.bounds]            # name = [low, high]: the optimised parameters, in their
                                 #   units (not in [parameters]; a design's value is replaced)
    [optimize.objective]         # kind = "mean" | "quantile" (q) |
                                 #   "probability_at_least" (target_pixels)

Every key is checked before any work; a mistake raises
:class:`~epc_fast.jobs.errors.ConfigError` naming the table, the key and the value.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from ..api import MAX_THREADS
from .objectives import OBJECTIVES
from .checks import checked_bounds, whole_numbers_only
from .problem import DEFAULT_BATCHES, DEFAULT_XTOL, MIN_BATCH_POINTS, design_readout
from ..jobs.document import MAX_CONFIG_BYTES, read_text, toml_document
from ..scan.config import parse_space
from ..jobs.errors import ConfigError
from ..jobs.schema import (choice, config_of, config_prefix, integer, number, number_list,
                           short, table_of, take, wrapped)
from ..scan.sampling.distributions import Grid
from ..scan.sampling.qmc import SAMPLINGS
from ..scan.sampling.space import POINT_PARAMETERS, Space, domain_problem

__all__ = ["OptimizeConfig", "parse_optimize_config", "load_optimize_config",
           "MAX_OPTIMIZE_POINTS", "DEFAULT_CURVE_POINTS"]

#: Draws of one optimisation: they are held in memory (~40 bytes a draw with one random
#: parameter).
MAX_OPTIMIZE_POINTS = 10**9
#: Candidates on the plotted curve of each parameter, by default.
DEFAULT_CURVE_POINTS = 41
MAX_CURVE_POINTS = 10_001
#: The keys of each objective's table besides ``kind``, with their checks (low, high).
OBJECTIVE_KEYS = {"mean": {}, "quantile": {"q": (0.0, 1.0)},
                  "probability_at_least": {"target_pixels": (0.0, None)}}


@dataclass
class OptimizeConfig:
    """A parsed optimiser configuration.

    Attributes
    ----------
    space : Space, the scene and the fixed design (the optimised parameters at their bounds'
        midpoints, replaced per candidate).
    bounds : {name: (low, high)}, each in its parameter's unit.
    objective : Mean, Quantile or ProbabilityAtLeast.
    points, seed, batches : int.
    threads : int or None.
    start_grid : int or None.
    xtol : 1, a fraction of each bound's range.
    curve_points : int, candidates on each parameter's plotted curve.
    source : str, the file it came from.
    text : str, the TOML it was read from.
    sampling : str, how the scene is drawn: "monte_carlo" or "sobol".
    """

    space: Space
    bounds: dict
    objective: object
    points: int
    seed: int
    batches: int
    threads: int | None
    start_grid: int | None
    xtol: float
    curve_points: int
    source: str
    text: str = ""
    sampling: str = "monte_carlo"

    def problem_kwargs(self) -> dict:
        """Keyword arguments of :class:`epc_fast.optimize.Problem`."""
        return {"space": self.space, "bounds": self.bounds, "objective": self.objective,
                "points": self.points, "seed": self.seed, "threads": self.threads,
                "sampling": self.sampling}

    def search_kwargs(self) -> dict:
        """Keyword arguments of :meth:`epc_fast.optimize.Problem.maximize`."""
        return {"batches": self.batches, "start_grid": self.start_grid, "xtol": self.xtol}


def _bounds(table) -> dict:
    table = table_of("optimize.bounds", table)
    if not table:
        raise ConfigError(f"{config_prefix()} [optimize.bounds]: give at least one parameter as "
                          "name = [low, high], e.g. pixel_pitch_um = [0.8, 4.0]")
    bounds = {}
    for name, value in table.items():
        if name not in POINT_PARAMETERS:
            raise ConfigError(f"{config_prefix()} [optimize.bounds]: unknown parameter "
                              f"{short(name)}; the parameters are {', '.join(POINT_PARAMETERS)}")
        pair = number_list("optimize.bounds", name, value, min_length=2)
        if whole_numbers_only(name):  # before [parameters] holds its midpoint, not whole
            raise ConfigError(f"{config_prefix()} [optimize.bounds]: {name} = {short(value)}: "
                              + whole_numbers_only(name))
        if len(pair) != 2 or not pair[0] < pair[1]:
            raise ConfigError(f"{config_prefix()} [optimize.bounds]: {name} = {short(value)}: "
                              "expected [low, high] with low < high")
        problem = domain_problem(name, Grid(tuple(pair)))
        if problem:
            raise ConfigError(f"{config_prefix()} [optimize.bounds]: {name} = {short(value)}: "
                              + problem.split(": ", 1)[1].replace("every value", "both bounds"))
        bounds[name] = (float(pair[0]), float(pair[1]))
    return bounds


def _objective(table):
    table = table_of("optimize.objective", table)
    kind = choice("optimize.objective", "kind", table.get("kind"), tuple(OBJECTIVE_KEYS))
    checks = OBJECTIVE_KEYS[kind]
    take(table, "optimize.objective", required=("kind",) + tuple(checks))
    arguments = {key: number("optimize.objective", key, table[key], low, high)
                 for key, (low, high) in checks.items()}
    return wrapped("optimize.objective", lambda: OBJECTIVES[kind](**arguments))


def parse_optimize_config(text: str, base_dir=".", source: str = "<string>") -> OptimizeConfig:
    """An :class:`OptimizeConfig` from TOML text; files it names are relative to
    ``base_dir``. Its mistakes name the optimize config (``optimize config [optimize]: ...``)."""
    with config_of("optimize"):
        return _optimize_config(text, base_dir, source)


def _optimize_config(text: str, base_dir, source: str) -> OptimizeConfig:
    document = toml_document(text, source)
    take(document, "top level", required=("optimize",),
         optional=("design", "parameters", "evaluate"))
    table = take(table_of("optimize", document["optimize"]), "optimize",
                 required=("points", "bounds", "objective"),
                 optional=("seed", "batches", "threads", "start_grid", "xtol", "curve_points",
                           "sampling"))
    bounds = _bounds(table["bounds"])
    objective = _objective(table["objective"])
    parameters = table_of("parameters", document.get("parameters", {}))
    given = sorted(set(parameters) & set(bounds))
    if given:
        raise ConfigError(f"{config_prefix()} [parameters]: {', '.join(given)} is optimised "
                          "([optimize.bounds]); remove it from [parameters]")
    # The optimised parameters at their midpoints: the space needs a value; each candidate
    # replaces it.
    middles = {name: 0.5 * (low + high) for name, (low, high) in bounds.items()}
    space = parse_space({**document, "parameters": {**parameters, **middles}}, base_dir)
    bounds = wrapped("optimize.bounds", lambda: checked_bounds(space, bounds))
    wrapped("design", lambda: design_readout(space, tuple(bounds)))
    threads = table.get("threads")
    start_grid = table.get("start_grid")
    points = integer("optimize", "points", table["points"], 1, MAX_OPTIMIZE_POINTS, size=True)
    batches = integer("optimize", "batches", table.get("batches", DEFAULT_BATCHES), 0, 1000)
    if space.is_random and (batches == 1 or (batches and points // batches < MIN_BATCH_POINTS)):
        raise ConfigError(f"{config_prefix()} [optimize]: batches = {batches}: expected 0 or 2 and "
                          f"more, each of at least {MIN_BATCH_POINTS} of the {points:,} points")
    sampling = choice("optimize", "sampling", table.get("sampling", "monte_carlo"), SAMPLINGS)
    unit = space.grid_size * DEFAULT_BATCHES
    if sampling == "sobol" and space.is_random and (batches not in (0, DEFAULT_BATCHES)
                                                    or points % unit):
        raise ConfigError(f"{config_prefix()} [optimize]: sampling = \"sobol\" draws "
                          f"{DEFAULT_BATCHES} replicates, which are the batches: expected "
                          f"batches = {DEFAULT_BATCHES} or 0 and points a multiple of {unit}; "
                          f"got batches = {batches}, points = {points}")
    return OptimizeConfig(
        space=space, bounds=bounds, objective=objective, points=points,
        seed=integer("optimize", "seed", table.get("seed", 0), 0, 2**64 - 1), batches=batches,
        threads=None if threads is None else integer("optimize", "threads", threads, 1,
                                                     MAX_THREADS),
        start_grid=None if start_grid is None else integer("optimize", "start_grid",
                                                           start_grid, 2, 1000),
        xtol=number("optimize", "xtol", table.get("xtol", DEFAULT_XTOL), 0.0, 0.1,
                    low_open=True),
        curve_points=integer("optimize", "curve_points",
                             table.get("curve_points", DEFAULT_CURVE_POINTS), 2,
                             MAX_CURVE_POINTS),
        source=source, text=text, sampling=sampling)


def load_optimize_config(path) -> OptimizeConfig:
    """An :class:`OptimizeConfig` from a TOML file (UTF-8, at most 16 MB)."""
    path = Path(path)
    with config_of("optimize"):
        text = read_text(path, MAX_CONFIG_BYTES)
    return parse_optimize_config(text, path.parent, str(path))
