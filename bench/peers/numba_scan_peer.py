"""The Numba peer of a Monte Carlo scan: one ``numba.prange`` loop that draws, evaluates and
reduces, as a strong user would write it instead of ``epc_fast.scan.run``.

The scanned space is the built-in default scan (``epc_fast.scan.config.default_config().space``):
the paper's four 1/3.2" designs on a grid axis (point i has design i mod 4), illuminance
log-uniform on [10, 1e5] lux, hand shake log-normal (median 4.39 degree/s, sigma 0.5 of ln),
every other parameter the designs' value or evaluate's default.

Draws follow the scan's counter-based stream contract (``epc_fast.scan.sampling.streams``),
implemented here in Numba:

- Philox4x32-10 (Salmon, Moraes, Dror and Shaw, SC'11; multipliers 0xD2511F53, 0xCD9E8D57, key
  increments 0x9E3779B9, 0xBB67AE85), the 32x32 -> 64-bit products in uint64; key
  (seed mod 2^32, seed div 2^32), counter (j mod 2^32, j div 2^32, crc32(name), 0) with
  j = i div 2 (one call serves points 2j and 2j + 1);
- one uniform per point and parameter, u = (k + 0.5) 2^-52 with k = xa 2^20 + (xb div 2^12),
  (xa, xb) = (x0, x1) for an even i and (x2, x3) for an odd i;
- log-uniform exp(log lo + u (log hi - log lo)) clamped to [lo, hi]; log-normal
  exp(log median + sigma ndtri(u)), ndtri by Wichura's AS 241 (PPND16, Applied Statistics 37,
  1988, 477-484; relative error about 1e-16).

The model is ``peers/numba_peer.py``'s: closed-form T_MPE (docs/model.md, "Exposure: T_MPE",
here with the designs' cos^4 corner falloff, which that peer's benchmark scene does not have), the blur of
section 4, and f50 by that peer's safeguarded Halley iteration (``_f50_halley``, rtol 1e-14) or,
with ``same_algorithm=True``, by the core's own algorithm (``_f50_core_algorithm``).

The reductions, per design, in the same loop, into per-thread accumulators that are summed once
at the end (the result does not depend on the thread count beyond the rounding of the mean and
standard deviation, which merge in another order):

- status counts; count, mean, std (ddof 0), min and max of EPC over its finite values
  (Welford's update per point, Chan's merge across threads);
- an 80-bin log10 histogram of EPC on [1e3, 1e7) pixels with the finite values below and above;
- the number and fraction of finite values below 2e6 pixels;
- an octave histogram on [1, 1e10) pixels, 512 bins an octave, and from it the 5, 50 and 95%
  quantiles as ``epc_fast.scan.Quantiles`` streams them (:func:`histogram_quantiles`).

On the log10 histogram a value's bin is floor((log10 EPC - log10 low) bins / (log10 high -
log10 low)) + 1 in slots 0 .. bins + 1 (0 below, bins + 1 at or above), as
``epc_fast.scan.reductions.histograms`` bins; on the octave histogram it is the value's exponent and
first 9 mantissa bits (from ``math.frexp``), less the first bin's, plus 1, clipped likewise, as
``epc_fast.scan.Quantiles`` bins. EPC = 0 (blur unbounded) is finite and falls below every
histogram.

    from peers import numba_scan_peer
    numba_scan_peer.warm_up(threads=2)             # compiles; no timing should include it
    result = numba_scan_peer.scan(2**21, seed=2009, threads=2)
    result["mean"], result["quantiles"]            # per design

Numba is a bench-only dependency (the ``bench`` extra).
"""

from __future__ import annotations

import math
import zlib
from dataclasses import dataclass

import numba
import numpy as np

from epc_fast.params import PARAMETERS
from epc_fast.scan.config import default_config
from epc_fast.scan.sampling.distributions import Grid, LogNormal, LogUniform
from epc_fast.spectra import DEFAULT_ELECTRONS_PER_LUX_S_M2
from epc_fast.status import Status

from .numba_peer import (START_COEFFICIENTS, START_DEGREE, _f50_core_algorithm, _f50_halley,
                         _guess_coefficients)

__all__ = ["scan", "warm_up", "Scene", "default_scene", "histogram_quantiles", "draws",
           "uniforms", "ndtri", "philox4x32_10", "stream_id", "HISTOGRAM", "QUANTILE_HISTOGRAM",
           "OctaveBins", "BELOW_THRESHOLD", "QUANTILES"]

# --- Philox4x32-10 and the uniforms (the stream contract) -----------------------------------

