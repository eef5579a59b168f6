"""A design space: each model parameter fixed, on a grid, or random, and a ``design`` axis.

Random parameter ``name``'s value at point i is its distribution's inverse CDF at one uniform,
from Philox4x32-10 keyed by the seed at the counter ``(j mod 2^32, j div 2^32, crc32(name), 0)``
of i's pair ``j = i div 2``, words (x0, x1) for an even i and (x2, x3) for an odd one
(:mod:`epc_fast.scan.sampling.streams`; a choice of designs is the parameter ``"design"``); grid
axes take point i to grid cell ``i mod grid size``. So a point's parameters depend only on the seed
and the point's index, never on the chunk size, the thread count or the machine that evaluates
it, a scan of n points is the prefix of a longer one, and adding a random parameter leaves the
others' draws unchanged. A chunk is a whole number of :data:`BLOCK_POINTS` points.
"""

from __future__ import annotations

import math
import textwrap
from dataclasses import dataclass

import numpy as np

from ...cfa import quad_bayer_binning
from ...exposure_limits import check_scan_cap
from ...modes import MODE_DEFAULTS
from ...mtf_table import lens_tables_of
from ...params import PARAMETER_NAMES, PARAMETERS, READOUT_CODES, SIZE_PARAMETERS, readout_codes
from ...sensor import SHAPE_KEYWORDS, SIZE_AND_SNR_AT, SIZE_WAYS
from . import qmc, streams
from ... import terms
from .distributions import Choice, Grid
from ..designs import design_dict, fill_left_out
from ..running.readout_modes import READOUT_KEYS, design_readout
from .domains import domain_of, inside_probability, domain_problem

__all__ = ["Space", "Points", "BLOCK_POINTS", "domain_problem"]

#: Points per block: chunks are whole numbers of blocks, which fixes the order in which the
#: reductions merge them.
BLOCK_POINTS = 1 << 16

#: The per-point keyword parameters of :func:`epc_fast.evaluate`.
POINT_PARAMETERS = tuple(n for n in PARAMETER_NAMES if n != "size") + SIZE_PARAMETERS
REQUIRED_PARAMETERS = ("illuminance_lux", "pixel_pitch_um", "f_number", "focal_length_mm")
#: The smallest share of a distribution's draws outside the domain that
#: :meth:`Space.describe` reports.
MIN_REPORTED_SHARE = 1e-6
#: Characters per line of :meth:`Space.describe`.
DESCRIBE_WIDTH = 100
#: Keyword options of :func:`epc_fast.evaluate` that a space may fix for every point.
EVALUATE_OPTIONS = ("spectrum", "f50_solver", "f50_rtol", "t_mpe_solver", "t_mpe_rtol",
                    "precision", "lens_mtf", "cfa", "demosaic", "epc_axes", "max_exposure_s")


@dataclass
class Points:
    """Points ``start .. stop - 1`` of a scan, or any points of it (:meth:`Space.points_at`).

    Attributes
    ----------
    start, stop : point indices; None for points that are not a range.
    index : int64 array, the point indices.
    parameters : {name: float or float64 array}, keyword arguments for :func:`epc_fast.evaluate`.
    indices : {axis name: int array}, each discrete axis's value index (``design``, grid and
        choice parameters).
    """

    start: int | None
    stop: int | None
    index: np.ndarray
    parameters: dict
    indices: dict

    def __len__(self) -> int:
        return self.index.size


def _readout_axis(axis):
    """A ``binning_readout`` axis with its names (``"digital"``, ``"charge"``) as their codes
    (:data:`epc_fast.params.READOUT_CODES`): a name, or a Grid or Choice of them."""
    if isinstance(axis, Grid):
        return Grid(tuple(np.atleast_1d(readout_codes(list(axis.values)))))
    if isinstance(axis, Choice):
        return Choice(tuple(np.atleast_1d(readout_codes(list(axis.values)))), axis.weights)
    return readout_codes(axis) if isinstance(axis, str) else axis


def _readout_text(readout: str, modes) -> str:
    """``"; charge binning"``, ``"; modes: binning=1 | binning=4"``: a design's readout, for
    people; empty for the default."""
    text = "" if readout == MODE_DEFAULTS["binning_readout"] else f"; {readout} binning"
    if modes:
        text += "; modes: " + " | ".join(
            ", ".join(f"{k}={v}" if isinstance(v, str) else f"{k}={v:g}" for k, v in m.items())
            or "the design's own" for m in modes)
    return text


