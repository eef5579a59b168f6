"""The e-SFR of a slanted edge (epc_fast.simulate.edge_sfr) against edges whose MTF is known
in closed form (helpers.edges): the curve, MTF50, the angle, the transposition, the window, the
bin correction, noise, and every bad input.

Frequencies are compared in cycles a pixel (f_mm x pitch_mm); Nyquist is 0.5 cycles a pixel.

The method's own error, and the tolerances below. Noiseless, the e-SFR is exact but for two
effects, both measured here on 256 x 128 images at 5 degrees:

- the rows' phases fill the quarter-pixel bins unevenly: a bin's mean sample position is off its
  centre by up to 0.004 pixels, an ESF error of up to (the LSF's peak) x 0.004, about 1e-3 of
  the contrast, and MTF errors of at most 0.0043 up to Nyquist (worst: a 1.5-pixel box);
- a point-sampled box's kinks have content at every frequency, which the bins (4 a pixel) fold
  about 2 cycles/pixel, and which the corrections amplify by up to 1.75 at twice Nyquist: at
  most 0.0098 between Nyquist and twice it.

Hence CURVE_TOL up to Nyquist and CURVE_TOL_2NYQ up to twice it, above the largest error
measured (1.3 to 1.4 x), and MTF50_RTOL for MTF50 (largest measured: 0.42 %).
"""

import math

import numpy as np
import pytest
from scipy.optimize import brentq

from epc_fast.simulate import EdgeSFR, esfr, mtf50
from helpers.edges import (box_esf, box_mtf, edge_image, gaussian_esf, gaussian_mtf, pixel_esf,
                           pixel_mtf)

PITCH_UM = 2.0
#: Absolute MTF error up to Nyquist: measured at most 0.0043 (the bins' uneven phases).
CURVE_TOL = 0.006
#: Absolute MTF error up to twice Nyquist: measured at most 0.0098 (a box's folded content).
CURVE_TOL_2NYQ = 0.013
#: Relative MTF50 error: measured at most 0.0042.
MTF50_RTOL = 0.006
#: x where sinc(x) = 0.5: a box of width b has its MTF50 at X50 / b.
X50 = brentq(lambda x: np.sinc(x) - 0.5, 0.1, 0.9)


def cycles_per_pixel(result):
    return result.frequency_cyc_per_mm * PITCH_UM * 1e-3


def mtf50_cycles_per_pixel(result):
    return result.mtf50_cyc_per_mm * PITCH_UM * 1e-3


def curve_error(result, mtf, f_max):
    """The largest |measured - true| MTF from 0 to f_max cycles/pixel."""
    f = cycles_per_pixel(result)
    inside = f <= f_max
    return np.abs(result.mtf[inside] - mtf(f[inside])).max()


def true_mtf50(mtf):
    return brentq(lambda f: mtf(f) - 0.5, 1e-6, 1.0)


# (name, ESF, MTF in cycles/pixel, angle from the vertical)
EDGES = [
    ("gaussian 0.5", gaussian_esf(0.5), lambda f: gaussian_mtf(0.5, f), 5.0),
    ("gaussian 1.0", gaussian_esf(1.0), lambda f: gaussian_mtf(1.0, f), 5.0),
    ("gaussian 2.0", gaussian_esf(2.0), lambda f: gaussian_mtf(2.0, f), -5.0),
    ("box 1.5", box_esf(1.5), lambda f: box_mtf(1.5, f), 5.0),
    ("box 2", box_esf(2.0), lambda f: box_mtf(2.0, f), 5.0),
    ("box 3", box_esf(3.0), lambda f: box_mtf(3.0, f), -5.0),
    ("sharp edge on square pixels", pixel_esf(5.0, 0.02), lambda f: pixel_mtf(5.0, 0.02, f), 5.0),
    ("sharp edge on square pixels, -8 deg", pixel_esf(-8.0, 0.02),
     lambda f: pixel_mtf(-8.0, 0.02, f), -8.0),
    ("gaussian 0.3 on square pixels", pixel_esf(5.0, 0.3), lambda f: pixel_mtf(5.0, 0.3, f), 5.0),
]


@pytest.mark.parametrize("name, esf, mtf, angle", EDGES, ids=[e[0] for e in EDGES])
def test_the_curve_matches_the_closed_form_mtf_to_twice_nyquist(name, esf, mtf, angle):
    result = esfr(edge_image(esf, 256, 128, angle), PITCH_UM, bin_correction=True)
    f = cycles_per_pixel(result)
    assert 2.0 - f[1] < f[-1] <= 2.0  # up to oversampling / 2 cycles/pixel, the DFT's last bin
    assert result.mtf[0] == pytest.approx(1.0, abs=1e-12)
    assert curve_error(result, mtf, 0.5) < CURVE_TOL
    assert curve_error(result, mtf, 1.0) < CURVE_TOL_2NYQ


