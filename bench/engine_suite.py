"""The engine benchmarks' shared pieces: sizes, rounds, peers, tolerances and the checks.

The suites ``test_bench_1e4.py``, ``test_bench_1e6.py`` and ``test_bench_1e7.py`` put every
peer of one size in one benchmark group, so that their medians come from the same run:

- the core on 1 and 2 threads (``epc_fast.evaluate(**designs, threads=t)``); at 10^7 also the
  scan-style call into preallocated outputs (``out=``) and, when ``evaluate`` has it, the lean
  call that computes only f50, EPC and status (``outputs=``);
- the NumPy reference (``backend="reference"``); at 10^7 on the first 10^6 points only (about 12 s
  a round there instead of two minutes): its name says ``scaled`` and its extra_info gives the
  points it ran on, so its points/s is comparable and its median is not;
- the Numba peer (``peers/numba_peer.py``: ``parallel=True``, closed-form T_MPE, f50 by a
  safeguarded Halley iteration) on 2 threads;
- SciPy's ``brentq`` called per point in plain Python (``peers/scipy_peer.py``) on the first
  1000 points.

Inputs: ``epc_fast.selfcheck.random_designs(n, seed=12345)`` (monochromatic, no jitter), made
once per session (``conftest.py``). Each benchmark checks its own answer against the reference
inside the test: statuses equal, f50 and EPC within the peer's relative tolerance times the
point's condition number (below, with the reason for each). ``extra_info`` records ``points``,
``points_per_s`` (points / median), ``peer``, ``threads``, the tolerance and the largest
relative error found (OK points), as it is and per condition number.

``EPC_FAST_BENCH_QUICK=1`` shrinks the sizes (10^6 -> 10^5, 10^7 -> 2*10^5 with a 2*10^4-point
reference) and the rounds, for a correctness pass over every benchmark body:

    EPC_FAST_BENCH_QUICK=1 python -m pytest bench --benchmark-disable -q
"""

from __future__ import annotations

import dataclasses
import itertools
import os
import time
from typing import Callable

import numpy as np
import pytest

import epc_fast
import epc_fast.api
from epc_fast import Status
from epc_fast.selfcheck import random_designs

QUICK = os.environ.get("EPC_FAST_BENCH_QUICK", "").strip() not in ("", "0")
SEED = 12345
#: Points the per-point SciPy peer runs on (the first ones of each size's designs).
BRENTQ_POINTS = 1000
#: Threads of the Numba peer and of the core's multi-threaded variants.
THREADS = 2

# Relative tolerances on f50 and EPC against the NumPy reference (OK points; statuses must be
# equal, and the non-OK values, 0 or NaN, equal too). Each is multiplied, point by point, by
# max(1, kappa), kappa = 2 theta / sin(2 theta) the condition number of the blur
# f_L tan(theta) in the shake angle theta = omega T_MPE / k (``blur_condition``): T_MPE is
# faithfully rounded by every implementation but not always to the same double, and near the
# unbounded-blur limit theta -> pi/2 tan turns one ulp of T_MPE into kappa ulps of blur, hence of
# f50 (MTF(f) depends on the blur through b f only, so f50 is at most as sensitive as 1/b). In
# 10^6 random designs kappa reaches ~10^4; it is 1 + O(theta^2) for the rest. The result must
# agree within the tolerance times the point's own condition number, as docs/numerics.md states
# the core's accuracy.
#: The core: the same formulas as the reference to a few ulp, f50 to f50_rtol = 1e-14 (the
#: reference bisects to adjacent floats), and f50's condition number in these scenes is O(1):
#: 1e-12 is the package's own self-check bound (epc_fast.selfcheck.TOLERANCE), with two orders
#: of magnitude to spare.
CORE_RTOL = 1e-12
#: The core with ``precision="float32"``: f50 solved in float32 to its tolerance floor 2^-21 =
#: 4.8e-7 plus the float32 rounding of the MTF near the root (measured max 6.3e-7 over 10^6
#: random designs, every solver); EPC ~ f50^2 doubles it. 2e-6 covers both with margin and still
#: fails on a float64 fallback gone wrong or a solver stopping early (errors >= 1e-5).
CORE_FLOAT32_RTOL = 2e-6
#: Numba: Halley stops at |step| <= 1e-14 f, but the MTF is an independent implementation (libm
#: acos and sin, the direct diffraction formula rather than the reference's series above
#: nu = 1/2, sin(pi x) rather than sinpi); it agrees to ~1e-15 (extra_info's max_rel_error).
#: 1e-10 is what we ask of an independent implementation: it still catches a wrong formula or
#: a root outside the bracket (errors >= 1e-6), without failing on libm's last bits.
NUMBA_RTOL = 1e-10
#: brentq: rtol 1e-14 and xtol 1e-15 f_hi, on the same independent MTF as the Numba peer (in
#: Python's math module): the same reasoning and bound as NUMBA_RTOL.
BRENTQ_RTOL = 1e-10
#: The reference against itself: the same code on the same input gives the same bits.
REFERENCE_RTOL = 0.0

