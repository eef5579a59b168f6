"""Fits the f50 solvers' starting guesses and writes their coefficients to
cpp/include/epc_fast/f50/coefficients.h (f50/guesses.h evaluates them).

Three fits, written as C++ tables with their largest and median errors:

- `accurate`: one wavelength and no jitter, where f50 depends on two numbers only; one table
  row per threshold of ACCURATE_THRESHOLDS (MTF50, 30, 20, 10). Fitted to 1e-8..5e-5, so that
  one Halley step reaches float64's precision and the solver stops after one evaluation of the
  MTF (two at 0.1, whose fit is the coarsest).
- `jitter`: one wavelength with jitter at MTF50, where f50 depends on three numbers (v_d, v_j
  and w below), a polynomial of total degree JITTER_DEGREE, fitted to 1.3e-6 (one evaluation).
- `cubic`: every other scene (jitter at another threshold, another threshold, a spectrum), a
  cheap guess to 0.4%.

The fits are deterministic (fixed nodes and seeds): re-running the script rewrites the same
file, byte for byte, with the same NumPy and LAPACK. `read_header` reads a written file back
into the same tables, so that a test checks the file is exactly what `coefficients_header`
makes of its own numbers.

`--check` instead measures the installed core's accurate and jitter starts densely against the
bisected f50 (core_start_errors): the evidence for f50/guesses.h's certified_start_error, the bound
within which Halley and Newton take a start as f50 without a step.

Each MTF factor alone reaches 1/2 at its own frequency: diffraction at nu = NU50 / (lambda F),
a sinc of length l at X50 / l. With x_i = 1 / f_i (diffraction, pixel, motion), S = sum x_i^2 and
v_i = x_i / sqrt(S), the system's f50 is f50 = P(v) / sqrt(S), where P is a smooth function on
the unit sphere; this script fits P as a cubic polynomial in v_d, s = v_p + v_m and t = v_p v_m
(symmetric in the two sincs), by least squares on the relative error over factor ratios
e^-7..e^7.

The accurate fit: with no jitter the sphere has two coordinates, v_d and
w = v_p^2 - v_m^2 (|w| <= 1 - v_d^2: no division to form it), and P(v) is smooth in both (the
sincs enter through the squares of their lengths, diffraction linearly). P is a polynomial of
total degree ACCURATE_DEGREE in a = 2 v_d - 1 and w, even in w (swapping pixel and motion
changes w's sign), fitted in the Chebyshev basis on Chebyshev
nodes in v_d and s = v_p^2 / (v_p^2 + v_m^2), the largest relative error then reduced by
Lawson's reweighting, and written in the power basis of (a, w^2) for Horner's rule.

    python tools/fit_f50_start.py            # fits (~2 min) and writes the header
    python tools/fit_f50_start.py --stdout   # the same text on stdout instead
    python tools/fit_f50_start.py --check    # the core's starts' largest errors (~4 min)
    python tools/fit_f50_start.py --degrees 10 20 24   # MTF50's accurate start at other degrees
"""

import re
from pathlib import Path
from typing import NamedTuple

import numpy as np

#: The generated header, beside f50/guesses.h.
HEADER = Path(__file__).resolve().parent.parent / "cpp/include/epc_fast/f50/coefficients.h"

NU50 = 0.4039727532995172   # D(nu) = 1/2, the circular-pupil diffraction MTF
X50 = 0.6033545644016142    # sinc(x) = 1/2
DEGREE = 3
ACCURATE_DEGREE = 10
#: the jitter start's total degree in (a, u, w)
JITTER_DEGREE = 8
#: the thresholds with an accurate start, in f50/guesses.h's row order
ACCURATE_THRESHOLDS = (0.5, 0.3, 0.2, 0.1)


def diffraction(nu):
    nu = np.minimum(nu, 1.0)
    return (2 / np.pi) * (np.arccos(nu) - nu * np.sqrt((1 - nu) * (1 + nu)))


