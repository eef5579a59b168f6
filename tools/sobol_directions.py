"""Writes python/epc_fast/data/sobol_joe_kuo.csv: the Sobol' direction numbers of the first
dimensions, one row per dimension as S. Joe and F. Y. Kuo publish them ("Constructing Sobol'
sequences with better two-dimensional projections", SIAM J. Sci. Comput. 30, 2635-2654, 2008;
the file new-joe-kuo-6.21201): d, s (the primitive polynomial's degree), a (its inner
coefficients as bits) and m_1 .. m_s. SciPy ships the same numbers (scipy.stats.qmc.Sobol's
``_sobol_direction_numbers.npz``: each polynomial as an integer with its leading and trailing
ones, and the m_i), from which this reads them.

    python tools/sobol_directions.py
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import scipy

DIMENSIONS = 64
OUT = Path(__file__).resolve().parents[1] / "python" / "epc_fast" / "data" / "sobol_joe_kuo.csv"


def main() -> None:
    data = np.load(os.path.join(os.path.dirname(scipy.__file__), "stats",
                                "_sobol_direction_numbers.npz"))
    lines = ["# Sobol' direction numbers, S. Joe and F. Y. Kuo (2008), new-joe-kuo-6.21201: "
             "dimension d (1: van der Corput), degree s, coefficients a, m_1 .. m_s",
             "d,s,a,m"]
    lines.append("1,0,0,")
    for d in range(1, DIMENSIONS):
        poly = int(data["poly"][d])
        s = poly.bit_length() - 1
        a = (poly >> 1) & ((1 << (s - 1)) - 1)
        m = " ".join(str(int(v)) for v in data["vinit"][d][:s])
        lines.append(f"{d + 1},{s},{a},{m}")
    OUT.write_text("\n".join(lines) + "\n")
    print(f"wrote {OUT} ({DIMENSIONS} dimensions)")


if __name__ == "__main__":
    main()