MASK32 = np.uint64(0xFFFFFFFF)
PHILOX_M0 = np.uint64(0xD2511F53)
PHILOX_M1 = np.uint64(0xCD9E8D57)
PHILOX_W0 = np.uint64(0x9E3779B9)
PHILOX_W1 = np.uint64(0xBB67AE85)
SHIFT_12 = np.uint64(12)
SHIFT_20 = np.uint64(20)
SHIFT_32 = np.uint64(32)
ZERO = np.uint64(0)
ONE = np.uint64(1)
#: 2^-52: the uniforms' grid step.
TWO_TO_MINUS_52 = 2.0 ** -52


@numba.njit(inline="always")
def _philox(c0, c1, c2, c3, k0, k1):
    """Philox4x32-10 of the counter (c0, c1, c2, c3) under the key (k0, k1): four output
    words. Every argument and result is a uint64 holding a 32-bit word, so that the 32x32-bit
    products are exact in uint64 and their high and low halves are a shift and a mask."""
    for round_ in range(10):
        if round_ > 0:  # the key is bumped before rounds 2 to 10
            k0 = (k0 + PHILOX_W0) & MASK32
            k1 = (k1 + PHILOX_W1) & MASK32
        product0 = PHILOX_M0 * c0
        product1 = PHILOX_M1 * c2
        c0, c1, c2, c3 = ((product1 >> SHIFT_32) ^ c1 ^ k0, product1 & MASK32,
                          (product0 >> SHIFT_32) ^ c3 ^ k1, product0 & MASK32)
    return c0, c1, c2, c3


@numba.njit(inline="always")
def _uniform_of(xa, xb):
    """1: (k + 0.5) 2^-52 with k = xa 2^20 + (xb div 2^12) < 2^52, every step exact."""
    k = (xa << SHIFT_20) | (xb >> SHIFT_12)
    return (float(k) + 0.5) * TWO_TO_MINUS_52


@numba.njit(inline="always")
def _pair_uniforms(pair, stream, key0, key1):
    """1: the uniforms of points 2 pair and 2 pair + 1 (pair a uint64) in stream ``stream``
    (uint64), from one call: words (x0, x1) for the even point, (x2, x3) for the odd one."""
    x0, x1, x2, x3 = _philox(pair & MASK32, pair >> SHIFT_32, stream, ZERO, key0, key1)
    return _uniform_of(x0, x1), _uniform_of(x2, x3)


@numba.njit(inline="always")
def _uniform(index, stream, key0, key1):
    """1: the uniform in (0, 1) of point ``index`` (uint64) in stream ``stream`` (uint64)."""
    even, odd = _pair_uniforms(index >> ONE, stream, key0, key1)
    return odd if index & ONE else even


def stream_id(name: str) -> int:
    """The stream of parameter ``name``: zlib's CRC-32 of its UTF-8 bytes."""
    return zlib.crc32(name.encode("utf-8"))


def _key(seed: int) -> tuple[np.uint64, np.uint64]:
    seed = int(seed)
    if not 0 <= seed < 1 << 64:
        raise ValueError(f"seed must be an integer in [0, 2^64), got {seed!r}")
    return np.uint64(seed & 0xFFFFFFFF), np.uint64(seed >> 32)


@numba.njit
def _philox_words(counter, key):
    out = np.empty(4, dtype=np.uint64)
    out[0], out[1], out[2], out[3] = _philox(counter[0], counter[1], counter[2], counter[3],
                                             key[0], key[1])
    return out


def philox4x32_10(counter, key) -> np.ndarray:
    """uint64 (4,): Philox4x32-10 of four 32-bit counter words under two 32-bit key words."""
    return _philox_words(np.asarray(counter, dtype=np.uint64), np.asarray(key, dtype=np.uint64))


@numba.njit
def _uniforms(key0, key1, stream, index):
    out = np.empty(index.shape[0])
    for j in range(index.shape[0]):
        out[j] = _uniform(index[j], stream, key0, key1)
    return out


def uniforms(seed: int, stream: int, index) -> np.ndarray:
    """float64: the uniforms of points ``index`` (integers in [0, 2^64)) in stream ``stream``
    (a :func:`stream_id`) under ``seed``, as the scan kernel draws them."""
    key0, key1 = _key(seed)
    return _uniforms(key0, key1, np.uint64(stream), np.asarray(index, dtype=np.uint64))


# --- Wichura's AS 241 (PPND16): the standard normal quantile --------------------------------

# Coefficients as published (Wichura 1988), lowest power first; B, D and F have leading 1.
AS241_A = (3.3871328727963666080e0, 1.3314166789178437745e+2, 1.9715909503065514427e+3,
           1.3731693765509461125e+4, 4.5921953931549871457e+4, 6.7265770927008700853e+4,
           3.3430575583588128105e+4, 2.5090809287301226727e+3)
