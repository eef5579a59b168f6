"""Histograms on fixed bins, and quantiles: exact when the values fit, else from a fine
histogram with a stated error.

A histogram's bins are equal in t (the value, or its log10 on log bins) over [t_low, t_high):
a value's bin is floor((t - t_low) bins / (t_high - t_low)), the arithmetic ``np.histogram``
uses for equal bins before it re-checks values within rounding of an edge (which this skips:
it halves the cost, and such a value is one in ~10^13). Streamed quantiles count on octave bins
(:class:`_OctaveBins`): a value's bin is read from its bits, with no rounding at all. Counts
are integers: they merge exactly.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..running.chunk import Chunk
from .targets import target_of
from .groups import GroupKey
from .summaries import check_output

__all__ = ["Histogram", "HistogramResult", "Quantiles", "QuantilesResult"]


def _slot_counts(slot: np.ndarray, group: np.ndarray, groups: int, slots: int) -> np.ndarray:
    """int64 (groups, slots): how many points of each group fall in each slot."""
    cell = group * slots + slot
    return np.bincount(cell, minlength=groups * slots).reshape(groups, slots)


@dataclass(frozen=True)
class BinLayout:
    """Equal bins on t in [first, last); slot 0 is below, slots 1..bins, bins + 1 above."""

    first: float
    last: float
    bins: int

    @property
    def edges(self) -> np.ndarray:
        return np.linspace(self.first, self.last, self.bins + 1)

    @property
    def slots(self) -> int:
        return self.bins + 2

    def slot(self, t: np.ndarray) -> np.ndarray:
        """The slot (int32) of each finite or -inf ``t``."""
        position = t - self.first
        position *= self.bins / (self.last - self.first)
        position += 1.0
        np.clip(position, 0.0, self.bins + 1.0, out=position)
        return position.astype(np.int32)

    def counts(self, t: np.ndarray, group: np.ndarray, groups: int) -> np.ndarray:
        """int64 (groups, slots): how many ``t`` of each group fall in each slot."""
        return _slot_counts(self.slot(t), group, groups, self.slots)


#: The finest octave bins: 2**40 an octave keeps a bin's key (a double's bits shifted right
#: by 52 - 40) below 2**52, where the core holds it exactly in a double.
MAX_OCTAVE_BITS = 40


@dataclass(frozen=True)
class _OctaveBins:
    """Bins by the leading bits of a positive double, ``2**k`` an octave.

    A positive double's bits, read as an unsigned integer and shifted right by ``shift`` =
    52 - k, keep its exponent and the first k bits of its mantissa: its *key*. Keys grow with
    the value, and the values of one key form the bin [m 2**e, (m + 1) 2**e) with 2**k <= m <
    2**(k + 1): bins at most 2**-k wide relative, whose edges are doubles. A value's bin is an
    integer function of its bits, so the core and NumPy bin every value alike, and a value on
    an edge is in the bin above it, exactly. Bins ``first_key .. first_key + bins - 1``; slot 0
    counts the values below the first edge (0 and any value <= 0 included), slots 1..bins the
    bins, bins + 1 the values at or above the last edge.
    """

    first_key: int
    bins: int
    shift: int

    @classmethod
    def covering(cls, low: float, high: float, bins_per_decade: int) -> "_OctaveBins":
        """The bins from ``low``'s to ``high``'s, at least as fine as ``bins_per_decade`` equal
        log bins: the least k whose bins, 2**-k wide, are at most 10**(1 / bins_per_decade) - 1
        wide (k = 9, 0.195%, at 1000)."""
        width = 10.0 ** (1.0 / bins_per_decade) - 1.0
        k = 0
        while 2.0 ** -k > width and k < MAX_OCTAVE_BITS:
            k += 1
        shift = 52 - k
        first, last = cls._key(low, shift), cls._key(high, shift)
        return cls(first, last - first + 1, shift)

    @staticmethod
    def _key(value: float, shift: int) -> int:
        return int(np.float64(value).view(np.uint64)) >> shift

    @property
    def relative_resolution(self) -> float:
        """A bin's width, relative, at most: 2**-k."""
        return 2.0 ** -(52 - self.shift)

    @property
    def edges(self) -> np.ndarray:
        """float64 (bins + 1,): the bins' edges, exact (the last may be inf)."""
        keys = np.arange(self.first_key, self.first_key + self.bins + 1, dtype=np.uint64)
        return (keys << np.uint64(self.shift)).view(np.float64)

    @property
    def slots(self) -> int:
        return self.bins + 2

    def slot(self, values: np.ndarray) -> np.ndarray:
        """The slot (int32) of each finite value."""
        values = np.ascontiguousarray(values, dtype=np.float64)
        keys = (values.view(np.uint64) >> np.uint64(self.shift)).astype(np.int64)
        keys -= self.first_key - 1
        np.clip(keys, 0, self.bins + 1, out=keys)
        keys[~(values > 0.0)] = 0
        return keys.astype(np.int32)

    def counts(self, values: np.ndarray, group: np.ndarray, groups: int) -> np.ndarray:
        """int64 (groups, slots): how many ``values`` of each group fall in each slot."""
        return _slot_counts(self.slot(values), group, groups, self.slots)