#: Result fields every benchmark compares.
COMPARED = ("f50_cyc_per_mm", "epc")
#: The lean call's outputs.
LEAN_OUTPUTS = ("f50_cyc_per_mm", "epc", "status")
#: The outputs the Numba and SciPy peers return (T_MPE, f50, EPC, status): the core asked for
#: the same writes the same bytes a point.
PEER_OUTPUTS = ("t_mpe_s", "f50_cyc_per_mm", "epc", "status")


def _label(n: int) -> str:
    """10000 -> '1e4', 200000 -> '2e5'."""
    exponent = len(str(n)) - 1
    mantissa = n / 10**exponent
    return f"{mantissa:g}e{exponent}"


@dataclasses.dataclass(frozen=True)
class Size:
    """One suite: its points, the reference's points (a prefix), and rounds per peer."""

    name: str                 # the suite's nominal size ("1e7"), its module's name
    points: int               # points the core and Numba evaluate
    reference_points: int     # the first points, those the reference evaluates
    rounds: dict              # peer -> (rounds, warmup_rounds)

    @property
    def group(self) -> str:
        label = _label(self.points)
        quick = " (quick)" if QUICK else ""
        return f"evaluate {label} points{quick}"

    @property
    def scaled_reference(self) -> bool:
        return self.reference_points < self.points

    def rounds_of(self, peer: str) -> dict:
        rounds, warmup = self.rounds[peer]
        if QUICK:
            rounds, warmup = min(rounds, 3), min(warmup, 1)
        return {"rounds": rounds, "warmup_rounds": warmup}


# Rounds: enough for a stable median at each size within ~10 minutes for the whole of bench/
# (the reference at 10^6 points takes ~12 s a round, the core on 1 thread at 10^7 ~11 s).
SIZES = {
    "1e4": Size("1e4", 10**4, 10**4, {
        "core": (200, 5), "reference": (10, 1), "numba": (200, 5), "brentq": (20, 1)}),
    "1e6": Size("1e6", 10**5 if QUICK else 10**6, 10**5 if QUICK else 10**6, {
        "core": (10, 1), "reference": (2, 0), "numba": (10, 1), "brentq": (20, 1),
        "paired": (15, 0)}),
    "1e7": Size("1e7", 2 * 10**5 if QUICK else 10**7, 2 * 10**4 if QUICK else 10**6, {
        "core": (5, 0), "reference": (2, 0), "numba": (5, 1), "brentq": (20, 1),
        "paired": (9, 0)}),
}