@pytest.mark.parametrize("name, esf, mtf, angle", EDGES, ids=[e[0] for e in EDGES])
def test_mtf50_matches_the_closed_form(name, esf, mtf, angle):
    result = esfr(edge_image(esf, 256, 128, angle), PITCH_UM, bin_correction=True)
    assert mtf50_cycles_per_pixel(result) == pytest.approx(true_mtf50(mtf), rel=MTF50_RTOL)


def test_mtf50_function_is_the_results_crossing_in_cycles_per_mm():
    image = edge_image(gaussian_esf(1.0), 128, 128, 5.0)
    result = esfr(image, PITCH_UM)
    assert mtf50(image, PITCH_UM) == result.mtf50_cyc_per_mm == result.crossing(0.5)
    # cycles/mm = cycles/pixel / pitch in mm: a pitch twice as large halves it
    assert mtf50(image, 2 * PITCH_UM) == pytest.approx(result.mtf50_cyc_per_mm / 2, rel=1e-12)


def test_mtf_at_is_the_grid_mtf_on_the_grid_and_the_crossing_solves_it():
    result = esfr(edge_image(gaussian_esf(1.0), 128, 128, 5.0), PITCH_UM)
    # the DFT and the directly summed transform agree to rounding
    np.testing.assert_allclose(result.mtf_at(result.frequency_cyc_per_mm), result.mtf,
                               rtol=0, atol=1e-12)
    assert result.mtf_at(100.0).shape == ()
    assert result.mtf_at(np.full((2, 3), 100.0)).shape == (2, 3)
    for level in (0.8, 0.5, 0.3, 0.1):
        f = result.crossing(level)
        assert result.mtf_at(f) == pytest.approx(level, abs=1e-9)  # bisected to 2**-60
        assert (result.mtf[cycles_per_pixel(result) < f * PITCH_UM * 1e-3] > level).all()


def test_crossing_is_nan_when_the_mtf_never_falls_that_low_and_refuses_a_bad_level():
    result = esfr(edge_image(gaussian_esf(0.3), 128, 128, 5.0), PITCH_UM)
    assert math.isnan(result.crossing(1e-9))
    for level in (0.0, 1.0, -0.5, math.nan):
        with pytest.raises(ValueError, match="level must be in"):
            result.crossing(level)


def test_a_long_box_blur_has_its_mtf50_found_on_the_exact_transform():
    # b = 100 pixels: MTF50 at 0.603 / b = 0.006 cycles/pixel, where the grid's spacing,
    # 1 / (the LSF's length) = 0.0005 cycles/pixel, is a twelfth of it; bisecting the
    # transform leaves no grid error, only the method's: the Hamming window's curvature over
    # the LSF (measured +0.09 %; +0.001 % with no window)
    image = edge_image(box_esf(100.0), 60, 2000, 5.0)
    result = esfr(image, PITCH_UM)
    assert cycles_per_pixel(result)[1] > X50 / 100 / 13
    assert result.mtf_at(result.mtf50_cyc_per_mm) == pytest.approx(0.5, abs=1e-9)
    # the transform is summed a few frequencies at a time over the 7946 bins, as the DFT is
    np.testing.assert_allclose(result.mtf_at(result.frequency_cyc_per_mm[:300]),
                               result.mtf[:300], rtol=0, atol=1e-11)
    assert mtf50_cycles_per_pixel(result) == pytest.approx(X50 / 100, rel=0.002)
    no_window = esfr(image, PITCH_UM, window=None)
    assert mtf50_cycles_per_pixel(no_window) == pytest.approx(X50 / 100, rel=1e-4)


@pytest.mark.parametrize("angle", [2.0, -2.0, 5.0, -5.0, 10.0, -10.0, 20.0, -20.0, 29.0])
def test_the_fitted_edge_angle_is_the_edges(angle):
    # the rows' centroids of a point-sampled Gaussian (sigma 0.7) are exact but for aliasing,
    # exp(-2 pi^2 sigma^2) ~ 6e-5 pixels a row: the fitted angle within 0.002 degrees
    result = esfr(edge_image(gaussian_esf(0.7), 128, 128, angle), PITCH_UM)
    assert result.edge_angle_deg == pytest.approx(angle, abs=0.002)
    assert result.transposed is False


