"""Inverse problems over the forward model: the illuminance at which EPC does something.

:func:`lux_for_epc` finds where a design reaches a target EPC, :func:`crossover_lux` where two
designs have equal EPC. Both run Brent's method on u = ln L in the compiled core, vectorised over
designs and targets (``backend="core"``), or a bisection on u to adjacent floats written with
whole-array NumPy over the reference model (``backend="reference"``, the readable spec).

Conventions shared by both backends:

- The forward EPC is evaluate's under ``epc_axes``: the paper's 4 S f50^2 (``"motion"``, the
  default) or 4 S f50 f50_across (``"both"``; f50_across does not depend on the illuminance
  and is solved once, at the range's top). It counts a point whose SNR target is unreachable
  (``Status.UNREACHABLE``) as 0: no image. ``Status.BLUR_UNBOUNDED`` is EPC 0 already. An
  input outside its domain makes the inverse :attr:`InverseStatus.INVALID`.
- :func:`lux_for_epc` solves g(u) = EPC(e^u) - target on [ln lo, ln hi]. Where g(lo) >= 0 (the
  target is met already at the lowest illuminance) or g(hi) < 0 (never met), the answer is
  :attr:`InverseStatus.NO_SOLUTION`.
- :func:`crossover_lux` samples d(u) = EPC_a(e^u) - EPC_b(e^u) at ``grid_points`` log-spaced
  illuminances from lo to hi inclusive. Scanning from the top, the first pair of neighbouring
  non-zero samples with opposite signs (zero samples are skipped) brackets the highest crossing,
  which is then solved on u. No sign change: :attr:`InverseStatus.NO_SOLUTION`.
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass

import numpy as np

from . import params
from ._validation import as_float_array, choice, column, integer, short, threads_of, tolerance
from .axes import check_epc_axes
from .call_options import BACKENDS
from .design import DESIGN_KEYWORDS, resolve
from .status import Status

__all__ = ["InverseStatus", "InverseResult", "lux_for_epc", "crossover_lux", "DEFAULT_LUX_RANGE"]

#: lux, the default search range: from deep dusk to well past full sunlight.
DEFAULT_LUX_RANGE = (1e-2, 1e7)


class InverseStatus(enum.IntEnum):
    """What happened to one inverse problem. The values are shared with the C++ core."""

    OK = 0
    """Solved: the illuminance and the EPC there are finite."""
    INVALID = 1
    """An input of the design(s) is outside its domain, or the target EPC is not finite and > 0."""
    NO_SOLUTION = 2
    """No root in the illuminance range: illuminance and EPC are NaN."""


@dataclass(frozen=True)
class InverseResult:
    """The solution of an inverse problem, shaped like the broadcast inputs (scalars for scalars).

    Attributes
    ----------
    illuminance_lux : lux, the illuminance found; NaN unless the status is OK.
    epc : pixels, the EPC there (of the first design, for a crossover); NaN unless OK.
    status : :class:`InverseStatus` codes (uint8 array).
    """

    illuminance_lux: np.ndarray | float
    epc: np.ndarray | float
    status: np.ndarray | InverseStatus


def lux_for_epc(design: dict, target_epc, *, lux_range=DEFAULT_LUX_RANGE, backend="core",
                threads=None, rtol=1e-13, f50_rtol=1e-14, epc_axes="motion") -> InverseResult:
    """lux: the illuminance at which a design's EPC reaches ``target_epc``.

    Parameters
    ----------
    design : dict
        Keyword arguments of :func:`epc_fast.evaluate` except ``illuminance_lux`` (e.g.
        ``presets.Design.evaluate_kwargs()``); values broadcast against each other and against
        ``target_epc``. ``binning``, ``binning_readout``, ``frames`` and
        ``alignment_error_um`` are per point as in evaluate; ``modes`` is not taken (solve for
        each mode), nor ``lens_mtf`` (a design's EPC past its table's end is undefined:
        evaluate it over a grid of illuminances); ``cfa``, ``demosaic`` and the colour terms
        are evaluate's.
    target_epc : array_like
        pixels, the EPC to reach (finite and > 0).
    lux_range : (float, float)
        lux, the search range (lo, hi) with 0 < lo < hi < inf.
    backend : {"core", "reference"}
        Brent's method in the compiled core, or the NumPy reference (bisection to adjacent floats,
        which ignores ``rtol`` and ``f50_rtol``).
    threads : int, optional
        Core threads; default ``OMP_NUM_THREADS`` or the number of cores.
    rtol : float
        1, Brent's tolerance on ln L, i.e. relative on L.
    f50_rtol : float
        1, relative tolerance of every forward f50 bisection.
    epc_axes : {"motion", "both"}
        The EPC solved for, as :func:`epc_fast.evaluate` counts it.

    Returns
    -------
    InverseResult
        NO_SOLUTION where the design already reaches the target at ``lo`` or not yet at ``hi``.
    """
    inputs = model_inputs(design)
    target = as_float_array("target_epc", target_epc)
    shape = _broadcast_shape({"design": inputs.shape, "target_epc": target.shape})
    lux_lo, lux_hi = _lux_range(lux_range)
    choice("backend", backend, BACKENDS)
    rtol = tolerance("rtol", rtol)
    f50_rtol = tolerance("f50_rtol", f50_rtol)
    columns = inputs.columns(shape)
    targets = column(target, shape)
    n = math.prod(shape)
    across = _f50_across(design, epc_axes, shape, lux_hi, backend, threads, f50_rtol)
    if backend == "core":
        from . import _core

        core_columns, domains = columns, params.domain_table()
        out = _core.lux_for_epc(core_columns, inputs.size_is_pixel_count, domains,
                                *inputs.spectrum_arrays(), n, targets, lux_lo, lux_hi, rtol,
                                f50_rtol, threads_of(threads),
                                demosaic_table=inputs.demosaic_argument(), f50_across=across)
    else:
        _check_threads(threads)
        out = _reference_lux_for_epc(_Model(inputs, columns, across),
                                     np.broadcast_to(targets, (n,)), lux_lo, lux_hi)
    return _result(out, shape)


def crossover_lux(design_a: dict, design_b: dict, *, lux_range=DEFAULT_LUX_RANGE,
                  grid_points=64, backend="core", threads=None, rtol=1e-13,
                  f50_rtol=1e-14, epc_axes="motion") -> InverseResult:
    """lux: the highest illuminance in ``lux_range`` at which two designs have equal EPC.

    Parameters
    ----------
    design_a, design_b : dict
        Keyword arguments of :func:`epc_fast.evaluate` except ``illuminance_lux``; the two
        broadcast against each other (pairs of designs). A ``spectrum``, if any, must be the
        same in both.
    lux_range : (float, float)
        lux, the search range (lo, hi) with 0 < lo < hi < inf.
    grid_points : int
        Log-spaced samples of EPC_a - EPC_b over ``lux_range`` (>= 2) that bracket the crossing:
        two crossings closer than one grid step can hide each other.
    backend, threads, rtol, f50_rtol, epc_axes
        As for :func:`lux_for_epc`.

    Returns
    -------
    InverseResult
        The crossing and EPC_a there; NO_SOLUTION where the sampled difference never changes
        sign (one design is better over the whole range, or the two are equal).
    """
    a, b = model_inputs(design_a), model_inputs(design_b)
    if not a.same_spectrum(b):
        raise ValueError("design_a and design_b must have the same spectrum (or neither one)")
    shape = _broadcast_shape({"design_a": a.shape, "design_b": b.shape})
    lux_lo, lux_hi = _lux_range(lux_range)
    grid_points = _grid_points(grid_points)
    choice("backend", backend, BACKENDS)
    rtol = tolerance("rtol", rtol)
    f50_rtol = tolerance("f50_rtol", f50_rtol)
    columns_a, columns_b = a.columns(shape), b.columns(shape)
    n = math.prod(shape)
    across_a = _f50_across(design_a, epc_axes, shape, lux_hi, backend, threads, f50_rtol)
    across_b = _f50_across(design_b, epc_axes, shape, lux_hi, backend, threads, f50_rtol)
    if backend == "core":
        from . import _core

        domains = params.domain_table()
        out = _core.crossover_lux(columns_a, columns_b, a.size_is_pixel_count,
                                  b.size_is_pixel_count, domains,
                                  *a.spectrum_arrays(), n, lux_lo, lux_hi, grid_points, rtol,
                                  f50_rtol, threads_of(threads),
                                  demosaic_table_a=a.demosaic_argument(),
                                  demosaic_table_b=b.demosaic_argument(),
                                  f50_across_a=across_a, f50_across_b=across_b)
    else:
        _check_threads(threads)
        out = _reference_crossover_lux(_Model(a, columns_a, across_a),
                                       _Model(b, columns_b, across_b), n, lux_lo, lux_hi,
                                       grid_points)
    return _result(out, shape)


# --- Arguments ------------------------------------------------------------------------------


def _f50_across(design: dict, epc_axes, shape, lux, backend, threads, f50_rtol):
    """cycles/mm, the design's f50 across the motion as a column of ``shape`` (it does not
    depend on the illuminance: solved at ``lux``) for ``epc_axes="both"``; None for
    ``"motion"``."""
    if check_epc_axes(epc_axes) == "motion":
        return None
    from .api import evaluate

    f50 = evaluate(lux, **design, outputs=("f50_across_cyc_per_mm",), backend=backend,
                   threads=threads, f50_rtol=f50_rtol).f50_across_cyc_per_mm
    return column(np.asarray(f50, dtype=np.float64), shape)


def _lux_range(lux_range) -> tuple[float, float]:
    """lux: (lo, hi), validated."""
    try:
        lo, hi = (float(x) for x in lux_range)
    except (TypeError, ValueError):
        raise TypeError(f"lux_range must be a pair of numbers (lo, hi), got "
                        f"{short(lux_range)}") from None
    if not 0.0 < lo < hi < math.inf:
        raise ValueError(f"lux_range must satisfy 0 < lo < hi < inf, got {lux_range!r}")
    return lo, hi


def _grid_points(value) -> int:
    count = integer("grid_points", value)
    if count < 2:
        raise ValueError(f"grid_points must be at least 2, got {count}")
    return count


def _check_threads(threads) -> None:
    """The reference runs on one thread but validates ``threads=`` like the core."""
    if threads is not None:
        threads_of(threads)


def _broadcast_shape(shapes: dict) -> tuple:
    try:
        return np.broadcast_shapes(*shapes.values())
    except ValueError:
        text = ", ".join(f"{name}{shape}" for name, shape in shapes.items())
        raise ValueError(f"the shapes do not broadcast: {text}") from None


# --- A design's keywords as model columns ----------------------------------------------------
# The inverse solvers take a design as evaluate()'s keywords without the illuminance, resolved
# as evaluate() resolves them (epc_fast.design.resolve).

_DESIGN_KEYWORDS = frozenset(DESIGN_KEYWORDS) - {"illuminance_lux", "lens", "lens_mtf"}


@dataclass(frozen=True)
class ModelInputs:
    """A design's model parameters as float64 arrays in :data:`params.PARAMETERS` order.

    The illuminance slot holds a placeholder 0 (the solvers choose the illuminance).
    """

    arrays: tuple
    shape: tuple
    size_is_pixel_count: bool
    spectrum: object
    #: a colour sensor's demosaicker's table (epc_fast.cfa), None for the monochrome sensor
    demosaic_table: object = None

    def demosaic_argument(self):
        """The demosaicker's table as the core takes it (epc_fast.core_call.core_tables)."""
        from .core_call import core_tables

        return None if self.demosaic_table is None else core_tables((self.demosaic_table,))[0]

    def columns(self, shape) -> list:
        """Contiguous 1-D columns of size 1 or prod(shape), as the core takes them."""
        return [column(a, shape) for a in self.arrays]

    def same_spectrum(self, other: "ModelInputs") -> bool:
        """Whether both are monochromatic, or share the same wavelengths and weights."""
        if self.spectrum is None or other.spectrum is None:
            return self.spectrum is other.spectrum
        return all(np.array_equal(x, y) for x, y in zip(self.spectrum_arrays(),
                                                        other.spectrum_arrays()))

    def spectrum_arrays(self) -> tuple:
        """(wavelengths_nm, weights) as the core takes them: empty for monochromatic."""
        if self.spectrum is None:
            return np.empty(0), np.empty(0)
        return (np.ascontiguousarray(self.spectrum.wavelengths_nm, dtype=np.float64),
                np.ascontiguousarray(self.spectrum.weights, dtype=np.float64))