AS241_B = (1.0, 4.2313330701600911252e+1, 6.8718700749205790830e+2, 5.3941960214247511077e+3,
           2.1213794301586595867e+4, 3.9307895800092710610e+4, 2.8729085735721942674e+4,
           5.2264952788528545610e+3)
AS241_C = (1.42343711074968357734e0, 4.63033784615654529590e0, 5.76949722146069140550e0,
           3.64784832476320460504e0, 1.27045825245236838258e0, 2.41780725177450611770e-1,
           2.27238449892691845833e-2, 7.74545014278341407640e-4)
AS241_D = (1.0, 2.05319162663775882187e0, 1.67638483018380384940e0, 6.89767334985100004550e-1,
           1.48103976427480074590e-1, 1.51986665636164571966e-2, 5.47593808499534494600e-4,
           1.05075007164441684324e-9)
AS241_E = (6.65790464350110377720e0, 5.46378491116411436990e0, 1.78482653991729133580e0,
           2.96560571828504891230e-1, 2.65321895265761230930e-2, 1.24266094738807843860e-3,
           2.71155556874348757815e-5, 2.01033439929228813265e-7)
AS241_F = (1.0, 5.99832206555887937690e-1, 1.36929880922735805310e-1, 1.48753612908506148525e-2,
           7.86869131145613259100e-4, 1.84631831751005468180e-5, 1.42151175831644588870e-7,
           2.04426310338993978564e-15)


@numba.njit(inline="always")
def _horner(c, r):
    """c0 + c1 r + ... + c7 r^7 by Horner's rule."""
    return ((((((c[7] * r + c[6]) * r + c[5]) * r + c[4]) * r + c[3]) * r + c[2]) * r
            + c[1]) * r + c[0]


@numba.njit(inline="always")
def _ndtri(p):
    """Phi^-1(p) for p in (0, 1): AS 241's three rational approximations, on
    |p - 1/2| <= 0.425, then in r = sqrt(-log(min(p, 1 - p))) on r <= 5 and beyond."""
    q = p - 0.5
    if abs(q) <= 0.425:
        r = 0.180625 - q * q
        return q * _horner(AS241_A, r) / _horner(AS241_B, r)  # (q num) / den, as published
    r = math.sqrt(-math.log(p if q < 0.0 else 1.0 - p))
    if r <= 5.0:
        r -= 1.6
        value = _horner(AS241_C, r) / _horner(AS241_D, r)
    else:
        r -= 5.0
        value = _horner(AS241_E, r) / _horner(AS241_F, r)
    return -value if q < 0.0 else value


@numba.njit
def _ndtri_array(p):
    out = np.empty(p.shape[0])
    for j in range(p.shape[0]):
        out[j] = _ndtri(p[j])
    return out


def ndtri(p) -> np.ndarray:
    """float64: the standard normal quantile at probabilities ``p`` in (0, 1) (AS 241)."""
    return _ndtri_array(np.ascontiguousarray(p, dtype=np.float64).ravel())


# --- The scene: what the kernel needs of the space ------------------------------------------

#: Parameters a design or the space may give; every other one must keep its default.
SUPPORTED = ("pixel_pitch_um", "f_number", "focal_length_mm", "sensor_area_mm2",
             "field_angle_deg", "snr_db", "stabilization", "reflectance", "read_noise_e",
             "wavelength_nm", "mtf_threshold", "electrons_per_lux_s_m2", "illuminance_lux",
             "shake_deg_per_s")
DEFAULTS = {p.name: p.default for p in PARAMETERS}
DEFAULTS["electrons_per_lux_s_m2"] = DEFAULT_ELECTRONS_PER_LUX_S_M2
#: f50's relative tolerance: evaluate's default f50_rtol.
F50_RTOL = 1e-14
OK = int(Status.OK)
UNREACHABLE = int(Status.UNREACHABLE)
BLUR_UNBOUNDED = int(Status.BLUR_UNBOUNDED)
STATUS_COUNT = len(Status)
DEG = math.pi / 180.0
HALF_PI = math.pi / 2.0
SMALLEST_NORMAL = float(np.finfo(np.float64).tiny)


