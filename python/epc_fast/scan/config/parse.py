"""Scan configurations in TOML: the space, the point count, the seed and the reductions.

The format, section by section (every value in the unit of the parameter it sets)::

    [scan]                       # points (required), seed, chunk_points, threads,
                                 #   sampling = "monte_carlo" | "sobol", replicates
    [design]                     # presets = ["HIGH_TIER", ...] (names in epc_fast.presets),
                                 # sampling = "grid" | "choice", weights = [...]
    [[design.custom]]            # name, evaluate's parameters, the sensor as
                                 #   sensor_width_mm + sensor_height_mm
                                 #   | sensor_diagonal_mm + aspect ("4:3")
                                 #   | sensor_area_mm2 | pixel_count,
                                 #   snr_at = "corner" | "axis" (or field_angle_deg): where the
                                 #   SNR target is met; default the corner when the sensor's
                                 #   shape and the focal length are given, as for the presets,
                                 #   else the axis (docs/sensor.md)
    [parameters]                 # name = 2.0 | {grid = [...]} | {choice = [...], weights = [...]}
                                 #   | {distribution = "uniform", low, high} | "log_uniform"
                                 #   | "normal" (mean, std) | "lognormal" (median, sigma)
                                 #   | "empirical" (samples = [...] or file = "one value a line")
                                 #   any distribution takes truncate = [low, high]
    [evaluate]                   # f50_rtol, t_mpe_solver, t_mpe_rtol, spectrum,
                                 #   lens_mtf = [[frequencies_cyc_per_mm], [mtf]] or a list
                                 #   of such tables, which lens = {choice = [0, 1, ...]}
                                 #   picks per point; cfa = "none" | "bayer"
                                 #   | "quad_bayer" (binning 1 or 2, one per call),
                                 #   demosaic = "malvar2004" | "bilinear" | "menon2007",
                                 #   epc_axes = "motion" | "both" (docs/model.md),
                                 #   max_exposure_s = 0.1 (s, the longest frame)
    [reductions.NAME]            # kind = "summary" | "histogram" | "quantiles"
                                 #   | "fraction_below" | "top_k", their arguments, and
                                 #   by = "design" | [part, ...] where a part is a name or
                                 #   {parameter = "illuminance_lux", log_bins = [low, high, n]}
                                 #   or {parameter = ..., edges = [...]};
                                 #   target = {standard_error = ..., relative = ...}
                                 #   (summary, fraction_below, quantiles): a stopping rule
    [output]                     # parquet = "directory" (a name inside the output directory),
                                 #   log_y = true: the bands plots' output on a log axis
    [sobol]                      # points, seed, of = "epc" | "log_epc" | [...], confidence,
                                 #   resamples, not_ok = "raise" | "zero": Sobol' indices of
                                 #   the space (config/indices.py)

Every key is checked before any work (its type, its range, and every size it controls, against
the bounds in :mod:`epc_fast.jobs.schema`); a mistake raises
:class:`~epc_fast.jobs.errors.ConfigError` naming the table, the key and the value.

:data:`DEFAULT_CONFIG` is the scan ``epc-fast scan`` runs without a file.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ... import presets
from ...api import F50_SOLVERS, MAX_THREADS, PRECISIONS, T_MPE_SOLVERS
from ...jobs.document import MAX_CONFIG_BYTES, read_text, toml_document
from .reductions import check_reductions, parse_reductions
from .indices import SobolConfig, parse_sobol
from ..sampling.distributions import (Choice, Empirical, Grid, LogNormal, LogUniform, Normal,
                                      Truncated, Uniform)
from ...jobs.errors import ConfigError
from ..sampling.qmc import MAX_REPLICATES, SAMPLINGS
from ..running.runner import DEFAULT_CHUNK_POINTS, sampled_scan
from ...jobs.schema import (MAX_LIST, boolean, check_size, choice, config_of, config_prefix,
                            file_name, integer, number, number_list, short, string, table_of, take,
                            wrapped)
from .bounds import MAX_CHUNK_POINTS, MAX_GROUPS, MAX_POINTS
from .samples import read_samples
from ...mtf_table import lens_tables_of
from ...params import SIZE_KEYWORDS, SIZE_PARAMETERS, readout_codes
from ...sensor import SHAPE_KEYWORDS, SIZE_AND_SNR_AT, SIZE_WAYS, design_parameters
from ..running.readout_modes import READOUT_KEYS
from ..sampling.space import BLOCK_POINTS, POINT_PARAMETERS, Space, domain_problem
from ...api import BINNING_READOUTS
from ...cfa import CFAS, DEMOSAICS
from ...axes import EPC_AXES
from .modes import design_modes

__all__ = ["ScanConfig", "load_config", "parse_config", "default_config", "DEFAULT_CONFIG",
           "toml_document", "parse_space"]

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

DISTRIBUTIONS = {"uniform": Uniform, "log_uniform": LogUniform, "normal": Normal,
                 "lognormal": LogNormal}
#: The checks of each distribution's keys: (key, low, low_open).
DISTRIBUTION_KEYS = {"uniform": (("low", None, False), ("high", None, False)),
                     "log_uniform": (("low", 0.0, True), ("high", 0.0, True)),
                     "normal": (("mean", None, False), ("std", 0.0, True)),
                     "lognormal": (("median", 0.0, True), ("sigma", 0.0, True))}
#: The keys of [evaluate] and their checks.
EVALUATE_CHOICES = {"f50_solver": F50_SOLVERS, "t_mpe_solver": T_MPE_SOLVERS,
                    "precision": PRECISIONS, "cfa": CFAS, "demosaic": DEMOSAICS,
                    "epc_axes": EPC_AXES}
EVALUATE_TOLERANCES = ("f50_rtol", "t_mpe_rtol")


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
    parquet : str or None, a directory name inside the output directory.
    source : str, the file it came from ("built-in default" for :data:`DEFAULT_CONFIG`).
    text : str, the TOML it was read from (recorded in the output's manifest).
    sobol : SobolConfig or None, the ``[sobol]`` table: Sobol' indices of the space.
    log_y : bool, ``[output] log_y``: the bands plots draw the output on a log axis.
    sampling : str, ``[scan] sampling``: "monte_carlo" or "sobol".
    replicates : int or None, ``[scan] replicates`` (None: the scan's default).
    """

    space: Space
    points: int
    seed: int
    reductions: dict
    chunk_points: int
    threads: int | None
    parquet: str | None
    source: str
    text: str = ""
    sobol: SobolConfig | None = None
    log_y: bool = False
    sampling: str = "monte_carlo"
    replicates: int | None = None

    def run_kwargs(self) -> dict:
        """Keyword arguments for :func:`epc_fast.scan.run` (all but ``parquet``)."""
        return {"points": self.points, "seed": self.seed, "reductions": self.reductions,
                "chunk_points": self.chunk_points, "threads": self.threads,
                "sampling": self.sampling, "replicates": self.replicates}