def _check_range(low: float, high: float, log: bool) -> None:
    if not (math.isfinite(low) and math.isfinite(high) and low < high and (low > 0 or not log)):
        raise ValueError(f"bins need finite low < high{' and low > 0 (log bins)' if log else ''}, "
                         f"got {low!r}, {high!r}")


@dataclass
class HistogramResult:
    """Per-group counts of an output's finite values on fixed bins.

    Attributes
    ----------
    of : str, the output.
    labels : {column: list}, each group's label.
    edges : float64 (bins + 1,), the output's unit, the bin edges.
    counts : int64 (groups, bins).
    below, above : int64 (groups,), finite values below ``edges[0]`` / at or above
        ``edges[-1]``.
    nonfinite : int64 (groups,), points whose output is NaN or infinite.
    """

    of: str
    labels: dict
    edges: np.ndarray
    counts: np.ndarray
    below: np.ndarray
    above: np.ndarray
    nonfinite: np.ndarray


@dataclass(frozen=True)
class Histogram:
    """A histogram of an output on fixed bins, per group.

    Parameters
    ----------
    low, high : the output's unit (pixels for EPC), the range of the bins.
    bins : int, the number of bins.
    log : bool, bins equal in log10 (default) or in value.
    by : group key, optional; None: one group.
    of : str, the output (default ``"epc"``).
    """

    low: float
    high: float
    bins: int = 100
    log: bool = True
    by: object = None
    of: str = "epc"

    def __post_init__(self):
        check_output(self.of)
        _check_range(self.low, self.high, self.log)
        if self.bins < 1:
            raise ValueError(f"bins must be >= 1, got {self.bins!r}")

    @property
    def bin_layout(self) -> BinLayout:
        if self.log:
            return BinLayout(math.log10(self.low), math.log10(self.high), int(self.bins))
        return BinLayout(float(self.low), float(self.high), int(self.bins))

    def start(self, key: GroupKey, points_total: int) -> dict:
        return {"counts": np.zeros((key.size, self.bin_layout.slots), np.int64),
                "points": np.zeros(key.size, np.int64)}

    def reduce(self, chunk: Chunk, key: GroupKey) -> dict:
        t = chunk.finite_log10(self.of) if self.log else chunk.finite_values(self.of)
        return {"counts": self.bin_layout.counts(t, chunk.finite_groups(self.of, key), key.size),
                "points": chunk.group_counts(key)}

    def merge(self, state: dict, partial: dict) -> dict:
        state["counts"] += partial["counts"]
        state["points"] += partial["points"]
        return state

    def finish(self, state: dict, key: GroupKey, space) -> HistogramResult:
        counts = state["counts"]
        edges = self.bin_layout.edges
        return HistogramResult(self.of, key.columns, 10.0 ** edges if self.log else edges,
                               counts[:, 1:-1], counts[:, 0], counts[:, -1],
                               state["points"] - counts.sum(axis=1))


