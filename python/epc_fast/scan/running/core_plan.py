"""A scan as the core's fused pass reads it: the space, the group keys and the reductions as
plain dicts and lists (``cpp/include/epc_fast/scan_space.h``, ``scan_groups.h``,
``scan/reductions.h``), and the core's partial results turned into each reduction's own partial,
which its ``merge`` and ``finish`` then take exactly as they take the NumPy path's.

The core forms every point's parameters itself from this description (docs/scan.md, the draw
contract), evaluates the model and folds the outputs into the reductions while the points are
in cache: no per-point array crosses into Python.
"""

from __future__ import annotations

import numpy as np

from ... import api, params
from ..._validation import choice, integer, tolerance
from ...design import one_wavelength, spectrum_of
from ...spectra import DEFAULT_ELECTRONS_PER_LUX_S_M2
from ...status import Status
from ..reductions.best import TopK
from .chunk import OUTPUTS
from .camera_terms import CameraTerms
from ..sampling.distributions import Choice, Grid
from ..reductions.groups import GroupKey
from ..reductions.histograms import Histogram, Quantiles
from ..sampling.space import Points, Space
from ..sampling.streams import stream_id
from ..reductions.summaries import FractionBelow, Summary

__all__ = ["CorePlan"]

#: The evaluate options a space may fix, and evaluate's defaults for them.
OPTION_DEFAULTS = {"f50_solver": "halley", "f50_rtol": 1e-14, "t_mpe_solver": "closed_form",
                   "t_mpe_rtol": 1e-15, "precision": "float64"}


def _slot_name(space: Space, slot: str) -> str:
    """The space's name of a parameter slot: ``size`` is pixel_count or sensor_area_mm2."""
    if slot != "size":
        return slot
    given = set(space.axes) | set(space.design_table)
    return next(n for n in params.SIZE_PARAMETERS if n in given)


def _default(slot: str) -> float:
    if slot == "electrons_per_lux_s_m2":
        return DEFAULT_ELECTRONS_PER_LUX_S_M2
    return float(params.PARAMETERS[params.PARAMETER_NAMES.index(slot)].default)