def f50(x_d, x_p, x_m, threshold=0.5, x_j=0.0):
    """The frequency where the MTF falls to `threshold` (in units of 1/x) by bisection, for
    inverse factor frequencies x_i = 1/f_i (each factor's own f50; jitter's Gaussian is
    2^-(f x_j)^2)."""
    def mtf(f):
        return (diffraction(f * x_d * NU50) * np.abs(np.sinc(f * x_p * X50))
                * np.abs(np.sinc(f * x_m * X50)) * np.exp2(-(f * x_j) ** 2))
    lo = np.zeros_like(x_d)
    # the first zero of each factor, and where jitter alone falls to the threshold
    hi = 1 / np.maximum.reduce([x_d * NU50, x_p * X50, x_m * X50,
                                x_j * np.sqrt(np.log2(1 / threshold)) + 0 * x_d])
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        above = mtf(mid) > threshold
        lo, hi = np.where(above, mid, lo), np.where(above, hi, mid)
    return 0.5 * (lo + hi)


def terms(v_d, s, t, degree=DEGREE):
    """The monomials v_d^i s^j t^k of total degree i + j + 2k <= degree, and their exponents."""
    exponents = cubic_exponents(degree)
    return np.stack([v_d ** i * s ** j * t ** k for i, j, k in exponents], 1), exponents


class Fitted(NamedTuple):
    """One start's coefficients (a table row) with its largest and median relative errors."""

    coefficients: np.ndarray
    largest: float
    median: float


