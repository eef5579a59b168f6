"""The speed/accuracy measurements of :mod:`epc_fast.tradeoff`: the settings, each one's f50
error against the NumPy reference and its throughput, and the Pareto front of the two."""

from __future__ import annotations

import functools
import inspect
import math
import statistics
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from ..api import evaluate
from ..selfcheck import random_designs
from ..status import Status

__all__ = [
    "Setting", "Accuracy", "Measurement", "default_settings", "split_by_knobs", "rejection",
    "evaluate_parameters", "knob_value", "f50_accuracy", "call_time_s", "points_per_s",
    "measure", "speedups", "pareto_front", "front_of", "rtol_text", "THREADS", "F50_SOLVERS",
    "F50_RTOLS", "SPECTRUM_SAMPLES", "BASELINE", "IMPLICIT_KNOB_VALUES", "PROBE_DESIGN",
]

#: Thread counts the throughput is measured on; the last one is the plot's and the speed-up's.
THREADS = (1, 2)
#: The f50 solvers and tolerances (1, relative) of the default settings.
F50_SOLVERS = ("halley", "newton", "bisection", "brent")
F50_RTOLS = (1e-14, 1e-10, 1e-6)
#: Wavelength samples of the polychromatic settings (epc_fast.spectra.diffraction_spectrum).
SPECTRUM_SAMPLES = (1, 4, 16, 64)
#: The setting every speed-up is relative to.
BASELINE = "default"
#: What a build without a knob does: its f50 is bisected, its arithmetic float64.
IMPLICIT_KNOB_VALUES = {"f50_solver": "bisection", "precision": "float64"}
#: The design the settings are tried on before they are measured (the paper's 1.4 µm design).
PROBE_DESIGN = dict(illuminance_lux=1000.0, pixel_pitch_um=1.4, f_number=2.8,
                    focal_length_mm=5.6, sensor_area_mm2=15.6751)


@dataclass(frozen=True)
class Setting:
    """A way to run :func:`evaluate`: a name and the keyword arguments that make it.

    Attributes
    ----------
    name : str
    kwargs : mapping
        Extra keyword arguments to :func:`evaluate` (``f50_solver``, ``f50_rtol``,
        ``t_mpe_solver``, ``t_mpe_rtol``, ``precision``, ...).
    spectrum_samples : int, optional
        Count of wavelengths: polychromatic diffraction with
        ``spectrum=diffraction_spectrum(spectrum_samples)`` (built on first use, it needs
        colour-science). None: monochromatic, 550 nm.
    """

    name: str
    kwargs: Mapping = field(default_factory=dict)
    spectrum_samples: int | None = None

    def knobs(self) -> set:
        """The names of the :func:`evaluate` arguments this setting passes."""
        return set(self.kwargs) | ({"spectrum"} if self.spectrum_samples else set())

    def reference_kwargs(self) -> dict:
        """Arguments for the reference run it is compared with: those that change the model
        (the spectrum), not those that change how it is solved."""
        if self.spectrum_samples is None:
            return {}
        return {"spectrum": _spectrum(self.spectrum_samples)}

    def evaluate_kwargs(self) -> dict:
        """Every extra argument to :func:`evaluate`, the spectrum built."""
        return {**self.kwargs, **self.reference_kwargs()}


@functools.lru_cache(maxsize=None)
def _spectrum(samples: int):
    from ..spectra import diffraction_spectrum

    return diffraction_spectrum(samples)


def rtol_text(rtol: float) -> str:
    """A tolerance as short as it goes: 1e-6, not 1e-06."""
    return f"{rtol:g}".replace("e-0", "e-")


def default_settings() -> list[Setting]:
    """The settings ``epc-fast bench`` measures: the default; each f50 solver at each of
    :data:`F50_RTOLS`; Brent's T_MPE; float32 (default tolerance and 1e-6); polychromatic
    diffraction with each of :data:`SPECTRUM_SAMPLES` wavelengths."""
    settings = [Setting(BASELINE)]
    settings += [Setting(f"{solver} rtol={rtol_text(rtol)}",
                         {"f50_solver": solver, "f50_rtol": rtol})
                 for solver in F50_SOLVERS for rtol in F50_RTOLS]
    settings.append(Setting("T_MPE brent", {"t_mpe_solver": "brent"}))
    settings.append(Setting("float32", {"precision": "float32"}))
    settings.append(Setting("float32 rtol=1e-6", {"precision": "float32", "f50_rtol": 1e-6}))
    settings += [Setting(f"poly {n}", {}, spectrum_samples=n) for n in SPECTRUM_SAMPLES]
    return settings


def evaluate_parameters() -> Mapping:
    """The installed :func:`evaluate`'s parameters (name -> inspect.Parameter)."""
    return inspect.signature(evaluate).parameters


