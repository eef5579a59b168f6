"""Fits the polynomial coefficients in cpp/include/epc_fast/polynomials.h with mpmath.

    python tools/fit_polynomials.py

Each function is written as x + x^3 P(x^2) (or x (c0 + x^2 P(x^2))) and P is a Chebyshev fit,
in 60-digit arithmetic, of the smooth remainder over the reduced range. The script prints the
coefficients as C++ and the largest relative error of the float64 Horner evaluation against
mpmath on a dense grid, in ulp.
"""

import mpmath as mp
import numpy as np

mp.mp.dps = 60


def fit(g, a, b, degree):
    coeffs, err = mp.chebyfit(g, [a, b], degree + 1, error=True)
    return [float(c) for c in reversed(coeffs)], err  # lowest order first


def horner(coeffs, t):
    acc = np.full_like(t, coeffs[-1])
    for c in reversed(coeffs[:-1]):
        acc = acc * t + c
    return acc


def sinpi_check(coeffs):
    r = np.linspace(-0.5, 0.5, 200001)
    r = r[r != 0]
    t = r * r
    approx = r * horner(coeffs, t)
    exact = np.array([float(mp.sinpi(mp.mpf(x))) for x in r[::97]])
    rel = np.abs(approx[::97] / exact - 1)
    return rel.max() / 2**-53


def asin_check(coeffs):
    z = np.linspace(0, 0.5, 100001)[1:]
    t = z * z
    approx = z + z * t * horner(coeffs, t)
    exact = np.array([float(mp.asin(mp.mpf(x))) for x in z[::53]])
    rel = np.abs(approx[::53] / exact - 1)
    return rel.max() / 2**-53


def main():
    # sin(pi r) = r * S(r^2), r in [-1/2, 1/2]: S(t) = sin(pi sqrt t) / sqrt t on [0, 1/4].
    s, s_err = fit(lambda t: mp.sinpi(mp.sqrt(t)) / mp.sqrt(t) if t > 0 else mp.pi, 0, 0.25, 8)
    # asin(z) = z + z^3 A(z^2), z in [0, 1/2]: A(t) = (asin(sqrt t) - sqrt t) / t^(3/2).
    a, a_err = fit(lambda t: (mp.asin(mp.sqrt(t)) - mp.sqrt(t)) / t**1.5 if t > 0
                   else mp.mpf(1) / 6, 0, 0.25, 13)
    print("sinpi coefficients (t^0 ..):", s, "fit error", float(s_err),
          "max ulp", sinpi_check(s))
    print("asin remainder coefficients (t^0 ..):", a, "fit error", float(a_err),
          "max ulp", asin_check(a))
    for name, cs in (("sinpi", s), ("asin", a)):
        print(f"constexpr double {name}_coefficients[] = {{")
        for c in cs:
            print(f"    {c!r},")
        print("};")


if __name__ == "__main__":
    main()