def _designs(table: dict):
    take(table, "design", optional=("presets", "custom", "sampling", "weights"))
    designs = []
    names = table.get("presets", [])
    if not isinstance(names, list) or not all(isinstance(n, str) for n in names):
        raise ConfigError(f"{config_prefix()} [design]: presets = {short(names)}: expected a list "
                          'of preset names, e.g. ["HIGH_TIER"]')
    #: {design name: where it was given}: a name names one design only.
    named = {}
    for name in names:
        found = getattr(presets, name, None) if name.isidentifier() else None
        if not (isinstance(found, presets.Design) or (isinstance(found, tuple) and found
                                                      and isinstance(found[0], presets.Design))):
            raise ConfigError(f"{config_prefix()} [design]: presets: {short(name)} is not a preset "
                              "of epc_fast.presets (e.g. HIGH_TIER, LOW_TIER, ZOOM_3X)")
        for design in found if isinstance(found, tuple) else (found,):
            if design.name in named:
                raise ConfigError(f"{config_prefix()} [design]: presets: {short(name)} gives the "
                                  f"design {short(design.name)} a second time")
            named[design.name] = f"the preset {name}'s design"
            designs.append(design)
    custom = table.get("custom", [])
    if not isinstance(custom, list) or len(custom) > MAX_LIST:
        raise ConfigError(f"{config_prefix()} [design]: custom = {short(custom)}: expected "
                          "[[design.custom]] tables")
    for index, entry in enumerate(custom):
        design = _custom_design(entry, index)
        # Space names a design without a name by its position.
        name = design.get("name", f"design {len(designs)}")
        if name in named:
            raise ConfigError(f"{config_prefix()} [design.custom[{index}]]: name = {short(name)}: "
                              f"expected a name no other design has ({named[name]} is named "
                              f"{short(name)})")
        named[name] = f"[design.custom[{index}]]"
        designs.append(design)
    check_size("design", "designs", len(designs), MAX_GROUPS, 64)
    if not designs:
        raise ConfigError(f"{config_prefix()} [design]: give presets or [[design.custom]] entries")
    sampling = choice("design", "sampling", table.get("sampling", "grid"), ("grid", "choice"))
    if sampling == "grid":
        if "weights" in table:
            raise ConfigError(f"{config_prefix()} [design]: weights need sampling = \"choice\"")
        return wrapped("design", lambda: Grid(designs))
    weights = table.get("weights")
    if weights is not None:
        weights = number_list("design", "weights", weights, low=0.0)
    return wrapped("design", lambda: Choice(designs, weights))


