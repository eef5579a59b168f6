"""The Sobol' indices of a space (:func:`epc_fast.scan.sobol_indices`), as arrays and as a table."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["SobolResult"]


@dataclass(frozen=True, eq=False)
class SobolResult:
    """First- and total-order Sobol' indices, per output, design and random parameter.

    Every index array is indexed ``[output, design, parameter]`` in the order of ``of``,
    ``designs`` (one entry, ``""``, for a space without designs) and ``parameters``. An index
    is a fraction (1) of the output's variance; each ``*_conf`` is the half-width of its
    ``confidence`` interval (SALib's bootstrap, normal approximation).

    Attributes
    ----------
    of : tuple of str, the outputs: ``"epc"`` (pixels) and/or ``"log_epc"`` (ln pixels).
    designs : tuple of str, the design names; ``("",)`` for a space without a design axis.
    parameters : tuple of str, the random parameters of the space.
    points : int, base points of Saltelli's design (N, a power of 2).
    evaluations : int, model evaluations per design: N (D + 2), or N (2 D + 2) with
        second-order indices, D the number of random parameters.
    seed : int, the seed of the design and of the bootstrap.
    confidence : 1, the level of the confidence intervals.
    not_ok : str, the policy for points that cannot meet the SNR target ("raise" or "zero").
    s1, s1_conf, st, st_conf : float arrays of shape (outputs, designs, parameters), 1.
    s2, s2_conf : float arrays of shape (outputs, designs, parameters, parameters), 1, the
        second-order indices above the diagonal (NaN elsewhere); None unless asked for.
    mean, std : float arrays of shape (outputs, designs): the output's mean and standard
        deviation over the evaluated points, in its unit (pixels, ln pixels).
    unreachable : int array of shape (designs,): evaluated points that cannot meet the SNR
        target, or only with a frame longer than ``max_exposure_s`` (EXPOSURE_LIMIT), counted
        as 0 pixels (``not_ok="zero"``; 0 otherwise, as such points raise).
    blur_unbounded : int array of shape (designs,): evaluated points whose blur is unbounded
        (EPC 0 pixels in the model).
    """

    of: tuple
    designs: tuple
    parameters: tuple
    points: int
    evaluations: int
    seed: int
    confidence: float
    not_ok: str
    s1: np.ndarray
    s1_conf: np.ndarray
    st: np.ndarray
    st_conf: np.ndarray
    s2: np.ndarray | None
    s2_conf: np.ndarray | None
    mean: np.ndarray
    std: np.ndarray
    unreachable: np.ndarray
    blur_unbounded: np.ndarray

    def index(self, name: str, parameter: str, of: str | None = None,
              design: str | None = None) -> float:
        """One index: ``name`` is ``"S1"``, ``"S1_conf"``, ``"ST"`` or ``"ST_conf"``; ``of``
        and ``design`` may be left out when there is only one."""
        arrays = {"S1": self.s1, "S1_conf": self.s1_conf, "ST": self.st, "ST_conf": self.st_conf}
        if name not in arrays:
            raise ValueError(f"name must be one of {', '.join(arrays)}; got {name!r}")
        return float(arrays[name][self._position("of", self.of, of),
                                  self._position("design", self.designs, design),
                                  self._position("parameter", self.parameters, parameter)])

    @staticmethod
    def _position(what: str, names: tuple, name) -> int:
        if name is None and len(names) == 1:
            return 0
        if name not in names:
            raise ValueError(f"{what} must be one of {', '.join(map(repr, names))}; got {name!r}")
        return names.index(name)

    def table(self) -> dict:
        """{column: list}: one row per output, design and parameter. Columns ``of``,
        ``design`` (for a space with designs), ``parameter``, ``S1``, ``S1 +-`` (the half-width
        of S1's interval at ``confidence``), ``ST``, ``ST +-``, and, where any point was not
        OK, ``unreachable points`` and ``blur unbounded points`` (per design)."""
        rows = [(o, d, p) for o in range(len(self.of)) for d in range(len(self.designs))
                for p in range(len(self.parameters))]
        columns = {"of": [self.of[o] for o, _, _ in rows]}
        if self.designs != ("",):
            columns["design"] = [self.designs[d] for _, d, _ in rows]
        columns["parameter"] = [self.parameters[p] for _, _, p in rows]
        level = self.confidence_text()
        for name, values, conf in (("S1", self.s1, self.s1_conf), ("ST", self.st, self.st_conf)):
            columns[name] = [float(values[row]) for row in rows]
            columns[f"{name} +-{level}"] = [float(conf[row]) for row in rows]
        if self.unreachable.any() or self.blur_unbounded.any():
            columns["unreachable points"] = [int(self.unreachable[d]) for _, d, _ in rows]
            columns["blur unbounded points"] = [int(self.blur_unbounded[d]) for _, d, _ in rows]
        return columns

    def confidence_text(self) -> str:
        """The confidence level as a percentage, e.g. ``"95%"``."""
        return f"{self.confidence * 100:g}%"

    def markdown(self) -> str:
        """:meth:`table` as a markdown table (indices to 4 significant digits)."""
        from ...jobs.table_formats import markdown

        return markdown(self.table())

    def headline(self) -> str:
        """One line: what was computed, on how many points, with which seed."""
        designs = len(self.designs)
        return (f"Sobol' indices of {' and '.join(self.of)} over {len(self.parameters)} random "
                f"parameter(s): {self.points:,} base points, {self.evaluations:,} evaluations"
                + (f" per design ({designs} designs)" if self.designs != ("",) else "")
                + f", seed {self.seed}, {self.confidence_text()} intervals")