def cubic_exponents(degree=DEGREE):
    """(i, j, k) of the cubic start's terms v_d^i s^j t^k, in its coefficients' order."""
    return [(i, j, k) for i in range(degree + 1) for j in range(degree + 1 - i)
            for k in range((degree - i - j) // 2 + 1)]


def fit_cubic(n=400_000, seed=0):
    """The cubic start's coefficients, in the order of cubic_exponents."""
    rng = np.random.default_rng(seed)
    x_d = np.ones(n)
    x_p = np.exp(rng.uniform(-7, 7, n))
    x_m = np.exp(rng.uniform(-7, 7, n)) * (rng.random(n) < 0.8)  # 20% without motion
    root_s = np.sqrt(x_d ** 2 + x_p ** 2 + x_m ** 2)
    v_d, v_p, v_m = x_d / root_s, x_p / root_s, x_m / root_s
    h = f50(x_d, x_p, x_m) * root_s
    columns, _ = terms(v_d, v_p + v_m, v_p * v_m)
    coefficients, *_ = np.linalg.lstsq(columns / h[:, None], np.ones(n), rcond=None)
    error = np.abs(columns @ coefficients / h - 1)
    return Fitted(coefficients, error.max(), np.median(error))


def accurate_target(v_d, s, threshold):
    """f sqrt(S) at v_d and s = v_p^2 / (v_p^2 + v_m^2), f where the MTF falls to `threshold`,
    by bisection (relative 1e-15)."""
    rest = 1 - v_d ** 2
    return f50(v_d, np.sqrt(s * rest), np.sqrt((1 - s) * rest), threshold)


def accurate_columns(a, w, degree=ACCURATE_DEGREE):
    """T_i(a) T_2j(w) for i + 2j <= degree, i outer (P is even in w: pixel and motion swap)."""
    ta = np.polynomial.chebyshev.chebvander(a, degree)
    tw = np.polynomial.chebyshev.chebvander(w, degree)
    return np.stack([ta[:, i] * tw[:, 2 * j] for i in range(degree + 1)
                     for j in range((degree - i) // 2 + 1)], 1)


def accurate_power_basis(chebyshev, degree=ACCURATE_DEGREE):
    """The same polynomial as c[i][j] a^i z^j with z = w^2 (i + 2j <= degree), from the
    Chebyshev coefficients; rows padded with zeros."""
    def cheb2poly(c):  # numpy drops trailing zeros; keep degree + 1 coefficients
        p = np.polynomial.chebyshev.cheb2poly(c)
        return np.concatenate([p, np.zeros(degree + 1 - len(p))])

    grid = np.zeros((degree + 1, degree + 1))  # Chebyshev coefficient of T_i(a) T_k(w)
    k = 0
    for i in range(degree + 1):
        for j in range((degree - i) // 2 + 1):
            grid[i, 2 * j] = chebyshev[k]
            k += 1
    grid = np.stack([cheb2poly(row) for row in grid], 0)  # along w: a polynomial in w
    grid = np.stack([cheb2poly(col) for col in grid.T], 1)  # along a
    return grid[:, 0::2]  # the odd powers of w are 0: coefficients of z^j


def horner(power, a, w, degree=ACCURATE_DEGREE):
    """Evaluates the power-basis polynomial as f50/guesses.h does: Horner in z = w^2, then in a."""
    z = w * w
    total = np.zeros_like(a)
    for i in range(degree, -1, -1):
        inner = np.zeros_like(a)
        for j in range((degree - i) // 2, -1, -1):
            inner = inner * z + power[i, j]
        total = total * a + inner
    return total


def chebyshev_nodes(n):
    """n Chebyshev (extrema) nodes on [0, 1], ends included."""
    return 0.5 - 0.5 * np.cos(np.pi * np.arange(n) / (n - 1))


def lawson(columns, rounds):
    """The coefficients c minimising max |columns c - 1| (columns: basis / target, so the
    relative error): least squares, reweighted by Lawson's rule, the weights growing where the
    error is largest."""
    weight = np.ones(columns.shape[0])
    for _ in range(rounds):
        root = np.sqrt(weight)
        coefficients, *_ = np.linalg.lstsq(columns * root[:, None], root, rcond=None)
        error = np.abs(columns @ coefficients - 1)
        weight = weight * error / np.sum(weight * error) * len(weight)
    return coefficients


def fit_accurate(threshold=0.5, nodes=140, check=400_000, seed=1, rounds=30,
                 degree=ACCURATE_DEGREE):
    """The accurate start's power-basis coefficients for one threshold, with its largest
    relative error over `check` random points and the domain's edges."""
    t = chebyshev_nodes(nodes)
    v_d, s = (g.ravel() for g in np.meshgrid(t, t, indexing="ij"))
    h = accurate_target(v_d, s, threshold)
    columns = accurate_columns(2 * v_d - 1, (2 * s - 1) * (1 - v_d ** 2), degree) / h[:, None]
    power = accurate_power_basis(lawson(columns, rounds), degree)
    rng = np.random.default_rng(seed)
    edge = np.linspace(0, 1, 2001)
    v_d = np.concatenate([rng.random(check), edge, edge, edge, np.zeros_like(edge), np.ones_like(edge)])
    s = np.concatenate([rng.random(check), np.zeros_like(edge), np.ones_like(edge), edge, edge, edge])
    h = accurate_target(v_d, s, threshold)
    error = np.abs(horner(power, 2 * v_d - 1, (2 * s - 1) * (1 - v_d ** 2), degree) / h - 1)
    return power, error.max(), np.median(error)


def accurate_terms(degree):
    """The accurate start's number of coefficients at total degree `degree` (i + 2j <= degree)."""
    return sum((degree - i) // 2 + 1 for i in range(degree + 1))


def print_degrees(degrees, threshold=0.5, nodes=80, rounds=40):
    """The accurate start's largest and median errors at other degrees, for the trade between
    its cost (a fused multiply-add a coefficient) and the tolerance it could be certified at
    (README, "Where the time goes"). The errors are against the bisected f50 (float64, about
    1e-16 relative), which bounds what the highest degrees can show. 80 nodes a side: at
    degree 24, 100 and 140 gave fits a thousand times worse (the least squares' conditioning;
    not pursued, as no degree paid off)."""
    for degree in degrees:
        _, largest, median = fit_accurate(threshold, nodes=nodes, rounds=rounds, degree=degree)
        print(f"threshold {threshold}, degree {degree} ({accurate_terms(degree)} coefficients): "
              f"relative error max {largest:.2e}, median {median:.2e}")


def jitter_target(v_d, t, s):
    """f sqrt(S) at threshold 1/2 with jitter, at v_d, t = v_j / sqrt(1 - v_d^2) (jitter's share
    of the rest) and s = v_p^2 / (v_p^2 + v_m^2), by bisection."""
    rest = 1 - v_d ** 2
    v_j = t * np.sqrt(rest)
    rest = np.maximum(rest - v_j ** 2, 0.0)
    return f50(v_d, np.sqrt(s * rest), np.sqrt((1 - s) * rest), 0.5, v_j)


def jitter_variables(v_d, t, s):
    """The jitter start's variables a = 2 v_d - 1, u = 2 v_j - 1 and w = v_p^2 - v_m^2."""
    rest = 1 - v_d ** 2
    v_j = t * np.sqrt(rest)
    return 2 * v_d - 1, 2 * v_j - 1, (2 * s - 1) * np.maximum(rest - v_j ** 2, 0.0)


def jitter_exponents(degree=JITTER_DEGREE):
    """(i, k, j) of the terms a^i u^k z^j, i + k + 2j <= degree, in f50/guesses.h's order."""
    return [(i, k, j) for i in range(degree + 1) for k in range(degree + 1 - i)
            for j in range((degree - i - k) // 2 + 1)]


def fit_jitter(nodes=56, check=400_000, seed=2, rounds=30, degree=JITTER_DEGREE):
    """The jitter start's power-basis coefficients (threshold 1/2, one wavelength), in the order
    of jitter_exponents, with the largest and median relative errors over `check` random points
    and the domain's faces."""
    exponents = jitter_exponents(degree)
    nd = np.polynomial.chebyshev.chebvander
    node = chebyshev_nodes(nodes)
    v_d, t, s = (g.ravel() for g in np.meshgrid(node, node, node, indexing="ij"))
    h = jitter_target(v_d, t, s)
    a, u, w = jitter_variables(v_d, t, s)
    ta, tu, tw = nd(a, degree), nd(u, degree), nd(w, degree)
    columns = np.stack([ta[:, i] * tu[:, k] * tw[:, 2 * j] for i, k, j in exponents], 1)
    chebyshev = lawson(columns / h[:, None], rounds)
    # to the power basis: along each axis in turn
    grid = np.zeros((degree + 1,) * 3)
    for (i, k, j), c in zip(exponents, chebyshev):
        grid[i, k, 2 * j] = c
    for axis in range(3):
        grid = np.apply_along_axis(
            lambda c: np.pad(np.polynomial.chebyshev.cheb2poly(c), (0, degree + 1))[:degree + 1],
            axis, grid)
    power = np.array([grid[i, k, 2 * j] for i, k, j in exponents])
    rng = np.random.default_rng(seed)
    edge = np.linspace(0, 1, 2001)
    zero, one = np.zeros_like(edge), np.ones_like(edge)
    v_d = np.concatenate([rng.random(check), edge, edge, edge, edge, zero, one, rng.random(2001)])
    t = np.concatenate([rng.random(check), zero, one, edge, edge, edge, edge, one])
    s = np.concatenate([rng.random(check), edge, edge, zero, one, edge, edge, rng.random(2001)])
    error = np.abs(horner_jitter(power, *jitter_variables(v_d, t, s), degree) / jitter_target(v_d, t, s) - 1)
    return power, error.max(), np.median(error)


def horner_jitter(power, a, u, w, degree=JITTER_DEGREE):
    """The jitter start as f50/guesses.h evaluates it: Horner in z = w^2, then u, then a."""
    z = w * w
    terms = dict(zip(jitter_exponents(degree), power))
    total = np.zeros_like(a)
    for i in range(degree, -1, -1):
        middle = np.zeros_like(a)
        for k in range(degree - i, -1, -1):
            inner = np.zeros_like(a)
            for j in range((degree - i - k) // 2, -1, -1):
                inner = inner * z + terms[(i, k, j)]
            middle = middle * u + inner
        total = total * a + middle
    return total


def accurate_row(power, degree=ACCURATE_DEGREE):
    """A threshold's power-basis grid c[i][j] as its table row: a^i z^j, i outer."""
    return np.array([power[i, j] for i in range(degree + 1) for j in range((degree - i) // 2 + 1)])


def accurate_power(row, degree=ACCURATE_DEGREE):
    """A table row back as the power-basis grid c[i][j] (zeros where i + 2j > degree)."""
    power = np.zeros((degree + 1, degree // 2 + 1))
    values = iter(row)
    for i in range(degree + 1):
        for j in range((degree - i) // 2 + 1):
            power[i, j] = next(values)
    return power


def fit_all():
    """Every start's fit: {threshold: Fitted} of the accurate start's rows, the jitter start's
    and the cubic start's."""
    accurate = {}
    for c in ACCURATE_THRESHOLDS:
        power, largest, median = fit_accurate(c)
        accurate[c] = Fitted(accurate_row(power), largest, median)
    power, largest, median = fit_jitter()
    return accurate, Fitted(power, largest, median), fit_cubic()


def _errors(fitted):
    return f"relative error max {fitted.largest:.2e}, median {fitted.median:.2e}"


def coefficients_header(accurate, jitter, cubic):
    """The text of f50/coefficients.h: the three starts' tables (fit_all's results)."""
    lines = [
        "// Generated by tools/fit_f50_start.py (python tools/fit_f50_start.py); do not edit.",
        "// The fitted coefficients of the f50 solvers' starting guesses, which guesses.h",
        "// evaluates (the fits, their variables and their domains: guesses.h and the tool).",
        "// Each start's largest and median relative errors against the bisected f50 are the",
        "// tool's, over its check points (400,000 random points and the domain's edges).",
        "#pragma once",
        "",
        "namespace epc_fast {",
        "namespace detail {",
        "",
        "// The accurate start: one row per threshold, the coefficients of a^i z^j",
        f"// (i + 2j <= {ACCURATE_DEGREE}) in float64, i outer.",
        f"constexpr int accurate_start_degree = {ACCURATE_DEGREE};",
        f"constexpr int accurate_start_terms = {accurate_terms(ACCURATE_DEGREE)};"
        f"  // i + 2j <= {ACCURATE_DEGREE}",
    ]
    lines += [f"// threshold {c!r}: {_errors(f)}" for c, f in accurate.items()]
    lines.append("constexpr double accurate_start_thresholds[] = "
                 f"{{{', '.join(repr(float(c)) for c in accurate)}}};")
    lines.append("constexpr double accurate_start_coefficients[][accurate_start_terms] = {")
    for c, fitted in accurate.items():
        lines.append(f"    {{  // threshold {c!r}")
        values = iter(fitted.coefficients)
        for i in range(ACCURATE_DEGREE + 1):
            last = (ACCURATE_DEGREE - i) // 2
            lines.append(f"        // a^{i}: z^0 .. z^{last}")
            lines += [f"        {float(next(values))!r}," for _ in range(last + 1)]
        lines.append("    },")
    lines += [
        "};",
        "",
        "// The jitter start (threshold 1/2): the coefficients of a^i u^k z^j",
        f"// (i + k + 2j <= {JITTER_DEGREE}) in float64, i outer, then k.",
        f"constexpr int jitter_start_degree = {JITTER_DEGREE};",
        f"constexpr int jitter_start_terms = {len(jitter_exponents())};"
        f"  // i + k + 2j <= {JITTER_DEGREE}",
        f"// jitter, threshold 0.5: {_errors(jitter)}",
        "constexpr double jitter_start_coefficients[jitter_start_terms] = {",
    ]
    last = None
    for (i, k, j), c in zip(jitter_exponents(), jitter.coefficients):
        if (i, k) != last:
            lines.append(f"    // a^{i} u^{k}: z^0 .. z^{(JITTER_DEGREE - i - k) // 2}")
            last = (i, k)
        lines.append(f"    {float(c)!r},")
    lines += [
        "};",
        "",
        "// The cubic start: the coefficients c_ijk of v_d^i s^j t^k (i + j + 2k <= 3), in",
        "// (i, j, k) order.",
        f"constexpr int cubic_start_terms = {len(cubic_exponents())};",
        f"// cubic, threshold 0.5, factor ratios e^-7..e^7: {_errors(cubic)}",
        "constexpr double cubic_start_coefficients[cubic_start_terms] = {",
    ]
    lines += [f"    {float(c)!r},  // {e}" for e, c in zip(cubic_exponents(), cubic.coefficients)]
    lines += [
        "};",
        "",
        "}  // namespace detail",
        "}  // namespace epc_fast",
    ]
    return "\n".join(lines) + "\n"


def read_header(text):
    """The tables of a written header, as coefficients_header takes them (the inverse of it)."""
    def block(name):
        body = re.search(rf"{name}\[[^]]*\](?:\[[^]]*\])? = {{(.*?)}};", text, re.S).group(1)
        body = re.sub(r"//[^\n]*", "", body)
        return [float(x) for x in re.findall(r"-?\d[\d.e+-]*", body)]

    def errors(label):
        found = re.search(rf"// {re.escape(label)}: relative error max (\S+), median (\S+)\n", text)
        return float(found.group(1).rstrip(",")), float(found.group(2))

    thresholds = block("accurate_start_thresholds")
    rows = np.reshape(block("accurate_start_coefficients"), (len(thresholds), -1))
    accurate = {c: Fitted(row, *errors(f"threshold {c!r}")) for c, row in zip(thresholds, rows)}
    jitter = Fitted(np.array(block("jitter_start_coefficients")), *errors("jitter, threshold 0.5"))
    cubic = Fitted(np.array(block("cubic_start_coefficients")),
                   *errors("cubic, threshold 0.5, factor ratios e^-7..e^7"))
    return accurate, jitter, cubic


def core_start_errors(n_random=4_000_000, n_grid=1001, n_grid_jitter=101, chunk=1_000_000):
    """The largest relative error of the installed core's own accurate and jitter starts
    (``epc_fast._core.testing.f50_start``, float64) against the bisected f50, over ``n_random``
    random points of each domain and a regular grid (``n_grid``^2; jitter ``n_grid_jitter``^3):
    the evidence behind f50/guesses.h's certified_start_error. Returns {row name: largest error}."""
    from epc_fast import _core  # the built package: this check measures what it computes

    def largest(columns, target, start):
        worst = 0.0
        for k in range(0, len(columns[0]), chunk):
            part = [c[k:k + chunk] for c in columns]
            worst = max(worst, float(np.max(np.abs(start(*part) / target(*part) - 1))))
        return worst

    rng = np.random.default_rng(11)
    grid = np.linspace(0, 1, n_grid)
    v_d, s = (np.concatenate([rng.random(n_random), g.ravel()])
              for g in np.meshgrid(grid, grid, indexing="ij"))

    def accurate_start(threshold):
        def start(v_d, s):
            rest = 1 - v_d ** 2
            return _core.testing.f50_start(v_d * NU50, np.sqrt(s * rest) * X50,
                                           np.sqrt((1 - s) * rest) * X50, 0.0, threshold)
        return start

    errors = {}
    for c in ACCURATE_THRESHOLDS:
        errors[f"threshold {c}"] = largest((v_d, s), lambda v, s_, c=c: accurate_target(v, s_, c),
                                           accurate_start(c))
    grid = np.linspace(0, 1, n_grid_jitter)
    v_d, t, s = (np.concatenate([rng.random(n_random), g.ravel()])
                 for g in np.meshgrid(grid, grid, grid, indexing="ij"))
    j50 = np.sqrt(np.log(2) / 2) / np.pi  # exp(-2 pi^2 y^2) = 1/2

    def jitter_start(v_d, t, s):
        rest = 1 - v_d ** 2
        v_j = t * np.sqrt(rest)
        rest = np.maximum(rest - v_j ** 2, 0.0)
        return _core.testing.f50_start(v_d * NU50, np.sqrt(s * rest) * X50,
                                       np.sqrt((1 - s) * rest) * X50, v_j * j50, 0.5)

    errors["jitter"] = largest((v_d, t, s), jitter_target, jitter_start)
    return errors


if __name__ == "__main__":
    import sys

    if "--degrees" in sys.argv[1:]:
        print_degrees([int(d) for d in sys.argv[sys.argv.index("--degrees") + 1:]])
    elif "--check" in sys.argv[1:]:
        for name, error in core_start_errors().items():
            print(f"{name}: largest relative error {error:.3e}")
    else:
        text = coefficients_header(*fit_all())
        if "--stdout" in sys.argv[1:]:
            print(text, end="")
        else:
            HEADER.write_text(text)
            print(f"wrote {HEADER}")