def model_inputs(design: dict) -> ModelInputs:
    """A design (evaluate() keywords without the illuminance) as :class:`ModelInputs`.

    The sensor's size and where the SNR target is met are given as to evaluate():
    ``pixel_count``, ``sensor_area_mm2``, ``sensor_width_mm`` and ``sensor_height_mm``, or
    ``sensor_diagonal_mm`` and ``aspect``; ``snr_at`` or ``field_angle_deg``.

    Raises TypeError for an unknown or missing keyword, or for a sensor size given in no way
    or in more than one; ValueError where the shapes do not broadcast.
    """
    if "lens_mtf" in design:
        raise TypeError("lens_mtf: the inverse solvers take no lens tables (a design's EPC is "
                        "undefined where its f50 passes its table's end, status BEYOND_TABLE); "
                        "evaluate the design over a grid of illuminances instead")
    if "modes" in design:
        raise TypeError("modes: the inverse solvers take one readout a design; solve for "
                        "each mode (a design with that mode's binning, frames, ...) and take "
                        "the lowest illuminance")
    if "max_exposure_s" in design:
        raise TypeError("max_exposure_s: the inverse solvers take no frame cap (EPC is NaN over "
                        "it, status EXPOSURE_LIMIT); solve without it and compare the T_MPE / "
                        "frames evaluate gives at the illuminance found with the cap")
    if "max_frames" in design or isinstance(design.get("frames"), str):
        raise TypeError("frames='auto' and max_frames: the inverse solvers take a whole number "
                        "of frames (night mode picks one per point); solve for each")
    unknown = sorted(set(design) - _DESIGN_KEYWORDS)
    if unknown:
        raise TypeError(f"a design holds evaluate()'s model keywords except illuminance_lux; "
                        f"got {', '.join(unknown)}")
    resolved = resolve(0.0, **design)
    return ModelInputs(tuple(resolved.arrays), resolved.shape,
                       resolved.sensor.is_pixel_count, resolved.spectrum,
                       resolved.color.demosaic_table)


