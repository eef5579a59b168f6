"""The k best points of a scan (largest or smallest output), with their parameters.

Ties are broken by the point index (the lower index wins), so the selection is the same for
every chunking: each chunk keeps its own k best by that order and the merge picks the k best
of the candidates.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..running.chunk import Chunk
from ...jobs.errors import TooLargeError
from .groups import GroupKey
from .summaries import check_output

__all__ = ["TopK", "TopKResult", "MAX_K"]

#: The most points a TopK keeps: the core's bound (scan/reductions.h, cpp/src/register_scan.cpp).
MAX_K = 1 << 20


def _best(order_key: np.ndarray, index: np.ndarray, k: int) -> np.ndarray:
    """Positions of the k smallest ``order_key`` (ties: smallest ``index``), best first."""
    if order_key.size > k:
        kth = np.partition(order_key, k - 1)[k - 1]
        better = np.flatnonzero(order_key < kth)
        tied = np.flatnonzero(order_key == kth)
        tied = tied[np.argsort(index[tied], kind="stable")][:k - better.size]
        chosen = np.concatenate((better, tied))
    else:
        chosen = np.arange(order_key.size)
    return chosen[np.lexsort((index[chosen], order_key[chosen]))]


@dataclass
class TopKResult:
    """The k best points, best first.

    Attributes
    ----------
    of : str, the output.
    index : int64 (k,), the points' indices in the scan (the same seed reproduces them).
    value : float64 (k,), the output's unit.
    parameters : {name: float64 (k,)}, every parameter that varies, at those points; ``design``
        holds design names.
    """

    of: str
    index: np.ndarray
    value: np.ndarray
    parameters: dict

    def columns(self) -> dict:
        """Table columns, one row per point."""
        return {"point": self.index, self.of: self.value, **self.parameters}


@dataclass(frozen=True)
class TopK:
    """The k points with the largest (or smallest) output.

    Parameters
    ----------
    k : int, how many points.
    of : str, the output (default ``"epc"``).
    largest : bool, the largest values (default) or the smallest.
    """

    k: int = 10
    of: str = "epc"
    largest: bool = True
    by = None

    def __post_init__(self):
        check_output(self.of)
        if self.k < 1:
            raise ValueError(f"k must be >= 1, got {self.k!r}")
        if self.k > MAX_K:
            raise TooLargeError(f"TopK k = {self.k!r}: at most {MAX_K:,} points are kept "
                                f"(each thread of the core holds k candidates)")

    def _order_key(self, values: np.ndarray) -> np.ndarray:
        return -values if self.largest else values

    def start(self, key: GroupKey, points_total: int) -> dict:
        return {"index": np.empty(0, np.int64), "value": np.empty(0), "parameters": {},
                "design": np.empty(0, np.intp)}

    def reduce(self, chunk: Chunk, key: GroupKey) -> dict:
        values = chunk.finite_values(self.of)
        positions = chunk.finite_positions(self.of)
        if positions is None:
            positions = np.arange(len(chunk))
        index = chunk.points.index[positions]
        chosen = _best(self._order_key(values), index, self.k)
        at = positions[chosen]
        parameters = {name: np.broadcast_to(value, (len(chunk),))[at]
                      for name, value in chunk.points.parameters.items()}
        design = chunk.points.indices.get("design", np.zeros(len(chunk), np.intp))[at]
        return {"index": index[chosen], "value": values[chosen], "parameters": parameters,
                "design": design}

    def merge(self, state: dict, partial: dict) -> dict:
        if not state["parameters"]:
            state["parameters"] = {n: np.empty(0) for n in partial["parameters"]}
        both = {name: np.concatenate((state[name], partial[name]))
                for name in ("index", "value", "design")}
        chosen = _best(self._order_key(both["value"]), both["index"], self.k)
        merged = {name: values[chosen] for name, values in both.items()}
        merged["parameters"] = {
            name: np.concatenate((values, partial["parameters"][name]))[chosen]
            for name, values in state["parameters"].items()}
        return merged

    def finish(self, state: dict, key: GroupKey, space) -> TopKResult:
        # Before the first merge (a scan stopped before its first chunk) the state holds no
        # parameter: the result is then every column with no row.
        parameters = {name: state["parameters"].get(name, np.empty(0))
                      for name in space.varying_parameters}
        if space.design_names:
            parameters = {"design": [space.design_names[i] for i in state["design"]],
                          **parameters}
        return TopKResult(self.of, state["index"], state["value"], parameters)