@dataclass(frozen=True)
class Scene:
    """The scan's space as the kernel reads it: per-design constants (arrays over the design
    axis, float64) and the two drawn parameters' distributions.

    Attributes
    ----------
    design_names : tuple of str.
    light : e-/s per lux, R K cos^4(theta) (p 1e-6 m)^2 / (4 F^2): the electron rate is
        illuminance x light (docs/model.md, "Exposure: T_MPE"; lens transmittance and fill
        factor are 1).
    electrons : e-, the photo-electrons T_MPE needs: sqrt(s)/2 (sqrt(s) + hypot(sqrt(s),
        2 sigma_r)), s = 10^(snr_db/10) (no dark current or PRNU).
    focal_length_mm, stabilization : mm, 1.
    lambda_f_mm, aperture_mm : mm, lambda F and the pixel aperture p 1e-3 (fill factor 1).
    sensor_area_mm2 : mm^2.
    mtf_threshold : 1, the MTF level c of f_c (0.5: f50).
    illuminance : (low, high) lux of the log-uniform illuminance.
    shake : (median degree/s, sigma of ln) of the log-normal hand shake.
    """

    design_names: tuple
    light: np.ndarray
    electrons: np.ndarray
    focal_length_mm: np.ndarray
    stabilization: np.ndarray
    lambda_f_mm: np.ndarray
    aperture_mm: np.ndarray
    sensor_area_mm2: np.ndarray
    mtf_threshold: float
    illuminance: tuple
    shake: tuple


def default_scene(space=None) -> Scene:
    """The :class:`Scene` of ``space`` (default: the built-in default scan's space), which must
    be a design grid, a log-uniform illuminance and a log-normal shake, the rest fixed."""
    space = default_config().space if space is None else space
    axes = space.axes
    if (set(axes) != {"design", "illuminance_lux", "shake_deg_per_s"}
            or not isinstance(axes["design"], Grid) or space.grid_axes != ("design",)
            or not isinstance(axes["illuminance_lux"], LogUniform)
            or not isinstance(axes["shake_deg_per_s"], LogNormal) or space.evaluate_options):
        raise ValueError("the peer scans a design grid x log-uniform illuminance x log-normal "
                         "shake: " + space.describe())
    unsupported = sorted(set(space.design_table) - set(SUPPORTED))
    if unsupported:
        raise ValueError(f"the peer's model lacks {', '.join(unsupported)}")
    designs = len(space.design_names)

    def column(name):
        values = space.design_table[name] if name in space.design_table else DEFAULTS[name]
        return np.broadcast_to(np.asarray(values, dtype=np.float64), (designs,)).copy()

    pitch, f_number = column("pixel_pitch_um"), column("f_number")
    cos_theta = np.cos(np.deg2rad(column("field_angle_deg")))
    cos2 = cos_theta * cos_theta
    light = (column("reflectance") * cos2 * cos2 * column("electrons_per_lux_s_m2")
             * pitch * pitch * 1e-12 / 4.0 / f_number / f_number)
    root_s = 10.0 ** (column("snr_db") / 20.0)
    electrons = root_s / 2.0 * (root_s + np.hypot(root_s, 2.0 * column("read_noise_e")))
    threshold = column("mtf_threshold")
    if np.any(threshold != threshold[0]):
        raise ValueError("the peer takes one MTF threshold for every design")
    lux, shake = axes["illuminance_lux"], axes["shake_deg_per_s"]
    return Scene(tuple(space.design_names), light, electrons, column("focal_length_mm"),
                 column("stabilization"), column("wavelength_nm") * 1e-6 * f_number,
                 pitch * 1e-3, column("sensor_area_mm2"), float(threshold[0]),
                 (float(lux.low), float(lux.high)), (float(shake.median), float(shake.sigma)))


# --- The reductions' bins -------------------------------------------------------------------


@dataclass(frozen=True)
class LogBins:
    """Equal bins in log10 of the value over [low, high): slot 0 below, 1..bins, bins + 1 at or
    above (the value's unit: pixels)."""

    low: float
    high: float
    bins: int

    @property
    def first(self) -> float:
        return math.log10(self.low)

    @property
    def scale(self) -> float:
        """bins per unit of log10."""
        return self.bins / (math.log10(self.high) - self.first)

    @property
    def log_edges(self) -> np.ndarray:
        """log10 of the bins + 1 edges."""
        return np.linspace(self.first, math.log10(self.high), self.bins + 1)

    @property
    def edges(self) -> np.ndarray:
        """The value's unit: the bins + 1 edges."""
        return 10.0 ** self.log_edges


@dataclass(frozen=True)
class OctaveBins:
    """2**k bins an octave: a positive value's key is its biased exponent times 2**k plus the
    first k bits of its mantissa (its bits shifted right by 52 - k); the bins are the keys from
    ``low``'s to ``high``'s. Slot 0 below (0 included), 1..bins, bins + 1 at or above."""

    low: float
    high: float
    k: int

    @staticmethod
    def key(value: float, k: int) -> int:
        return int(np.float64(value).view(np.uint64)) >> (52 - k)

    @property
    def first_key(self) -> int:
        return self.key(self.low, self.k)

    @property
    def bins(self) -> int:
        return self.key(self.high, self.k) - self.first_key + 1

    @property
    def edges(self) -> np.ndarray:
        """The value's unit: the bins + 1 edges, exact."""
        keys = np.arange(self.first_key, self.first_key + self.bins + 1, dtype=np.uint64)
        return (keys << np.uint64(52 - self.k)).view(np.float64)

    @property
    def log_edges(self) -> np.ndarray:
        """log10 of the edges."""
        return np.log10(self.edges)