def test_a_near_horizontal_edge_is_measured_transposed():
    image = edge_image(gaussian_esf(1.0), 128, 128, 5.0)
    upright = esfr(image, PITCH_UM)
    lying = esfr(image.T, PITCH_UM)
    assert lying.transposed is True and upright.transposed is False
    np.testing.assert_array_equal(lying.mtf, upright.mtf)
    assert lying.edge_angle_deg == upright.edge_angle_deg
    # 62 degrees from the vertical is 28 from the horizontal: accepted, transposed (rows and
    # columns swapped, the edge moves to larger columns down the rows: +28)
    steep = esfr(edge_image(gaussian_esf(1.0), 128, 128, 62.0), PITCH_UM)
    assert steep.transposed is True
    assert steep.edge_angle_deg == pytest.approx(28.0, abs=0.002)


#: Pixels: the rms widths of an elliptical Gaussian blur along the rows (x) and the columns
#: (y): an edge's normal at angle a from the x axis sees sqrt(sx^2 cos^2 a + sy^2 sin^2 a).
SIGMA_X, SIGMA_Y = 2.0, 0.6


def normal_sigma(angle_deg):
    a = math.radians(angle_deg)
    return math.hypot(SIGMA_X * math.cos(a), SIGMA_Y * math.sin(a))


@pytest.mark.parametrize("angle", [75.0, -75.0, 85.0, -88.0, 5.0])
def test_an_edge_measures_the_mtf_along_its_normal_near_horizontal_along_the_columns(angle):
    # An elliptical Gaussian blur, wide along the rows, narrow along the columns: a
    # near-vertical edge (5 degrees) measures the wide one, a near-horizontal edge (75 to 88
    # degrees from the vertical, either way) the narrow one, each as its normal projects
    # the ellipse (the edge's ESF is the blur's projection onto the normal). The closed
    # form within the tolerances of the upright edges above (the near-horizontal edge is
    # measured transposed: the same method on the same sampling). The closed form is the
    # edge's own MTF: the bins' average divided out.
    sigma = normal_sigma(angle)
    image = edge_image(gaussian_esf(sigma), 128, 256, angle)
    result = esfr(image, PITCH_UM, bin_correction=True)
    assert result.transposed is (abs(angle) > 45)
    mtf = lambda f: gaussian_mtf(sigma, f)  # noqa: E731
    assert curve_error(result, mtf, 0.5) < CURVE_TOL
    assert mtf50_cycles_per_pixel(result) == pytest.approx(true_mtf50(mtf), rel=MTF50_RTOL)
    if abs(angle) > 45:  # the narrow axis: well above the wide one's MTF50
        wide = true_mtf50(lambda f: gaussian_mtf(normal_sigma(5.0), f))
        assert mtf50_cycles_per_pixel(result) > 2.5 * wide
    # the image transposed is the same edge measured along the other axis: the same MTF
    turned = esfr(image.T, PITCH_UM, bin_correction=True)
    assert turned.transposed is not result.transposed
    np.testing.assert_array_equal(turned.mtf, result.mtf)


def test_a_dark_to_bright_and_a_bright_to_dark_edge_give_the_same_mtf():
    image = edge_image(gaussian_esf(1.0), 128, 128, 5.0)
    np.testing.assert_allclose(esfr(image[:, ::-1], PITCH_UM).mtf, esfr(image, PITCH_UM).mtf,
                               atol=CURVE_TOL)


def test_no_window_also_matches_the_closed_form():
    mtf = lambda f: gaussian_mtf(1.0, f)  # noqa: E731
    result = esfr(edge_image(gaussian_esf(1.0), 256, 128, 5.0), PITCH_UM, window=None,
                  bin_correction=True)
    assert curve_error(result, mtf, 0.5) < CURVE_TOL
    assert mtf50_cycles_per_pixel(result) == pytest.approx(true_mtf50(mtf), rel=MTF50_RTOL)


def test_without_the_bin_correction_the_mtf_is_low_by_the_bins_sinc():
    # the standard's e-SFR keeps the bins' average, sinc(f D) with D a quarter pixel: 2.5 % low
    # at Nyquist, 10 % at twice it
    image = edge_image(gaussian_esf(0.5), 256, 128, 5.0)
    corrected = esfr(image, PITCH_UM, bin_correction=True)
    standard = esfr(image, PITCH_UM)  # the default: the standard's, a lab's
    assert standard.bin_correction is False and corrected.bin_correction is True
    np.testing.assert_array_equal(standard.mtf, esfr(image, PITCH_UM, bin_correction=False).mtf)
    f = cycles_per_pixel(standard)
    inside = f <= 1.0  # below the correction's cap of 10, reached near 2 cycles/pixel
    np.testing.assert_allclose(standard.mtf[inside], (corrected.mtf * np.sinc(f / 4))[inside],
                               rtol=1e-12)
    nyquist = np.array([0.5]) / (PITCH_UM * 1e-3)
    true = gaussian_mtf(0.5, 0.5)  # 0.29
    assert standard.mtf_at(nyquist)[0] / true == pytest.approx(np.sinc(0.125), abs=0.01)
    assert corrected.mtf_at(nyquist)[0] / true == pytest.approx(1.0, abs=0.01)
    assert np.sinc(0.125) < 0.975


