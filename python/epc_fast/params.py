"""The model's parameters: names with units, defaults and domains (docs/model.md,
"Quantities, units and defaults" and "Per-point status").

This table is the one place where a parameter's domain is written down. The NumPy reference
uses it to flag invalid points, the API uses it for ``invalid="raise"`` messages, and the C++
core receives the same bounds with every call, so the two backends cannot drift apart.

A domain is an interval ``lo .. hi`` whose ends are open or closed. NaN is outside every
domain; an infinite end is inside only when that end is closed (``full_well_e = inf`` means
"no full well").

Where physics sets no bound, the domain still stops at ``BIG`` = 1e30 (``TINY`` = 1e-30 below
the f-number, the wavelength and the stabilisation; -3000 and +1000 dB for the SNR target): far
beyond any camera, and where float64 stops being able to carry the model. Inside these bounds
every intermediate of the evaluation is finite and normal where its digits matter (the
electron rate stays below 3e167 e-/s, the electrons needed above 1e-300 and, whenever T_MPE
is finite, below 1e162 or T_MPE itself, f50 below 1e66 cycles/mm, EPC below 5e216), so a
point is either OK with finite outputs or carries a status that says why not;
docs/numerics.md gives the derivation and what each output's accuracy is.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

__all__ = ["Param", "ParameterTable", "PARAMETERS", "PARAMETER_NAMES", "SIZE_PARAMETERS",
           "SIZE_KEYWORDS", "in_domain", "BIG", "TINY", "SNR_DB_MIN", "SNR_DB_MAX",
           "WAVEFRONT_RMS_WAVES_MAX", "DENOISE_SIGMA_PX_MAX", "domain_table", "parameters",
           "LENS_INDEX", "CFA_PARAMETERS", "COLOR_NOISE_GAIN_MIN",
           "COLOR_NOISE_GAIN_MAX", "READOUT_CODES",
           "readout_codes"]

INF = math.inf
#: The largest magnitude of a parameter that physics leaves unbounded (see the module docstring).
BIG = 1e30
#: The smallest f-number and wavelength (nm), which bound the diffraction cut-off 1/(lambda F),
#: and the smallest stabilisation, which with BIG deg/s bounds the shake rate at 1e60 deg/s.
TINY = 1e-30
#: dB: the SNR target's range. The electrons needed are at least s = 10^(snr_db/10), a normal
#: float64 from -3000 dB; up to +1000 dB (1e100 electrons) every product stays finite.
SNR_DB_MIN = -3000.0
SNR_DB_MAX = 1000.0
#: waves: the largest rms wavefront error. Shannon's ATF holds to 0.18 waves, but above
#: W = 0.1642 waves its product with the diffraction MTF rises again past nu = 0.55 (at an MTF
#: near 0.04), and f50's bracket needs a falling MTF (docs/model.md, "The cut-off frequency f50").
WAVEFRONT_RMS_WAVES_MAX = 0.16
#: The colour noise gain's domain (of the model's column, g_c g_d for a Bayer sensor: a g_c of
#: 0.01 and more with any demosaicker): with denoising's smallest gain (8e-6 at sigma 100) and
#: the lowest SNR target (-3000 dB, s = 1e-300), s g stays above 2.2e-308, a normal double, so
#: T_MPE keeps its digits (docs/numerics.md); a real camera's gain is of order 1.
COLOR_NOISE_GAIN_MIN = 0.005
COLOR_NOISE_GAIN_MAX = 100.0
#: output pixels: the largest denoising sigma; its kernel has 2 ceil(4 sigma) + 1 = 801 taps.
DENOISE_SIGMA_PX_MAX = 100.0


@dataclass(frozen=True)
class Param:
    """One per-point model parameter.

    Parameters
    ----------
    name : str
        The keyword name, with its unit as a suffix.
    default : float or None
        None when the parameter is required.
    lo, hi : float
        Ends of the domain.
    lo_closed, hi_closed : bool
        Whether ``lo`` / ``hi`` belong to the domain.
    meaning : str
        One line: what it is, unit first.
    integer : bool
        Whether only the whole numbers of the interval belong to the domain (``binning``,
        ``frames``).
    """

    name: str
    default: float | None
    lo: float
    hi: float
    lo_closed: bool
    hi_closed: bool
    meaning: str
    integer: bool = False

    def domain_text(self) -> str:
        left = "[" if self.lo_closed else "("
        right = "]" if self.hi_closed else ")"
        whole = " integers" if self.integer else ""
        return f"{left}{self.lo:g}, {self.hi:g}{right}{whole}"

    @property
    def keywords(self) -> tuple[str, ...]:
        """The keywords of :func:`epc_fast.evaluate` that set it: its name, or for the sensor's
        size slot ``"size"`` the ways of giving a sensor's size."""
        return SIZE_KEYWORDS if self.name == "size" else (self.name,)

    @property
    def unit(self) -> str:
        """The unit, as the meaning starts with it."""
        return self.meaning.split(": ", 1)[0]