class Space:
    """A design space for :func:`epc_fast.scan.run`.

    Parameters
    ----------
    design : sequence, Grid or Choice of designs, optional
        Designs (:class:`epc_fast.presets.Design` or mappings of :func:`epc_fast.evaluate`
        parameters, with an optional ``"name"``, the sensor given any way
        :func:`epc_fast.evaluate` takes it, and ``snr_at``). A plain sequence is a grid axis. A
        parameter some designs give and others leave out takes in those the value evaluate
        gives that design alone: its default, under ``cfa="bayer"`` the colour filter's
        ``cfa_transmittance`` and ``color_noise_gain`` (:mod:`epc_fast.scan.designs`).
    evaluate_options : mapping, optional
        Options of :func:`epc_fast.evaluate` shared by every point: ``spectrum``, ``f50_rtol``,
        ``t_mpe_solver``, ``t_mpe_rtol``, ``lens_mtf`` (a lens table or a list of them, which
        ``lens`` picks per point), ``cfa`` and ``demosaic`` (a colour sensor), ``epc_axes``
        (how EPC counts the resolution: ``"both"`` is evaluated as arrays, not in the core's
        fused pass), ``max_exposure_s`` (a frame cap, one value: EXPOSURE_LIMIT counted).
    **parameters : float, Grid, Choice or a distribution
        Any per-point parameter of :func:`epc_fast.evaluate`, in its unit: a number (fixed), a
        :class:`Grid`, a :class:`Choice` or a distribution (:class:`Uniform`,
        :class:`LogUniform`, :class:`Normal`, :class:`LogNormal`, :class:`Truncated`,
        :class:`Empirical`). A parameter given here replaces the designs' value of it;
        parameters given nowhere take evaluate's defaults.

    Every value is checked here, before any point: each parameter against its domain
    (:func:`domain_problem`), the designs' names (each its own, with a letter or digit) and the
    sensor's size (given once, by the designs or as a parameter); a ValueError or TypeError
    names the parameter or design, the value and what is expected.
    """

    def __init__(self, design=None, evaluate_options=None, **parameters):
        unknown = sorted(set(parameters) - set(POINT_PARAMETERS))
        readout = [name for name in unknown if name in READOUT_KEYS]
        if readout:
            raise TypeError(f"{readout[0]} is how a design's sensor is read, one per design: "
                            "give it in each design (a [[design.custom]] key, a Design field)")
        if unknown:
            extra = ("; a sensor's width, height, diagonal and aspect are given per design"
                     if set(unknown) & set(SHAPE_KEYWORDS) else "")
            raise TypeError(f"unknown parameter(s) {', '.join(unknown)}; the parameters are "
                            f"{', '.join(POINT_PARAMETERS)}{extra}")
        self.axes: dict = {}
        self.design_names: tuple[str, ...] = ()
        #: Where each design meets the SNR target, for people (``"corner (27.03 deg)"``).
        self.design_snr_at: tuple[str, ...] = ()
        self.design_table: dict[str, np.ndarray] = {}
        #: Per design: how its sensor is read (``"digital"`` or ``"charge"``) and its readout
        #: modes (a tuple of dicts, :mod:`epc_fast.modes`; None: the design's own readout).
        self.design_readout: tuple[str, ...] = ()
        self.design_modes: tuple = ()
        self.design_varying: tuple[str, ...] = ()
        self.design_constant: tuple[str, ...] = ()
        if design is not None:
            self._set_designs(design, overridden=set(parameters),
                              cfa=(evaluate_options or {}).get("cfa", "none"))
        for name, axis in parameters.items():
            self.axes[name] = self._checked_axis(name, axis)
        self.evaluate_options = dict(evaluate_options or {})
        bad = sorted(set(self.evaluate_options) - set(EVALUATE_OPTIONS))
        if bad:
            raise TypeError(f"unknown evaluate option(s) {', '.join(bad)}; the options are "
                            f"{', '.join(EVALUATE_OPTIONS)}")
        if self.evaluate_options.get("lens_mtf") is not None:
            self.evaluate_options["lens_mtf"] = self._lens_tables()
        if "max_exposure_s" in self.evaluate_options:  # a frame cap: one value a scan
            self.evaluate_options["max_exposure_s"] = check_scan_cap(
                self.evaluate_options["max_exposure_s"])
        self._check_required()
        self._check_domains()
        self.grid_axes = tuple(n for n, a in self.axes.items() if isinstance(a, Grid))
        self.grid_shape = tuple(len(self.axes[n].values) for n in self.grid_axes)
        #: How the random parameters are sampled (:class:`epc_fast.scan.sampling.qmc.Sampling`):
        #: plain Monte Carlo in one replicate here; :func:`epc_fast.scan.run` scans a copy
        #: (:meth:`sampled`) with its own.
        self.sampling = qmc.Sampling("monte_carlo", 1)
        self._sobol_tables: dict = {}

    def sampled(self, sampling: "qmc.Sampling") -> "Space":
        """A copy of the space that samples as ``sampling`` says (the same axes and designs).
        A ValueError when Sobol' sampling meets more random parameters than its direction
        numbers cover."""
        if sampling.sobol and len(self.random_axes) > qmc.MAX_DIMENSIONS:
            raise ValueError(f"sampling='sobol' covers up to {qmc.MAX_DIMENSIONS} random "
                             f"parameters; this space has {len(self.random_axes)}")
        copy = object.__new__(Space)
        copy.__dict__.update(self.__dict__)
        copy.sampling = sampling
        copy._sobol_tables = {}
        return copy

    @property
    def random_axes(self) -> tuple[str, ...]:
        """The random parameters (choices included), in order: their Sobol' dimensions."""
        return tuple(n for n, a in self.axes.items() if not isinstance(a, (float, Grid)))

    def sobol_tables(self, seed: int) -> tuple[np.ndarray, np.ndarray]:
        """(direction numbers (dimensions, 32), scrambling keys (replicates, dimensions)),
        uint32, of this space's Sobol' sampling under ``seed``."""
        if seed not in self._sobol_tables:
            dimensions = len(self.random_axes)
            self._sobol_tables = {seed: (qmc.direction_numbers(dimensions), qmc.scramble_keys(
                seed, self.sampling.replicates, dimensions))}
        return self._sobol_tables[seed]

    def _set_designs(self, design, overridden: set, cfa):
        axis = design if isinstance(design, (Grid, Choice)) else Grid(tuple(design))
        resolved = [design_dict(d, i) for i, d in enumerate(axis.values)]
        entries = [{k: v for k, v in entry.items() if k not in overridden}
                   for entry, _ in resolved]
        readouts = [design_readout(entry, overridden) for entry in entries]
        self.design_readout = tuple(readout for readout, _ in readouts)
        self.design_modes = tuple(modes for _, modes in readouts)
        self.design_snr_at = tuple(where for _, where in resolved)
        names = fill_left_out(entries, cfa)  # (a Bayer design's, the colour filter's)
        unknown = sorted(names - set(POINT_PARAMETERS))
        if unknown:
            raise TypeError(f"designs give unknown parameter(s) {', '.join(unknown)}; a design "
                            f"gives parameters of epc_fast.evaluate ({', '.join(POINT_PARAMETERS)}"
                            f"), its sensor as {', '.join(SHAPE_KEYWORDS)}, and snr_at")
        self.design_names = tuple(str(e["name"]) for e in entries)
        for position, name in enumerate(self.design_names):
            if not any(c.isalnum() for c in name):
                raise ValueError(f"design {position}'s name is {name!r}: expected a name with a "
                                 "letter or digit")
            first = self.design_names.index(name)
            if first != position:
                raise ValueError(f"design names must differ: {name!r} is the name of designs "
                                 f"{first} and {position}")
        self.design_table = {n: np.array([float(e[n]) for e in entries]) for n in sorted(names)}
        self.design_varying = tuple(n for n, v in self.design_table.items() if np.any(v != v[0]))
        self.design_constant = tuple(n for n in self.design_table if n not in self.design_varying)
        self.axes["design"] = type(axis)(**{**vars(axis), "values": self.design_names})

    @staticmethod
    def _checked_axis(name, axis):
        if name == "binning_readout":  # its names, "digital" and "charge", as their codes
            axis = _readout_axis(axis)
        if isinstance(axis, (Grid, Choice)):
            values = np.asarray(axis.values)
            if values.dtype.kind not in "iuf":
                raise TypeError(f"{name}'s values must be numbers, got {axis.values!r}")
            return axis
        if hasattr(axis, "from_uniform"):
            return axis
        try:
            return float(axis)
        except (TypeError, ValueError):
            raise TypeError(f"{name} must be a number, a Grid, a Choice or a distribution, "
                            f"got {axis!r}") from None

    def _check_required(self):
        given = set(self.axes) | set(self.design_table)
        missing = [n for n in REQUIRED_PARAMETERS if n not in given]
        if missing:
            raise TypeError(f"the space does not give {', '.join(missing)}")
        sizes = [n for n in SIZE_PARAMETERS if n in given]
        if not sizes and self.design_names:
            raise TypeError(f"design {self.design_names[0]!r} gives no sensor size: give it in "
                            f"the design, one of four ways: {SIZE_WAYS}; {SIZE_AND_SNR_AT}")
        if not sizes:
            raise TypeError("the space gives no sensor size: give pixel_count or "
                            "sensor_area_mm2, or designs that give it one of four ways: "
                            f"{SIZE_WAYS}; {SIZE_AND_SNR_AT}")
        if len(sizes) != 1:
            raise TypeError(f"give exactly one of {' and '.join(SIZE_PARAMETERS)} "
                            f"(given: {sizes or 'neither'})")

    def _lens_tables(self) -> tuple:
        """The space's checked lens tables; a ValueError for a wavefront error beside them."""
        given = ("wavefront_rms_waves" in self.axes and self.axes["wavefront_rms_waves"] != 0.0
                 or np.any(self.design_table.get("wavefront_rms_waves", 0.0) != 0.0))
        if given:
            raise ValueError("give lens_mtf or wavefront_rms_waves, not both: a lens's MTF "
                             "table includes its aberrations")
        return lens_tables_of(self.evaluate_options["lens_mtf"])

    @property
    def lens_count(self) -> int:
        """The number of lens tables (``lens`` takes 0 .. lens_count - 1); 1 without them."""
        return len(self.evaluate_options.get("lens_mtf") or ()) or 1

    def _check_domains(self):
        """A ValueError naming the parameter, its value and its domain when a fixed value, a
        grid's or a choice's value, a distribution or a design's value lies outside the
        parameter's domain (:func:`domain_problem`): refused before the first point."""
        for name, axis in self.axes.items():
            problem = (None if name == "design"
                       else domain_problem(name, axis, self.lens_count))
            if problem:
                raise ValueError(f"{name} = {problem}")
        for name, values in self.design_table.items():
            for design, value in zip(self.design_names, values):
                problem = domain_problem(name, float(value), self.lens_count)
                if problem:
                    raise ValueError(f"design {design!r}: {name} = {problem}")
        if self.evaluate_options.get("cfa") == "quad_bayer":  # one layout for every point
            axis = self.axes.get("binning")
            quad_bayer_binning(np.array([*self.design_table.get("binning", ()), *getattr(
                axis, "values", () if axis is None or not isinstance(axis, float) else (axis,))]))

    @property
    def has_modes(self) -> bool:
        """Whether a design lists readout modes: then each chunk's points are evaluated per
        design's modes (:mod:`epc_fast.scan.running.readout_modes`), not by the core's fused
        pass, and the scan keeps each point's mode (a design's ``binning_readout`` is one of
        its columns)."""
        return any(m is not None for m in self.design_modes)

    @property
    def mode_count(self) -> int:
        """The most readout modes a design lists (1 for a design without modes)."""
        return max((len(m) if m is not None else 1 for m in self.design_modes), default=1)

    @property
    def grid_size(self) -> int:
        """Points in one pass over every combination of the grid axes (1 without grids)."""
        return math.prod(self.grid_shape)

    @property
    def is_random(self) -> bool:
        """Whether any parameter or the design is drawn at random."""
        return any(not isinstance(a, (float, Grid)) for a in self.axes.values())

    @property
    def discrete_axes(self) -> tuple[str, ...]:
        """Names of the grid and choice axes, whose value index is a group key."""
        return tuple(n for n, a in self.axes.items() if isinstance(a, (Grid, Choice)))

    @property
    def varying_parameters(self) -> tuple[str, ...]:
        """Parameters that are not the same at every point."""
        varying = [n for n, a in self.axes.items() if n != "design" and not isinstance(a, float)]
        return tuple(varying) + self.design_varying

    def axis_values(self, name: str) -> tuple:
        """The values of a discrete axis (design names on the ``design`` axis)."""
        return self.axes[name].values

    def points(self, seed: int, start: int, stop: int) -> Points:
        """The parameters of points ``start .. stop - 1``; ``start`` is a whole block."""
        if start % BLOCK_POINTS or not 0 <= start < stop:
            raise ValueError(f"a range of points starts at a block ({BLOCK_POINTS} points) and "
                             f"is not empty, got {start} .. {stop}")
        index = np.arange(start, stop, dtype=np.int64)
        indices, parameters = self._grid_columns(start, stop - start)
        self._replicate_column(index, indices)
        self._drawn_columns(seed, index, indices, parameters)
        return Points(start, stop, index, parameters, indices)

    def points_at(self, seed: int, index) -> Points:
        """The parameters of the points ``index`` (int array_like of point indices >= 0, in any
        order, repeats allowed): the same values as :meth:`points` gives them."""
        index = np.asarray(index, dtype=np.int64).reshape(-1)
        if index.size and index.min() < 0:
            raise ValueError(f"point indices are >= 0, got {index.min()}")
        indices, parameters = {}, {}
        if self.grid_axes:
            indices, parameters = self._grid_cells(index % self.grid_size)
        self._replicate_column(index, indices)
        self._drawn_columns(seed, index, indices, parameters)
        return Points(None, None, index, parameters, indices)

    def _replicate_column(self, index: np.ndarray, indices: dict):
        """Adds each point's replicate, (i div grid size) mod replicates, as ``"replicate"``."""
        if self.sampling.replicates > 1:
            indices["replicate"] = qmc.positions(index, self.grid_size,
                                                 self.sampling.replicates)[1]

    def _uniforms(self, seed: int, name: str, index: np.ndarray) -> np.ndarray:
        """The uniforms of random parameter ``name`` at points ``index``: its name's Philox
        stream, or its Sobol' dimension (:mod:`epc_fast.scan.sampling.qmc`)."""
        if not self.sampling.sobol:
            return streams.uniforms(seed, streams.stream_id(name), index)
        directions, keys = self.sobol_tables(seed)
        d = self.random_axes.index(name)
        k, r = qmc.positions(index, self.grid_size, self.sampling.replicates)
        return qmc.sobol_uniform(directions[d], keys[r, d], k)

    def _drawn_columns(self, seed: int, index: np.ndarray, indices: dict, parameters: dict):
        """Adds the random and fixed parameters at points ``index`` to ``indices`` and
        ``parameters``: a random axis's values (a choice's value indices) at its uniforms."""
        for name, axis in self.axes.items():
            if isinstance(axis, Choice):
                u = self._uniforms(seed, name, index)
                indices[name] = axis.indices_from_uniform(u)
                if name != "design":
                    parameters[name] = np.asarray(axis.values, dtype=np.float64)[indices[name]]
            elif isinstance(axis, float):
                parameters[name] = axis
            elif not isinstance(axis, Grid):
                u = self._uniforms(seed, name, index)
                parameters[name] = axis.from_uniform(u)
        for name in self.design_constant:
            parameters[name] = float(self.design_table[name][0])
        if isinstance(self.axes.get("design"), Choice):
            for name in self.design_varying:
                parameters[name] = self.design_table[name][indices["design"]]

    def _grid_cells(self, cell: np.ndarray) -> tuple[dict, dict]:
        """Value indices and values of the grid axes (and the designs' parameters on a design
        grid) at grid cells ``cell``, in mixed radix with the last grid axis fastest."""
        indices = {}
        for name, size in reversed(tuple(zip(self.grid_axes, self.grid_shape))):
            cell, indices[name] = np.divmod(cell, size)
        values = {}
        for name in self.grid_axes:
            if name == "design":
                values.update({param: self.design_table[param][indices[name]]
                               for param in self.design_varying})
            else:
                values[name] = np.asarray(self.axes[name].values, dtype=np.float64)[indices[name]]
        return indices, values

    def _grid_columns(self, start: int, n: int) -> tuple[dict, dict]:
        """:meth:`_grid_cells` at ``n`` points from ``start``: computed over one period, then
        tiled."""
        if not self.grid_axes:
            return {}, {}
        period = min(self.grid_size, n)
        cell = (np.arange(period, dtype=np.int64) + start % self.grid_size) % self.grid_size
        indices, values = self._grid_cells(cell)
        repeats = -(-n // period)
        return ({k: np.tile(v, repeats)[:n] for k, v in indices.items()},
                {k: np.tile(v, repeats)[:n] for k, v in values.items()})

    def snr_target_text(self) -> list[str]:
        """Per design (or one line without designs): the SNR target and where it is met, each
        marked "default" where nobody chose it."""
        level = self._level_text("snr_db", "dB")
        where_axis = self.axes.get("field_angle_deg")
        if where_axis is not None:
            where = (f"field angle {where_axis:g} deg" if isinstance(where_axis, float)
                     else f"field_angle_deg {where_axis!r}")
            return [f"{level} at {where}"] * max(1, len(self.design_names))
        if self.design_snr_at:
            return [f"{level} at {where}" for where in self.design_snr_at]
        return [f"{level} at axis (default)"]

    def _level_text(self, name: str, unit: str) -> str:
        axis = self.axes.get(name)
        if axis is not None:
            return f"{axis:g} {unit}" if isinstance(axis, float) else f"{name} {axis!r}"
        if name in self.design_table:
            values = np.unique(self.design_table[name])
            return " or ".join(f"{v:g}" for v in values) + f" {unit}"
        default = next(p.default for p in PARAMETERS if p.name == name)
        return f"{default:g} {unit}"

    def defaults(self) -> dict:
        """{name: value}: the model parameters nobody set, at the values the points take
        (evaluate's defaults; a Bayer sensor's colour filter's, :func:`terms.default_values`)."""
        given = set(self.axes) | set(self.design_table)
        if self.design_modes and all(self.design_modes):  # what every design's modes set
            given |= set.intersection(*({k for mode in modes for k in mode}
                                        for modes in self.design_modes))
        values = terms.default_values(self.evaluate_options.get("cfa", "none"))
        return {name: value for name, value in values.items() if name not in given}

    def describe(self) -> str:
        """One line per axis: how each parameter varies; where each design meets its SNR
        target; the terms on beside the axes (:func:`terms.terms_on`); and the defaults every
        point takes (nobody set them)."""
        lines = []
        targets = self.snr_target_text()
        for name, axis in self.axes.items():
            if name == "design":
                kind = "grid" if isinstance(axis, Grid) else f"choice (weights {axis.weights})"
                lines.append(f"design: {kind} over {len(self.design_names)}:")
                lines.extend(f"  {design}: SNR target {target}{_readout_text(readout, modes)}"
                             for design, target, readout, modes in zip(
                                 self.design_names, targets, self.design_readout,
                                 self.design_modes))
            else:
                share = 0.0 if isinstance(axis, (float, Grid, Choice)) else \
                    1.0 - inside_probability(name, axis)
                lines.append(f"{name}: {axis!r}" + (
                    f": {100 * share:.2g}% of the draws fall outside the domain "
                    f"{domain_of(name).domain_text()} and are INVALID points"
                    if share >= MIN_REPORTED_SHARE else ""))
        if not self.design_names:
            lines.append(f"SNR target: {targets[0]}")
        on = "; ".join(terms.terms_on(self))
        if on:
            lines.append(textwrap.fill(f"terms on: {on}", DESCRIBE_WIDTH,
                                       subsequent_indent="  ", break_on_hyphens=False))
        names = {code: name for name, code in READOUT_CODES.items()}  # binning_readout's
        defaults = [f"{name}={names[value]}" if name == "binning_readout" else f"{name}={value:g}"
                    for name, value in self.defaults().items()]
        if "electrons_per_lux_s_m2" not in self.axes and \
                "electrons_per_lux_s_m2" not in self.design_table:
            defaults.append("electrons_per_lux_s_m2=(D50, QE 0.7 on 480-580 nm)")
        lines.append(textwrap.fill("defaults (not set here): " + ", ".join(defaults),
                                   DESCRIBE_WIDTH, subsequent_indent="  ",
                                   break_on_hyphens=False))
        return "\n".join(lines)

    def __repr__(self) -> str:
        return "Space(\n  " + self.describe().replace("\n", "\n  ") + "\n)"