@pytest.mark.parametrize("esf, low", [(gaussian_esf(1.0), 0.0026), (gaussian_esf(0.5), 0.0102),
                                      (pixel_esf(5.0, 0.02), 0.0223)])
def test_the_standards_mtf50_lies_below_the_corrected_one_by_the_figures_the_module_gives(esf,
                                                                                          low):
    # MTF50 at 0.19, 0.37 and 0.60 cycles/pixel: the bins' sinc(f / 4) lowers it by 0.3 %,
    # 1.0 % and 2.2 % (edge_sfr's docstring); to 0.0001, the figures' last digit
    image = edge_image(esf, 256, 128, 5.0)
    ratio = mtf50(image, PITCH_UM) / mtf50(image, PITCH_UM, bin_correction=True)
    assert 1.0 - ratio == pytest.approx(low, abs=1e-4)


def test_oversampling_sets_the_bins_and_the_frequency_range():
    image = edge_image(gaussian_esf(1.0), 256, 128, 5.0)
    for oversampling in (2, 8):
        result = esfr(image, PITCH_UM, oversampling=oversampling, bin_correction=True)
        f = cycles_per_pixel(result)
        assert oversampling / 2 - f[1] < f[-1] <= oversampling / 2  # the DFT's last bin
        assert result.bin_width_mm == pytest.approx(PITCH_UM * 1e-3 / oversampling)
        assert mtf50_cycles_per_pixel(result) == pytest.approx(
            true_mtf50(lambda f: gaussian_mtf(1.0, f)), rel=MTF50_RTOL)


def test_a_roi_crops_the_image():
    image = edge_image(gaussian_esf(1.0), 128, 128, 5.0)
    padded = np.pad(image, ((7, 3), (5, 11)), constant_values=np.nan)
    cropped = esfr(padded, PITCH_UM, roi=(7, 135, 5, 133))
    np.testing.assert_array_equal(cropped.mtf, esfr(image, PITCH_UM).mtf)


def test_the_result_is_an_edge_sfr_that_says_its_pitch():
    result = esfr(edge_image(gaussian_esf(1.0), 64, 64, 5.0).astype(np.float32), 1.4)
    assert isinstance(result, EdgeSFR)
    assert result.pitch_um == 1.4
    with pytest.raises(AttributeError):
        result.pitch_um = 2.0


# --- Noise -----------------------------------------------------------------------------------

#: Seeds for the scatter over noise.
SEEDS = range(20)


def _noisy_mtf50s(noise, window):
    sigma = 1.0
    clean = edge_image(gaussian_esf(sigma), 128, 128, 5.0)
    true = true_mtf50(lambda f: gaussian_mtf(sigma, f))
    return np.array([mtf50_cycles_per_pixel(esfr(
        clean + np.random.default_rng(seed).normal(0.0, noise, clean.shape), PITCH_UM,
        window=window, bin_correction=True)) / true - 1 for seed in SEEDS])


def test_mtf50_scatter_under_noise():
    # contrast 1000, Gaussian noise 10 (1 %), sigma 1 pixel, 128 x 128 at 5 degrees. Measured
    # over these 20 seeds: mean +0.10 %, standard deviation 0.71 %, largest 1.4 %.
    # The bounds: the mean within 0.3 % (noiseless error) + 3 x 0.71 % / sqrt(20) = 0.8 %;
    # the standard deviation below 1.2 % (an estimate from 20 seeds scatters by 1/sqrt(38) =
    # 16 %: 1.2 % is 4 such deviations above the measured 0.71 %).
    errors = _noisy_mtf50s(10.0, "hamming")
    assert abs(errors.mean()) < 0.008
    assert errors.std(ddof=1) < 0.012
    # the scatter grows with the noise: measured 1.32 % at noise 20
    assert _noisy_mtf50s(20.0, "hamming").std(ddof=1) > errors.std(ddof=1)