class ParameterTable(tuple):
    """The parameters (a tuple of :class:`Param`), printed as a table: keyword, unit, default,
    domain and meaning."""

    __slots__ = ()

    def __str__(self) -> str:
        rows = [("keyword", "unit", "default", "domain", "meaning")]
        for p in self:
            default = ("required" if p.default is None and p.name != "electrons_per_lux_s_m2"
                       else "D50" if p.default is None else f"{p.default:g}")
            keyword = " | ".join(SIZE_PARAMETERS) if p.name == "size" else p.name
            rows.append((keyword, p.unit, default, p.domain_text(),
                         p.meaning.split(": ", 1)[-1]))
        widths = [max(len(row[i]) for row in rows) for i in range(4)]
        return "\n".join("  ".join(cell.ljust(w) for cell, w in zip(row, widths)) + "  " + row[4]
                         for row in rows)

    def __repr__(self) -> str:
        return str(self)


def _p(name, default, lo, hi, lo_closed, hi_closed, meaning, integer=False):
    return Param(name, default, float(lo), float(hi), lo_closed, hi_closed, meaning, integer)


# The order is the core's parameter order (cpp/include/epc_fast/params.h, enum ParamIndex).
# "size" is the core's slot for the sensor's size, a pixel count or an area in mm^2: evaluate
# takes it as pixel_count or sensor_area_mm2 (or makes the area of a width and a height, or of
# a diagonal and an aspect ratio), never as "size".
PARAMETERS: tuple[Param, ...] = ParameterTable((
    _p("illuminance_lux", None, 0, BIG, True, False, "lux: illuminance on the gray target"),
    _p("pixel_pitch_um", None, 0, BIG, False, False, "um: pixel pitch"),
    _p("f_number", None, TINY, INF, False, False, "1: working f-number"),
    _p("focal_length_mm", None, 0, BIG, False, False, "mm: focal length"),
    _p("size", None, 0, BIG, False, False,
       "pixels or mm^2: the sensor's size, as pixel_count or sensor_area_mm2 (or "
       "sensor_width_mm and sensor_height_mm, or sensor_diagonal_mm and aspect)"),
    _p("reflectance", 0.4, 0, 1, True, True, "1: reflectance of the Lambertian gray target"),
    _p("lens_transmittance", 1.0, 0, 1, True, True, "1: lens and filter transmittance"),
    _p("field_angle_deg", 0.0, -90, 90, False, False,
       "degree: field angle of the image point (cos^4 falloff)"),
    _p("fill_factor", 1.0, 0, 1, False, True, "1: light-collecting fraction of the pixel area"),
    _p("electrons_per_lux_s_m2", None, 0, BIG, False, False,
       "e-/(lux s m^2): photo-electrons per focal-plane lux second per m^2 (None: the D50 default)"),
    _p("read_noise_e", 0.0, 0, BIG, True, False, "e- rms: read noise"),
    _p("dark_current_e_per_s", 0.0, 0, BIG, True, False, "e-/s: dark current"),
    _p("prnu", 0.0, 0, INF, True, False, "1: photo-response non-uniformity, rms fraction"),
    _p("full_well_e", INF, 0, INF, False, True, "e-: full-well capacity (inf: none)"),
    _p("snr_db", 30.0, SNR_DB_MIN, SNR_DB_MAX, True, True,
       "dB: target SNR, 20 log10(signal/noise)"),
    _p("shake_deg_per_s", 4.39, 0, BIG, True, False, "degree/s: camera angular velocity"),
    _p("stabilization", 1.0, TINY, INF, False, False,
       "1: image stabilisation factor k (motion / k)"),
    _p("jitter_um", 0.0, 0, INF, True, False, "um: rms Gaussian jitter (0: off)"),
    _p("wavelength_nm", 550.0, TINY, INF, False, False, "nm: wavelength for diffraction"),
    _p("mtf_threshold", 0.5, 0, 1, False, False, "1: MTF level defining the cut-off (0.5: f50)"),
    _p("binning", 1.0, 1, BIG, True, False,
       "1: pixel binning k, k x k pixels read as one output pixel (1: off)", integer=True),
    _p("frames", 1.0, 1, BIG, True, False,
       "1: burst capture, the exposure split into n frames aligned and summed (1: off)",
       integer=True),
    _p("alignment_error_um", 0.0, 0, BIG, True, False,
       "um: rms alignment error of each frame of a burst (0: off)"),
    _p("wavefront_rms_waves", 0.0, 0, WAVEFRONT_RMS_WAVES_MAX, True, True,
       "waves: rms wavefront error of the lens, in waves at every wavelength (0: off)"),
    _p("denoise_sigma_px", 0.0, 0, DENOISE_SIGMA_PX_MAX, True, True,
       "output pixels: sigma of the Gaussian denoising filter (0: off)"),
    # its upper end is the call's number of lens tables less 1 (parameters(lens_count)): 0
    # without lens_mtf
    _p("lens", 0.0, 0, 0, True, True,
       "1: index of the point's table in lens_mtf, a whole number (0 without lens_mtf)",
       integer=True),
    # a colour sensor's (docs/model.md, "The colour filter array"): 1, the monochrome
    # sensor's; evaluate's None takes epc_fast.cfa's defaults with cfa="bayer" (CFA_PARAMETERS)
    _p("cfa_transmittance", 1.0, 0, 1, False, True,
       "1: the colour cell's electrons against K's monochrome sensor's (1: none)"),
    _p("color_noise_gain", 1.0, COLOR_NOISE_GAIN_MIN, COLOR_NOISE_GAIN_MAX, True, True,
       "1: the noise variance gain of colour correction to luminance (1: none)"),
    # evaluate takes it as "digital" (0) or "charge" (1), or an array of them (READOUT_CODES)
    _p("binning_readout", 0.0, 0, 1, True, True,
       "1: how a binned pixel is read: 0 digital (k^2 reads of sigma_r), 1 charge (one read)",
       integer=True),
))