# --- The NumPy reference --------------------------------------------------------------------


@dataclass(frozen=True)
class _Model:
    """One design's columns, evaluated by the reference at chosen illuminances."""

    inputs: ModelInputs
    columns: list
    #: cycles/mm, each point's f50 across the motion (epc_axes="both"), or None
    across: np.ndarray | None = None

    def epc(self, lux, repeat=1):
        """pixels: EPC at ``lux``, 0 where the SNR target is unreachable, NaN where invalid.

        ``lux`` is 1-D with ``repeat`` consecutive entries per design point.
        """
        from .reference.call import run_reference  # the NumPy reference, loaded when asked

        columns = [np.repeat(c, repeat) if c.size > 1 else c for c in self.columns[1:]]
        out = run_reference([lux, *columns], lux.shape, self.inputs.size_is_pixel_count,
                            self.inputs.spectrum, demosaic_table=self.inputs.demosaic_table)
        epc = out["epc"]
        if self.across is not None:  # 4 S f50 f50_across = EPC f50_across / f50
            across = np.repeat(self.across, repeat) if self.across.size > 1 else self.across
            with np.errstate(invalid="ignore", divide="ignore"):
                epc = np.where(out["f50_cyc_per_mm"] > 0.0,
                               epc * (across / out["f50_cyc_per_mm"]), epc)
        return np.where(out["status"] == Status.UNREACHABLE, 0.0, epc)