def split_by_knobs(settings: Sequence[Setting], parameters) -> tuple[list, list]:
    """The settings whose every knob is in ``parameters``, and the others.

    Returns
    -------
    kept : list of Setting
    skipped : list of (Setting, list of str)
        Each with the names of the knobs ``parameters`` lacks, sorted.
    """
    kept, skipped = [], []
    for setting in settings:
        missing = sorted(setting.knobs() - set(parameters))
        if missing:
            skipped.append((setting, missing))
        else:
            kept.append(setting)
    return kept, skipped


def rejection(setting: Setting) -> str | None:
    """Why :func:`evaluate` refuses ``setting`` on one design (a value it does not know, a
    spectrum without colour-science), or None when it runs."""
    try:
        evaluate(**PROBE_DESIGN, **setting.evaluate_kwargs(), threads=1)
    except (TypeError, ValueError, ImportError) as exc:
        return f"{type(exc).__name__}: {exc}"
    return None


def knob_value(setting: Setting, name: str, parameters):
    """The value of knob ``name`` in ``setting``: its own, else the installed default, else
    what a build without the knob does (:data:`IMPLICIT_KNOB_VALUES`)."""
    if name in setting.kwargs:
        return setting.kwargs[name]
    if name in parameters and parameters[name].default is not inspect.Parameter.empty:
        return parameters[name].default
    return IMPLICIT_KNOB_VALUES.get(name)


# --- Measurement ---------------------------------------------------------------------------------


@dataclass(frozen=True)
class Accuracy:
    """f50 of a setting against the reference, on the points both give status OK.

    Attributes
    ----------
    max_rel_error, median_rel_error : 1, relative error of f50 (NaN where no point compares).
    points_compared : count of points OK in both.
    status_mismatches : count of points whose status differs (0 for a correct setting).
    """

    max_rel_error: float
    median_rel_error: float
    points_compared: int
    status_mismatches: int


def f50_accuracy(result, reference) -> Accuracy:
    """:class:`Accuracy` of ``result`` against ``reference`` (two :class:`epc_fast.Result`
    of the same points)."""
    ok = (result.status == Status.OK) & (reference.status == Status.OK)
    f50, exact = result.f50_cyc_per_mm[ok], reference.f50_cyc_per_mm[ok]
    with np.errstate(divide="ignore", invalid="ignore"):
        errors = np.abs(f50 - exact) / np.abs(exact)
    mismatches = int(np.count_nonzero(result.status != reference.status))
    if errors.size == 0:
        return Accuracy(math.nan, math.nan, 0, mismatches)
    return Accuracy(float(np.max(errors)), float(np.median(errors)), int(errors.size),
                    mismatches)


def _out_kwarg(out) -> dict:
    """``out=out`` for evaluate, or nothing (an older build may not have out=)."""
    return {} if out is None else {"out": out}


def call_time_s(points: Mapping, kwargs: Mapping, threads: int, out=None) -> float:
    """s, the wall time of one ``evaluate(**points, **kwargs, threads=threads, out=out)``."""
    extra = _out_kwarg(out)
    start = time.perf_counter()
    evaluate(**points, **kwargs, threads=threads, **extra)
    return time.perf_counter() - start


def points_per_s(points: Mapping, kwargs_list: Sequence[Mapping], threads: Sequence[int],
                 rounds: int, progress: Callable[[str], None] | None = None) -> list[dict]:
    """points/s of ``evaluate(**points, **kwargs)`` for each ``kwargs`` of ``kwargs_list``
    on each thread count: the points over the median wall time of ``rounds`` calls, after one
    untimed warm-up call.

    Every call writes into one set of output arrays, made by the first warm-up call and passed
    back as ``out=``: the time is the model's, not that of paging in fresh output arrays, which
    would add the same cost to every setting (a large share of the fast settings' time) and
    so flatten their differences.

    The rounds are interleaved (round 1 of every setting, then round 2, ...), so that a
    machine that slows down or speeds up during the run (other work, clock changes) moves
    every setting alike rather than the ones measured at the time.

    Returns
    -------
    list of dict
        For each ``kwargs``, threads -> points/s.
    """
    n = len(next(iter(points.values())))
    calls = [(i, t) for i in range(len(kwargs_list)) for t in threads]
    if progress is not None:
        progress(f"warm-up: {len(calls)} calls of {n:,} points")
    reuse = "out" in evaluate_parameters()  # an older build without out= pages in fresh arrays
    out = None
    for i, t in calls:
        result = evaluate(**points, **kwargs_list[i], threads=t, **_out_kwarg(out))
        out = result if reuse and out is None else out
    times_s = {call: [] for call in calls}
    for r in range(rounds):
        if progress is not None:
            progress(f"timing round {r + 1} of {rounds}")
        for i, t in calls:
            times_s[(i, t)].append(call_time_s(points, kwargs_list[i], t, out))
    return [{t: n / statistics.median(times_s[(i, t)]) for t in threads}
            for i in range(len(kwargs_list))]


