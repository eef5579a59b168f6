"""Per-group count, mean, std, min, max and status counts; the fraction below a threshold.

Every reduction follows one protocol (see :mod:`epc_fast.scan.running.runner`):
``start(key, points_total) -> state``, ``reduce(chunk, key) -> partial``,
``merge(state, partial) -> state`` (called in block order), ``finish(state, key, space)``.

Mean and variance are accumulated per block of :data:`~epc_fast.scan.sampling.space.BLOCK_POINTS`
points (count, mean, sum of squared deviations; ``np.bincount`` adds in point order) and
merged block after block with Chan's update, so the result does not depend on the chunk size,
the thread count or where a chunk was evaluated: it is the same to the last bit.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...status import Status
from ..running.chunk import OUTPUTS, Chunk
from .groups import GroupKey
from .targets import target_of

__all__ = ["Summary", "SummaryResult", "FractionBelow", "FractionBelowResult", "Moments",
           "check_output"]

STATUS_COUNT = len(Status)
#: The statuses a summary's table shows only where some point has them.
_WHERE_GIVEN = (Status.BEYOND_TABLE, Status.EXPOSURE_LIMIT)


def check_output(of: str) -> None:
    """A ValueError unless ``of`` is an output a reduction can take."""
    if of not in OUTPUTS:
        raise ValueError(f"of must be one of {', '.join(OUTPUTS)}; got {of!r}")


@dataclass
class SummaryResult:
    """Per-group statistics of one output over the points where it is finite.

    Attributes
    ----------
    of : str, the output (e.g. ``"epc"``: pixels).
    labels : {column: list}, each group's label.
    points : int64 (groups,), points in each group, whatever their status.
    status_counts : int64 (groups, len(Status)), points per :class:`epc_fast.Status`.
    count : int64 (groups,), points whose output is finite.
    mean, std, min, max : float64 (groups,), in the output's unit; std with ddof=0. NaN (and
        +inf, -inf for min, max) where a group has no finite value.
    mode_counts : int64 (groups, modes + 1), when the space's designs have readout modes:
        points per group at which the camera picks each mode (column 0: no mode has an EPC;
        column i + 1: mode i, the design's i-th); None otherwise.
    mean_error, std_error : float64 (groups,), the output's unit: the standard errors of
        ``mean`` and ``std`` (:mod:`epc_fast.scan.reductions.replicates`); NaN where the scan cannot
        tell (one replicate); None outside a scan.
    """

    of: str
    labels: dict
    points: np.ndarray
    status_counts: np.ndarray
    count: np.ndarray
    mean: np.ndarray
    std: np.ndarray
    min: np.ndarray
    max: np.ndarray
    mode_counts: np.ndarray | None = None
    mean_error: np.ndarray | None = None
    std_error: np.ndarray | None = None

    @property
    def mode_share(self) -> np.ndarray | None:
        """float64 (groups, modes): the share of each group's points at which the camera picks
        mode i (NaN for an empty group); None without modes."""
        if self.mode_counts is None:
            return None
        return np.divide(self.mode_counts[:, 1:], self.points[:, None],
                         out=np.full(self.mode_counts[:, 1:].shape, np.nan),
                         where=self.points[:, None] > 0)

    def columns(self) -> dict:
        """Table columns, one row per group."""
        # BEYOND_TABLE and EXPOSURE_LIMIT only where a point has them: a scan without
        # tabulated MTFs or a frame cap has none
        statuses = {s.name.lower().replace("_", " "): self.status_counts[:, s]
                    for s in Status
                    if s not in _WHERE_GIVEN or self.status_counts[:, s].any()}
        # a group with no finite value has no extremes: NaN, not the empty min's +inf
        empty = ~np.isfinite(self.mean)
        columns = {**self.labels, "points": self.points, **statuses, "mean": self.mean}
        if self.mean_error is not None:
            columns["mean error"] = self.mean_error
        columns["std"] = self.std
        if self.std_error is not None:
            columns["std error"] = self.std_error
        columns.update({"min": np.where(empty, np.nan, self.min),
                        "max": np.where(empty, np.nan, self.max)})
        if self.mode_counts is not None:
            share = self.mode_share
            columns.update({f"mode {i}": share[:, i] for i in range(share.shape[1])})
            if self.mode_counts[:, 0].any():
                columns["no mode"] = np.divide(
                    self.mode_counts[:, 0], self.points, out=np.full(self.points.shape, np.nan),
                    where=self.points > 0)
        return columns


def _status_counts(chunk: Chunk, key: GroupKey) -> np.ndarray:
    """int64 (groups, len(Status)): points per group and status."""
    status = chunk.result.status
    if not np.any(status):
        counts = np.zeros((key.size, STATUS_COUNT), np.int64)
        counts[:, Status.OK] = chunk.group_counts(key)
        return counts
    cell = chunk.group_indices(key) * STATUS_COUNT + status
    return np.bincount(cell, minlength=key.size * STATUS_COUNT).reshape(key.size, STATUS_COUNT)


@dataclass
class Moments:
    """Running count, mean and sum of squared deviations per group (Chan et al.)."""

    count: np.ndarray
    mean: np.ndarray
    m2: np.ndarray

    def add(self, count: np.ndarray, mean: np.ndarray, m2: np.ndarray) -> None:
        total = self.count + count
        weight = np.divide(count, total, out=np.zeros(total.shape), where=total > 0)
        delta = mean - self.mean
        self.mean += delta * weight
        self.m2 += m2 + delta * delta * self.count * weight
        self.count = total


@dataclass(frozen=True)
class Summary:
    """Count, mean, std, min, max and status counts of an output, per group.

    Parameters
    ----------
    by : group key, optional (see :mod:`epc_fast.scan.reductions.groups`); None: one group.
    of : str, the output summarised (default ``"epc"``, pixels).
    target : :class:`~epc_fast.scan.reductions.targets.Target` or mapping, optional: how
        accurate the mean must be, in every group, for a scan with a stopping rule to stop.
    """

    by: object = None
    of: str = "epc"
    target: object = None

    def __post_init__(self):
        check_output(self.of)
        object.__setattr__(self, "target", target_of(self.target))

    def start(self, key: GroupKey, points_total: int) -> dict:
        groups = key.size
        return {"status": np.zeros((groups, STATUS_COUNT), np.int64),
                "moments": Moments(np.zeros(groups, np.int64), np.zeros(groups),
                                    np.zeros(groups)),
                "min": np.full(groups, np.inf), "max": np.full(groups, -np.inf)}

    def reduce(self, chunk: Chunk, key: GroupKey) -> dict:
        groups = key.size
        values = chunk.finite_values(self.of)
        cells = chunk.block_count * groups
        cell = chunk.finite_blocks(self.of) * groups + chunk.finite_groups(self.of, key)
        count = np.bincount(cell, minlength=cells)
        total = np.bincount(cell, weights=values, minlength=cells)
        mean = np.divide(total, count, out=np.zeros(cells), where=count > 0)
        deviation = values - mean[cell]
        deviation *= deviation
        m2 = np.bincount(cell, weights=deviation, minlength=cells)
        low, high = chunk.finite_min_max(self.of, key)
        blocks = (chunk.block_count, groups)
        partial = {"status": _status_counts(chunk, key), "count": count.reshape(blocks),
                   "mean": mean.reshape(blocks), "m2": m2.reshape(blocks), "min": low,
                   "max": high}
        mode = getattr(chunk.result, "mode", None)
        if mode is not None:
            partial["modes"] = _mode_counts(chunk, key, np.asarray(mode))
        return partial

    def merge(self, state: dict, partial: dict) -> dict:
        state["status"] += partial["status"]
        for block in zip(partial["count"], partial["mean"], partial["m2"]):
            state["moments"].add(*block)
        np.minimum(state["min"], partial["min"], out=state["min"])
        np.maximum(state["max"], partial["max"], out=state["max"])
        if "modes" in partial:
            state["modes"] = _added(state.get("modes"), partial["modes"])
        return state

    def finish(self, state: dict, key: GroupKey, space) -> SummaryResult:
        moments = state["moments"]
        present = moments.count > 0
        mean = np.where(present, moments.mean, np.nan)
        std = np.sqrt(np.divide(moments.m2, moments.count, out=np.full(key.size, np.nan),
                                where=present))
        modes = None
        if getattr(space, "has_modes", False):
            modes = _added(np.zeros((key.size, space.mode_count + 1), np.int64),
                           state.get("modes", np.zeros((key.size, 1), np.int64)))
        return SummaryResult(self.of, key.columns, state["status"].sum(axis=1), state["status"],
                             moments.count, mean, std, state["min"], state["max"], modes)


def _mode_counts(chunk: Chunk, key: GroupKey, mode: np.ndarray) -> np.ndarray:
    """int64 (groups, modes + 1): points per group and picked mode (column 0: none)."""
    width = int(mode.max(initial=-1)) + 2
    cell = chunk.group_indices(key) * width + (mode.astype(np.int64) + 1)
    return np.bincount(cell, minlength=key.size * width).reshape(key.size, width)


def _added(a: np.ndarray | None, b: np.ndarray) -> np.ndarray:
    """The sum of two count tables of (groups, columns), the narrower padded with zeros."""
    if a is None:
        return b.copy()
    if a.shape[1] < b.shape[1]:
        a, b = b.copy(), a
    a[:, :b.shape[1]] += b
    return a


@dataclass
class FractionBelowResult:
    """Per-group fraction of the finite values below a threshold.

    Attributes
    ----------
    of : str, the output.
    threshold : the output's unit.
    labels : {column: list}, each group's label.
    count : int64 (groups,), points whose output is finite.
    below : int64 (groups,), of those, points below the threshold.
    fraction : float64 (groups,), below / count (NaN for an empty group).
    standard_error : float64 (groups,), the standard error of ``fraction``: under Monte Carlo
        sqrt(fraction (1 - fraction) / count), under Sobol' sampling the replicates' spread
        (:mod:`epc_fast.scan.reductions.replicates`).
    name : str, the column name in tables.
    """

    of: str
    threshold: float
    labels: dict
    count: np.ndarray
    below: np.ndarray
    fraction: np.ndarray
    standard_error: np.ndarray
    name: str

    def columns(self) -> dict:
        """Table columns, one row per group."""
        return {**self.labels, self.name: self.fraction,
                f"{self.name} error": self.standard_error}


@dataclass(frozen=True)
class FractionBelow:
    """How often an output falls below a threshold (e.g. EPC < 2 Mpixel), per group.

    Parameters
    ----------
    threshold : the output's unit (pixels for EPC).
    by : group key, optional; None: one group.
    of : str, the output (default ``"epc"``).
    target : :class:`~epc_fast.scan.reductions.targets.Target` or mapping, optional: how
        accurate the fraction must be, in every group, for a scan with a stopping rule to stop.
    """

    threshold: float
    by: object = None
    of: str = "epc"
    target: object = None

    def __post_init__(self):
        check_output(self.of)
        object.__setattr__(self, "target", target_of(self.target))

    @property
    def column_name(self) -> str:
        return f"P({self.of} < {self.threshold:g})"

    def start(self, key: GroupKey, points_total: int) -> dict:
        return {"count": np.zeros(key.size, np.int64), "below": np.zeros(key.size, np.int64)}

    def reduce(self, chunk: Chunk, key: GroupKey) -> dict:
        group = chunk.finite_groups(self.of, key)
        below = np.bincount(group, weights=chunk.finite_values(self.of) < self.threshold,
                            minlength=key.size)
        return {"count": chunk.finite_group_counts(self.of, key),
                "below": below.astype(np.int64)}

    def merge(self, state: dict, partial: dict) -> dict:
        state["count"] += partial["count"]
        state["below"] += partial["below"]
        return state

    def finish(self, state: dict, key: GroupKey, space) -> FractionBelowResult:
        count, below = state["count"], state["below"]
        fraction = np.divide(below, count, out=np.full(key.size, np.nan), where=count > 0)
        error = np.sqrt(np.divide(fraction * (1.0 - fraction), count,
                                  out=np.full(key.size, np.nan), where=count > 0))
        return FractionBelowResult(self.of, float(self.threshold), key.columns, count, below,
                                   fraction, error, self.column_name)