def _bisect_log_lux(g, u_lo, u_hi, sign_lo):
    """u where g changes sign in [u_lo, u_hi], halved until the ends are adjacent floats.

    ``sign_lo`` is the sign of g at ``u_lo`` (+1 or -1, per lane); a lane whose ends are NaN
    is left alone and returns NaN. A zero of g counts as the ``u_hi`` side.
    """
    while True:
        mid = u_lo + 0.5 * (u_hi - u_lo)
        active = (mid > u_lo) & (mid < u_hi)
        if not active.any():
            return mid
        on_lo_side = np.sign(g(mid)) == sign_lo
        u_lo = np.where(active & on_lo_side, mid, u_lo)
        u_hi = np.where(active & ~on_lo_side, mid, u_hi)


def _reference_lux_for_epc(model: _Model, target, lux_lo, lux_hi) -> dict:
    n = target.size
    g_lo = model.epc(np.full(n, lux_lo)) - target
    g_hi = model.epc(np.full(n, lux_hi)) - target
    invalid = ~(np.isfinite(target) & (target > 0)) | np.isnan(g_lo) | np.isnan(g_hi)
    status = np.select([invalid, (g_lo >= 0) | (g_hi < 0)],
                       [InverseStatus.INVALID, InverseStatus.NO_SOLUTION], InverseStatus.OK)
    solve = status == InverseStatus.OK
    u = _bisect_log_lux(lambda v: model.epc(np.exp(v)) - target,
                        np.where(solve, math.log(lux_lo), np.nan),
                        np.where(solve, math.log(lux_hi), np.nan), -1.0)
    lux = np.exp(u)
    return {"illuminance_lux": lux, "epc": model.epc(lux), "status": status.astype(np.uint8)}