#: The per-design histogram of EPC: 80 log bins on [1e3, 1e7) pixels.
HISTOGRAM = LogBins(1e3, 1e7, 80)
#: The quantiles' histogram: 512 bins an octave on [1, 1e10) pixels (Quantiles' defaults).
QUANTILE_HISTOGRAM = OctaveBins(1.0, 1e10, 9)
#: pixels: the fraction-below threshold.
BELOW_THRESHOLD = 2e6
#: The quantiles read from QUANTILE_HISTOGRAM.
QUANTILES = (0.05, 0.5, 0.95)


# The bins as plain numbers, which the kernel reads as compile-time constants.
HISTOGRAM_FIRST, HISTOGRAM_SCALE = HISTOGRAM.first, HISTOGRAM.scale
HISTOGRAM_BINS, HISTOGRAM_SLOTS = float(HISTOGRAM.bins), HISTOGRAM.bins + 2
FINE_K, FINE_FIRST_KEY = QUANTILE_HISTOGRAM.k, QUANTILE_HISTOGRAM.first_key
FINE_BINS, FINE_SLOTS = QUANTILE_HISTOGRAM.bins, QUANTILE_HISTOGRAM.bins + 2


@numba.njit(inline="always")
def _slot(t, first, scale, bins):
    """The slot of t = log10(value) (-inf for 0): as epc_fast.scan.reductions.histograms bins it."""
    position = (t - first) * scale + 1.0
    return int(min(max(position, 0.0), bins + 1.0))


@numba.njit(inline="always")
def _octave_slot(value, k, first_key, bins):
    """The slot of a finite value on octave bins: its key from frexp (value = m 2^e, m in
    [1/2, 1): biased exponent e + 1022, mantissa bits floor((2m - 1) 2^k), both exact)."""
    if not value > 0.0:
        return 0
    m, e = math.frexp(value)
    key = (e + 1022) * (1 << k) + int((2.0 * m - 1.0) * (1 << k))
    return min(max(key - first_key + 1, 0), bins + 1)


# --- The kernel -----------------------------------------------------------------------------


@numba.njit(inline="always")
def _draw(index, key0, key1, lux_stream, shake_stream, lux_low, lux_high, lux_log_low,
          lux_log_span, shake_log_median, shake_sigma):
    """Point ``index``'s illuminance (lux; log-uniform, clamped to [low, high]) and hand shake
    (degree/s; log-normal) by the stream contract."""
    return _values(_uniform(index, lux_stream, key0, key1),
                   _uniform(index, shake_stream, key0, key1), lux_low, lux_high, lux_log_low,
                   lux_log_span, shake_log_median, shake_sigma)


@numba.njit(inline="always")
def _values(u_lux, u_shake, lux_low, lux_high, lux_log_low, lux_log_span, shake_log_median,
            shake_sigma):
    """The illuminance and hand shake at their uniforms."""
    lux = min(max(math.exp(lux_log_low + u_lux * lux_log_span), lux_low), lux_high)
    return lux, math.exp(shake_log_median + shake_sigma * _ndtri(u_shake))


@numba.njit
def _draws(index, key0, key1, lux_stream, shake_stream, lux_low, lux_high, lux_log_low,
           lux_log_span, shake_log_median, shake_sigma):
    lux = np.empty(index.shape[0])
    shake = np.empty(index.shape[0])
    for j in range(index.shape[0]):
        lux[j], shake[j] = _draw(index[j], key0, key1, lux_stream, shake_stream, lux_low,
                                 lux_high, lux_log_low, lux_log_span, shake_log_median,
                                 shake_sigma)
    return lux, shake


@numba.njit(inline="always")
def _epc(lux, shake, light, electrons, focal, stabilization, lambda_f, aperture, area,
         threshold, rtol, alpha, beta, log_c, same_algorithm, coefficients, degree):
    """EPC (pixels) and status of one point: T_MPE in closed form, blur, f50, 4 S f50^2."""
    rate = lux * light
    if not rate >= SMALLEST_NORMAL:  # no light
        return math.nan, UNREACHABLE
    t_mpe = electrons / rate
    angle = shake * DEG * t_mpe / stabilization
    if not angle < HALF_PI:
        return 0.0, BLUR_UNBOUNDED
    blur = focal * math.tan(angle)
    if same_algorithm:
        f50, _ = _f50_core_algorithm(lambda_f, aperture, blur, threshold, rtol, coefficients,
                                     degree)
    else:
        f50, _ = _f50_halley(lambda_f, aperture, blur, threshold, rtol, alpha, beta, log_c)
    return 4.0 * area * f50 * f50, OK