class CorePlan:
    """One scan's description for the core: built once per run (and once per Dask task).

    Parameters
    ----------
    space : Space
    seed : int, in [0, 2**64).
    plan : tuple of :class:`~epc_fast.scan.running.tasks.PlanItem`, the reductions the core folds
        (exact quantiles and anything per point are the caller's).
    terms : :class:`~epc_fast.scan.running.camera_terms.CameraTerms`, optional: the space's lens
        tables, colour sensor and readout modes (None: the space has none of them).
    """

    def __init__(self, space: Space, seed: int, plan: tuple = (), terms: CameraTerms | None = None):
        self.space = space
        self.seed = seed
        self.terms = CameraTerms() if terms is None else terms
        # the replicate first: the slowest grid axis (qmc.py), none for one replicate
        self.axis_names = (("replicate",) if space.sampling.replicates > 1 else ()) + tuple(
            n for n, a in space.axes.items() if isinstance(a, (Grid, Choice)))
        self.names = tuple(_slot_name(space, slot) for slot in params.PARAMETER_NAMES)
        # the points as the space gives them (scan_points), and as the model reads them in
        # the fused pass: a colour sensor's columns as evaluate forms them, the modes' own
        # parameters at their defaults (the modes set them)
        self.spec = self._space_spec(model=False)
        self.pass_spec = (self._space_spec(model=True) if self.terms.color or self.terms.set_by_modes
                          else self.spec)
        self.plan = tuple(plan)
        keys: list = []
        self.reduction_specs = []
        for item in self.plan:
            key_index = None
            if not isinstance(item.reduction, TopK):
                spec = self._key_spec(item.key)
                if spec not in keys:
                    keys.append(spec)
                key_index = keys.index(spec)
            self.reduction_specs.append(self._reduction_spec(item.reduction, key_index))
        self.key_specs = keys
        self.options = self._options()
        # EPC and the status counted in both directions (kernel.h across_f50)
        self.epc_both = space.evaluate_options.get("epc_axes", "motion") == "both"

    # -- the space ---------------------------------------------------------------------------

    def _space_spec(self, model: bool) -> dict:
        space = self.space
        axes = []
        replicates = space.sampling.replicates
        for name in self.axis_names:
            if name == "replicate":
                axes.append({"grid": True, "size": replicates, "stream": 0, "dimension": 0,
                             "cumulative": None})
                continue
            axis = space.axes[name]
            cumulative = None
            if isinstance(axis, Choice):
                cumulative = axis.stream_spec()["cumulative"]
            axes.append({"grid": isinstance(axis, Grid), "size": len(axis.values),
                         "stream": stream_id(name), "cumulative": cumulative,
                         "dimension": self._dimension(name)})
        spectrum, wavelength = self._spectrum()
        sources = []
        terms = self.terms
        color = (terms.color or {}) if model else {}
        by_modes = terms.set_by_modes if model else frozenset()
        for slot, name in zip(params.PARAMETER_NAMES, self.names):
            if slot == "wavelength_nm" and wavelength is not None:
                sources.append({"kind": "fixed", "value": wavelength})
            elif slot in by_modes:  # the modes' columns; the call's default between
                sources.append({"kind": "fixed", "value": _default(slot)})
            elif slot in color:
                sources.append(self._color_source(name, slot, *color[slot]))
            else:
                sources.append(self._source(name, slot))
        wavelengths = weights = np.empty(0)
        if spectrum is not None:
            wavelengths, weights = spectrum.wavelengths_nm, spectrum.weights
        sobol = None
        if space.sampling.sobol:
            directions, keys = space.sobol_tables(self.seed)
            sobol = {"dimensions": len(space.random_axes), "replicates": replicates,
                     "directions": directions, "keys": np.ascontiguousarray(keys.T),
                     "replicate_axis": 0 if replicates > 1 else -1}
        return {"seed": self.seed, "axes": axes, "params": list(sources), "sobol": sobol,
                "size_is_pixel_count": self.names[params.PARAMETER_NAMES.index("size")]
                == "pixel_count",
                "domains": params.domain_table(len(terms.lens_tables or ()) or 1),
                "wavelengths_nm": np.ascontiguousarray(wavelengths, dtype=np.float64),
                "weights": np.ascontiguousarray(weights, dtype=np.float64),
                "lens_tables": terms.lens_tables, "demosaic_table": terms.demosaic_table}

    def _color_source(self, name: str, slot: str, default: float, scale: float) -> dict:
        """A colour sensor's column (camera_terms.CameraTerms.color): its ``default`` where the
        space does not give it, its given values times ``scale`` where it does, as
        :func:`epc_fast.cfa.sensor_color` forms them."""
        if name not in self.space.axes and name not in self.space.design_table:
            return {"kind": "fixed", "value": float(default)}
        source = self._source(name, slot)
        if scale == 1.0:
            return source
        if source["kind"] == "fixed":
            return {**source, "value": source["value"] * scale}
        if source["kind"] == "axis":
            return {**source, "values": source["values"] * scale}
        raise AssertionError("a drawn colour column is the arrays'")  # camera_terms refuses it

    def _source(self, name: str, slot: str) -> dict:
        space = self.space
        if name in space.axes:
            axis = space.axes[name]
            if isinstance(axis, float):
                return {"kind": "fixed", "value": axis}
            if isinstance(axis, (Grid, Choice)):
                return {"kind": "axis", "axis": self.axis_names.index(name),
                        "values": np.asarray(axis.values, dtype=np.float64)}
            return {"kind": "drawn", "stream": stream_id(name), "draw": axis.stream_spec(),
                    "dimension": self._dimension(name)}
        if name in space.design_table:
            column = space.design_table[name]
            if name in space.design_constant:
                return {"kind": "fixed", "value": float(column[0])}
            return {"kind": "axis", "axis": self.axis_names.index("design"),
                    "values": np.asarray(column, dtype=np.float64)}
        return {"kind": "fixed", "value": _default(slot)}

    def _dimension(self, name: str) -> int:
        """A random parameter's Sobol' dimension (0 for the others and under Monte Carlo)."""
        random = self.space.random_axes
        return random.index(name) if name in random else 0

    def _spectrum(self):
        """The space's spectrum (None: monochromatic) and, for a spectrum whose weight is on
        one wavelength, that wavelength (evaluate's rule: the monochromatic model at it)."""
        spectrum = self.space.evaluate_options.get("spectrum")
        if spectrum is None:
            return None, None
        if "wavelength_nm" in self.space.axes or "wavelength_nm" in self.space.design_table:
            raise ValueError("a space gives either wavelength_nm or a spectrum, not both")
        spec = spectrum_of(spectrum)
        wavelength = one_wavelength(spec)
        if wavelength is not None:
            return None, float(wavelength)
        return spec, None

    def _options(self) -> tuple:
        given = {k: v for k, v in self.space.evaluate_options.items() if k != "spectrum"}
        options = {**OPTION_DEFAULTS, **given}
        choice("f50_solver", options["f50_solver"], api.F50_SOLVERS)
        choice("t_mpe_solver", options["t_mpe_solver"], api.T_MPE_SOLVERS)
        choice("precision", options["precision"], api.PRECISIONS)
        return (options["f50_solver"], tolerance("f50_rtol", options["f50_rtol"]),
                options["t_mpe_solver"], tolerance("t_mpe_rtol", options["t_mpe_rtol"]),
                options["precision"])

    # -- keys and reductions -----------------------------------------------------------------

    def _key_spec(self, key: GroupKey) -> list:
        parts = []
        for part in key.parts:
            if part.kind in ("axis", "replicate"):
                parts.append({"kind": "axis", "axis": self.axis_names.index(part.name),
                              "size": part.size})
            elif part.kind == "design value":
                parts.append({"kind": "lookup", "axis": self.axis_names.index("design"),
                              "size": part.size,
                              "lookup": np.asarray(part.lookup, dtype=np.float64)})
            else:
                slot = self.names.index(part.name)
                spec = {"kind": "binned", "param": slot, "size": part.size,
                        "inner_edges": np.asarray(part.inner_edges, dtype=np.float64),
                        "first": 0.0, "scale": 1.0}
                if part.log_spacing is not None:
                    spec.update(kind="binned_log", first=part.log_spacing[0],
                                scale=part.log_spacing[1])
                parts.append(spec)
        return parts

    @staticmethod
    def _reduction_spec(reduction, key_index) -> dict:
        of = OUTPUTS.index(reduction.of)
        if isinstance(reduction, TopK):
            return {"kind": "top_k", "of": of, "k": int(reduction.k),
                    "largest": bool(reduction.largest)}
        spec = {"kind": None, "of": of, "key": key_index}
        if isinstance(reduction, Summary):
            spec["kind"] = "summary"
        elif isinstance(reduction, FractionBelow):
            spec.update(kind="fraction_below", threshold=float(reduction.threshold))
        elif isinstance(reduction, Histogram):
            bins = reduction.bin_layout
            spec.update(kind="histogram", first=bins.first, last=bins.last, bins=bins.bins,
                        log=bool(reduction.log))
        elif isinstance(reduction, Quantiles):
            bins = reduction.bin_layout
            spec.update(kind="quantiles", first_key=bins.first_key, bins=bins.bins,
                        shift=bins.shift)
        else:
            raise TypeError(f"the core cannot fold {reduction!r}")
        return spec

    # -- running -----------------------------------------------------------------------------

    def reduce(self, start: int, stop: int, threads: int) -> dict:
        """The partial of every planned reduction over points ``start .. stop - 1``, each in
        the form its ``merge`` takes."""
        from ... import _core

        partials = _core.scan_chunk(self.pass_spec, self.key_specs, self.reduction_specs,
                                    *self.options, start, stop, threads, self.epc_both,
                                    self.terms.modes)
        result = {}
        for item, partial in zip(self.plan, partials):
            if isinstance(item.reduction, TopK):
                partial = self._top_k_partial(item.reduction, partial)
            elif isinstance(item.reduction, Summary):
                partial = _every_status(partial)
            result[item.name] = partial
        return result

    def _top_k_partial(self, reduction: TopK, partial: dict) -> dict:
        index = partial["index"]
        value = -partial["order_key"] if reduction.largest else partial["order_key"]
        points = self.points_at(index)
        parameters = {name: np.broadcast_to(points.parameters[name], index.shape).copy()
                      for name in self.space.varying_parameters}
        design = points.indices.get("design", np.zeros(index.size, np.intp))
        return {"index": index, "value": value, "parameters": parameters,
                "design": np.asarray(design, dtype=np.intp)}

    def points_at(self, index: np.ndarray) -> Points:
        """The parameters of the points ``index`` (int64), formed by the core as its fused
        pass forms them: :class:`Points` with the parameters the space gives."""
        from ... import _core

        index = np.ascontiguousarray(index, dtype=np.int64)
        values, axes = _core.scan_points(self.spec, index)
        space = self.space
        given = set(space.axes) | set(space.design_table)
        parameters = {}
        for name, source, column in zip(self.names, self.spec["params"], values):
            if name not in given:
                continue
            parameters[name] = source["value"] if column is None else column
        parameters.pop("design", None)
        indices = {name: axis.astype(np.intp) for name, axis in zip(self.axis_names, axes)}
        start = int(index[0]) if index.size else 0
        return Points(start, start + index.size, index, parameters, indices)

    def points(self, start: int, stop: int) -> Points:
        """Points ``start .. stop - 1`` as :meth:`points_at` forms them."""
        return self.points_at(np.arange(start, stop, dtype=np.int64))


def checked_seed(seed) -> int:
    """A scan's seed: an integer in [0, 2**64), or a ValueError naming it; None draws one."""
    if seed is None:
        return int(np.random.SeedSequence().generate_state(1, np.uint64)[0])
    value = integer("seed", seed)
    if not 0 <= value < 2**64:
        raise ValueError(f"seed must be an integer in [0, 2**64), got {seed!r}")
    return value


def _every_status(partial: dict) -> dict:
    """A summary's partial with a status count for every :class:`epc_fast.Status`: the core
    counts the statuses it can give (a frame cap's EXPOSURE_LIMIT is the arrays'), the others
    are 0."""
    counts = partial["status"]
    if counts.shape[1] == len(Status):
        return partial
    padded = np.zeros((counts.shape[0], len(Status)), np.int64)
    padded[:, :counts.shape[1]] = counts
    return {**partial, "status": padded}
