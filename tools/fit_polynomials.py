"""Fits the polynomial coefficients in cpp/include/epc_fast/polynomials.h with mpmath.

    python tools/fit_polynomials.py

Each function is written as x + x^3 P(x^2) (or x (c0 + x^2 P(x^2)), or z^3 P(z^2)) and P is a
Chebyshev fit, in 60-digit arithmetic, of the smooth remainder over the reduced range. The
script prints the coefficients as C++ and the largest relative error of the float64 Horner
evaluation against mpmath on a dense grid, in ulp.

The diffraction MTF near its cut-off, D(nu) = (2/pi)(acos nu - nu sqrt(1 - nu^2)) for
nu in [1/2, 1], is fitted as a whole in z = sqrt((1 - nu)/2) = sin(phi/2) (nu = cos phi):
D = (4 asin z - sin(4 asin z)) / pi = z^3 P(z^2), z in [0, 1/2]. Written so, it keeps its
relative precision down to nu = 1, where the textbook form's two terms cancel.
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


def diffraction_exact(nu):
    nu = mp.mpf(nu)
    return 2 / mp.pi * (mp.acos(nu) - nu * mp.sqrt(1 - nu * nu))


def diffraction_check(coeffs):
    """ulp of D(nu) on nu in [1/2, 1), z = sqrt((1 - nu)/2) formed in float64 as the core does."""
    nu = np.linspace(0.5, 1.0, 40001)[:-1]
    nu = np.concatenate([nu, 1.0 - np.logspace(-15, -2, 400)])
    z = np.sqrt(0.5 * (1.0 - nu))
    t = z * z
    approx = z * t * horner(coeffs, t)
    pick = np.concatenate([np.arange(0, 40000, 41), np.arange(40000, nu.size)])
    exact = np.array([float(diffraction_exact(v)) for v in nu[pick]])
    rel = np.abs(approx[pick] / exact - 1)
    return rel.max() / 2**-53


def main():
    # sin(pi r) = r * S(r^2), r in [-1/2, 1/2]: S(t) = sin(pi sqrt t) / sqrt t on [0, 1/4].
    s, s_err = fit(lambda t: mp.sinpi(mp.sqrt(t)) / mp.sqrt(t) if t > 0 else mp.pi, 0, 0.25, 8)
    # asin(z) = z + z^3 A(z^2), z in [0, 1/2]: A(t) = (asin(sqrt t) - sqrt t) / t^(3/2).
    a, a_err = fit(lambda t: (mp.asin(mp.sqrt(t)) - mp.sqrt(t)) / t**1.5 if t > 0
                   else mp.mpf(1) / 6, 0, 0.25, 13)
    # D(nu) = z^3 P(z^2), z = sin(phi/2) in [0, 1/2]: P(t) = D / t^(3/2), P(0) = 64 / (6 pi).
    def diffraction_remainder(t):
        if t == 0:
            return mp.mpf(64) / (6 * mp.pi)
        x = 4 * mp.asin(mp.sqrt(t))
        return (x - mp.sin(x)) / mp.pi / t**1.5

    d, d_err = fit(diffraction_remainder, 0, 0.25, 13)
    print("sinpi coefficients (t^0 ..):", s, "fit error", float(s_err),
          "max ulp", sinpi_check(s))
    print("asin remainder coefficients (t^0 ..):", a, "fit error", float(a_err),
          "max ulp", asin_check(a))
    print("diffraction coefficients (t^0 ..):", d, "fit error", float(d_err),
          "max ulp", diffraction_check(d))
    for name, cs in (("sinpi", s), ("asin", a), ("diffraction", d)):
        print(f"constexpr double {name}_coefficients[] = {{")
        for c in cs:
            print(f"    {c!r},")
        print("};")


if __name__ == "__main__":
    main()