@numba.njit
def _scan_part(start, stop, key0, key1, lux_stream, shake_stream, lux_low, lux_high,
               lux_log_low, lux_log_span, shake_log_median, shake_sigma, light, electrons,
               focal, stabilization, lambda_f, aperture, area, threshold, rtol,
               same_algorithm, coefficients, degree, status, count, mean, m2, low, high,
               below, histogram, fine):
    """Draw, evaluate and reduce points start .. stop - 1 into one thread's accumulators
    (each indexed by design first), written out once at the end: the thread updates arrays of
    its own allocation, so that no cache line it writes per point is shared with another
    thread's (the parts' rows of the outputs are 32 bytes apart)."""
    out_status, out_count, out_mean, out_m2 = status, count, mean, m2
    out_low, out_high, out_below, out_histogram, out_fine = low, high, below, histogram, fine
    status, count, below = np.zeros_like(status), np.zeros_like(count), np.zeros_like(below)
    mean, m2 = np.zeros_like(mean), np.zeros_like(m2)
    low, high = np.full_like(low, math.inf), np.full_like(high, -math.inf)
    histogram, fine = np.zeros_like(histogram), np.zeros_like(fine)
    designs = light.shape[0]
    alpha, beta, log_c = _guess_coefficients(threshold)
    lux_uniforms, shake_uniforms = (0.0, 0.0), (0.0, 0.0)
    for i in range(start, stop):
        d = i % designs
        if i == start or i % 2 == 0:  # one Philox call a stream serves the pair i div 2
            pair = np.uint64(i) >> ONE
            lux_uniforms = _pair_uniforms(pair, lux_stream, key0, key1)
            shake_uniforms = _pair_uniforms(pair, shake_stream, key0, key1)
        lux, shake = _values(lux_uniforms[i % 2], shake_uniforms[i % 2], lux_low, lux_high,
                             lux_log_low, lux_log_span, shake_log_median, shake_sigma)
        epc, state = _epc(lux, shake, light[d], electrons[d], focal[d], stabilization[d],
                          lambda_f[d], aperture[d], area[d], threshold, rtol, alpha, beta,
                          log_c, same_algorithm, coefficients, degree)
        status[d, state] += 1
        if not math.isfinite(epc):
            continue
        n = count[d] + 1  # Welford: the running mean and sum of squared deviations
        count[d] = n
        delta = epc - mean[d]
        mean[d] += delta / n
        m2[d] += delta * (epc - mean[d])
        low[d] = min(low[d], epc)
        high[d] = max(high[d], epc)
        if epc < BELOW_THRESHOLD:
            below[d] += 1
        t = math.log10(epc) if epc > 0.0 else -math.inf
        histogram[d, _slot(t, HISTOGRAM_FIRST, HISTOGRAM_SCALE, HISTOGRAM_BINS)] += 1
        fine[d, _octave_slot(epc, FINE_K, FINE_FIRST_KEY, FINE_BINS)] += 1
    out_status[:], out_count[:], out_mean[:], out_m2[:] = status, count, mean, m2
    out_low[:], out_high[:], out_below[:] = low, high, below
    out_histogram[:], out_fine[:] = histogram, fine


@numba.njit(parallel=True)
def _scan_kernel(points, parts, key0, key1, lux_stream, shake_stream, lux_low, lux_high,
                 lux_log_low, lux_log_span, shake_log_median, shake_sigma, light, electrons,
                 focal, stabilization, lambda_f, aperture, area, threshold, rtol,
                 same_algorithm, coefficients, degree):
    """The scan: prange over ``parts`` contiguous ranges of points, one per thread, each with
    its own accumulators (leading axis: the part)."""
    designs = light.shape[0]
    status = np.zeros((parts, designs, STATUS_COUNT), dtype=np.int64)
    count = np.zeros((parts, designs), dtype=np.int64)
    mean = np.zeros((parts, designs))
    m2 = np.zeros((parts, designs))
    low = np.full((parts, designs), math.inf)
    high = np.full((parts, designs), -math.inf)
    below = np.zeros((parts, designs), dtype=np.int64)
    histogram = np.zeros((parts, designs, HISTOGRAM_SLOTS), dtype=np.int64)
    fine = np.zeros((parts, designs, FINE_SLOTS), dtype=np.int64)
    base, extra = points // parts, points % parts
    for part in numba.prange(parts):
        start = part * base + min(part, extra)
        stop = start + base + (1 if part < extra else 0)
        _scan_part(start, stop, key0, key1, lux_stream, shake_stream, lux_low, lux_high,
                   lux_log_low, lux_log_span, shake_log_median, shake_sigma, light, electrons,
                   focal, stabilization, lambda_f, aperture, area, threshold, rtol,
                   same_algorithm, coefficients, degree, status[part], count[part],
                   mean[part], m2[part], low[part], high[part], below[part], histogram[part],
                   fine[part])
    return status, count, mean, m2, low, high, below, histogram, fine


