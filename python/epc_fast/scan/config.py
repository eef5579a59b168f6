"""Scan configurations in TOML: the space, the point count, the seed and the reductions.

The format, section by section (every value in the unit of the parameter it sets)::

    [scan]                       # points (required), seed, chunk_points, threads
    [design]                     # presets = ["HIGH_TIER", ...] (names in epc_fast.presets),
                                 # [[design.custom]] tables of parameters with a name,
                                 # sampling = "grid" | "choice", weights = [...]
    [parameters]                 # name = 2.0 | {grid = [...]} | {choice = [...], weights = [...]}
                                 #   | {distribution = "uniform", low, high} | "log_uniform"
                                 #   | "normal" (mean, std) | "lognormal" (median, sigma)
                                 #   | "empirical" (samples = [...] or file = "one value a line")
                                 #   any distribution takes truncate = [low, high]
    [evaluate]                   # f50_rtol, t_mpe_solver, t_mpe_rtol
    [reductions.NAME]            # kind = "summary" | "histogram" | "quantiles"
                                 #   | "fraction_below" | "top_k", their arguments, and
                                 #   by = "design" | [part, ...] where a part is a name or
                                 #   {parameter = "illuminance_lux", log_bins = [low, high, n]}
                                 #   or {parameter = ..., edges = [...]}
    [output]                     # parquet = "directory" (relative to the output directory)

:data:`DEFAULT_CONFIG` is the scan ``epc-fast scan`` runs without a file.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .. import presets
from .best import TopK
from .distributions import (Choice, Empirical, Grid, LogNormal, LogUniform, Normal, Truncated,
                            Uniform)
from .groups import Binned
from .histograms import Histogram, Quantiles
from .runner import DEFAULT_CHUNK_POINTS
from .space import Space
from .summaries import FractionBelow, Summary

__all__ = ["ScanConfig", "load_config", "parse_config", "default_config", "DEFAULT_CONFIG"]

#: The built-in scan: the paper's 1/3.2" designs over a log-uniform illuminance and a
#: log-normal hand shake (median 4.39 degree/s, the paper's value).
DEFAULT_CONFIG = """\
[scan]
points = 1_000_000
seed = 2009

[design]
presets = ["HIGH_TIER"]

[parameters]
illuminance_lux = { distribution = "log_uniform", low = 10, high = 100_000 }
shake_deg_per_s = { distribution = "lognormal", median = 4.39, sigma = 0.5 }

[reductions.summary]
kind = "summary"
by = "design"

[reductions.quantiles]
kind = "quantiles"
q = [0.05, 0.5, 0.95]
by = "design"

[reductions.below_2_mpx]
kind = "fraction_below"
threshold = 2e6
by = "design"

[reductions.distribution]
kind = "histogram"
low = 1e3
high = 1e7
bins = 80
by = "design"

