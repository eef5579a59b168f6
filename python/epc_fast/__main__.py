"""Command line: ``epc-fast`` or ``python -m epc_fast``.

With no sub-command it prints the build (version, OpenMP, threads), checks the core against the
NumPy reference on random points, and evaluates the paper's 1/3.2" designs over illuminance.
"""

from __future__ import annotations

import argparse
import sys

import numpy as np

from . import __version__, evaluate
from .presets import HIGH_TIER
from .selfcheck import self_check

ILLUMINANCES_LUX = (100.0, 300.0, 1000.0, 3000.0, 10000.0, 100000.0)


def _info() -> None:
    from . import _core

    print(f"epc_fast {__version__}")
    print(f"OpenMP: {'on' if _core.openmp_enabled() else 'off'}, "
          f"threads: {_core.default_threads()}")


def _design_table() -> None:
    lux = np.asarray(ILLUMINANCES_LUX)
    print('\nEPC in megapixels of the paper\'s 1/3.2" designs (30 dB at the image corner):')
    print(f"{'design':<18}{'pixels':>8}" + "".join(f"{x:>10g}" for x in lux) + "  lux")
    for design in HIGH_TIER:
        epc = evaluate(lux, **design.evaluate_kwargs()).epc
        print(f"{design.name:<18}{design.pixel_count / 1e6:>7.2f}M"
              + "".join(f"{e / 1e6:>10.3f}" for e in epc))


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="epc-fast", description=__doc__.splitlines()[0])
    parser.add_argument("--check-points", type=int, default=20000,
                        help="random points for the core-vs-reference self-check")
    args = parser.parse_args(argv)
    _info()
    report = self_check(args.check_points)
    print(report.summary())
    _design_table()
    return 0 if report.passed else 1


if __name__ == "__main__":
    sys.exit(main())
