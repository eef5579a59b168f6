"""The paper's quantitative statements, held against the model (docs/model.md, "The paper's
systems").

Each :class:`Statement` pairs a claim with the paper's value and the model's value under three
readings of the paper's SNR target (:data:`epc_fast.presets.READINGS`): the preset (30 dB at the
image corner) and the literal 30 dB and 33 dB on the optical axis. Claims come in four kinds:

- ``paper``: the paper's statements listed in docs/model.md, "The paper's systems", which the
  preset must reproduce within the stated tolerance;
- ``known limit``: stated by the paper, but docs/model.md says no model of this family
  reproduces it (reported, not tuned away);
- ``derived``: follows exactly from the paper's model as docs/model.md writes it down;
- ``model only``: a quantity the paper discusses whose value docs/model.md does not give: the
  model's value, with no paper value to compare (fill it in from the paper when at hand).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Callable

import numpy as np

from ..api import evaluate
from ..inverse import InverseStatus, crossover_lux, lux_for_epc
from ..params import PARAMETERS
from ..presets import FIGURE_3, HIGH_TIER, LOW_TIER, READINGS, ZOOM_3X, Design, stack

__all__ = ["Statement", "Figure", "FIGURES", "CLAIMS", "PAPER_LUX_RANGE", "KINDS", "VGA_PIXELS",
           "RAYLEIGH_FACTOR", "statements"]

#: lux, the illuminance range of the paper's figures and statements.
PAPER_LUX_RANGE = (100.0, 100000.0)
KINDS = ("paper", "known limit", "derived", "model only")
#: pixels, VGA (640 x 480).
VGA_PIXELS = 640 * 480
#: 1, the Rayleigh criterion: the Airy disc's first dark ring is at 1.22 lambda F.
RAYLEIGH_FACTOR = 1.22
_DEFAULT_WAVELENGTH_NM = next(p.default for p in PARAMETERS if p.name == "wavelength_nm")
_READING_ORDER = ("corner_30db", "on_axis_30db", "on_axis_33db")


@dataclass(frozen=True)
class Figure:
    """One of the paper's figures: EPC of some designs over illuminance; and its companion,
    what limits each of them (:func:`epc_fast.plotting.limits.plot_limits_over_illuminance`)."""

    name: str
    title: str
    designs: tuple

    @property
    def limits_name(self) -> str:
        """The companion's name, the figure's with ``_limits`` (``fig1_limits``)."""
        return f"{self.name}_limits"

    @property
    def limits_title(self) -> str:
        """The companion's title, the figure's with what it shows."""
        return f"{self.title}: what limits each design"


FIGURES = (
    Figure("fig1", 'Figure 1: 1/3.2" sensor, four pixel sizes', HIGH_TIER),
    Figure("fig2", 'Figure 2: 1/8" sensor, four pixel sizes', LOW_TIER),
    Figure("fig3", 'Figure 3: 1.75 µm on 1/3.2", image stabilisation and 3x zoom', FIGURE_3),
)


@dataclass(frozen=True)
class Statement:
    """A quantitative claim and the model's value under each reading of the paper.

    Attributes
    ----------
    id : str
    text : str, the claim.
    kind : str, one of :data:`KINDS`.
    unit : str, of every value.
    relation : str, how the model's value must relate to the paper's: "≈" (within
        ``tolerance``, relative), "<", ">" or "≥".
    paper_value : the paper's value; NaN for a ``model only`` claim.
    tolerance : 1, relative, for "≈".
    preset_value, on_axis_30db_value, on_axis_33db_value : the model's value under each reading
        (NaN where the quantity does not exist, e.g. a level never reached).
    simulated_value : the value checked on simulated captures of the preset
        (:mod:`epc_fast.paper.simulated`); NaN where not simulated, where a capture cannot check
        it (geometry) or where the simulated EPC never reaches it near the model's value.
    """

    id: str
    text: str
    kind: str
    unit: str
    relation: str
    paper_value: float
    tolerance: float
    preset_value: float
    on_axis_30db_value: float
    on_axis_33db_value: float
    simulated_value: float = math.nan

    @property
    def deviation(self) -> float:
        """1: the preset's relative deviation from the paper, preset / paper - 1 (NaN: none)."""
        return self.preset_value / self.paper_value - 1.0

    @property
    def simulated_deviation(self) -> float:
        """1: the simulated value's relative deviation from the model's preset value."""
        return self.simulated_value / self.preset_value - 1.0

    @property
    def simulated_holds(self) -> bool | None:
        """Whether the simulated value satisfies the relation to the paper; None without a
        paper value or a simulated value."""
        if math.isnan(self.paper_value) or math.isnan(self.simulated_value):
            return None
        value, paper = self.simulated_value, self.paper_value
        return bool({"≈": abs(value / paper - 1.0) <= self.tolerance, "<": value < paper,
                     ">": value > paper, "≥": value >= paper}[self.relation])

    @property
    def holds(self) -> bool | None:
        """Whether the preset's value satisfies the relation; None without a paper value."""
        if math.isnan(self.paper_value):
            return None
        value, paper = self.preset_value, self.paper_value
        return bool({"≈": abs(value / paper - 1.0) <= self.tolerance, "<": value < paper,
                     ">": value > paper, "≥": value >= paper}[self.relation])


