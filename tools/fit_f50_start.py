"""Fits the f50 solvers' starting guess (cpp/include/epc_fast/f50.h, start_f50).

Each MTF factor alone reaches 1/2 at its own frequency: diffraction at nu = NU50 / (lambda F),
a sinc of length l at X50 / l. With x_i = 1 / f_i (diffraction, pixel, motion), S = sum x_i^2 and
v_i = x_i / sqrt(S), the system's f50 is f50 = P(v) / sqrt(S), where P is a smooth function on
the unit sphere; this script fits P as a cubic polynomial in v_d, s = v_p + v_m and t = v_p v_m
(symmetric in the two sincs), by least squares on the relative error over factor ratios
e^-7..e^7, and prints the coefficients for f50.h with the largest and median errors.

    python tools/fit_f50_start.py
"""

import numpy as np

NU50 = 0.4039727532995172   # D(nu) = 1/2, the circular-pupil diffraction MTF
X50 = 0.6033545644016142    # sinc(x) = 1/2
DEGREE = 3


def diffraction(nu):
    nu = np.minimum(nu, 1.0)
    return (2 / np.pi) * (np.arccos(nu) - nu * np.sqrt((1 - nu) * (1 + nu)))


def f50(x_d, x_p, x_m):
    """f50 (in units of 1/x) by bisection, for inverse factor frequencies x_i = 1/f_i."""
    def mtf(f):
        return (diffraction(f * x_d * NU50) * np.abs(np.sinc(f * x_p * X50))
                * np.abs(np.sinc(f * x_m * X50)))
    lo = np.zeros_like(x_d)
    hi = 1 / np.maximum.reduce([x_d * NU50, x_p * X50, x_m * X50])
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        above = mtf(mid) > 0.5
        lo, hi = np.where(above, mid, lo), np.where(above, hi, mid)
    return 0.5 * (lo + hi)


def terms(v_d, s, t, degree=DEGREE):
    """The monomials v_d^i s^j t^k of total degree i + j + 2k <= degree, and their exponents."""
    columns, exponents = [], []
    for i in range(degree + 1):
        for j in range(degree + 1 - i):
            for k in range((degree - i - j) // 2 + 1):
                columns.append(v_d ** i * s ** j * t ** k)
                exponents.append((i, j, k))
    return np.stack(columns, 1), exponents


def main(n=400_000, seed=0):
    rng = np.random.default_rng(seed)
    x_d = np.ones(n)
    x_p = np.exp(rng.uniform(-7, 7, n))
    x_m = np.exp(rng.uniform(-7, 7, n)) * (rng.random(n) < 0.8)  # 20% without motion
    root_s = np.sqrt(x_d ** 2 + x_p ** 2 + x_m ** 2)
    v_d, v_p, v_m = x_d / root_s, x_p / root_s, x_m / root_s
    h = f50(x_d, x_p, x_m) * root_s
    columns, exponents = terms(v_d, v_p + v_m, v_p * v_m)
    coefficients, *_ = np.linalg.lstsq(columns / h[:, None], np.ones(n), rcond=None)
    error = np.abs(columns @ coefficients / h - 1)
    print(f"relative error of the start: max {error.max():.2e}, median {np.median(error):.2e}")
    for (i, j, k), c in zip(exponents, coefficients):
        print(f"    {{{i}, {j}, {k}, {float(c)!r}}},")


if __name__ == "__main__":
    main()