class Data:
    """Designs and reference results, each made once per session (``conftest.data``)."""

    def __init__(self):
        self._designs = {}
        self._references = {}

    def designs(self, n: int) -> dict:
        if n not in self._designs:
            self._designs[n] = random_designs(n, seed=SEED)
        return self._designs[n]

    def prefix(self, n: int, m: int) -> dict:
        """The first m of the n designs (contiguous views)."""
        return {k: v[:m] for k, v in self.designs(n).items()}

    def reference(self, size: Size):
        """The NumPy reference on the first ``size.reference_points`` designs, with the blur's
        condition number at each of them (``blur_condition``) as ``.condition``."""
        key = (size.points, size.reference_points)
        if key not in self._references:
            designs = self.prefix(*key)
            result = epc_fast.evaluate(**designs, backend="reference")
            self._references[key] = Reference(result, blur_condition(designs, result))
        return self._references[key]


@dataclasses.dataclass(frozen=True)
class Reference:
    """The reference's Result and the blur's condition number per point."""

    result: object
    condition: np.ndarray

    def __getattr__(self, name):
        return getattr(self.result, name)


def blur_condition(designs: dict, reference) -> np.ndarray:
    """max(1, 2 theta / sin(2 theta)) per point, theta = shake angle during T_MPE (rad); 1 where
    the status is not OK (statuses and the fixed values 0 or NaN are compared exactly)."""
    ok = reference.status == Status.OK
    stabilization = designs.get("stabilization", 1.0)
    theta = np.where(ok, np.deg2rad(designs["shake_deg_per_s"]) * reference.t_mpe_s
                     / stabilization, 0.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        kappa = np.where(theta > 0, 2.0 * theta / np.sin(2.0 * theta), 1.0)
    return np.maximum(kappa, 1.0)


# --- The check inside every benchmark ---------------------------------------------------------


def check(benchmark, got: dict, reference, rtol: float, prefix: str = "") -> None:
    """Statuses equal to the reference's, f50 and EPC within ``rtol`` times the blur's condition
    number (at least 1) of it, non-OK values (0, NaN) identical, on the points both
    cover (a prefix of the designs: the core's output at 10^7 is sliced to the reference's
    10^6 points, the reference to brentq's 1000). Records the tolerance and the largest
    relative error in extra_info (their keys after ``prefix``)."""
    m = min(np.shape(got["status"])[0], np.shape(reference.status)[0])
    status = np.asarray(got["status"])[:m]
    np.testing.assert_array_equal(status, reference.status[:m], err_msg="statuses differ")
    ok = status == Status.OK
    allowed = rtol * reference.condition[:m]
    worst = worst_scaled = 0.0
    for name in COMPARED:
        value = np.asarray(got[name])[:m]
        want = getattr(reference, name)[:m]
        same = (value == want) | (np.isnan(value) & np.isnan(want))
        with np.errstate(invalid="ignore", divide="ignore"):
            error = np.where(same, 0.0, np.abs(value / want - 1.0))
        bad = np.flatnonzero(~(error <= allowed))
        assert bad.size == 0, (
            f"{name}: {bad.size} of {m} points off the reference by more than {rtol:g} times "
            f"the blur's condition number; first at index {bad[0]}: {value[bad[0]]!r} against "
            f"{want[bad[0]]!r} (relative error {error[bad[0]]:.3g}, condition number "
            f"{reference.condition[bad[0]]:.3g})")
        if ok.any():
            worst = max(worst, float(np.max(error[ok])))
            worst_scaled = max(worst_scaled, float(np.max(error[ok] / reference.condition[:m][ok])))
    benchmark.extra_info[prefix + "rtol"] = rtol
    benchmark.extra_info[prefix + "max_rel_error"] = worst
    benchmark.extra_info[prefix + "max_rel_error_per_condition"] = worst_scaled
    benchmark.extra_info[prefix + "checked_points"] = int(m)


def record(benchmark, peer: str, points: int, threads: int, **extra) -> None:
    """extra_info before the run: what ran, on how many points."""
    benchmark.extra_info.update(peer=peer, points=int(points), threads=int(threads), **extra)


def record_throughput(benchmark) -> None:
    """extra_info after the run: points / median (absent when benchmarks are disabled)."""
    stats = getattr(benchmark, "stats", None)
    if stats:
        median = stats.stats.median
        benchmark.extra_info["median_s"] = median
        benchmark.extra_info["points_per_s"] = benchmark.extra_info["points"] / median


def as_fields(result) -> dict:
    """A Result (or a peer's tuple t, f50, epc, status) as a dict of the compared fields."""
    if isinstance(result, tuple):
        return dict(zip(("t_mpe_s", "f50_cyc_per_mm", "epc", "status"), result))
    return {name: getattr(result, name) for name in COMPARED + ("status",)}


def output_arrays(n: int) -> dict:
    """Preallocated outputs for ``evaluate(out=)``: every Result field, its pages touched."""
    dtypes = getattr(epc_fast.api, "OUTPUT_DTYPES", None) or {
        f.name: np.dtype(np.uint8 if f.name in ("status", "cause") else np.float64)
        for f in dataclasses.fields(epc_fast.Result)}
    return {name: np.full(n, 0, dtype=dtype) for name, dtype in dtypes.items()}


# --- The benchmarks, one function per peer; each size's module calls them --------------------


def bench_core(benchmark, data: Data, size: Size, threads: int,
               precision: str = "float64") -> None:
    designs = data.designs(size.points)
    extra = {} if precision == "float64" else {"variant": f"precision={precision}"}
    record(benchmark, "core", size.points, threads, precision=precision, **extra)
    result = benchmark.pedantic(epc_fast.evaluate,
                                kwargs=dict(designs, threads=threads, precision=precision),
                                iterations=1, **size.rounds_of("core"))
    record_throughput(benchmark)
    rtol = CORE_RTOL if precision == "float64" else CORE_FLOAT32_RTOL
    check(benchmark, as_fields(result), data.reference(size), rtol)


def bench_core_into_outputs(benchmark, data: Data, size: Size, outputs: dict) -> None:
    """The scan's way: the same preallocated output arrays, reused every round."""
    designs = data.designs(size.points)
    record(benchmark, "core", size.points, THREADS, variant="out= preallocated")
    result = benchmark.pedantic(epc_fast.evaluate,
                                kwargs=dict(designs, threads=THREADS, out=outputs),
                                iterations=1, **size.rounds_of("core"))
    record_throughput(benchmark)
    assert result.epc is outputs["epc"] or np.shares_memory(result.epc, outputs["epc"])
    check(benchmark, as_fields(result), data.reference(size), CORE_RTOL)


def bench_core_outputs(benchmark, data: Data, size: Size, outputs: tuple = LEAN_OUTPUTS) -> None:
    """Only ``outputs`` computed (``outputs=``): f50, EPC and status unless told."""
    designs = data.designs(size.points)
    record(benchmark, "core", size.points, THREADS, variant="outputs=" + ",".join(outputs))
    result = benchmark.pedantic(epc_fast.evaluate,
                                kwargs=dict(designs, threads=THREADS, outputs=outputs),
                                iterations=1, **size.rounds_of("core"))
    record_throughput(benchmark)
    check(benchmark, as_fields(result), data.reference(size), CORE_RTOL)


def bench_reference(benchmark, data: Data, size: Size) -> None:
    m = size.reference_points
    designs = data.prefix(size.points, m)
    extra = {"scaled": True, "of_points": size.points} if size.scaled_reference else {}
    record(benchmark, "reference", m, 1, **extra)
    result = benchmark.pedantic(epc_fast.evaluate, kwargs=dict(designs, backend="reference"),
                                iterations=1, **size.rounds_of("reference"))
    record_throughput(benchmark)
    check(benchmark, as_fields(result), data.reference(size), REFERENCE_RTOL)


def bench_numba(benchmark, data: Data, size: Size, numba_evaluate,
                same_algorithm: bool = False) -> None:
    """The Numba peer; with ``same_algorithm``, running the core's own f50 algorithm (its
    accurate start and stop test: peers/numba_peer.py), recorded as peer numba_same_algorithm."""
    designs = data.designs(size.points)
    if same_algorithm:
        record(benchmark, "numba_same_algorithm", size.points, THREADS,
               f50_solver="safeguarded Halley, the core's start and stop test")
        designs = dict(designs, same_algorithm=True)
    else:
        record(benchmark, "numba", size.points, THREADS, f50_solver="safeguarded Halley")
    result = benchmark.pedantic(numba_evaluate, kwargs=designs, iterations=1,
                                **size.rounds_of("numba"))
    record_throughput(benchmark)
    check(benchmark, as_fields(result), data.reference(size), NUMBA_RTOL)


def bench_brentq(benchmark, data: Data, size: Size, brentq_evaluate) -> None:
    designs = data.prefix(size.points, BRENTQ_POINTS)
    record(benchmark, "brentq", BRENTQ_POINTS, 1, f50_solver="scipy.optimize.brentq per point")
    result = benchmark.pedantic(brentq_evaluate, kwargs=designs, iterations=1,
                                **size.rounds_of("brentq"))
    record_throughput(benchmark)
    check(benchmark, as_fields(result), data.reference(size), BRENTQ_RTOL)


# --- Paired: two calls taken in turn, for the speed-up of one over the other ------------------


@dataclasses.dataclass(frozen=True)
class Contender:
    """One side of a paired benchmark: its label, the call (given the designs as keyword
    arguments, and ``kwargs`` besides) and the tolerance its answer is checked at."""

    label: str
    call: Callable
    kwargs: dict
    rtol: float


def core_contender(label: str, **kwargs) -> Contender:
    """``epc_fast.evaluate(**designs, **kwargs)`` (threads=THREADS unless given)."""
    kwargs.setdefault("threads", THREADS)
    float32 = kwargs.get("precision") == "float32"
    return Contender(label, epc_fast.evaluate, kwargs, CORE_FLOAT32_RTOL if float32 else CORE_RTOL)


def numba_contender(numba_evaluate) -> Contender:
    return Contender("numba", numba_evaluate, {}, NUMBA_RTOL)


def bench_paired(benchmark, data: Data, size: Size, first: Contender, second: Contender) -> None:
    """``first`` and ``second`` on the same points, taken in turn in every round (``first``
    leads in even rounds, ``second`` in odd ones), each call timed on its own: a drift in the
    machine's speed, which on a shared machine can move the ratio of two benchmarks of a group
    run a minute apart by a third, falls on both sides of a round alike. The benchmark's own
    median is a round's, both calls; extra_info records each side's median seconds and
    points/s, and the speed-up of ``first`` over ``second`` (second's seconds over first's)
    per round: its median, least and greatest. One untimed pair first, so that neither side's
    first call (new pages, thread pools) counts. Both answers are checked, each at its own
    tolerance."""
    designs = data.designs(size.points)
    sides = (first, second)
    seconds = ([], [])
    results = [None, None]
    rounds = itertools.count()

    def one_round():
        order = (0, 1) if next(rounds) % 2 == 0 else (1, 0)
        for k in order:
            side = sides[k]
            start = time.perf_counter()
            results[k] = side.call(**designs, **side.kwargs)
            seconds[k].append(time.perf_counter() - start)

    one_round()
    for s in seconds:
        s.clear()
    benchmark.extra_info.update(paired=True, pair_points=int(size.points),
                                first=first.label, second=second.label)
    benchmark.pedantic(one_round, iterations=1, **size.rounds_of("paired"))
    a, b = np.array(seconds[0]), np.array(seconds[1])
    speedup = b / a
    benchmark.extra_info.update(
        paired_rounds=int(a.size),
        first_median_s=float(np.median(a)), second_median_s=float(np.median(b)),
        first_points_per_s=size.points / float(np.median(a)),
        second_points_per_s=size.points / float(np.median(b)),
        speedup_median=float(np.median(speedup)), speedup_min=float(speedup.min()),
        speedup_max=float(speedup.max()))
    reference = data.reference(size)
    for prefix, side, result in (("first_", first, results[0]), ("second_", second, results[1])):
        check(benchmark, as_fields(result), reference, side.rtol, prefix=prefix)