# --- The entry points -----------------------------------------------------------------------


def _merged_moments(count, mean, m2):
    """Per design: the parts' counts, means and sums of squared deviations (parts first)
    merged in part order by Chan, Golub and LeVeque's pairwise update."""
    total, mu, ss = count[0].astype(np.int64), mean[0].copy(), m2[0].copy()
    for n, m, s in zip(count[1:], mean[1:], m2[1:]):
        merged = total + n
        weight = np.divide(n, merged, out=np.zeros(merged.shape), where=merged > 0)
        delta = m - mu
        mu += delta * weight
        ss += s + delta * delta * total * weight
        total = merged
    return total, mu, ss


def histogram_quantiles(counts, low, high, q=QUANTILES, bins=QUANTILE_HISTOGRAM):
    """Quantiles per group from log-bin slot counts, as ``epc_fast.scan.Quantiles`` streams
    them: the order statistics around rank q (n - 1) lie in known bins, which bound the sample
    quantile (clipped to the group's [low, high]); the estimate interpolates in log10 within
    the bin of rank q (n - 1), counting the bin's values as spread evenly through it.

    Parameters
    ----------
    counts : int64 (groups, bins + 2), slot counts (below, the bins, at or above).
    low, high : (groups,), the value's unit: each group's least and greatest value.
    q : probabilities.
    bins : the :class:`OctaveBins` of ``counts``.

    Returns
    -------
    estimate, lower, upper : float64 (groups, len(q)), the value's unit (pixels for EPC); NaN
        for a group without values.
    """
    q = np.asarray(q, dtype=np.float64)
    edges = np.concatenate(([-np.inf], bins.edges, [np.inf]))
    t_edges = np.concatenate(([-np.inf], bins.log_edges, [np.inf]))
    shape = (counts.shape[0], q.size)
    estimate, lower, upper = np.full(shape, np.nan), np.full(shape, np.nan), np.full(shape,
                                                                                       np.nan)
    for g, group_counts in enumerate(counts):
        cumulative = np.cumsum(group_counts)
        n = cumulative[-1]
        if n == 0:
            continue
        rank = q * (n - 1)
        floor = np.floor(rank)
        first = np.searchsorted(cumulative, floor, side="right")
        second = np.searchsorted(cumulative, np.minimum(floor + 1, n - 1), side="right")
        lower[g] = np.clip(edges[first], low[g], high[g])
        upper[g] = np.clip(edges[second + 1], low[g], high[g])
        slot = np.searchsorted(cumulative, rank, side="right")
        before = np.where(slot > 0, cumulative[slot - 1], 0)
        fraction = (rank - before + 0.5) / group_counts[slot]
        with np.errstate(invalid="ignore"):  # -inf + fraction * inf in the open-ended slots
            t = t_edges[slot] + fraction * (t_edges[slot + 1] - t_edges[slot])
        inside = np.isfinite(t)
        middle = 0.5 * (lower[g] + upper[g])
        estimate[g] = np.clip(np.where(inside, 10.0 ** np.where(inside, t, 0.0), middle),
                              lower[g], upper[g])
    return estimate, lower, upper


def _draw_arguments(seed: int, scene: Scene) -> tuple:
    """The kernel's draw arguments: the key's two words, the two streams, the illuminance's
    bounds, log low and log high - log low, and the shake's log median and sigma."""
    lux_low, lux_high = scene.illuminance
    lux_log_low = math.log(lux_low)
    median, sigma = scene.shake
    return (*_key(seed), np.uint64(stream_id("illuminance_lux")),
            np.uint64(stream_id("shake_deg_per_s")), lux_low, lux_high, lux_log_low,
            math.log(lux_high) - lux_log_low, math.log(median), sigma)