@dataclass
class QuantilesResult:
    """Per-group quantiles of an output's finite values, with bounds on the true values.

    Attributes
    ----------
    of : str, the output.
    labels : {column: list}, each group's label.
    q : float64 (nq,), the probabilities.
    estimate : float64 (groups, nq), the output's unit; NaN for a group with no finite value.
        Rows are the groups in the order of ``labels``, columns the probabilities of ``q``;
        :meth:`quantile` reads it by probability and label.
    lower, upper : float64 (groups, nq), the output's unit: the sample quantile
        (``np.quantile``'s default "linear" method, or any method between the two order
        statistics around it) lies in [lower, upper], and so does the estimate. Equal to
        ``estimate`` when exact.
    exact : bool, whether the values were kept and the quantiles computed exactly.
    relative_resolution : 1, one bin of the histogram as a ratio minus 1 (0 when exact): on
        dense samples [lower, upper] spans one or two bins.
    standard_error : float64 (groups, nq), the output's unit: the estimates' standard errors
        from the scan's replicates (:mod:`epc_fast.scan.reductions.replicates`); NaN with one
        replicate; None outside a scan.
    """

    of: str
    labels: dict
    q: np.ndarray
    estimate: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    exact: bool
    relative_resolution: float
    standard_error: np.ndarray | None = None

    def columns(self) -> dict:
        """Table columns, one row per group: ``q5``, ``q50``, ... for q = 0.05, 0.5, ...,
        each followed by its standard error (``q5 error``) when the scan gives them."""
        columns = dict(self.labels)
        for i, q in enumerate(self.q):
            columns[f"q{100 * q:g}"] = self.estimate[:, i]
            if self.standard_error is not None:
                columns[f"q{100 * q:g} error"] = self.standard_error[:, i]
        return columns

    def quantile(self, q: float, **group):
        """The estimate of probability ``q`` (one of :attr:`q`), by group label.

        Without ``group``: {label: estimate} in group order, the label being the group's one
        label (e.g. the design's name) or the tuple of its labels. With ``group`` (label
        columns as keywords, e.g. ``design='1/3.2" 1.4 um'``): the estimate of the one group
        they match, a float. ``result["quantiles"].quantile(0.5)`` gives each design's median.
        """
        matches = np.flatnonzero(np.isclose(self.q, q, rtol=1e-12, atol=0.0))
        if matches.size == 0:
            raise ValueError(f"q={q!r} is not one of this result's probabilities "
                             f"{[float(x) for x in self.q]}")
        column = self.estimate[:, matches[0]]
        names = list(self.labels)
        rows = list(zip(*self.labels.values())) if names else [()]
        if not group:
            keys = [row[0] if len(row) == 1 else row for row in rows]
            return {key: float(value) for key, value in zip(keys, column)}
        unknown = sorted(set(group) - set(names))
        if unknown:
            raise ValueError(f"{', '.join(unknown)}: not a label column of this result "
                             f"({', '.join(names) or 'a single group'})")
        found = [i for i, row in enumerate(rows)
                 if all(row[names.index(k)] == v for k, v in group.items())]
        if len(found) != 1:
            what = "no group" if not found else f"{len(found)} groups"
            raise ValueError(f"{what} match {group}; give a value of each label column "
                             f"({', '.join(names)})")
        return float(column[found[0]])

    def error_statement(self) -> str:
        """One line: how exact the quantiles are.

        Streamed quantiles are bounded by the bins of the order statistics around them:
        relative bounds where the lower bound is positive; where it is 0 or less (a quantile
        in the histogram's bin below ``low``, e.g. EPC = 0 where the blur is unbounded) the
        bound is absolute, [lower, upper] in the output's unit, and the line says so.
        """
        if self.exact:
            return "exact"
        finite = np.isfinite(self.lower) & np.isfinite(self.upper)
        positive = finite & (self.lower > 0)
        width = np.divide(self.upper, self.lower, out=np.zeros(self.lower.shape),
                          where=positive) - 1.0
        worst = np.max(width[positive], initial=0.0)
        text = (f"streamed from a histogram (bins at most {100 * self.relative_resolution:.3g}% "
                f"wide): the true quantiles lie within bounds at most {100 * worst:.2g}% wide")
        absolute = finite & ~positive
        if absolute.any():
            text += (f"; {np.count_nonzero(absolute)} at or below the histogram's range lie in "
                     f"absolute bounds [{np.min(self.lower[absolute]):.4g}, "
                     f"{np.max(self.upper[absolute]):.4g}] ({self.of})")
        return text