@dataclass(frozen=True)
class _Claim:
    """A statement before evaluation: ``value(backend=, threads=)`` gives its three values."""

    id: str
    text: str
    kind: str
    unit: str
    relation: str
    paper_value: float
    tolerance: float
    value: Callable  # (**options) -> array of one value per reading, in _READING_ORDER


def _read(design: Design) -> dict:
    """evaluate() keywords of ``design`` under each reading, as arrays of shape (3,)."""
    return stack([design.read_as(reading) for reading in _READING_ORDER])


def _solved(result) -> np.ndarray:
    return np.where(result.status == InverseStatus.OK, result.illuminance_lux, np.nan)


def _crossover(small: Design, big: Design) -> Callable:
    """lux: where ``small`` stops losing to ``big`` (the highest crossing in the paper's range)."""
    return lambda **options: _solved(crossover_lux(_read(small), _read(big),
                                                   lux_range=PAPER_LUX_RANGE, **options))


def _lux_for(design: Design, target_epc: float) -> Callable:
    """lux: where ``design`` reaches ``target_epc`` pixels within the paper's range."""
    return lambda **options: _solved(lux_for_epc(_read(design), target_epc,
                                                 lux_range=PAPER_LUX_RANGE, **options))


def _kept_fraction(design: Design, lux: float) -> Callable:
    """1: EPC / physical pixel count at ``lux``, through :func:`epc_fast.evaluate`; the count
    is ``design.pixel_count``, N = S / p² (:func:`epc_fast.sensor.physical_pixel_count`), as
    the figures' dotted lines, not the array's columns x rows."""
    return lambda **options: evaluate(lux, **_read(design), **options).epc / design.pixel_count


def _stabilisation_light_ratio(design: Design, target_epc: float) -> Callable:
    """1: the light ``design`` needs for ``target_epc`` over the light its IS variant needs."""
    plain, stabilised = _lux_for(design, target_epc), _lux_for(design.stabilized(), target_epc)
    return lambda **options: plain(**options) / stabilised(**options)


def _constant(value: float) -> Callable:
    """A value that no reading changes (the optics' geometry)."""
    return lambda **options: np.full(len(_READING_ORDER), value)


def _rayleigh_um(design: Design) -> float:
    return RAYLEIGH_FACTOR * _DEFAULT_WAVELENGTH_NM * 1e-3 * design.f_number


_HIGH_2_8, _HIGH_2_2, _HIGH_1_75, _HIGH_1_4 = HIGH_TIER
_LOW_2_8, _LOW_2_2, _LOW_1_75, _LOW_1_4 = LOW_TIER
_STABILISED_1_75 = FIGURE_3[1]

