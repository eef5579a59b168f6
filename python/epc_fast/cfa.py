"""The colour filter array and its demosaicking: the names, the defaults and the demosaicker's
luminance MTF table (docs/model.md, "The colour filter array").

A Bayer sensor passes each pixel's light through a red, green or blue filter (the RGGB cell), so
a pixel collects ``cfa_transmittance`` t of a monochrome pixel's electrons on average; the
camera demosaicks the mosaic, white-balances it and corrects its colour, and the luminance it
delivers carries the noise variance of a monochrome pixel times ``color_noise_gain`` (the colour
correction) and the demosaicker's noise gain g_d, and the demosaicker's luminance MTF M_dem.

The constants are written by tools/cfa_defaults.py (t, the channels and the colour noise gain)
and tools/demosaic_mtf.py (g_d and the table); nothing here imports colour-science.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ._validation import short
from .mtf_table import MtfTable, mtf_table

__all__ = ["CFAS", "DEMOSAICS", "DEFAULT_CFA_TRANSMITTANCE", "DEFAULT_COLOR_NOISE_GAIN",
           "DEFAULT_CHANNEL_TRANSMITTANCES", "DEFAULT_LUMINANCE_WEIGHTS", "DEMOSAIC_NOISE_GAIN",
           "DEMOSAIC_MTF_PATH", "REMOSAIC_NOISE_GAIN", "REMOSAIC_MTF_PATH", "QUAD_BAYER_BINNINGS",
           "check_cfa", "check_demosaic", "color_noise_gain", "demosaic_mtf_table",
           "remosaic_mtf_table", "quad_bayer_binning", "SensorColor", "sensor_color"]

#: The colour filter arrays: none (the monochrome sensor), Bayer's RGGB cell, and the quad
#: Bayer sensor (2 x 2 pixels under one filter, those blocks in the RGGB arrangement): read
#: full size (binning 1) it is remosaicked to RGGB and demosaicked, binned 2 x 2 it is the
#: Bayer sensor of twice the pitch.
CFAS = ("none", "bayer", "quad_bayer")
#: The binnings a quad Bayer sensor is read at: 1 (full size, remosaicked) and 2 (its 2 x 2
#: blocks binned: a Bayer sensor).
QUAD_BAYER_BINNINGS = (1, 2)
#: The demosaickers, those of the colour-demosaicing package: bilinear interpolation,
#: Malvar, He and Cutler (2004) and Menon, Andriani and Calvagno (2007).
DEMOSAICS = ("bilinear", "malvar2004", "menon2007")

#: (R, G, B), each channel's response to D50 light over the sum of the three channels', for the
#: Nikon D5100 of colour-science's ``MSDS_CAMERA_SENSITIVITIES["Nikon 5100 (NPL)"]`` (measured
#: at the UK National Physical Laboratory, each channel scaled to a peak of 1):
#: t_c = integral(E_D50 S_c) / integral(E_D50 (S_R + S_G + S_B)). The monochrome reference is
#: the three channels' sum: with every filter's peak transmittance 1 the filters split the
#: spectrum among them and the bare sensor sees their sum (tools/cfa_defaults.py).
DEFAULT_CHANNEL_TRANSMITTANCES = (0.2789, 0.4171, 0.3040)

#: 1, the Bayer cell's mean transmittance relative to the monochrome sensor:
#: t = (t_R + 2 t_G + t_B) / 4 of :data:`DEFAULT_CHANNEL_TRANSMITTANCES` (the Nikon D5100
#: under D50, colour-science's "Nikon 5100 (NPL)"; tools/cfa_defaults.py). A Bayer pixel
#: collects about a third of the light a monochrome one does.
DEFAULT_CFA_TRANSMITTANCE = 0.3543

#: (y_R, y_G, y_B), sum 1: the luminance row of the colour correction, the 3x3 matrix from
#: white-balanced camera RGB to CIE XYZ (D50 white at Y = 1) fitted by least squares on the 24
#: patches of colour-science's ``SDS_COLOURCHECKERS["ColorChecker N Ohta"]`` under D50 (CIE
#: 1931 2 degree observer), the white point held exactly; the fit's rms error in Y is 0.005.
DEFAULT_LUMINANCE_WEIGHTS = (0.2714, 0.9512, -0.2226)

#: 1, the variance gain of white balance and colour correction to luminance for shot noise:
#: g = t sum_c y_c^2 / t_c with :data:`DEFAULT_CHANNEL_TRANSMITTANCES` and
#: :data:`DEFAULT_LUMINANCE_WEIGHTS` (the Nikon D5100 under D50; tools/cfa_defaults.py): the
#: luminance's variance over its mean, both on the cell's scale t S, for channel c's shot noise
#: of variance t_c S. Read noise (variance independent of t_c) has the gain
#: t^2 sum_c y_c^2 / t_c^2 = 0.839, 9 % below; the model applies 0.920 to both, overstating
#: the read-noise variance by 9.6 %.
DEFAULT_COLOR_NOISE_GAIN = 0.9199

#: {demosaicker: g_d}, the demosaicker's variance gain on the luminance: the luminance variance
#: of a flat Bayer capture with shot noise over color_noise_gain times its mean (both on the
#: cell's scale), measured by tools/demosaic_mtf.py with the default channels and weights (the
#: interpolation averages neighbouring pixels' noise, so g_d < 1): over 16 seeds of a 192 x
#: 192 flat patch, 0.6160, 0.8332 and 0.9961, each +- 0.0023 at most (one standard error).
#: Bilinear interpolation has the closed form sum_c y_c^2 k_c / t_c / sum_c y_c^2 / t_c =
#: 0.6147, k_c the mean over the cell of the sum of squares of channel c's interpolation
#: weights (k_G = 5/8, k_R = k_B = 9/16). Read noise alone, of one variance in every channel,
#: has 0.908, 0.978 and 0.998 times g_c g_d (measured), which the model's one gain ignores.
DEMOSAIC_NOISE_GAIN = {"bilinear": 0.616, "malvar2004": 0.833, "menon2007": 0.996}

#: The shipped table of each demosaicker's luminance MTF against f p_out (cycles/pixel),
#: written by tools/demosaic_mtf.py.
DEMOSAIC_MTF_PATH = Path(__file__).resolve().parent / "data" / "demosaic_mtf.csv"


#: {demosaicker: g_d}, the variance gain on the luminance of a quad Bayer sensor read full
#: size, remosaicked (:mod:`epc_fast.simulate.remosaic`) and demosaicked, measured as
#: :data:`DEMOSAIC_NOISE_GAIN` by tools/remosaic_mtf.py: over 16 seeds of a 192 x 192 flat
#: patch, 0.5012, 0.6592 and 0.7388, each +- 0.0018 at most (one standard error). The
#: remosaic replaces five pixels in eight by interpolations of their neighbours, which
#: average their noise: a pixel's variance falls below the Bayer sensor's, the noise spread
#: to lower frequencies (the model counts the variance, as it does the demosaicker's).
REMOSAIC_NOISE_GAIN = {"bilinear": 0.501, "malvar2004": 0.659, "menon2007": 0.739}

#: The shipped table of the remosaic and each demosaicker's luminance MTF against f p_out
#: (cycles/pixel), written by tools/remosaic_mtf.py.
REMOSAIC_MTF_PATH = Path(__file__).resolve().parent / "data" / "remosaic_mtf.csv"


def check_cfa(cfa) -> str:
    """``cfa`` itself when it is one of :data:`CFAS`, else a ValueError naming it."""
    if not isinstance(cfa, str) or cfa not in CFAS:
        raise ValueError(f"cfa: one of {', '.join(map(repr, CFAS))}, got {short(cfa)}")
    return cfa


def check_demosaic(demosaic) -> str:
    """``demosaic`` itself when it is one of :data:`DEMOSAICS`, else a ValueError naming it."""
    if not isinstance(demosaic, str) or demosaic not in DEMOSAICS:
        raise ValueError(f"demosaic: one of {', '.join(map(repr, DEMOSAICS))}, got "
                         f"{short(demosaic)}")
    return demosaic


def color_noise_gain(channel_transmittances=DEFAULT_CHANNEL_TRANSMITTANCES,
                     luminance_weights=DEFAULT_LUMINANCE_WEIGHTS) -> float:
    """1, t sum_c y_c^2 / t_c with t = (t_R + 2 t_G + t_B) / 4: the shot-noise variance gain of
    white balance and colour correction to luminance (:data:`DEFAULT_COLOR_NOISE_GAIN`). It does
    not change when every t_c is scaled by one factor."""
    t_c = np.asarray(channel_transmittances, dtype=float)
    y = np.asarray(luminance_weights, dtype=float)
    t = (t_c[0] + 2.0 * t_c[1] + t_c[2]) / 4.0
    return float(t * np.sum(y * y / t_c))


@functools.lru_cache(maxsize=None)
def _table_columns(path: Path = DEMOSAIC_MTF_PATH) -> dict:
    """{column name: values} of a shipped CSV (comment lines start with '#')."""
    lines = [line for line in path.read_text().splitlines()
             if line.strip() and not line.startswith("#")]
    names = [name.strip() for name in lines[0].split(",")]
    values = np.array([[float(v) for v in line.split(",")] for line in lines[1:]])
    return {name: values[:, i] for i, name in enumerate(names)}


def demosaic_mtf_table(algorithm) -> MtfTable:
    """The demosaicker's luminance MTF M_dem against f p_out, cycles/pixel, an
    :class:`~epc_fast.mtf_table.MtfTable` (1 at 0, never rising, held at its last value past
    its last frequency), from :data:`DEMOSAIC_MTF_PATH`."""
    columns = _table_columns()
    name = check_demosaic(algorithm)
    return mtf_table(f"demosaic_mtf[{name!r}]", (columns["f_cyc_per_px"], columns[name]))


def remosaic_mtf_table(algorithm) -> MtfTable:
    """The luminance MTF against f p_out, cycles/pixel, of a quad Bayer sensor read full size,
    remosaicked and demosaicked by ``algorithm``, an :class:`~epc_fast.mtf_table.MtfTable`,
    from :data:`REMOSAIC_MTF_PATH`."""
    columns = _table_columns(REMOSAIC_MTF_PATH)
    name = check_demosaic(algorithm)
    return mtf_table(f"remosaic_mtf[{name!r}]", (columns["f_cyc_per_px"], columns[name]))


@dataclass(frozen=True)
class SensorColor:
    """A call's colour sensor as the model takes it: the ``cfa_transmittance`` t and
    ``color_noise_gain`` columns (for a Bayer sensor g_c g_d, the colour correction's gain
    times the demosaicker's) and the demosaicker's table (None for the monochrome sensor)."""

    transmittance: object
    noise_gain: object
    demosaic_table: MtfTable | None


#: The monochrome sensor with no filter: t = 1, g_c = 1, no demosaicker.
_MONOCHROME = SensorColor(1.0, 1.0, None)


def sensor_color(cfa, demosaic, cfa_transmittance, color_noise_gain,
                 binning=1.0) -> SensorColor:
    """evaluate's ``cfa``, ``demosaic``, ``cfa_transmittance`` and ``color_noise_gain`` as
    :class:`SensorColor`. The transmittance t and the colour noise gain g_c are model
    parameters either way (a monochrome sensor behind a filter has a t too); None takes 1 for
    ``cfa="none"`` and the defaults (:data:`DEFAULT_CFA_TRANSMITTANCE`,
    :data:`DEFAULT_COLOR_NOISE_GAIN`) for ``"bayer"`` and ``"quad_bayer"``, whose demosaicker
    adds its noise gain g_d to g_c and its table. A quad Bayer sensor takes them by its
    ``binning`` (:func:`quad_bayer_binning`): at 2 the Bayer sensor's (:data:`DEMOSAIC_NOISE_GAIN`,
    :func:`demosaic_mtf_table`), at 1 the remosaic's (:data:`REMOSAIC_NOISE_GAIN`,
    :func:`remosaic_mtf_table`)."""
    check_cfa(cfa)
    check_demosaic(demosaic)
    if cfa == "none" and cfa_transmittance is None and color_noise_gain is None:
        return _MONOCHROME  # most calls: made once (a frozen dataclass costs a call 0.4 us)
    bayer = cfa != "none"
    t = (DEFAULT_CFA_TRANSMITTANCE if bayer else 1.0) if cfa_transmittance is None \
        else cfa_transmittance
    g_c = (DEFAULT_COLOR_NOISE_GAIN if bayer else 1.0) if color_noise_gain is None \
        else color_noise_gain
    if not bayer:
        return SensorColor(t, g_c, None)
    from ._validation import as_float_array

    full_size = cfa == "quad_bayer" and quad_bayer_binning(binning) == 1
    g_d = (REMOSAIC_NOISE_GAIN if full_size else DEMOSAIC_NOISE_GAIN)[demosaic]
    table = remosaic_mtf_table(demosaic) if full_size else demosaic_mtf_table(demosaic)
    gain = as_float_array("color_noise_gain", g_c) * g_d
    return SensorColor(t, gain if gain.ndim else float(gain), table)


def quad_bayer_binning(binning) -> int:
    """The one binning of :data:`QUAD_BAYER_BINNINGS` a call's quad Bayer sensor is read at;
    a ValueError naming ``cfa``, ``binning`` and the value for any other, or for both at once
    (one call reads one layout: evaluate's ``modes`` evaluates each binning as its own call).
    Points whose binning is not a number are left to the parameters' check (INVALID)."""
    values = np.asarray(binning)
    if values.dtype.kind not in "iuf":
        return 1
    finite = np.unique(values[np.isfinite(values)]) if values.ndim else (
        np.array([float(values)]) if np.isfinite(values) else np.array([]))
    other = [v for v in finite if v not in QUAD_BAYER_BINNINGS]
    if other:
        raise ValueError(f"cfa='quad_bayer': binning must be 1 (full size, remosaicked) or 2 "
                         f"(binned 2 x 2: a Bayer sensor), got binning {short(float(other[0]))}")
    if finite.size > 1:
        raise ValueError("cfa='quad_bayer': binning takes one value per call (1 full size or "
                         "2 binned: two layouts), got both; evaluate them as modes: "
                         "modes=[{'binning': 1}, {'binning': 2}]")
    return int(finite[0]) if finite.size else 1