def _custom_design(entry, index: int) -> dict:
    """A [[design.custom]] table: evaluate's parameters, its sensor any of the four ways
    (``sensor_width_mm`` and ``sensor_height_mm``, ``sensor_diagonal_mm`` and ``aspect``,
    ``sensor_area_mm2``, ``pixel_count``) and ``snr_at``; checked whole here so that a mistake
    names this table."""
    where = f"design.custom[{index}]"
    entry = table_of(where, entry)
    known = set(POINT_PARAMETERS) | set(SHAPE_KEYWORDS) | {"name", "snr_at", *READOUT_KEYS}
    design = {}
    for key, value in entry.items():
        if key not in known:
            raise ConfigError(f"{config_prefix()} [{where}]: unknown key {short(key)}; a design "
                              "gives parameters of epc_fast.evaluate (pixel_pitch_um, "
                              "f_number, focal_length_mm, ...), its sensor (sensor_width_mm "
                              "and sensor_height_mm, or sensor_diagonal_mm and aspect, or "
                              "sensor_area_mm2, or pixel_count), snr_at, binning_readout and "
                              "modes")
        if key in ("name", "snr_at"):
            design[key] = string(where, key, value)
            if key == "name" and not any(c.isalnum() for c in value):
                raise ConfigError(f"{config_prefix()} [{where}]: name = {short(value)}: expected a "
                                  "name with a letter or digit")
        elif key == "aspect" and isinstance(value, str):
            design[key] = value
        elif key == "binning_readout":
            design[key] = choice(where, key, value, BINNING_READOUTS)
        elif key == "modes":
            design[key] = value  # checked below, with the design's name
        else:
            design[key] = number(where, key, value)
    label = f"[{where}]" + (f" {design['name']!r}" if "name" in design else "")
    for key, value in design.items():  # (lens: by the Space, which knows the tables)
        problem = (domain_problem(key, value)
                   if key in POINT_PARAMETERS and key not in ("lens", "binning_readout") else None)
        if problem:
            raise ConfigError(f"{config_prefix()} {label}: {key} = {problem}")
    if "modes" in design:
        design["modes"] = design_modes(where, label, design)
    try:
        design_parameters({k: v for k, v in design.items()
                           if k != "name" and k not in READOUT_KEYS})
    except (TypeError, ValueError) as error:
        raise ConfigError(f"{config_prefix()} {label}: {error}") from None
    return design


def _readout_codes(value):
    """``binning_readout``'s names (a name, or a grid's or choice's) as their codes."""
    try:
        if isinstance(value, dict):
            return {k: ([float(c) for c in np.atleast_1d(readout_codes(v))]
                        if k in ("grid", "choice") and isinstance(v, list) else v)
                    for k, v in value.items()}
        return readout_codes(value) if isinstance(value, str) else value
    except ValueError as error:
        raise ConfigError(f"{config_prefix()} [parameters]: {error}") from None


