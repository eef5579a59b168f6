"""The ``[sobol]`` table of a scan config: Sobol' indices of the config's space, beside the
scan's reductions (``epc-fast scan`` writes them as sobol.csv and sobol.md; ``epc-fast sobol``
computes them alone).

Every key is optional (``[sobol]`` alone asks for the defaults)::

    [sobol]
    points = 4096          # base points N of Saltelli's design, a power of 2 >= 16
    seed = 2009            # default: the [scan] seed
    of = ["epc", "log_epc"]  # "epc" (default), "log_epc" or both
    confidence = 0.95      # level of the intervals
    resamples = 100        # bootstrap resamples
    not_ok = "raise"       # or "zero": unreachable points count as 0 pixels (of = "epc")

The indices need their own points (Saltelli's design), not the scan's: a scan's random points
cannot give them.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

from ...jobs.errors import ConfigError
from ...jobs.schema import check_size, choice, integer, number, short, table_of, take, wrapped
from ..indices.estimate import (MAX_BOOTSTRAP_VALUES, MAX_DESIGN_VALUES, MIN_POINTS,
                                NOT_OK_POLICIES, OUTPUTS, design_rows, random_parameters)

__all__ = ["SobolConfig", "parse_sobol", "SOBOL_FILES", "DEFAULT_SOBOL_POINTS"]

#: The files the indices are written to in the output directory.
SOBOL_FILES = ("sobol.csv", "sobol.md")
#: Base points when ``[sobol]`` does not give them.
DEFAULT_SOBOL_POINTS = 4096
#: Bytes SALib's bootstrap takes per base point and resample (several int64 and float64
#: arrays alive at once).
BOOTSTRAP_BYTES = 48


@dataclass(frozen=True)
class SobolConfig:
    """The arguments of :func:`epc_fast.scan.sobol_indices` a config gives (all but the
    space and the threads)."""

    points: int = DEFAULT_SOBOL_POINTS
    seed: int = 0
    of: tuple = ("epc",)
    confidence: float = 0.95
    resamples: int = 100
    not_ok: str = "raise"

    def kwargs(self) -> dict:
        """Keyword arguments for :func:`epc_fast.scan.sobol_indices`."""
        return asdict(self)

    def check(self, space) -> "SobolConfig":
        """Refuse what :func:`~epc_fast.scan.sobol_indices` would refuse on ``space``, and every
        size past its bound, before any work; the message names the key and value."""
        if self.points & (self.points - 1) or self.points < MIN_POINTS:
            raise ConfigError(f"scan config [sobol]: points = {self.points}: expected a power "
                              f"of 2, at least {MIN_POINTS}")
        check_size("sobol", "points x resamples", self.points * self.resamples,
                   MAX_BOOTSTRAP_VALUES, BOOTSTRAP_BYTES)
        parameters = len(random_parameters(space))
        if not parameters:
            raise ConfigError("scan config [sobol]: the space has no random parameter (a "
                              "distribution, a choice or a grid in [parameters])")
        check_size("sobol", f"the design's values (points x rows x {parameters} parameters)",
                   design_rows(self.points, parameters) * parameters, MAX_DESIGN_VALUES, 8)
        if self.not_ok == "zero" and "log_epc" in self.of:
            raise ConfigError(f"scan config [sobol]: not_ok = \"zero\" counts unreachable points "
                              f"as EPC 0, whose log is -inf: it cannot go with of = "
                              f"{short(list(self.of))}")
        return self


def _of(value) -> tuple:
    values = [value] if isinstance(value, str) else value
    if (not isinstance(values, list) or not values or len(set(map(str, values))) != len(values)
            or not all(isinstance(v, str) and v in OUTPUTS for v in values)):
        raise ConfigError(f"scan config [sobol]: of = {short(value)}: expected "
                          + " or ".join(f'"{o}"' for o in OUTPUTS) + ", or a list of them")
    return tuple(values)


def parse_sobol(table, scan_seed: int, space) -> SobolConfig:
    """The :class:`SobolConfig` of a ``[sobol]`` table, checked against ``space``; the seed
    defaults to the scan's."""
    table = take(table_of("sobol", table), "sobol",
                 optional=("points", "seed", "of", "confidence", "resamples", "not_ok"))
    config = SobolConfig(
        points=integer("sobol", "points", table.get("points", DEFAULT_SOBOL_POINTS), MIN_POINTS,
                       MAX_BOOTSTRAP_VALUES, size=True),
        seed=integer("sobol", "seed", table.get("seed", scan_seed), 0, 2**64 - 1),
        of=_of(table.get("of", "epc")),
        confidence=number("sobol", "confidence", table.get("confidence", 0.95), 0.0, 1.0,
                          low_open=True, high_open=True),
        resamples=integer("sobol", "resamples", table.get("resamples", 100), 2,
                          MAX_BOOTSTRAP_VALUES, size=True),
        not_ok=choice("sobol", "not_ok", table.get("not_ok", "raise"), NOT_OK_POLICIES))
    return wrapped("sobol", lambda: config.check(space))
