"""The colour filter array and its demosaicking: the names, the defaults and the demosaicker's
luminance MTF table (docs/model.md, "The colour filter array").

A Bayer sensor passes each pixel's light through a red, green or blue filter (the RGGB cell), so
a pixel collects ``cfa_transmittance`` t of the electrons of the monochrome sensor that the
electron constant K describes, under the same light, on average (:func:`bayer_light` computes t
from spectra); the
camera demosaicks the mosaic, white-balances it and corrects its colour, and the luminance it
delivers carries the noise variance of a monochrome pixel times ``color_noise_gain`` (the colour
correction) and the demosaicker's noise gain g_d, and the demosaicker's luminance MTF M_dem.

The constants are written by tools/cfa_defaults.py (t, the channels and the colour noise gain)
and tools/demosaic_mtf.py (g_d and the table); nothing here imports colour-science
(:func:`bayer_light` reads the photopic V(λ) through :mod:`epc_fast.spectra`, as K does).
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
           "remosaic_mtf_table", "quad_bayer_binning", "SensorColor", "sensor_color",
           "BayerLight", "bayer_light"]

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

#: (R, G, B), each channel's electrons over those of the monochrome sensor that the electron
#: constant K describes (:mod:`epc_fast.spectra`: quantum efficiency 0.7 on 480..580 nm only),
#: under D50: :func:`bayer_light` of the Nikon D5100 of colour-science's
#: ``MSDS_CAMERA_SENSITIVITIES["Nikon 5100 (NPL)"]`` (silicon, filters and infrared cut
#: together, measured at the UK National Physical Laboratory: Darrodi et al., J. Opt. Soc.
#: Am. A 32 (2015) 381), each channel's quantum efficiency scaled to the same peak 0.7, the
#: silicon response outside 480..580 nm the D5100's own (tools/cfa_defaults.py). A green
#: pixel collects about what K's sensor does; the three together 2.38 K.
DEFAULT_CHANNEL_TRANSMITTANCES = (0.7485, 0.9970, 0.6308)

#: 1, the Bayer cell's mean electrons over those of the monochrome sensor that K describes,
#: under the same illuminant: t = (t_R + 2 t_G + t_B) / 4 of
#: :data:`DEFAULT_CHANNEL_TRANSMITTANCES` (the Nikon D5100 under D50; tools/cfa_defaults.py).
DEFAULT_CFA_TRANSMITTANCE = 0.8433

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
#: t^2 sum_c y_c^2 / t_c^2 = 0.830, 9 % below; the model applies 0.915 to both, overstating
#: the read-noise variance by 10 %. One factor on every t_c changes neither gain.
DEFAULT_COLOR_NOISE_GAIN = 0.9146

#: {demosaicker: g_d}, the demosaicker's variance gain on the luminance: the luminance variance
#: of a flat Bayer capture with shot noise over color_noise_gain times its mean (both on the
#: cell's scale), measured by tools/demosaic_mtf.py with the default channels and weights (the
#: interpolation averages neighbouring pixels' noise, so g_d <= 1 within the measurement's
#: error): over 16 seeds of a 192 x 192 flat patch, 0.6174, 0.8364 and 1.0013, each +- 0.0017
#: at most (one standard error). It depends on the channels' ratios, not their scale.
#: Bilinear interpolation has the closed form sum_c y_c^2 k_c / t_c / sum_c y_c^2 / t_c =
#: 0.6148, k_c the mean over the cell of the sum of squares of channel c's interpolation
#: weights (k_G = 5/8, k_R = k_B = 9/16). Read noise alone, of one variance in every channel,
#: has 0.899, 0.973 and 0.996 times g_c g_d (measured), which the model's one gain ignores.
DEMOSAIC_NOISE_GAIN = {"bilinear": 0.617, "malvar2004": 0.836, "menon2007": 1.001}

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


# --- A Bayer sensor's light from spectra ------------------------------------------------------
# t and each channel's against the monochrome sensor that K describes: channel c's pixel
# collects K_c = K[QE F_c] electrons per lux s m^2, the reference sensor K = K[QE_ref], both
# epc_fast.spectra.electrons_per_lux_s_m2 under the same illuminant on the same grid, and
# t_c = K_c / K. The CIE photopic V behind K comes from colour-science through epc_fast.spectra.

#: The channels' names, in the order of every triple.
_BAYER_CHANNELS = ("R", "G", "B")


@dataclass(frozen=True)
class BayerLight:
    """A Bayer sensor's light against the reference monochrome sensor, under one illuminant.

    transmittance : 1, t = (t_R + 2 t_G + t_B) / 4, the RGGB cell's mean electrons over the
        reference sensor's: evaluate's ``cfa_transmittance``.
    channel_transmittances : 1, (t_R, t_G, t_B), each channel's electrons over the reference
        sensor's (above 1 where the channel collects more than the reference).
    white_balance : 1, (t_G / t_R, 1, t_G / t_B), the gains that make the illuminant's white
        give equal channels, green's 1 (as raw converters state them).
    color_noise_gain : 1, :func:`epc_fast.cfa.color_noise_gain` of the channels and the
        luminance weights: evaluate's ``color_noise_gain``.
    electrons_per_lux_s_m2 : e-/(lux·s·m²), K of the reference monochrome sensor: evaluate's
        ``electrons_per_lux_s_m2``.
    """

    transmittance: float
    channel_transmittances: tuple
    white_balance: tuple
    color_noise_gain: float
    electrons_per_lux_s_m2: float


def bayer_light(filter_transmittances, illuminant="D50", quantum_efficiency=None,
                reference_quantum_efficiency=None, wavelengths_nm=None,
                luminance_weights=None) -> BayerLight:
    """A Bayer sensor's t, channels, white balance, colour noise gain and K from spectra.

    Parameters
    ----------
    filter_transmittances : sequence of three array_like or callable
        1, (R, G, B): each channel's filter transmittance in [0, 1], sampled on the grid or a
        function of wavelength in nm returning it. A camera's measured channel responses
        (silicon and filters together, each scaled to a peak of 1) go here with the peak
        quantum efficiency as ``quantum_efficiency``.
    illuminant : str or array_like
        As in :func:`epc_fast.spectra.electrons_per_lux_s_m2`: a key of
        ``colour.SDS_ILLUMINANTS`` (default "D50") or the relative spectral power (>= 0, any
        scale) sampled on ``wavelengths_nm``.
    quantum_efficiency : None, float, array_like or callable
        1, in [0, 1]: the quantum efficiency of the silicon under the filters; None for
        :func:`epc_fast.spectra.default_qe` (K's default sensor), a number for a flat QE.
    reference_quantum_efficiency : None, float, array_like or callable
        1, in [0, 1]: the reference monochrome sensor's quantum efficiency, the one K
        describes; None for ``quantum_efficiency`` (the same silicon with no filter).
    wavelengths_nm : array_like, optional
        nm, the sample grid, as in :func:`epc_fast.spectra.electrons_per_lux_s_m2` (default
        :data:`epc_fast.spectra.GRID_NM`; required when ``illuminant`` is an array).
    luminance_weights : sequence of three floats, optional
        1, (y_R, y_G, y_B), summing to 1: the luminance row of the colour correction;
        default :data:`epc_fast.cfa.DEFAULT_LUMINANCE_WEIGHTS`.

    Returns
    -------
    BayerLight
        Channel c collects t_c K electrons per lux·s·m², with t_c = K[QE·F_c] / K[QE_ref] and
        K[q] = :func:`epc_fast.spectra.electrons_per_lux_s_m2` (illuminant, q, wavelengths_nm).

    Raises
    ------
    ValueError, TypeError
        Naming the argument and its value: a filter or a QE outside [0, 1] or of the wrong
        length, a channel or a reference sensor that collects no electrons, weights that do
        not sum to 1; the illuminant's and the grid's errors are
        :func:`~epc_fast.spectra.electrons_per_lux_s_m2`'s.

    Notes
    -----
    Needs colour-science for the photopic V(λ) (and a named illuminant), as K does. evaluate
    takes ``cfa_transmittance`` in (0, 1]: a t above 1 (a sensor under the filters that
    collects more than the reference) is the same rate as ``electrons_per_lux_s_m2`` t K with
    ``cfa_transmittance`` 1, since t enters the model only through the rate t K.
    """
    from . import spectra

    grid = _grid_of(illuminant, wavelengths_nm)
    qe = (spectra.default_qe(grid) if quantum_efficiency is None
          else _light_on_grid("quantum_efficiency", quantum_efficiency, grid))
    qe_ref = qe if reference_quantum_efficiency is None else _light_on_grid(
        "reference_quantum_efficiency", reference_quantum_efficiency, grid)
    filters = _light_filters(filter_transmittances, grid)
    weights = _light_weights(luminance_weights if luminance_weights is not None
                       else DEFAULT_LUMINANCE_WEIGHTS)

    def electrons(q):
        return spectra.electrons_per_lux_s_m2(illuminant, q, wavelengths_nm)

    k_ref = electrons(qe_ref)
    if not k_ref > 0.0:
        name = "quantum_efficiency" if reference_quantum_efficiency is None \
            else "reference_quantum_efficiency"
        raise ValueError(f"{name}: the reference sensor collects no electrons under the "
                         f"illuminant (K = {k_ref!r}), got {short(qe_ref)}")
    channels = []
    for c, f in zip(_BAYER_CHANNELS, filters):
        k_c = electrons(qe * f)
        if not k_c > 0.0:
            raise ValueError(f"filter_transmittances: channel {c} collects no electrons under "
                             f"the illuminant with this quantum efficiency, got {short(f)}")
        channels.append(k_c / k_ref)
    t_r, t_g, t_b = channels
    return BayerLight(transmittance=(t_r + 2.0 * t_g + t_b) / 4.0,
                      channel_transmittances=(t_r, t_g, t_b),
                      white_balance=(t_g / t_r, 1.0, t_g / t_b),
                      color_noise_gain=color_noise_gain(channels, weights),
                      electrons_per_lux_s_m2=k_ref)


def _grid_of(illuminant, wavelengths_nm) -> np.ndarray:
    """The grid spectra samples on: GRID_NM for a named illuminant without a grid, else the
    given one (spectra checks it again, and refuses an array illuminant without one)."""
    from . import spectra

    if wavelengths_nm is None:
        if not isinstance(illuminant, str):
            raise ValueError("wavelengths_nm: required when illuminant is given as an array")
        return spectra.GRID_NM
    try:
        grid = np.array(wavelengths_nm, dtype=float)
    except (TypeError, ValueError):
        raise TypeError(f"wavelengths_nm: a 1-D array of numbers, got "
                        f"{short(wavelengths_nm)}") from None
    if grid.ndim != 1 or grid.size < 2 or not np.all(np.isfinite(grid)):
        raise ValueError(f"wavelengths_nm: a 1-D array of at least 2 finite numbers, got "
                         f"{short(wavelengths_nm)}")
    return grid


def _light_on_grid(name, values, grid) -> np.ndarray:
    """``values`` (a number, samples on the grid or a function of nm) as an array on the grid,
    every sample in [0, 1]."""
    if isinstance(values, (str, bytes, dict, bool)):
        raise TypeError(f"{name}: a number, an array or a callable, got {short(values)}")
    sampled = values(grid.copy()) if callable(values) else values
    try:
        array = np.array(sampled, dtype=float)
    except (TypeError, ValueError):
        raise TypeError(f"{name}: numbers, got {short(sampled)}") from None
    if array.ndim == 0:
        array = np.full(grid.shape, float(array))
    if array.shape != grid.shape:
        raise ValueError(f"{name}: {grid.size} samples (one per wavelength), got shape "
                         f"{array.shape}: {short(sampled)}")
    ok = np.isfinite(array) & (array >= 0.0) & (array <= 1.0)
    if not np.all(ok):
        bad = int(np.argmin(ok))
        raise ValueError(f"{name}: in [0, 1] (a fraction, not a percentage), got "
                         f"{array[bad]!r} at {grid[bad]:g} nm")
    return array


def _light_filters(filter_transmittances, grid) -> list:
    """The three filters on the grid."""
    if isinstance(filter_transmittances, (str, bytes, dict)) or callable(filter_transmittances):
        raise TypeError(f"filter_transmittances: three filters (R, G, B), got "
                        f"{short(filter_transmittances)}")
    try:
        filters = list(filter_transmittances)
    except TypeError:
        raise TypeError(f"filter_transmittances: three filters (R, G, B), got "
                        f"{short(filter_transmittances)}") from None
    if len(filters) != 3:
        raise ValueError(f"filter_transmittances: three filters (R, G, B), got {len(filters)}: "
                         f"{short(filter_transmittances)}")
    return [_light_on_grid(f"filter_transmittances[{i}] ({c})", f, grid)
            for i, (c, f) in enumerate(zip(_BAYER_CHANNELS, filters))]


def _light_weights(luminance_weights) -> np.ndarray:
    try:
        y = np.array(luminance_weights, dtype=float)
    except (TypeError, ValueError):
        y = None
    if y is None or y.shape != (3,) or not np.all(np.isfinite(y)) or abs(y.sum() - 1.0) > 1e-9:
        raise ValueError(f"luminance_weights: three finite weights (R, G, B) summing to 1, got "
                         f"{short(luminance_weights)}")
    return y