def _parameter(name: str, value, base: Path):
    where = f"parameters.{name}"
    if name == "binning_readout":
        value = _readout_codes(value)
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        return number("parameters", name, value)
    if not isinstance(value, dict):
        raise ConfigError(f"{config_prefix()} [parameters]: {name} = {short(value)}: expected a "
                          "finite number or a table ({grid = [...]}, {choice = [...]}, "
                          "{distribution = ...})")
    if "grid" in value:
        return Grid(number_list(where, "grid", take(value, where, required=("grid",))["grid"]))
    if "choice" in value:
        take(value, where, required=("choice",), optional=("weights",))
        weights = value.get("weights")
        values = number_list(where, "choice", value["choice"])
        if weights is not None:
            weights = number_list(where, "weights", weights, low=0.0)
        return wrapped(where, lambda: Choice(values, weights))
    if "distribution" not in value:
        raise ConfigError(f"{config_prefix()} [{where}]: give grid, choice or distribution")
    kind = choice(where, "distribution", value["distribution"],
                  tuple(DISTRIBUTIONS) + ("empirical",))
    rest = {k: v for k, v in value.items() if k not in ("distribution", "truncate")}
    if kind == "empirical":
        take(rest, where, optional=("samples", "file"))
        if ("samples" in rest) == ("file" in rest):
            raise ConfigError(f"{config_prefix()} [{where}]: give samples or file")
        if "samples" in rest:
            samples = number_list(where, "samples", rest["samples"])
        else:
            samples = read_samples(where, rest["file"], base)
        distribution = wrapped(where, lambda: Empirical(samples))
    else:
        checks = DISTRIBUTION_KEYS[kind]
        take(rest, where, required=tuple(key for key, _, _ in checks))
        arguments = {key: number(where, key, rest[key], low, low_open=low_open)
                     for key, low, low_open in checks}
        distribution = wrapped(where, lambda: DISTRIBUTIONS[kind](**arguments))
    if "truncate" in value:
        low, high = number_list(where, "truncate", value["truncate"], min_length=2)[:2]
        if len(value["truncate"]) != 2:
            raise ConfigError(f"{config_prefix()} [{where}]: truncate = "
                              f"{short(value['truncate'])}: expected [low, high]")
        return wrapped(where, lambda: Truncated(distribution, low, high))
    return distribution


def _evaluate_options(table) -> dict:
    table = take(table_of("evaluate", table), "evaluate", optional=(
        *EVALUATE_CHOICES, *EVALUATE_TOLERANCES, "spectrum", "lens_mtf", "max_exposure_s"))
    options = {}
    for key, value in table.items():
        if key in EVALUATE_CHOICES:
            options[key] = choice("evaluate", key, value, EVALUATE_CHOICES[key])
        elif key in EVALUATE_TOLERANCES:
            options[key] = number("evaluate", key, value, 0.0, 1.0, high_open=True)
        elif key == "lens_mtf":
            options[key] = _lens_tables(value)
        elif key == "max_exposure_s":  # s, the frame cap (docs/model.md)
            options[key] = number("evaluate", key, value, 0.0, low_open=True)
        else:
            if not (isinstance(value, list) and len(value) == 2):
                raise ConfigError(f"{config_prefix()} [evaluate]: spectrum = {short(value)}: "
                                  "expected [[wavelengths_nm, ...], [weights, ...]]")
            options[key] = (number_list("evaluate", "spectrum", value[0], low=0.0),
                            number_list("evaluate", "spectrum", value[1], low=0.0))
    return options


def _lens_tables(value) -> tuple:
    """``[evaluate] lens_mtf``: one table [[frequencies_cyc_per_mm, ...], [mtf, ...]] or a list
    of them (``lens`` picks one per point), each checked (epc_fast.mtf_table)."""
    if not isinstance(value, list) or not value:
        raise ConfigError(f"{config_prefix()} [evaluate]: lens_mtf = {short(value)}: expected "
                          "[[frequencies_cyc_per_mm, ...], [mtf, ...]] or a list of them")
    try:
        return lens_tables_of(value)
    except ValueError as error:
        raise ConfigError(f"{config_prefix()} [evaluate]: {error}") from None


def _scan_table(scan) -> dict:
    scan = take(table_of("scan", scan), "scan", required=("points",),
                optional=("seed", "chunk_points", "threads", "sampling", "replicates"))
    chunk_points = integer("scan", "chunk_points", scan.get("chunk_points", DEFAULT_CHUNK_POINTS),
                           BLOCK_POINTS, MAX_CHUNK_POINTS, size=True)
    if chunk_points % BLOCK_POINTS:
        raise ConfigError(f"{config_prefix()} [scan]: chunk_points = {chunk_points}: expected a "
                          f"multiple of {BLOCK_POINTS} (the block)")
    threads = scan.get("threads")
    return {"points": integer("scan", "points", scan["points"], 1, MAX_POINTS, size=True),
            "seed": integer("scan", "seed", scan.get("seed", 0), 0, 2**64 - 1),
            "chunk_points": chunk_points,
            "threads": None if threads is None else integer("scan", "threads", threads, 1,
                                                            MAX_THREADS),
            "sampling": choice("scan", "sampling", scan.get("sampling", "monte_carlo"),
                               SAMPLINGS),
            "replicates": None if scan.get("replicates") is None else integer(
                "scan", "replicates", scan["replicates"], 1, MAX_REPLICATES)}


