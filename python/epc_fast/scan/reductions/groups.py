"""Group keys: which group each point belongs to, for per-group reductions.

A key is one or more parts, combined in mixed radix (the last part varies fastest):

- ``"design"`` or the name of a grid or choice parameter: the index of the point's value;
- the name of a parameter the designs give (e.g. ``"pixel_pitch_um"``): the index of the
  point's value among the designs' distinct values;
- :class:`Binned` ``(name, edges)``: the bin of a continuous parameter.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..sampling.space import Points, Space

__all__ = ["Binned", "GroupKey", "group_key", "replicated"]


@dataclass(frozen=True)
class Binned:
    """A continuous parameter cut into bins; the outer two bins are open-ended.

    Parameters
    ----------
    parameter : str, the parameter's name.
    edges : sequence of floats, the parameter's unit; increasing, at least 3. The bins are
        (-inf, edges[1]), [edges[1], edges[2]), ..., [edges[-2], +inf): ``edges[0]`` and
        ``edges[-1]`` only label the outer bins (for plots, give the range of the values).
    """

    parameter: str
    edges: tuple

    def __post_init__(self):
        edges = tuple(float(e) for e in self.edges)
        if len(edges) < 3 or not all(a < b for a, b in zip(edges, edges[1:])):
            raise ValueError(f"Binned needs at least 3 increasing edges, got {self.edges!r}")
        object.__setattr__(self, "edges", edges)


@dataclass(frozen=True)
class _Part:
    kind: str            # "axis", "design value" or "binned"
    name: str
    size: int
    lookup: np.ndarray | None = None   # design index -> value index ("design value")
    inner_edges: np.ndarray | None = None   # "binned"
    log_spacing: tuple | None = None   # "binned" on log-equal edges: log10(edges[0]), 1/step


@dataclass(frozen=True)
class GroupKey:
    """A resolved group key: point -> group index in ``0 .. size - 1``.

    Attributes
    ----------
    by : tuple, the key's parts (empty for a single group).
    size : number of groups.
    columns : {column name: list}, the label columns of every group, in group order.
    """

    by: object
    size: int
    columns: dict
    parts: tuple

    @property
    def identity(self) -> tuple:
        """What tells two keys apart: their parts' kinds and names, and their size (a key and
        its :func:`replicated` copy share ``by`` and differ here)."""
        return (self.by, tuple((part.kind, part.name) for part in self.parts), self.size)

    def indices(self, points: Points) -> np.ndarray:
        """The group index of every point."""
        if len(self.parts) == 1:
            return _part_indices(self.parts[0], points)
        combined = np.zeros(len(points), dtype=np.intp)
        for part in self.parts:
            combined *= part.size
            combined += _part_indices(part, points)
        return combined


def _part_indices(part: _Part, points: Points) -> np.ndarray:
    if part.kind in ("axis", "replicate"):
        return points.indices[part.name]
    if part.kind == "design value":
        return part.lookup[points.indices["design"]]
    values = np.broadcast_to(points.parameters[part.name], (len(points),))
    if part.log_spacing is None:
        return np.searchsorted(part.inner_edges, values, side="right")
    first, scale = part.log_spacing
    with np.errstate(divide="ignore"):
        position = np.log10(np.fmax(values, 0.0)) - first
    position *= scale
    np.clip(position, 0.0, part.size - 1.0, out=position)
    return position.astype(np.intp)


def _log_spacing(edges: tuple) -> tuple | None:
    """(log10 of the first edge, bins per decade) when the edges are equal steps in log10
    (e.g. ``np.geomspace``): bins are then found arithmetically, ~7x faster than a search, and
    may differ from it only for a value within rounding of an edge."""
    if edges[0] <= 0:
        return None
    logs = np.log10(edges)
    steps = np.diff(logs)
    if not np.allclose(steps, steps[0], rtol=1e-9, atol=0.0):
        return None
    return float(logs[0]), float(1.0 / steps[0])


def _as_parts(by) -> tuple:
    if by is None:
        return ()
    if isinstance(by, (str, Binned)):
        return (by,)
    return tuple(by)


def _resolve(space: Space, item) -> tuple[_Part, dict]:
    if isinstance(item, Binned):
        if item.parameter not in space.axes and item.parameter not in space.design_table:
            raise ValueError(f"cannot bin {item.parameter}: the space does not vary it")
        edges = item.edges
        return (_Part("binned", item.parameter, len(edges) - 1,
                      inner_edges=np.asarray(edges[1:-1]), log_spacing=_log_spacing(edges)),
                {f"{item.parameter} low": list(edges[:-1]),
                 f"{item.parameter} high": list(edges[1:])})
    if item in space.discrete_axes:
        return _Part("axis", item, len(space.axis_values(item))), {item: list(
            space.axis_values(item))}
    if item in space.design_table:
        values, lookup = np.unique(space.design_table[item], return_inverse=True)
        return _Part("design value", item, len(values), lookup=lookup), {item: list(values)}
    raise ValueError(f"cannot group by {item!r}: group by 'design', a grid or choice parameter, "
                     f"a parameter the designs give, or Binned(parameter, edges) "
                     f"(discrete axes: {', '.join(space.discrete_axes) or 'none'})")


def group_key(space: Space, by) -> GroupKey:
    """Resolve ``by`` (None, a part, or a sequence of parts) against ``space``."""
    parts, labels = [], []
    for item in _as_parts(by):
        part, columns = _resolve(space, item)
        parts.append(part)
        labels.append(columns)
    size = int(np.prod([p.size for p in parts], dtype=np.int64))
    columns = {}
    for i, (part, part_columns) in enumerate(zip(parts, labels)):
        inner = int(np.prod([p.size for p in parts[i + 1:]], dtype=np.int64))
        outer = size // (part.size * inner)
        for name, values in part_columns.items():
            columns[name] = list(np.tile(np.repeat(np.asarray(values, dtype=object), inner),
                                         outer))
    return GroupKey(_as_parts(by), size, columns, tuple(parts))


def replicated(key: GroupKey, replicates: int) -> GroupKey:
    """``key`` with the point's replicate (:mod:`epc_fast.scan.sampling.qmc`) as its first, slowest
    part: group ``r * key.size + g``; ``key`` itself for one replicate."""
    if replicates == 1:
        return key
    columns = {"replicate": list(np.repeat(np.arange(replicates), key.size))}
    columns.update({name: list(values) * replicates for name, values in key.columns.items()})
    part = _Part("replicate", "replicate", replicates)
    return GroupKey(key.by, key.size * replicates, columns, (part,) + key.parts)