PARAMETER_NAMES: tuple[str, ...] = tuple(p.name for p in PARAMETERS)
#: ``binning_readout``'s names and their codes in its column.
READOUT_CODES = {"digital": 0.0, "charge": 1.0}


def readout_codes(binning_readout):
    """The ``binning_readout`` column: 0.0 for ``"digital"``, 1.0 for ``"charge"``, a float64
    array of them for an array of names; numbers are returned as they are (0 and 1 lie in its
    domain, other numbers make their points INVALID). A ValueError names a name that is
    neither."""
    if isinstance(binning_readout, str):
        if binning_readout not in READOUT_CODES:
            raise ValueError(f"binning_readout must be one of 'digital', 'charge'; got "
                             f"{str(binning_readout)!r}")
        return READOUT_CODES[binning_readout]
    names = np.asarray(binning_readout)
    if names.dtype.kind not in "US" and not (
            names.dtype.kind == "O" and names.size
            and all(isinstance(v, (str, bytes)) for v in names.reshape(-1))):
        return binning_readout  # numbers, or what the parameters' check refuses by type
    codes = np.full(names.shape, np.nan)
    for name, code in READOUT_CODES.items():
        codes[names == name] = code
    bad = np.flatnonzero(np.isnan(codes.reshape(-1)))
    if bad.size:
        raise ValueError(f"binning_readout must be one of 'digital', 'charge' at every point; "
                         f"got {names.reshape(-1)[bad[0]].item()!r} at flat index {int(bad[0])}")
    return codes
#: The colour sensor's parameters, whose default in evaluate's signature is None: 1 for the
#: monochrome sensor (their default here), epc_fast.cfa's with cfa="bayer".
CFA_PARAMETERS = ("cfa_transmittance", "color_noise_gain")

#: The two public names of the "size" slot.
SIZE_PARAMETERS = ("pixel_count", "sensor_area_mm2")
#: Every keyword that gives a sensor's size (evaluate makes an area of the others).
SIZE_KEYWORDS = SIZE_PARAMETERS + ("sensor_width_mm", "sensor_height_mm", "sensor_diagonal_mm",
                                   "aspect")


def in_domain(param: Param, values) -> np.ndarray:
    """Boolean array: which ``values`` lie in ``param``'s domain (NaN never does)."""
    v = np.asarray(values, dtype=np.float64)
    above = (v >= param.lo) if param.lo_closed else (v > param.lo)
    below = (v <= param.hi) if param.hi_closed else (v < param.hi)
    if param.integer:
        with np.errstate(invalid="ignore"):
            return above & below & (v == np.floor(v))
    return above & below


#: The position of ``lens`` in PARAMETERS.
LENS_INDEX = PARAMETER_NAMES.index("lens")


def parameters(lens_count: int = 1) -> tuple[Param, ...]:
    """PARAMETERS with the domain of ``lens`` for a call with ``lens_count`` lens tables:
    the whole numbers 0 .. lens_count - 1 (0 alone for a call without ``lens_mtf``)."""
    if lens_count == 1:
        return PARAMETERS
    lens = PARAMETERS[LENS_INDEX]
    return ParameterTable(PARAMETERS[:LENS_INDEX] + (
        Param(lens.name, lens.default, 0.0, float(lens_count - 1), True, True, lens.meaning,
              True),) + PARAMETERS[LENS_INDEX + 1:])


@functools.lru_cache(maxsize=16)
def domain_table(lens_count: int = 1) -> np.ndarray:
    """The domains as a float64 array of shape (n_params, 5): lo, hi, lo_closed, hi_closed,
    integer; ``lens`` in 0 .. lens_count - 1 (:func:`parameters`).

    This is what the C++ core receives with every call: made once per ``lens_count``, and
    read-only.
    """
    table = np.array(
        [[p.lo, p.hi, float(p.lo_closed), float(p.hi_closed), float(p.integer)]
         for p in parameters(lens_count)],
        dtype=np.float64,
    )
    table.setflags(write=False)
    return table

