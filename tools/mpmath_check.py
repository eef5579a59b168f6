"""The NumPy reference (or, with ``--backend core``, the compiled core) against the tests'
50-digit mpmath model of docs/model.md (tests/helpers/mp_model.py), on random designs: one
line, the statuses that differ and the largest relative error of T_MPE, f50 and EPC where
mpmath finds a point OK.

    python tools/mpmath_check.py --points 200 --seed 0

The designs are those of ``epc-fast bench`` (:func:`epc_fast.selfcheck.random_designs`): the
first ``--points`` of its ``--error-points`` compared designs, with the same ``--seed``. Needs
mpmath (the test extra) and this source checkout: the model lives beside the tests, not in the
installed package.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

TESTS = Path(__file__).resolve().parents[1] / "tests"
#: The outputs compared with mpmath.
OUTPUTS = ("t_mpe_s", "f50_cyc_per_mm", "epc")


@dataclass(frozen=True)
class MpmathCheck:
    """The reference against mpmath on some points.

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
    backend: str = "reference"

    def summary(self) -> str:
        errors = ", ".join(f"{name} {value:.1e}" for name, value in self.max_rel_error.items())
        return (f"{self.backend} vs mpmath (50 digits) on {self.points} points: "
                f"{self.status_mismatches} status mismatches, max relative error {errors}")


def _mp_model():
    """tests/helpers/mp_model.py, imported under the tests' own name for it."""
    if str(TESTS) not in sys.path:
        sys.path.insert(0, str(TESTS))
    from helpers import mp_model

    return mp_model


def mpmath_check(points: Mapping, reference, count: int,
                 backend: str = "reference") -> MpmathCheck:
    """The first ``count`` of ``points`` (monochromatic designs, as
    :func:`epc_fast.selfcheck.random_designs` gives) and the reference's results on them
    (``evaluate(..., backend="reference")``), against mpmath at 50 digits."""
    from epc_fast import Cause, Status
    from epc_fast.spectra import DEFAULT_ELECTRONS_PER_LUX_S_M2

    model = _mp_model()
    worst = dict.fromkeys(OUTPUTS, 0.0)
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
        for name in OUTPUTS:
            worst[name] = max(worst[name], model.relative_error(
                float(getattr(reference, name)[i]), exact[name]))
    return MpmathCheck(count, mismatches, worst, backend)


def main(argv=None) -> int:
    import epc_fast
    from epc_fast.selfcheck import random_designs

    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--points", type=int, default=100, help="designs checked (default 100)")
    parser.add_argument("--error-points", type=int, default=100_000,
                        help="the designs drawn, as epc-fast bench --error-points (default 1e5)")
    parser.add_argument("--seed", type=int, default=0, help="seed of the random designs")
    parser.add_argument("--backend", choices=("reference", "core"), default="reference",
                        help="the backend checked (default reference; core: the compiled core "
                        "at the level EPC_FAST_ISA or the CPU picks)")
    args = parser.parse_args(argv)
    if not 1 <= args.points <= args.error_points:
        parser.error("expected 1 <= --points <= --error-points")
    designs = {name: values[:args.points]
               for name, values in random_designs(args.error_points, args.seed).items()}
    name = "reference"
    if args.backend == "core":
        from epc_fast import _core

        name = f"core {_core.isa}"
    check = mpmath_check(designs, epc_fast.evaluate(**designs, backend=args.backend),
                         args.points, name)
    print(check.summary())
    return 0 if check.status_mismatches == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
