"""The real-camera terms of a space as the core's fused pass reads them: its lens tables, a
colour sensor's demosaicker and colour columns, and the readout modes its designs share; or
None where the pass cannot read them, and each chunk's points are evaluated as arrays
(:mod:`epc_fast.scan.running.tasks`).

The fused pass gives every point the outputs :func:`epc_fast.evaluate` gives it, bit for bit:
the same tables, the same colour columns (a Bayer sensor's ``color_noise_gain`` times its
demosaicker's noise gain, :func:`epc_fast.cfa.sensor_color`) and the same one pass over the
modes (``evaluate(modes=...)``, :mod:`epc_fast.modes`). It cannot read:

- a quad Bayer sensor (its layout, table and gain follow each point's binning);
- a frame cap or night mode (:mod:`epc_fast.exposure_limits`: passes of their own);
- designs read in more than one way (each readout group is its own call);
- a drawn ``color_noise_gain`` under a colour filter (the core draws it unscaled);
- lens tables with a ``lens`` index that varies, or whose most permissive design the space
  does not bound (a normal or log-normal f-number, wavelength or pitch): the tables are
  checked against diffraction before the first point.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ... import params
from ...cfa import DEMOSAIC_NOISE_GAIN, sensor_color
from ...core_call import core_tables
from ...design import spectrum_of
from ...modes import core_codes
from ...mtf_table import check_lens_tables
from ..sampling.distributions import Choice, Empirical, Grid, LogUniform, Truncated, Uniform
from .readout_modes import readout_groups, readout_kwargs

__all__ = ["CameraTerms", "camera_terms"]


@dataclass(frozen=True)
class CameraTerms:
    """What the fused pass needs beyond the space's parameters.

    lens_tables : list of (knots, values, coefficients) or None, as ``_core.evaluate`` takes
        them (:func:`epc_fast.core_call.core_tables`).
    demosaic_table : one such triple or None.
    color : {slot: (default, scale)}: a colour column's value where the space does not give
        it, and the factor the values it gives take (the demosaicker's noise gain; 1 for the
        transmittance).
    modes : the designs' readout modes as the core takes them (:func:`epc_fast.modes.core_codes`),
        or None.
    set_by_modes : the parameters a mode sets, which the points take at their defaults.
    """

    lens_tables: list | None = None
    demosaic_table: tuple | None = None
    color: dict | None = None
    modes: list | None = None
    set_by_modes: frozenset = frozenset()


def camera_terms(space) -> CameraTerms | None:
    """The space's terms as the fused pass reads them, or None where it cannot (module
    docstring). A ValueError where a lens table lies above diffraction at the space's most
    permissive design, as :func:`epc_fast.evaluate` raises it for a point there."""
    options = space.evaluate_options
    cfa = options.get("cfa", "none")
    if cfa == "quad_bayer" or options.get("max_exposure_s", math.inf) != math.inf:
        return None
    modes, set_by_modes = None, frozenset()
    if space.has_modes:
        groups = readout_groups(space)
        if len(groups) != 1:
            return None
        _, readout, design_modes = groups[0]
        extra, set_by_modes = readout_kwargs(readout, design_modes)
        # (one mode, the design's own readout, index 0, where the designs list none)
        call = {"backend": "core", "invalid": "nan", "cfa": cfa, "max_exposure_s": math.inf,
                "max_frames": None, "frames": 1.0, "outputs": ("epc",)}
        modes = core_codes(call, tuple(extra.get("modes", ({},))), ("epc",), "motion")
        if modes is None:
            return None
    color = None
    demosaic = None
    if cfa != "none":
        demosaic_name = options.get("demosaic", "malvar2004")
        sensor = sensor_color(cfa, demosaic_name, None, None)
        if _kind(space, "color_noise_gain") == "drawn":
            return None
        color = {"cfa_transmittance": (sensor.transmittance, 1.0),
                 "color_noise_gain": (sensor.noise_gain, DEMOSAIC_NOISE_GAIN[demosaic_name])}
        demosaic = core_tables((sensor.demosaic_table,))[0]
    tables = options.get("lens_mtf")
    lens = None
    if tables is not None:
        index = _fixed(space, "lens", 0.0)
        f_number, pitch = _lowest(space, "f_number"), _lowest(space, "pixel_pitch_um")
        wavelength = _shortest_wavelength(space)
        if index is None or None in (f_number, pitch, wavelength):
            return None
        check_lens_tables(tables, f_number, wavelength, pitch, index)
        lens = core_tables(tables)
    return CameraTerms(lens, demosaic, color, modes, frozenset(set_by_modes))


def _kind(space, name: str) -> str:
    """How the space gives parameter ``name``: "fixed" (a number, a design constant, or not at
    all), "values" (a grid, a choice or the designs' column) or "drawn"."""
    if name in space.axes:
        axis = space.axes[name]
        if isinstance(axis, float):
            return "fixed"
        return "values" if isinstance(axis, (Grid, Choice)) else "drawn"
    if name in space.design_table and name not in space.design_constant:
        return "values"
    return "fixed"


def _fixed(space, name: str, default: float):
    """Parameter ``name``'s one value over the space, or None where it varies."""
    if name in space.axes:
        axis = space.axes[name]
        return float(axis) if isinstance(axis, float) else None
    if name in space.design_table:
        column = np.asarray(space.design_table[name], dtype=np.float64)
        return float(column[0]) if np.all(column == column[0]) else None
    return default


def _lowest(space, name: str):
    """The least value parameter ``name`` takes over the space (a bound its draws reach or
    approach), or None where the space does not bound it below (a normal or log-normal
    distribution)."""
    if name in space.axes:
        axis = space.axes[name]
        if isinstance(axis, float):
            return axis
        if isinstance(axis, (Grid, Choice)):
            return float(np.min(axis.values))
        if isinstance(axis, Truncated):
            parent = _distribution_low(axis.distribution)
            low = axis.low if parent is None else max(axis.low, parent)
            return low if math.isfinite(low) else None
        return _distribution_low(axis)
    if name in space.design_table:
        return float(np.min(space.design_table[name]))
    return float(params.PARAMETERS[params.PARAMETER_NAMES.index(name)].default)


def _distribution_low(distribution):
    if isinstance(distribution, (Uniform, LogUniform)):
        return float(distribution.low)
    if isinstance(distribution, Empirical):
        return float(np.min(distribution.samples))
    return None


def _shortest_wavelength(space):
    """The shortest wavelength (nm) of the space's points: its spectrum's shortest with a
    weight, or the least ``wavelength_nm``."""
    spectrum = space.evaluate_options.get("spectrum")
    if spectrum is None:
        return _lowest(space, "wavelength_nm")
    given = spectrum_of(spectrum)
    return float(np.min(given.wavelengths_nm[given.weights > 0.0]))
