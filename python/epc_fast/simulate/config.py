"""Simulator configurations in TOML, for ``epc-fast simulate``.

The designs are a scan config's ``[design]`` and ``[evaluate]`` tables (``presets = [...]``
and ``[[design.custom]]`` tables with their ``binning_readout`` and ``modes``; a colour sensor,
``cfa`` and ``demosaic``, and a lens's ``lens_mtf`` in ``[evaluate]``), read by the scan's own
parser (:func:`epc_fast.scan.config.parse_space`), so that one config serves both;
``[simulate]`` sets the charts and the seed::

    [simulate]                   # seed, star_width_um (µm of scene the star covers), spokes,
                                 #   edge_rows, max_edge_columns, flat_px, max_blur_px
                                 #   (pixels)

Every key is checked before any capture; a mistake raises
:class:`~epc_fast.jobs.errors.ConfigError` naming the table, the key, the value and what is
expected.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from ..jobs.document import MAX_CONFIG_BYTES, read_text, toml_document
from ..scan.config import parse_space
from ..jobs.errors import ConfigError
from ..jobs.schema import config_of, config_prefix, integer, number, short, table_of, take
from ..terms import terms_on
from .agreement import MAX_EDGE_COLUMNS
from .camera import GAIN_RTOL
from .charts import MIN_EDGE_PX
from .review import DEFAULTS
from .star import MIN_STAR_PX

__all__ = ["SimulateConfig", "parse_simulate_config", "load_simulate_config", "MAX_CHART_PX",
           "DEFAULT_LUX"]

#: Pixels, the largest side of a star or a flat patch, and the most rows of an edge: a
#: picture for a review, not a benchmark.
MAX_CHART_PX = 4096
#: lux, the light levels without ``--lux``: a dim room, an office, an overcast day.
DEFAULT_LUX = (10.0, 100.0, 1000.0)
#: The integer keys of [simulate] and their bounds (low, high).
INTEGER_KEYS = {"seed": (0, 2**64 - 1), "spokes": (4, 720), "max_blur_px": (0, 100_000),
                "edge_rows": (MIN_EDGE_PX, MAX_CHART_PX),
                "max_edge_columns": (MIN_EDGE_PX, MAX_EDGE_COLUMNS),
                "flat_px": (2, MAX_CHART_PX)}


@dataclass
class SimulateConfig:
    """A parsed simulator configuration.

    Attributes
    ----------
    designs : list of (name, kwargs): each design's name and its keywords of
        :func:`epc_fast.evaluate`.
    snr_target : list of str, each design's SNR target and where it is met, for people.
    settings : dict, ``[simulate]`` over :data:`epc_fast.simulate.review.DEFAULTS`.
    source : str, the file it came from.
    text : str, the TOML it was read from.
    terms : list of str, the model terms the designs turn on, for people
        (:func:`epc_fast.terms.terms_on`).
    """

    designs: list
    snr_target: list
    settings: dict = field(default_factory=dict)
    source: str = "<string>"
    text: str = ""
    terms: list = field(default_factory=list)


def _settings(table) -> dict:
    table = take(table_of("simulate", table), "simulate", optional=tuple(DEFAULTS))
    settings = dict(DEFAULTS)
    for key, value in table.items():
        if key in INTEGER_KEYS:
            settings[key] = integer("simulate", key, value, *INTEGER_KEYS[key])
        else:
            settings[key] = number("simulate", key, value, low=0.0, low_open=True)
    return settings


def _output_pitches_um(kwargs: dict) -> list:
    """µm, the output pixel pitches a design captures at: its pitch times its binning, or
    each of its modes' binning."""
    readouts = kwargs.get("modes") or [kwargs]
    return [float(kwargs["pixel_pitch_um"]) * float(r.get("binning", 1.0)) for r in readouts]


def _check_star(settings: dict, designs) -> None:
    """A ConfigError when the star is under MIN_STAR_PX or over MAX_CHART_PX output pixels
    for a design (or one of its modes): the same width is fewer pixels at a larger pitch."""
    width = settings["star_width_um"]
    for name, kwargs in designs:
        for pitch in _output_pitches_um(kwargs):
            pixels = round(width / pitch)
            if not MIN_STAR_PX <= pixels <= MAX_CHART_PX:
                raise ConfigError(f"{config_prefix()} [simulate]: star_width_um = {short(width)}: "
                                  f"expected a width of {MIN_STAR_PX} to {MAX_CHART_PX:,} "
                                  f"pixels of every design, got {pixels:,} pixels of {name!r} "
                                  f"({pitch:g} um)")


def _check_color(designs) -> None:
    """A ConfigError for a design whose ``color_noise_gain`` is not the capture's own, its
    filters' (1 without a CFA; the default channels' and weights' for a Bayer sensor): no
    capture has it (:func:`epc_fast.simulate.capture`)."""
    from ..cfa import color_noise_gain

    for name, kwargs in designs:
        given = kwargs.get("color_noise_gain")
        own = color_noise_gain() if kwargs.get("cfa", "none") != "none" else 1.0
        if given is not None and not abs(given - own) <= GAIN_RTOL * own:
            raise ConfigError(f"{config_prefix()} [design] {name!r}: color_noise_gain = {given:g}: "
                              f"expected the capture's own, {own:.4g} (its filters'), or none")


def _designs(space) -> list:
    """(name, keywords of :func:`epc_fast.evaluate`) of each of the space's designs: its
    parameters, its ``binning_readout`` (when not digital) and ``modes``, and ``[evaluate]``'s
    options."""
    designs = []
    for i, name in enumerate(space.design_names):
        kwargs = {key: float(values[i]) for key, values in space.design_table.items()
                  if key != "binning_readout"}  # by its name, below
        if space.design_readout[i] != "digital":
            kwargs["binning_readout"] = space.design_readout[i]
        if space.design_modes[i]:
            kwargs["modes"] = [dict(mode) for mode in space.design_modes[i]]
        kwargs.update(space.evaluate_options)
        designs.append((name, kwargs))
    return designs


def parse_simulate_config(text: str, source: str = "<string>") -> SimulateConfig:
    """A :class:`SimulateConfig` from TOML text, every key checked; its mistakes name the
    simulate config (``simulate config [design]: ...``)."""
    with config_of("simulate"):
        return _simulate_config(text, source)


def _simulate_config(text: str, source: str) -> SimulateConfig:
    document = toml_document(text, source)
    take(document, "top level", required=("design",), optional=("evaluate", "simulate"))
    settings = _settings(document.get("simulate", {}))
    # The scan's parser reads the designs and [evaluate]; a space needs an illuminance, which
    # the simulator's --lux replaces.
    space = parse_space({"design": document["design"], "evaluate": document.get("evaluate", {}),
                         "parameters": {"illuminance_lux": 1.0}})
    designs = _designs(space)
    _check_color(designs)
    _check_star(settings, designs)
    return SimulateConfig(designs, list(space.snr_target_text()), settings, source, text,
                          terms_on(space))


def load_simulate_config(path) -> SimulateConfig:
    """A :class:`SimulateConfig` from a TOML file (UTF-8, at most 16 MB)."""
    path = Path(path)
    with config_of("simulate"):
        text = read_text(path, MAX_CONFIG_BYTES)
    return parse_simulate_config(text, str(path))