CLAIMS = (
    _Claim("rayleigh_f2.8", "Rayleigh blur 1.22·λ·F at 550 nm is 1.88 µm at F/2.8", "paper",
           "µm", "≈", 1.88, 0.005 / 1.88, _constant(_rayleigh_um(HIGH_TIER[0]))),
    _Claim("rayleigh_f4.9", "Rayleigh blur 1.22·λ·F at 550 nm is 3.29 µm at F/4.9", "paper",
           "µm", "≈", 3.29, 0.005 / 3.29, _constant(_rayleigh_um(ZOOM_3X))),
    _Claim("fov_normal", "diagonal field of view of the 5.6 mm lens on 1/3.2\" is 54° "
           "(Table 1)", "paper", "degree", "≈", 54.0, 0.5 / 54.0,
           _constant(HIGH_TIER[0].diagonal_field_of_view_deg)),
    _Claim("fov_zoom", "diagonal field of view of the 3x zoom (16.8 mm) is 19.3° (Table 1)",
           "paper", "degree", "≈", 19.3, 0.05 / 19.3,
           _constant(ZOOM_3X.diagonal_field_of_view_deg)),
    _Claim("crossover_1.4_1.75", '1/3.2": 1.4 µm has lower EPC than 1.75 µm below about '
           "7500 lux", "paper", "lux", "≈", 7500.0, 0.10, _crossover(_HIGH_1_4, _HIGH_1_75)),
    _Claim("crossover_1.4_2.2", '1/3.2": 1.4 µm has lower EPC than 2.2 µm below about '
           "5500 lux", "paper", "lux", "≈", 5500.0, 0.10, _crossover(_HIGH_1_4, _HIGH_2_2)),
    _Claim("crossover_1.4_2.8", '1/3.2": 1.4 µm has lower EPC than 2.8 µm below about '
           "4000 lux", "paper", "lux", "≈", 4000.0, 0.10, _crossover(_HIGH_1_4, _HIGH_2_8)),
    _Claim("fraction_1.4_100klux", '1/3.2" at 100,000 lux: EPC(1.4 µm) is less than 46% of its '
           "pixel count", "paper", "1", "<", 0.46, 0.0, _kept_fraction(_HIGH_1_4, 1e5)),
    _Claim("vga_1.4", '1/3.2": below 1000 lux EPC(1.4 µm) is under VGA; value: the lux at '
           "which it reaches 640×480", "paper", "lux", "≥", 1000.0, 0.0,
           _lux_for(_HIGH_1_4, VGA_PIXELS)),
    _Claim("fraction_2.8_100klux", '1/3.2" at 100,000 lux: the 2.8 µm design keeps more than '
           "93% of its pixels", "known limit", "1", ">", 0.93, 0.0, _kept_fraction(_HIGH_2_8, 1e5)),
    _Claim("is_4x_light", "4x IS is worth 4x the light: the lux the 1.75 µm design needs for "
           "1 Mpixel over the lux it needs with IS (exact when shot-noise limited)", "derived",
           "1", "≈", 4.0, 1e-9, _stabilisation_light_ratio(_HIGH_1_75, 1e6)),
    _Claim("crossover_1/8_1.4_1.75", '1/8": 1.4 µm has lower EPC than 1.75 µm below this',
           "model only", "lux", "", math.nan, math.nan, _crossover(_LOW_1_4, _LOW_1_75)),
    _Claim("crossover_1/8_1.4_2.2", '1/8": 1.4 µm has lower EPC than 2.2 µm below this',
           "model only", "lux", "", math.nan, math.nan, _crossover(_LOW_1_4, _LOW_2_2)),
    _Claim("crossover_1/8_1.4_2.8", '1/8": 1.4 µm has lower EPC than 2.8 µm below this',
           "model only", "lux", "", math.nan, math.nan, _crossover(_LOW_1_4, _LOW_2_8)),
    _Claim("2mp_2.2", '1/3.2" 2.2 µm keeps 2 Mpixel above this light level', "model only",
           "lux", "", math.nan, math.nan, _lux_for(_HIGH_2_2, 2e6)),
    _Claim("2mp_1.75", '1/3.2" 1.75 µm keeps 2 Mpixel above this light level', "model only",
           "lux", "", math.nan, math.nan, _lux_for(_HIGH_1_75, 2e6)),
    _Claim("2mp_1.4", '1/3.2" 1.4 µm keeps 2 Mpixel above this light level', "model only",
           "lux", "", math.nan, math.nan, _lux_for(_HIGH_1_4, 2e6)),
    _Claim("2mp_1.75_is", '1/3.2" 1.75 µm with 4x IS keeps 2 Mpixel above this light level',
           "model only", "lux", "", math.nan, math.nan, _lux_for(_STABILISED_1_75, 2e6)),
)


def statements(*, backend="core", threads=None, simulate=False) -> tuple:
    """Every claim of :data:`CLAIMS`, evaluated under the three readings.

    Parameters
    ----------
    backend : {"core", "reference"}
        Passed to :func:`epc_fast.evaluate` and the inverse solvers.
    threads : int, optional
    simulate : bool
        Also check each claim on simulated captures of the preset
        (:func:`epc_fast.paper.simulated.simulated_values`: about 20 s, SciPy needed).

    Returns
    -------
    tuple of Statement
    """
    out = []
    for claim in CLAIMS:
        values = np.asarray(claim.value(backend=backend, threads=threads), dtype=np.float64)
        out.append(Statement(claim.id, claim.text, claim.kind, claim.unit, claim.relation,
                             claim.paper_value, claim.tolerance, *map(float, values)))
    if simulate:
        from .simulated import simulated_values

        values = simulated_values(out)
        out = [replace(s, simulated_value=values[s.id]) for s in out]
    return tuple(out)