@dataclass(frozen=True)
class Quantiles:
    """Quantiles of an output, per group: exact up to ``exact_up_to`` points, else estimated.

    Parameters
    ----------
    q : sequence of floats in [0, 1].
    by : group key, optional; None: one group.
    of : str, the output (default ``"epc"``).
    low, high : the output's unit, the range of the histogram used beyond ``exact_up_to``
        points (default 1 to 1e10, pixels); quantiles outside it are bounded only by the
        group's min and max.
    bins_per_decade : int, the histogram's resolution: its bins are at most
        10**(1 / bins_per_decade) - 1 wide, relative. They are octave bins (2**k an octave,
        the least k that is that fine: at 1000, 512 an octave, 0.195% wide), each value's bin
        read from its bits.
    exact_up_to : int, scans of at most this many points keep every finite value (16 bytes
        each with its group index) and compute exact quantiles.
    target : :class:`~epc_fast.scan.reductions.targets.Target` or mapping, optional: how
        accurate every quantile must be, in every group, for a scan with a stopping rule to stop.
    """

    q: tuple = (0.05, 0.5, 0.95)
    by: object = None
    of: str = "epc"
    low: float = 1.0
    high: float = 1e10
    bins_per_decade: int = 1000
    exact_up_to: int = 1 << 22
    target: object = None

    def __post_init__(self):
        check_output(self.of)
        object.__setattr__(self, "target", target_of(self.target))
        _check_range(self.low, self.high, log=True)
        q = tuple(float(p) for p in np.atleast_1d(self.q))
        if not q or not all(0.0 <= p <= 1.0 for p in q):
            raise ValueError(f"q must hold probabilities in [0, 1], got {self.q!r}")
        object.__setattr__(self, "q", q)
        if self.bins_per_decade < 1:
            raise ValueError(f"bins_per_decade must be >= 1, got {self.bins_per_decade!r}")

    @property
    def bin_layout(self) -> _OctaveBins:
        return _OctaveBins.covering(self.low, self.high, self.bins_per_decade)

    def start(self, key: GroupKey, points_total: int) -> dict:
        if points_total <= self.exact_up_to:
            return {"exact": True, "values": [], "groups": []}
        return {"exact": False, "counts": np.zeros((key.size, self.bin_layout.slots), np.int64),
                "min": np.full(key.size, np.inf), "max": np.full(key.size, -np.inf)}

    def reduce(self, chunk: Chunk, key: GroupKey) -> dict:
        values = chunk.finite_values(self.of)
        group = chunk.finite_groups(self.of, key)
        if chunk.points_total <= self.exact_up_to:
            return {"values": values, "groups": group}
        low, high = chunk.finite_min_max(self.of, key)
        return {"min": low, "max": high,
                "counts": self.bin_layout.counts(values, group, key.size)}

    def merge(self, state: dict, partial: dict) -> dict:
        if state["exact"]:
            state["values"].append(partial["values"])
            state["groups"].append(partial["groups"])
        else:
            state["counts"] += partial["counts"]
            np.minimum(state["min"], partial["min"], out=state["min"])
            np.maximum(state["max"], partial["max"], out=state["max"])
        return state

    def finish(self, state: dict, key: GroupKey, space) -> QuantilesResult:
        q = np.asarray(self.q)
        if state["exact"]:
            estimate = _exact_quantiles(state, key.size, q)
            return QuantilesResult(self.of, key.columns, q, estimate, estimate, estimate,
                                   True, 0.0)
        bins = self.bin_layout
        estimate, lower, upper = _histogram_quantiles(bins, state, q)
        return QuantilesResult(self.of, key.columns, q, estimate, lower, upper, False,
                               bins.relative_resolution)


def _order_statistic_q(q: np.ndarray, n: np.ndarray) -> np.ndarray:
    """(groups, 3 nq): each group's q, then q - s and q + s, s = sqrt(q (1 - q) / n), in [0, 1]."""
    with np.errstate(divide="ignore", invalid="ignore"):
        step = np.sqrt(q * (1.0 - q) / n[:, None])
    low, high = np.clip(q - step, 0.0, 1.0), np.clip(q + step, 0.0, 1.0)
    return np.nan_to_num(np.concatenate([np.broadcast_to(q, low.shape), low, high], axis=1))