def _highest_sign_change(d):
    """Per row of ``d``: indices (j, k) of the highest pair of neighbouring non-zero samples
    with opposite signs (zeros between them skipped), and whether there is one."""
    rows, count = d.shape
    sign = np.sign(d)
    index = np.arange(count)
    # next_nonzero[:, j]: the index of the first non-zero sample above j (count: none).
    marks = np.where(sign != 0, index, count)
    at_or_above = np.minimum.accumulate(marks[:, ::-1], axis=1)[:, ::-1]
    next_nonzero = np.concatenate([at_or_above[:, 1:], np.full((rows, 1), count)], axis=1)
    partner = np.take_along_axis(sign, np.minimum(next_nonzero, count - 1), axis=1)
    change = (next_nonzero < count) & (sign * partner < 0)
    found = change.any(axis=1)
    j = count - 1 - np.argmax(change[:, ::-1], axis=1)
    k = np.where(found, next_nonzero[np.arange(rows), j], j)
    return j, k, found


def _log_lux_grid(lux_lo, lux_hi, grid_points):
    """ln lux: ``grid_points`` equally spaced from ln lo to ln hi, both ends exact."""
    u_lo, u_hi = math.log(lux_lo), math.log(lux_hi)
    grid = u_lo + (u_hi - u_lo) * np.arange(grid_points) / (grid_points - 1)
    grid[-1] = u_hi
    return grid


def _reference_crossover_lux(a: _Model, b: _Model, n, lux_lo, lux_hi, grid_points) -> dict:
    grid = _log_lux_grid(lux_lo, lux_hi, grid_points)
    lux_grid = np.tile(np.exp(grid), n)
    d = (a.epc(lux_grid, grid_points) - b.epc(lux_grid, grid_points)).reshape(n, grid_points)
    invalid = np.isnan(d).any(axis=1)
    j, k, found = _highest_sign_change(np.where(invalid[:, None], 0.0, d))
    status = np.select([invalid, ~found], [InverseStatus.INVALID, InverseStatus.NO_SOLUTION],
                       InverseStatus.OK)
    solve = status == InverseStatus.OK
    sign_lo = np.sign(d[np.arange(n), j])
    u = _bisect_log_lux(lambda v: a.epc(np.exp(v)) - b.epc(np.exp(v)),
                        np.where(solve, grid[j], np.nan), np.where(solve, grid[k], np.nan),
                        sign_lo)
    lux = np.exp(u)
    return {"illuminance_lux": lux, "epc": a.epc(lux), "status": status.astype(np.uint8)}


# --- Results ----------------------------------------------------------------------------------


def _result(out: dict, shape) -> InverseResult:
    if shape == ():
        return InverseResult(float(out["illuminance_lux"][0]), float(out["epc"][0]),
                             InverseStatus(int(out["status"][0])))
    return InverseResult(out["illuminance_lux"].reshape(shape), out["epc"].reshape(shape),
                         out["status"].reshape(shape))
