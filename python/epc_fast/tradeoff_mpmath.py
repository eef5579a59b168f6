"""The NumPy reference against the 50-digit mpmath model of tests/helpers/mp_model.py
(``epc-fast bench --mpmath K``)."""

from __future__ import annotations

import functools
import importlib
import sys
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

from .spectra import DEFAULT_ELECTRONS_PER_LUX_S_M2
from .status import Cause, Status

__all__ = ["MpmathCheck", "mpmath_check"]


@dataclass(frozen=True)
class MpmathCheck:
    """The reference against the 50-digit mpmath model of tests/helpers/mp_model.py.

    Attributes
    ----------
    points : count of points checked.
    status_mismatches : count whose (status, cause) differs from the one mpmath owes.
    max_rel_error : dict
        Output name -> the largest relative error over the points mpmath finds OK.
    """

    points: int
    status_mismatches: int
    max_rel_error: dict

    def summary(self) -> str:
        errors = ", ".join(f"{name} {value:.1e}" for name, value in self.max_rel_error.items())
        return (f"reference vs mpmath (50 digits) on {self.points} points: "
                f"{self.status_mismatches} status mismatches, max relative error {errors}")


def _tests_folders() -> list[Path]:
    """Where tests/helpers/mp_model.py may be: in this module's source checkout (an editable
    install), or under the working folder."""
    return [Path(__file__).resolve().parents[2] / "tests", Path.cwd() / "tests"]


@functools.lru_cache(maxsize=1)
def _mpmath_model():
    """tests/helpers/mp_model.py, imported: its ``mp_model`` (MODEL.md at 50 digits, statuses
    included), ``expected_status`` and ``relative_error``. Needs a source checkout and mpmath
    (the test extra)."""
    for folder in _tests_folders():
        if (folder / "helpers" / "mp_model.py").is_file():
            sys.path.insert(0, str(folder))  # the tests' own name for it: helpers.mp_model
            try:
                return importlib.import_module("helpers.mp_model")
            finally:
                sys.path.remove(str(folder))
    raise ImportError("the mpmath check uses tests/helpers/mp_model.py from a source checkout: "
                      "run from the repository's root (searched "
                      + ", ".join(str(f) for f in _tests_folders()) + ")")


def mpmath_check(points: Mapping, reference, count: int) -> MpmathCheck:
    """The first ``count`` of ``points`` (monochromatic designs, as :func:`random_designs`
    gives) and the reference's results on them, against mpmath at 50 digits."""
    model = _mpmath_model()
    outputs = ("t_mpe_s", "f50_cyc_per_mm", "epc")
    worst = dict.fromkeys(outputs, 0.0)
    mismatches = 0
    count = min(count, len(next(iter(points.values()))))
    for i in range(count):
        design = {name: float(values[i]) for name, values in points.items()}
        design.setdefault("electrons_per_lux_s_m2", DEFAULT_ELECTRONS_PER_LUX_S_M2)
        exact = model.mp_model(design)
        got = (Status(int(reference.status[i])), Cause(int(reference.cause[i])))
        if got != model.expected_status(exact):
            mismatches += 1
            continue
        if exact["status"] != "ok":
            continue
        for name in outputs:
            worst[name] = max(worst[name],
                              model.relative_error(float(getattr(reference, name)[i]),
                                                   exact[name]))
    return MpmathCheck(count, mismatches, worst)
