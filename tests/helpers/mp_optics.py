"""The newer MTF and noise terms of docs/model.md in mpmath, for helpers/mp_model.py: the
wavefront error's aberration transfer function, the Gaussian denoising filter (its weights,
noise gain and transfer), the monotone cubic interpolant of an MTF table (a lens's, or a
demosaicker's) and the demosaickers' shipped table. Each is written from docs/model.md's
formula, at the caller's working precision, from float64 inputs taken exactly.
"""

import functools
from pathlib import Path

import mpmath as mp

#: The demosaickers' luminance MTF against f p_out (cycles/pixel), the data docs/model.md names.
DEMOSAIC_CSV = Path(__file__).resolve().parents[2] / "python" / "epc_fast" / "data" / \
    "demosaic_mtf.csv"


def mp_atf(nu, wavefront_rms_waves):
    """Shannon's ATF(nu) = 1 - (W/0.18)^2 (1 - 4 (nu - 1/2)^2) at nu = f lambda F < 1, for an
    rms wavefront error of W waves (docs/model.md, "System MTF"); the diffraction MTF it
    multiplies is 0 from nu = 1 on, so its value there does not matter (1 is returned)."""
    nu, w = mp.mpf(nu), mp.mpf(wavefront_rms_waves)
    if nu >= 1:
        return mp.mpf(1)
    w0 = mp.mpf(18) / 100  # waves: where the ATF reaches 0 at nu = 1/2
    return 1 - (w / w0) ** 2 * (1 - 4 * (nu - mp.mpf(1) / 2) ** 2)


def mp_denoise_kernel(denoise_sigma_px):
    """[h_0, h_1, ..., h_n]: the sampled Gaussian exp(-i^2 / (2 sigma^2)) on |i| <= n =
    ceil(4 sigma), normalised so that h_0 + 2 sum_{i>=1} h_i = 1 (h_-i = h_i); [1] at sigma = 0
    (no filter)."""
    sigma = mp.mpf(denoise_sigma_px)
    if sigma == 0:
        return [mp.mpf(1)]
    reach = int(mp.ceil(4 * sigma))
    e = [mp.exp(-mp.mpf(i) ** 2 / (2 * sigma**2)) for i in range(reach + 1)]
    total = e[0] + 2 * mp.fsum(e[1:])
    return [v / total for v in e]


def mp_noise_gain_denoise(denoise_sigma_px):
    """g = (sum_i h_i^2)^2 over every tap i (both signs), the separable filter's gain on the
    variance of white pixel noise; 1 at sigma = 0."""
    h = mp_denoise_kernel(denoise_sigma_px)
    one_d = h[0] ** 2 + 2 * mp.fsum(v**2 for v in h[1:])
    return one_d**2


def mp_mtf_denoise(f_p_out, kernel):
    """H = h_0 + 2 sum_{i>=1} h_i cos(2 pi x i) at x = f p_out (cycles per output pixel) up to
    the output's Nyquist frequency x = 1/2, and its value there beyond; `kernel` is
    :func:`mp_denoise_kernel`'s list."""
    x = min(mp.mpf(f_p_out), mp.mpf(1) / 2)
    return kernel[0] + 2 * mp.fsum(h * mp.cospi(2 * x * i) for i, h in enumerate(kernel)
                                   if i > 0)


def _knots(frequencies, mtf):
    """The table's knots as mpf lists, with the point (0, 1) put first when the table starts
    above frequency 0 (every MTF is 1 there)."""
    f, m = [mp.mpf(v) for v in frequencies], [mp.mpf(v) for v in mtf]
    if f[0] > 0:
        f, m = [mp.mpf(0)] + f, [mp.mpf(1)] + m
    return f, m


def _sign(x):
    return (x > 0) - (x < 0)


def _end_slope(h0, h1, delta0, delta1):
    """An end knot's slope: the three-point formula ((2 h0 + h1) delta0 - h0 delta1) / (h0 + h1),
    0 where its sign is not the end segment's, 3 delta0 where it exceeds that in size and the
    secants change sign (Fritsch and Butland's shape-preserving end condition)."""
    d = ((2 * h0 + h1) * delta0 - h0 * delta1) / (h0 + h1)
    if _sign(d) != _sign(delta0):
        return mp.mpf(0)
    if _sign(delta0) != _sign(delta1) and abs(d) > 3 * abs(delta0):
        return 3 * delta0
    return d


def mp_table_slopes(f, m):
    """The knot slopes of the monotone interpolant (Fritsch-Carlson with Fritsch-Butland's
    slopes, SciPy's PchipInterpolator): at an inner knot 0 where the neighbouring secants
    differ in sign or either is 0, else their weighted harmonic mean
    (w1 + w2) / (w1 / delta_{k-1} + w2 / delta_k), w1 = 2 h_k + h_{k-1}, w2 = h_k + 2 h_{k-1};
    :func:`_end_slope` at the ends; two knots: the secant's slope at both."""
    h = [b - a for a, b in zip(f, f[1:])]
    delta = [(b - a) / hk for a, b, hk in zip(m, m[1:], h)]
    if len(f) == 2:
        return [delta[0], delta[0]]
    d = [_end_slope(h[0], h[1], delta[0], delta[1])]
    for k in range(1, len(f) - 1):
        if delta[k - 1] * delta[k] > 0:
            w1, w2 = 2 * h[k] + h[k - 1], h[k] + 2 * h[k - 1]
            d.append((w1 + w2) / (w1 / delta[k - 1] + w2 / delta[k]))
        else:
            d.append(mp.mpf(0))
    d.append(_end_slope(h[-1], h[-2], delta[-1], delta[-2]))
    return d


def mp_table_interpolant(frequencies, mtf):
    """L(f): the cubic Hermite interpolant of the table (frequencies, mtf) with the knot slopes
    of :func:`mp_table_slopes`, held at its last value past its last frequency (docs/model.md,
    "Tabulated MTFs")."""
    f, m = _knots(frequencies, mtf)
    d = mp_table_slopes(f, m)

    def interpolant(x):
        x = mp.mpf(x)
        if x >= f[-1]:
            return m[-1]
        k = max(j for j in range(len(f) - 1) if f[j] <= x)
        h = f[k + 1] - f[k]
        t = (x - f[k]) / h
        return ((2 * t**3 - 3 * t**2 + 1) * m[k] + (t**3 - 2 * t**2 + t) * h * d[k]
                + (-2 * t**3 + 3 * t**2) * m[k + 1] + (t**3 - t**2) * h * d[k + 1])

    return interpolant


def mp_table_end(frequencies, mtf):
    """Where f50's bracket ends on a lens table: its first frequency with MTF 0, or its last
    frequency when it has none."""
    f, m = _knots(frequencies, mtf)
    return next((fk for fk, mk in zip(f, m) if mk == 0), f[-1])


@functools.lru_cache(maxsize=None)
def demosaic_table(demosaic):
    """(frequencies in cycles/pixel, M_dem) of the demosaicker, from :data:`DEMOSAIC_CSV` (lines
    starting with '#' are comments), as tuples of floats."""
    rows = [line.split(",") for line in DEMOSAIC_CSV.read_text().splitlines()
            if line.strip() and not line.startswith("#")]
    column = [name.strip() for name in rows[0]].index(demosaic)
    return (tuple(float(row[0]) for row in rows[1:]),
            tuple(float(row[column]) for row in rows[1:]))