def test_the_hamming_window_lowers_the_scatter():
    # measured standard deviations at noise 10: 0.71 % windowed, 1.18 % without
    assert _noisy_mtf50s(10.0, "hamming").std(ddof=1) < _noisy_mtf50s(10.0, None).std(ddof=1)


# --- Bad input -------------------------------------------------------------------------------

GOOD = edge_image(gaussian_esf(1.0), 64, 64, 5.0)


@pytest.mark.parametrize("image, error, match", [
    (GOOD[0], ValueError, "image must be 2-D"),
    (GOOD[None], ValueError, "image must be 2-D"),
    (GOOD.astype(complex), TypeError, "image must hold real numbers"),
    (GOOD > 500, TypeError, "image must hold real numbers"),
    (GOOD.astype(object), TypeError, "image must hold real numbers"),
    ("edge", TypeError, "image must"),
    (None, TypeError, "image must"),
    (np.where(GOOD > 1000, np.nan, GOOD), ValueError, "NaN or infinite"),
    (np.where(GOOD > 1000, np.inf, GOOD), ValueError, "NaN or infinite"),
    (GOOD[:15], ValueError, "at least 16 rows and 16 columns"),
    (GOOD[:, :15], ValueError, "at least 16 rows and 16 columns"),
    (np.full((64, 64), 7.0), ValueError, "image: no edge found"),
    (np.zeros((64, 64)), ValueError, "image: no edge found"),
    (np.random.default_rng(1).normal(size=(64, 64)), ValueError, "image: no single edge"),
    (edge_image(gaussian_esf(1.0), 64, 64, 0.0), ValueError, "image: the edge is 0.00 degrees"),
    (edge_image(gaussian_esf(1.0), 64, 64, 0.5), ValueError, "image: the edge is 0.50 degrees"),
    (edge_image(gaussian_esf(1.0), 64, 160, 40.0), ValueError, "image: the edge is 40.00 degrees"),
])
def test_a_bad_image_is_refused_naming_it(image, error, match):
    with pytest.raises(error, match=match):
        esfr(image, PITCH_UM)


@pytest.mark.parametrize("pitch, error", [
    (0.0, ValueError), (-1.0, ValueError), (math.nan, ValueError), (math.inf, ValueError),
    ("2", TypeError), (None, TypeError), (True, TypeError), ([2.0], TypeError),
    (1 + 2j, TypeError),
])
def test_a_bad_pitch_is_refused_naming_it(pitch, error):
    with pytest.raises(error, match="pitch_um"):
        esfr(GOOD, pitch)


@pytest.mark.parametrize("roi, error, match", [
    ((0, 64, 0), ValueError, r"roi must be \(row0, row1, col0, col1\)"),
    (5, TypeError, r"roi must be \(row0, row1, col0, col1\)"),
    ((0, 64.0, 0, 64), TypeError, "roi must be an integer"),
    ((10, 5, 0, 64), ValueError, "roi=.* must satisfy 0 <= row0 < row1 <= 64"),
    ((0, 65, 0, 64), ValueError, "roi=.* must satisfy"),
    ((-1, 64, 0, 64), ValueError, "roi=.* must satisfy"),
    ((0, 10, 0, 64), ValueError, "at least 16 rows and 16 columns in its roi"),
])
def test_a_bad_roi_is_refused_naming_it(roi, error, match):
    with pytest.raises(error, match=match):
        esfr(GOOD, PITCH_UM, roi=roi)


@pytest.mark.parametrize("keyword, value, error", [
    ("oversampling", 0, ValueError), ("oversampling", -4, ValueError),
    ("oversampling", 4.0, TypeError), ("oversampling", True, TypeError),
    ("window", "hann", ValueError), ("window", 1, ValueError),
    ("window", np.hamming(16), ValueError),
    ("bin_correction", "yes", TypeError), ("bin_correction", None, TypeError),
])
def test_a_bad_option_is_refused_naming_it(keyword, value, error):
    with pytest.raises(error, match=keyword):
        esfr(GOOD, PITCH_UM, **{keyword: value})


def test_too_few_columns_for_the_angle_is_refused():
    # at 29 degrees the edge moves 34 columns over the 63 rows of 35 whole phase cycles: 39
    # columns leave the rows (39 - 1 - 34.4) cos(29 deg) = 3.2 pixels along the normal in
    # common, 42 leave 5.8
    with pytest.raises(ValueError, match="image: the rows share only 3.18 pixels"):
        esfr(edge_image(gaussian_esf(0.5), 64, 39, 29.0), PITCH_UM)
    assert esfr(edge_image(gaussian_esf(0.5), 64, 42, 29.0), PITCH_UM).transposed is False