def draws(seed: int, index, scene: Scene | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The illuminance (lux) and hand shake (degree/s) the kernel draws at points ``index``
    (integers in [0, 2^64)), by the same compiled code: float64 arrays of index's length."""
    scene = default_scene() if scene is None else scene
    index = np.ascontiguousarray(index, dtype=np.uint64).ravel()
    return _draws(index, *_draw_arguments(seed, scene))


def scan(points: int, seed: int, threads: int, same_algorithm: bool = False,
         scene: Scene | None = None) -> dict:
    """Draw, evaluate and reduce ``points`` points of the default scan in one prange loop.

    Parameters
    ----------
    points : int, the scan's points 0 .. points - 1.
    seed : int in [0, 2^64), the stream contract's key.
    threads : int, Numba threads (at most ``numba.config.NUMBA_NUM_THREADS``); the points are
        split into this many contiguous parts, one per thread.
    same_algorithm : bool, f50 by the core's own algorithm instead of the Numba peer's Halley
        iteration from its fitted guess (``peers/numba_peer.py``).
    scene : Scene, optional; default :func:`default_scene` ().

    Returns
    -------
    dict of NumPy arrays, per design (the leading axis, in ``design_names``' order; EPC and
    its statistics in pixels):

    - ``design_names`` : str (designs,).
    - ``points`` : int64 (designs,), points of each design, whatever their status.
    - ``status_counts`` : int64 (designs, 4), points per :class:`epc_fast.Status`.
    - ``count`` : int64 (designs,), points whose EPC is finite (OK and blur unbounded, EPC 0).
    - ``mean``, ``std``, ``min``, ``max`` : float64 (designs,), over the finite EPC; std with
      ddof 0; NaN (min +inf, max -inf) for a design without finite EPC.
    - ``histogram_edges`` : float64 (81,), pixels: 80 bins equal in log10 on [1e3, 1e7).
    - ``histogram`` : int64 (designs, 80); ``histogram_below``, ``histogram_above`` : int64
      (designs,), the finite EPC below 1e3 (EPC 0 included) and at or above 1e7.
    - ``below_threshold`` : float64 scalar array, 2e6 pixels; ``below`` : int64 (designs,),
      the finite EPC below it; ``fraction_below`` : float64 (designs,), below / count.
    - ``quantile_q`` : float64 (3,), 0.05, 0.5, 0.95; ``quantile_counts`` : int64
      (designs, bins + 2), slot counts of the octave histogram on [1, 1e10), 512 bins an
      octave (slot 0 below, bins + 1 at or above); ``quantiles``, ``quantiles_lower``,
      ``quantiles_upper`` : float64 (designs, 3), the estimate and the bounds on the sample
      quantile (:func:`histogram_quantiles`).
    """
    points, threads = int(points), int(threads)
    if points < 1 or threads < 1:
        raise ValueError(f"points and threads must be >= 1, got {points}, {threads}")
    scene = default_scene() if scene is None else scene
    if same_algorithm and scene.mtf_threshold != 0.5:
        raise ValueError("same_algorithm: the core's accurate start holds at threshold 0.5 only")
    previous = numba.get_num_threads()
    numba.set_num_threads(threads)
    try:
        status, count, mean, m2, low, high, below, histogram, fine = _scan_kernel(
            points, threads, *_draw_arguments(seed, scene), scene.light, scene.electrons,
            scene.focal_length_mm, scene.stabilization, scene.lambda_f_mm, scene.aperture_mm,
            scene.sensor_area_mm2, scene.mtf_threshold, F50_RTOL, bool(same_algorithm),
            START_COEFFICIENTS, START_DEGREE)
    finally:
        numba.set_num_threads(previous)
    count, mean, m2 = _merged_moments(count, mean, m2)
    present = count > 0
    histogram, fine = histogram.sum(axis=0), fine.sum(axis=0)
    low, high, below = low.min(axis=0), high.max(axis=0), below.sum(axis=0)
    estimate, lower, upper = histogram_quantiles(fine, low, high)
    return {
        "design_names": np.array(scene.design_names),
        "points": status.sum(axis=(0, 2)),
        "status_counts": status.sum(axis=0),
        "count": count,
        "mean": np.where(present, mean, np.nan),
        "std": np.sqrt(np.divide(m2, count, out=np.full(count.shape, np.nan), where=present)),
        "min": low,
        "max": high,
        "histogram_edges": HISTOGRAM.edges,
        "histogram": histogram[:, 1:-1],
        "histogram_below": histogram[:, 0],
        "histogram_above": histogram[:, -1],
        "below_threshold": np.array(BELOW_THRESHOLD),
        "below": below,
        "fraction_below": np.divide(below, count, out=np.full(count.shape, np.nan),
                                    where=present),
        "quantile_q": np.array(QUANTILES),
        "quantile_counts": fine,
        "quantiles": estimate,
        "quantiles_lower": lower,
        "quantiles_upper": upper,
    }


def warm_up(threads: int = 2) -> None:
    """Compile the kernel (both f50 algorithms share its one signature) and start Numba's
    thread pool on a few points, so that no timed call pays for either."""
    scan(64, seed=0, threads=threads)
