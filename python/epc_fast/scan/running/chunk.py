"""One evaluated chunk as the reductions see it, with the arrays they share computed once."""

from __future__ import annotations

import numpy as np

from ...api import Result
from ..reductions.groups import GroupKey
from ..sampling.space import BLOCK_POINTS, Points

__all__ = ["Chunk", "OUTPUTS"]

#: The outputs a reduction can summarise: the float fields of :class:`epc_fast.Result`.
#: The core's fused pass reads them by their index here, up to the last share (its
#: n_scan_outputs); the f50 across the motion is the arrays' alone.
OUTPUTS = ("electron_rate_e_per_s", "electrons", "t_mpe_s", "blur_mm", "f50_cyc_per_mm", "epc",
           "share_diffraction", "share_pixel", "share_motion", "share_jitter",
           "share_alignment", "f50_across_cyc_per_mm")


class Chunk:
    """Points ``start .. stop - 1`` of a scan of ``points_total`` points, and the model's result
    at each.

    Reductions look only at points whose output is finite (``finite_*``); status counts look at
    every point. Arrays of a group key are cached by the key's :attr:`GroupKey.identity`.
    """

    def __init__(self, points: Points, result: Result, points_total: int):
        self.points = points
        self.result = result
        self.points_total = points_total
        self._cache: dict = {}

    def __len__(self) -> int:
        return len(self.points)

    @property
    def block_count(self) -> int:
        """Blocks the chunk spans (the last may be partly used)."""
        return -(-len(self.points) // BLOCK_POINTS)

    def _cached(self, key, compute):
        if key not in self._cache:
            self._cache[key] = compute()
        return self._cache[key]

    def group_indices(self, key: GroupKey) -> np.ndarray:
        """The group of every point."""
        return self._cached(("groups", key.identity), lambda: key.indices(self.points))

    def finite_positions(self, of: str) -> np.ndarray | None:
        """Positions in the chunk of the points whose ``of`` is finite; None when all are."""
        def compute():
            finite = np.isfinite(getattr(self.result, of))
            return None if finite.all() else np.flatnonzero(finite)
        return self._cached(("positions", of), compute)

    def _finite(self, name: str, of: str, values: np.ndarray) -> np.ndarray:
        def compute():
            positions = self.finite_positions(of)
            return values if positions is None else values[positions]
        return self._cached((name, of), compute)

    def finite_values(self, of: str) -> np.ndarray:
        """The finite values of output ``of``."""
        return self._finite("values", of, getattr(self.result, of))

    def finite_groups(self, of: str, key: GroupKey) -> np.ndarray:
        """The groups of the points whose ``of`` is finite."""
        return self._finite(("groups", key.identity), of, self.group_indices(key))

    def finite_blocks(self, of: str) -> np.ndarray:
        """Block (within the chunk) of each point whose ``of`` is finite."""
        blocks = np.repeat(np.arange(self.block_count), BLOCK_POINTS)[:len(self)]
        return self._finite("blocks", of, blocks)

    def group_counts(self, key: GroupKey) -> np.ndarray:
        """int64 (groups,): points in each group, whatever their status."""
        return self._cached(("counts", key.identity), lambda: np.bincount(
            self.group_indices(key), minlength=key.size))

    def finite_group_counts(self, of: str, key: GroupKey) -> np.ndarray:
        """int64 (groups,): points in each group whose ``of`` is finite."""
        return self._cached(("finite counts", of, key.identity), lambda: np.bincount(
            self.finite_groups(of, key), minlength=key.size))

    def finite_min_max(self, of: str, key: GroupKey) -> tuple[np.ndarray, np.ndarray]:
        """The least and greatest finite ``of`` of each group (+inf, -inf when it has none)."""
        def compute():
            values, group = self.finite_values(of), self.finite_groups(of, key)
            low = np.full(key.size, np.inf)
            high = np.full(key.size, -np.inf)
            np.minimum.at(low, group, values)
            np.maximum.at(high, group, values)
            return low, high
        return self._cached(("min max", of, key.identity), compute)

    def finite_log10(self, of: str) -> np.ndarray:
        """log10 of the finite values of ``of``; -inf for values <= 0."""
        def compute():
            clipped = np.maximum(self.finite_values(of), 0.0)
            with np.errstate(divide="ignore"):
                return np.log10(clipped, out=clipped)
        return self._cached(("log10", of), compute)