@dataclass(frozen=True)
class Measurement:
    """One setting measured.

    Attributes
    ----------
    setting : Setting
    f50_solver : str, f50_rtol : float (1), precision : str
        The knobs' values as run (:func:`knob_value`).
    accuracy : Accuracy
    points_per_s : dict
        Threads -> points/s.
    """

    setting: Setting
    f50_solver: str
    f50_rtol: float
    precision: str
    accuracy: Accuracy
    points_per_s: dict


def measure(settings: Sequence[Setting], *, throughput_points: int, error_points: int,
            rounds: int, seed: int = 0, threads: Sequence[int] = THREADS,
            progress: Callable[[str], None] | None = None) -> list[Measurement]:
    """Measure each setting's f50 error and throughput.

    Parameters
    ----------
    settings : sequence of Setting
        Each run as it is: filter them first (:func:`split_by_knobs`, :func:`rejection`).
    throughput_points : count of random designs timed (``random_designs(n, seed)``).
    error_points : count of random designs compared with the reference; the reference runs
        once per spectrum.
    rounds : timed calls per setting and thread count (their median counts), interleaved
        across the settings (:func:`points_per_s`).
    seed : random_designs' seed.
    threads : thread counts to time.
    progress : called with a line before each setting's error and each timing round.
    """
    parameters = evaluate_parameters()
    compared = random_designs(error_points, seed)
    references, accuracies = {}, []
    for setting in settings:
        if progress is not None:
            progress(f"f50 error of {setting.name}")
        if setting.spectrum_samples not in references:
            references[setting.spectrum_samples] = evaluate(
                **compared, **setting.reference_kwargs(), backend="reference")
        accuracies.append(f50_accuracy(evaluate(**compared, **setting.evaluate_kwargs()),
                                       references[setting.spectrum_samples]))
    del compared, references
    speeds = points_per_s(random_designs(throughput_points, seed),
                          [s.evaluate_kwargs() for s in settings], threads, rounds, progress)
    return [Measurement(setting, knob_value(setting, "f50_solver", parameters),
                        knob_value(setting, "f50_rtol", parameters),
                        knob_value(setting, "precision", parameters), accuracy, speed)
            for setting, accuracy, speed in zip(settings, accuracies, speeds)]


def speedups(measurements: Sequence[Measurement], threads: int = THREADS[-1],
             baseline: str = BASELINE) -> list[float]:
    """Each measurement's points/s on ``threads`` threads over the baseline's (NaN for all
    when the baseline was not measured)."""
    base = next((m.points_per_s[threads] for m in measurements if m.setting.name == baseline),
                math.nan)
    return [m.points_per_s[threads] / base for m in measurements]


# --- The Pareto front ----------------------------------------------------------------------------


def pareto_front(errors: Sequence[float], speeds: Sequence[float]) -> list[int]:
    """Indices of the points no other point dominates, by increasing error.

    Lower error and higher speed are better; a point dominates another when it is at least as
    good in both and better in one. Equal points do not dominate each other (both are on the
    front). Points with a NaN error or speed are left out.

    Parameters
    ----------
    errors : relative errors (any unit: only their order counts).
    speeds : points/s (likewise).
    """
    if len(errors) != len(speeds):
        raise ValueError(f"errors and speeds differ in length: {len(errors)} != {len(speeds)}")
    candidates = [i for i in range(len(errors))
                  if not (math.isnan(errors[i]) or math.isnan(speeds[i]))]

    def dominates(a, b):
        return (errors[a] <= errors[b] and speeds[a] >= speeds[b]
                and (errors[a] < errors[b] or speeds[a] > speeds[b]))

    front = [i for i in candidates if not any(dominates(j, i) for j in candidates)]
    return sorted(front, key=lambda i: (errors[i], -speeds[i], i))


def front_of(measurements: Sequence[Measurement], threads: int = THREADS[-1]) -> list[int]:
    """Indices of the Pareto front (:func:`pareto_front`) of max relative error against
    points/s on ``threads`` threads, among the monochromatic settings.

    The polychromatic settings compute another model (and are compared with a reference of
    that model): they are slower for a reason no monochromatic setting shares, and their
    errors differ from the others' only in the last digit, so they are left out of the front.
    """
    errors = [m.accuracy.max_rel_error if m.setting.spectrum_samples is None else math.nan
              for m in measurements]
    return pareto_front(errors, [m.points_per_s[threads] for m in measurements])