[reductions.bands]
kind = "quantiles"
q = [0.05, 0.25, 0.5, 0.75, 0.95]
by = ["design", { parameter = "illuminance_lux", log_bins = [10, 100_000, 16] }]
bins_per_decade = 200
"""

REDUCTIONS = {"summary": Summary, "histogram": Histogram, "quantiles": Quantiles,
              "fraction_below": FractionBelow, "top_k": TopK}
DISTRIBUTIONS = {"uniform": Uniform, "log_uniform": LogUniform, "normal": Normal,
                 "lognormal": LogNormal}


@dataclass
class ScanConfig:
    """A parsed configuration: the arguments of :func:`epc_fast.scan.run`.

    Attributes
    ----------
    space : Space
    points : int
    seed : int
    reductions : {name: reduction}
    chunk_points : int
    threads : int or None
    parquet : str or None, a directory relative to the output directory.
    source : str, the file it came from ("built-in default" for :data:`DEFAULT_CONFIG`).
    """

    space: Space
    points: int
    seed: int
    reductions: dict
    chunk_points: int
    threads: int | None
    parquet: str | None
    source: str

    def run_kwargs(self) -> dict:
        """Keyword arguments for :func:`epc_fast.scan.run` (all but ``parquet``)."""
        return {"points": self.points, "seed": self.seed, "reductions": self.reductions,
                "chunk_points": self.chunk_points, "threads": self.threads}


def _toml():
    try:
        import tomllib
    except ModuleNotFoundError:  # Python < 3.11
        try:
            import tomli as tomllib
        except ModuleNotFoundError:
            raise ImportError("reading scan configs on Python < 3.11 needs tomli: "
                              "pip install tomli") from None
    return tomllib


def _take(table: dict, where: str, required=(), optional=()) -> dict:
    """The keys of ``table``, refusing unknown or missing ones with a message naming ``where``."""
    unknown = sorted(set(table) - set(required) - set(optional))
    if unknown:
        raise ValueError(f"scan config [{where}]: unknown key(s) {', '.join(unknown)}; known: "
                         f"{', '.join(tuple(required) + tuple(optional))}")
    missing = [k for k in required if k not in table]
    if missing:
        raise ValueError(f"scan config [{where}]: missing {', '.join(missing)}")
    return table


def _integer(table: dict, name: str, default=None):
    """``table[name]`` as an int (1e6 is accepted: TOML writes large counts so)."""
    value = table.get(name, default)
    if isinstance(value, float) and value.is_integer():
        return int(value)
    if value is not default and (isinstance(value, bool) or not isinstance(value, int)):
        raise ValueError(f"scan config [scan]: {name} must be an integer, got {value!r}")
    return value


def _designs(table: dict):
    _take(table, "design", optional=("presets", "custom", "sampling", "weights"))
    designs = []
    for name in table.get("presets", []):
        found = getattr(presets, name, None)
        if not (isinstance(found, presets.Design) or (isinstance(found, tuple) and found
                                                      and isinstance(found[0], presets.Design))):
            raise ValueError(f"scan config [design]: {name!r} is not a preset of "
                             "epc_fast.presets (e.g. HIGH_TIER, LOW_TIER, ZOOM_3X)")
        designs.extend(found if isinstance(found, tuple) else (found,))
    designs.extend(table.get("custom", []))
    if not designs:
        raise ValueError("scan config [design]: give presets or [[design.custom]] entries")
    sampling = table.get("sampling", "grid")
    if sampling == "grid":
        if "weights" in table:
            raise ValueError("scan config [design]: weights need sampling = \"choice\"")
        return Grid(designs)
    if sampling == "choice":
        return Choice(designs, table.get("weights"))
    raise ValueError(f"scan config [design]: sampling is \"grid\" or \"choice\", got {sampling!r}")


def _parameter(name: str, value, base: Path):
    where = f"parameters.{name}"
    if isinstance(value, (int, float)):
        return float(value)
    if not isinstance(value, dict):
        raise ValueError(f"scan config [{where}]: a number or a table, got {value!r}")
    if "grid" in value:
        return Grid(_take(value, where, required=("grid",))["grid"])
    if "choice" in value:
        _take(value, where, required=("choice",), optional=("weights",))
        return Choice(value["choice"], value.get("weights"))
    kind = value.get("distribution")
    rest = {k: v for k, v in value.items() if k not in ("distribution", "truncate")}
    if kind == "empirical":
        _take(rest, where, optional=("samples", "file"))
        if ("samples" in rest) == ("file" in rest):
            raise ValueError(f"scan config [{where}]: give samples or file")
        samples = rest["samples"] if "samples" in rest else np.loadtxt(base / rest["file"])
        distribution = Empirical(samples)
    elif kind in DISTRIBUTIONS:
        cls = DISTRIBUTIONS[kind]
        fields = tuple(cls.__dataclass_fields__)
        distribution = cls(**_take(rest, where, required=fields))
    else:
        raise ValueError(f"scan config [{where}]: distribution must be one of "
                         f"{', '.join(tuple(DISTRIBUTIONS) + ('empirical',))}, or use grid or "
                         f"choice; got {kind!r}")
    if "truncate" in value:
        low, high = value["truncate"]
        return Truncated(distribution, low, high)
    return distribution


def _group_part(part, where: str):
    if isinstance(part, str):
        return part
    if not isinstance(part, dict):
        raise ValueError(f"scan config [{where}]: a group is a name or a table, got {part!r}")
    _take(part, where, required=("parameter",), optional=("log_bins", "edges"))
    if ("log_bins" in part) == ("edges" in part):
        raise ValueError(f"scan config [{where}]: give log_bins = [low, high, n] or edges")
    if "edges" in part:
        return Binned(part["parameter"], part["edges"])
    low, high, count = part["log_bins"]
    return Binned(part["parameter"], np.geomspace(low, high, int(count) + 1))


def _reduction(name: str, table: dict):
    where = f"reductions.{name}"
    table = dict(table)
    kind = table.pop("kind", None)
    if kind not in REDUCTIONS:
        raise ValueError(f"scan config [{where}]: kind must be one of {', '.join(REDUCTIONS)}, "
                         f"got {kind!r}")
    cls = REDUCTIONS[kind]
    _take(table, where, optional=tuple(cls.__dataclass_fields__))
    if "by" in table:
        by = table["by"]
        table["by"] = (tuple(_group_part(p, where) for p in by) if isinstance(by, list)
                       else _group_part(by, where))
    if "q" in table:
        table["q"] = tuple(table["q"])
    return cls(**table)


def parse_config(text: str, base_dir=".", source: str = "<string>") -> ScanConfig:
    """A :class:`ScanConfig` from TOML text; files it names are relative to ``base_dir``."""
    document = _toml().loads(text)
    _take(document, "top level", required=("scan",),
          optional=("design", "parameters", "evaluate", "reductions", "output"))
    scan = _take(document["scan"], "scan", required=("points",),
                 optional=("seed", "chunk_points", "threads"))
    counts = {name: _integer(scan, name, default) for name, default in (
        ("points", None), ("seed", 0), ("chunk_points", DEFAULT_CHUNK_POINTS), ("threads", None))}
    reductions = {name: _reduction(name, table)
                  for name, table in document.get("reductions", {}).items()}
    output = _take(document.get("output", {}), "output", optional=("parquet",))
    design = _designs(document["design"]) if "design" in document else None
    parameters = {name: _parameter(name, value, Path(base_dir))
                  for name, value in document.get("parameters", {}).items()}
    space = Space(design=design, evaluate_options=document.get("evaluate"), **parameters)
    return ScanConfig(space, counts["points"], counts["seed"], reductions or None,
                      counts["chunk_points"], counts["threads"], output.get("parquet"), source)


def load_config(path) -> ScanConfig:
    """A :class:`ScanConfig` from a TOML file."""
    path = Path(path)
    return parse_config(path.read_text(), path.parent, str(path))


def default_config() -> ScanConfig:
    """The built-in scan, :data:`DEFAULT_CONFIG`."""
    return parse_config(DEFAULT_CONFIG, source="built-in default")