def _check_sizes(design) -> None:
    """A ConfigError naming the first [[design.custom]] table that gives no sensor size (none
    is in [parameters]): the size belongs in the design's table, where its shape decides
    where the SNR target is met."""
    custom = [entry for entry in design.values if isinstance(entry, dict)]
    for index, entry in enumerate(custom):
        if not set(entry) & set(SIZE_KEYWORDS):
            name = f" {short(entry['name'])}" if "name" in entry else ""
            raise ConfigError(f"{config_prefix()} [design.custom[{index}]]{name}: no sensor size: "
                              f"give it in this table, one of four ways: {SIZE_WAYS}; "
                              f"{SIZE_AND_SNR_AT}")


def _space_builder(document: dict, base_dir):
    """A function that builds the :class:`Space` of a config's ``[design]``, ``[parameters]``
    and ``[evaluate]`` tables, every key of which is checked here, before it is called."""
    design = _designs(table_of("design", document["design"])) if "design" in document else None
    parameters = {name: _parameter(name, value, Path(base_dir)) for name, value
                  in table_of("parameters", document.get("parameters", {})).items()}
    options = _evaluate_options(document.get("evaluate", {}))
    if design is not None and not set(parameters) & set(SIZE_PARAMETERS):
        _check_sizes(design)
    return lambda: wrapped("parameters", lambda: Space(design=design, evaluate_options=options,
                                                       **parameters))


def parse_space(document: dict, base_dir=".") -> Space:
    """The :class:`Space` of a config's ``[design]``, ``[parameters]`` and ``[evaluate]``
    tables (``document``, a parsed TOML document), every key checked; files it names are
    relative to ``base_dir``. Shared by the scan's, the optimiser's and the simulator's configs;
    its messages name the config of the command reading it
    (:func:`~epc_fast.jobs.schema.config_of`)."""
    return _space_builder(document, base_dir)()


def parse_config(text: str, base_dir=".", source: str = "<string>",
                 command: str = "scan") -> ScanConfig:
    """A :class:`ScanConfig` from TOML text; files it names are relative to ``base_dir``.

    Every key is checked (type, range, size) before anything is evaluated; a mistake raises
    :class:`~epc_fast.jobs.errors.ConfigError` (a ValueError) naming ``command``'s config
    (``epc-fast sobol`` reads the same file: ``"sobol"``), the table, the key and the value.
    """
    with config_of(command):
        return _scan_config(text, base_dir, source)


def _scan_config(text: str, base_dir, source: str) -> ScanConfig:
    document = toml_document(text, source)
    take(document, "top level", required=("scan",),
         optional=("design", "parameters", "evaluate", "reductions", "output", "sobol"))
    counts = _scan_table(document["scan"])
    output = take(table_of("output", document.get("output", {})), "output",
                  optional=("parquet", "log_y"))
    log_y = boolean("output", "log_y", output.get("log_y", False))
    parquet = output.get("parquet")
    if parquet is not None:
        parquet = file_name("output", "parquet", parquet)
    build_space = _space_builder(document, base_dir)
    reductions = parse_reductions(table_of("reductions", document.get("reductions", {})))
    space = build_space()
    sampled, _, _ = wrapped("scan", lambda: sampled_scan(
        space, counts["points"], reductions or None, counts["sampling"], counts["replicates"]))
    check_reductions(reductions, space, sampled.sampling.replicates)
    sobol = (parse_sobol(document["sobol"], counts["seed"], space) if "sobol" in document
             else None)
    return ScanConfig(space, counts["points"], counts["seed"], reductions or None,
                      counts["chunk_points"], counts["threads"], parquet, source, text, sobol,
                      log_y, counts["sampling"], counts["replicates"])


def load_config(path, command: str = "scan") -> ScanConfig:
    """A :class:`ScanConfig` from a TOML file (UTF-8, at most 16 MB), its mistakes naming
    ``command``'s config."""
    path = Path(path)
    with config_of(command):
        text = read_text(path, MAX_CONFIG_BYTES)
    return parse_config(text, path.parent, str(path), command)


def default_config(command: str = "scan") -> ScanConfig:
    """The built-in scan, :data:`DEFAULT_CONFIG`."""
    return parse_config(DEFAULT_CONFIG, source="built-in default", command=command)