def finish_with_order_statistics(reduction: "Quantiles", state: dict, key: GroupKey):
    """``reduction.finish`` with the quantiles' standard errors under independent draws, in the
    same pass over the values: half the distance between the quantiles at q -/+ sqrt(q (1 - q)
    / n) (n a group's finite values), the order statistics that bound a 68% interval of the
    q-quantile whatever the distribution (binomial counts of the values below it). The
    estimates are ``finish``'s, bit for bit (each quantile is computed on its own)."""
    q = np.asarray(reduction.q)
    nq = q.size
    if state["exact"]:
        group = np.concatenate(state["groups"]) if state["groups"] else np.empty(0, np.intp)
        n = np.bincount(group, minlength=key.size)
        every = _exact_quantiles(state, key.size, _order_statistic_q(q, n))
        estimate = every[:, :nq]
        lower = upper = estimate
    else:
        n = state["counts"].sum(axis=1)
        every, lower, upper = _histogram_quantiles(reduction.bin_layout, state,
                                                   _order_statistic_q(q, n))
        estimate, lower, upper = every[:, :nq], lower[:, :nq], upper[:, :nq]
    error = np.where(n[:, None] > 1, 0.5 * (every[:, 2 * nq:] - every[:, nq:2 * nq]), np.nan)
    bins = reduction.bin_layout
    return QuantilesResult(reduction.of, key.columns, q, estimate, lower, upper,
                           bool(state["exact"]),
                           0.0 if state["exact"] else bins.relative_resolution, error)


def _exact_quantiles(state: dict, groups: int, q: np.ndarray) -> np.ndarray:
    values = np.concatenate(state["values"]) if state["values"] else np.empty(0)
    group = np.concatenate(state["groups"]) if state["groups"] else np.empty(0, np.intp)
    order = np.argsort(group, kind="stable")
    splits = np.cumsum(np.bincount(group, minlength=groups))[:-1]
    estimate = np.full((groups, q.shape[-1]), np.nan)
    for g, part in enumerate(np.split(values[order], splits)):
        if part.size:
            estimate[g] = np.quantile(part, q[g] if q.ndim == 2 else q)
    return estimate


def _histogram_quantiles(bins: _OctaveBins, state: dict, q: np.ndarray):
    """Quantiles from slot counts: the bins of the order statistics around q (n - 1) bound the
    sample quantile; the estimate interpolates in log10 within the bin."""
    counts = state["counts"]
    edges = np.concatenate(([-np.inf], bins.edges, [np.inf]))
    t_edges = np.concatenate(([-np.inf], np.log10(bins.edges), [np.inf]))
    groups = counts.shape[0]
    estimate, lower, upper = (np.full((groups, q.shape[-1]), np.nan) for _ in range(3))
    for g in range(groups):
        cumulative = np.cumsum(counts[g])
        n = cumulative[-1]
        if n == 0:
            continue
        rank = (q[g] if q.ndim == 2 else q) * (n - 1)
        below = np.floor(rank)
        slot_low = np.searchsorted(cumulative, below, side="right")
        slot_high = np.searchsorted(cumulative, np.minimum(below + 1, n - 1), side="right")
        low, high = state["min"][g], state["max"][g]
        lower[g] = np.clip(edges[slot_low], low, high)
        upper[g] = np.clip(edges[slot_high + 1], low, high)
        slot = np.searchsorted(cumulative, rank, side="right")
        before = np.where(slot > 0, cumulative[slot - 1], 0)
        fraction = (rank - before + 0.5) / counts[g][slot]
        with np.errstate(invalid="ignore"):
            t = t_edges[slot] + fraction * (t_edges[slot + 1] - t_edges[slot])
        inside = np.isfinite(t)
        middle = 0.5 * (lower[g] + upper[g])
        estimate[g] = np.clip(np.where(inside, 10.0 ** np.where(inside, t, 0.0), middle),
                              lower[g], upper[g])
    return estimate, lower, upper
