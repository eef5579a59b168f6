"""A lens's tabulated MTF in the NumPy reference (epc_fast.reference.lens and its place in
epc_fast.reference.model and .sensitivity): a table of the aberration-free diffraction MTF
gives the aberration-free model, a table of prysm's defocused pupil gives the first crossing of
prysm's MTF times the other factors, f50 past a table's end is Status.BEYOND_TABLE, and the
shares and elasticities with a table against their definitions.

Every tolerance says why it is that size.
"""

import numpy as np
import pytest

import epc_fast
from epc_fast import Status, reference
from epc_fast.mtf_table import mtf_table
from epc_fast.reference.lens import lens_bracket, mtf_lens

#: Three OK designs from dim to bright light (f50 set by motion, by both, by the optics).
POINTS = dict(illuminance_lux=np.array([10.0, 100.0, 3000.0]),
              pixel_pitch_um=np.array([0.8, 1.4, 2.0]), focal_length_mm=4.0, pixel_count=8e6,
              read_noise_e=2.0, backend="reference")


def diffraction_table(f_number, points=400, wavelength_nm=550.0):
    """The aberration-free diffraction MTF sampled at ``points`` frequencies from 0 to its
    cut-off 1/(lambda F) (D = 0 there)."""
    cut_off = 1.0 / (wavelength_nm * 1e-6 * f_number)
    f = np.linspace(0.0, cut_off, points)
    m = reference.mtf_diffraction(f, wavelength_nm, f_number)
    m[-1] = 0.0  # D vanishes at the cut-off; its formula leaves a rounding residue
    return f, m


def first_crossing(f, m, c=0.5):
    """The first crossing of c by the piecewise-linear m(f)."""
    i = int(np.argmax(m <= c))
    return f[i - 1] + (m[i - 1] - c) / (m[i - 1] - m[i]) * (f[i] - f[i - 1])


# --- A table of the aberration-free MTF is the aberration-free model ---------------------------


@pytest.mark.parametrize("f_number", [1.8, 2.4, 4.0])
def test_a_dense_table_of_diffraction_gives_the_aberration_free_f50_and_epc(f_number):
    # The bound: the Fritsch-Butland knot slope is a weighted harmonic mean of the two secants,
    # which differ by about h D''; it is off D' by O(h^2 (D''^2 / |D'| + |D'''|)), and a cubic
    # Hermite's value is off by at most (4/27) h times its slopes' error, plus h^4 max|D''''| /
    # 384. With h = 1/399 in nu = f lambda F and, where f50 lies (D = 0.5 at nu = 0.40, below
    # nu = 0.75, where |D'| > 0.84, |D''| < 1.5, |D'''| < 4), the MTF is off by below
    # (4/27) h^3 6 = 1.4e-8 (measured: 8.7e-9 on nu <= 0.9). f50 moves by that over
    # |f dMTF/df| = c A >= 0.25 at these points (A, the MTF's log-slope, >= 0.5): below 1e-7
    # relative; EPC twice that. Held to 1e-6 and 2e-6 (measured: below 8e-10).
    p = dict(POINTS, f_number=f_number)
    plain = epc_fast.evaluate(**p)
    table = epc_fast.evaluate(**p, lens_mtf=diffraction_table(f_number))
    assert np.all(plain.status == Status.OK) and np.all(table.status == Status.OK)
    np.testing.assert_allclose(table.f50_cyc_per_mm, plain.f50_cyc_per_mm, rtol=1e-6)
    np.testing.assert_allclose(table.epc, plain.epc, rtol=2e-6)
    # the light and the exposure do not depend on the optics' MTF: the same bits
    for name in ("electron_rate_e_per_s", "electrons", "t_mpe_s", "blur_mm"):
        assert np.array_equal(getattr(table, name), getattr(plain, name)), name


def test_the_interpolant_is_within_its_bound_of_diffraction_below_0_9_of_the_cut_off():
    # the bound of the test above, (4/27) h^3 max|...| with the derivatives' growth towards
    # nu = 0.9 (|D'''| = 15 there): 6e-8
    f, m = diffraction_table(2.4)
    fine = np.linspace(0.0, 0.9 * f[-1], 100_001)
    error = mtf_lens(fine, 0.0, [mtf_table("lens_mtf", (f, m))]) - reference.mtf_diffraction(
        fine, 550.0, 2.4)
    assert np.max(np.abs(error)) < 6e-8


def test_the_table_replaces_the_wavelength_and_the_spectrum():
    # the optics' MTF is the table's: the wavelength and a spectrum change nothing
    p = dict(POINTS, f_number=2.4, lens_mtf=diffraction_table(2.4))
    base = epc_fast.evaluate(**p)
    other = epc_fast.evaluate(**p, wavelength_nm=450.0)
    spectral = epc_fast.evaluate(**p, spectrum=([450.0, 650.0], [0.5, 0.5]))
    for r in (other, spectral):
        assert np.array_equal(r.f50_cyc_per_mm, base.f50_cyc_per_mm)


# --- Against prysm's pupil: a defocused lens --------------------------------------------------


def _prysm_defocus_mtf(w_waves, f_number, wavelength_um=0.55, n=256):
    """(f cycles/mm, MTF) of a circular pupil with w waves rms of defocus, by prysm, along a
    radius up to the cut-off, on prysm's own frequency grid."""
    pytest.importorskip("prysm")  # a test peer, not a dependency
    from prysm.coordinates import cart_to_polar, make_xy_grid
    from prysm.geometry import circle
    from prysm.otf import mtf_from_psf
    from prysm.polynomials import zernike_nm
    from prysm.propagation import Wavefront

    diameter_mm = 10.0
    efl_mm = f_number * diameter_mm
    x, y = make_xy_grid(n, diameter=diameter_mm)
    r, t = cart_to_polar(x, y)
    rho = r / (diameter_mm / 2)
    zernike = zernike_nm(2, 0, rho, t, norm=True)
    wf = Wavefront.from_amp_and_phase(circle(1, rho).astype(float),
                                      w_waves * wavelength_um * 1e3 * zernike, wavelength_um,
                                      diameter_mm / n)
    mtf = mtf_from_psf(wf.focus(efl_mm, Q=2).intensity)
    cy, cx = np.array(mtf.data.shape) // 2
    f = mtf.x[cy, cx:] if mtf.x.ndim == 2 else mtf.x[cx:]
    m = mtf.data[cy, cx:] / mtf.data[cy, cx]
    inside = f < 1.0 / (wavelength_um * 1e-3 * f_number)
    return f[inside], m[inside]


BRIGHT = dict(illuminance_lux=np.array([3000.0, 10000.0]), pixel_pitch_um=0.8, f_number=2.4,
              focal_length_mm=4.0, pixel_count=8e6, read_noise_e=2.0, backend="reference")


def test_a_20_point_table_of_prysms_defocused_pupil_gives_the_first_crossing_of_its_mtf():
    # prysm's MTF (0.1 waves rms defocus, F/2.4) on its own grid of 2.96 cycles/mm, times the
    # model's other factors there, crosses 0.5 at f50: the reference's f50 from 20 of prysm's
    # points must be that crossing. The table's error: the bound of the dense test above with
    # h = 0.046 in nu (12 of prysm's steps), (4/27) h^3 6 = 9e-5 of MTF, over c A >= 0.25:
    # 4e-4 relative; the crossing's own linear interpolation over prysm's step (h / f50)^2 / 8
    # = 1e-4 at f50 >= 100 cycles/mm. Held to 1e-3 (measured 1.8e-4 and 5.6e-5).
    f, m = _prysm_defocus_mtf(0.1, 2.4)
    assert np.all(np.diff(m) <= 0.0)  # 0.1 waves of defocus: a falling MTF
    step = f.size // 20
    table = (f[::step], m[::step])
    r = epc_fast.evaluate(**BRIGHT, lens_mtf=table)
    assert np.all(r.status == Status.OK)
    for i in range(2):
        others = (reference.mtf_pixel(f, BRIGHT["pixel_pitch_um"], 1.0)
                  * reference.mtf_motion(f, r.blur_mm[i]))
        crossing = first_crossing(f, m * others)
        assert crossing > 100.0
        assert r.f50_cyc_per_mm[i] == pytest.approx(crossing, rel=1e-3)


def test_prysms_defocus_table_agrees_with_shannons_atf_within_its_documented_error():
    # Shannon's ATF for 0.1 waves of defocus is 11.3% optimistic at the optics' own MTF50
    # (tests/reference/test_optics.py, ATF_MTF50_ERROR, with 0.5 points for its grid); the
    # system's f50, where the pixel and motion also fall, moves by less
    f, m = _prysm_defocus_mtf(0.1, 2.4)
    step = f.size // 20
    table = epc_fast.evaluate(**BRIGHT, lens_mtf=(f[::step], m[::step]))
    shannon = epc_fast.evaluate(**BRIGHT, wavefront_rms_waves=0.1)
    assert np.all(np.abs(shannon.f50_cyc_per_mm / table.f50_cyc_per_mm - 1.0) <= 0.113 + 0.005)


# --- Several tables, picked per point ---------------------------------------------------------


def test_a_list_of_tables_is_picked_per_point_by_lens():
    sharp = diffraction_table(2.4)
    soft = (np.array([0.0, 50.0, 100.0, 200.0]), np.array([1.0, 0.7, 0.35, 0.0]))
    lens = np.array([0.0, 1.0, 1.0, 0.0])[:, None]  # broadcast against the three points
    r = epc_fast.evaluate(**POINTS, f_number=2.4, lens_mtf=[sharp, soft], lens=lens)
    assert r.epc.shape == (4, 3)
    one = epc_fast.evaluate(**POINTS, f_number=2.4, lens_mtf=sharp)
    two = epc_fast.evaluate(**POINTS, f_number=2.4, lens_mtf=soft)
    for row, expected in zip(r.f50_cyc_per_mm, (one, two, two, one)):
        assert np.array_equal(row, expected.f50_cyc_per_mm)
    assert np.all(two.f50_cyc_per_mm < one.f50_cyc_per_mm)


def test_the_bracket_ends_at_a_tables_first_zero_or_its_last_frequency():
    tables = [mtf_table("a", ([0.0, 100.0, 150.0, 300.0], [1.0, 0.4, 0.0, 0.0])),
              mtf_table("b", ([0.0, 80.0], [1.0, 0.6]))]
    assert lens_bracket(np.array([0.0, 1.0]), tables).tolist() == [150.0, 80.0]
    # the monotone interpolant is 0 from the first zero on and above 0 before it
    assert mtf_lens(np.array([149.9, 150.0, 220.0]), 0.0, tables[:1]).tolist()[1:] == [0.0, 0.0]
    assert mtf_lens(149.9, 0.0, tables[:1]) > 0.0


# --- f50 past the table's end -----------------------------------------------------------------


def test_f50_past_the_tables_last_frequency_is_beyond_table_with_finite_exposure():
    # a sharp camera (bright light, small pixels) whose lens table ends at 50 cycles/mm, at
    # MTF 0.8: f50 lies past it
    short = (np.array([0.0, 25.0, 50.0]), np.array([1.0, 0.9, 0.8]))
    p = dict(BRIGHT, lens_mtf=short)
    r = epc_fast.evaluate(**p, outputs=("t_mpe_s", "blur_mm", "electrons", "f50_cyc_per_mm",
                                        "epc", "status", "share_lens", "elasticities"))
    assert np.all(r.status == Status.BEYOND_TABLE)
    assert np.all(np.isnan(r.f50_cyc_per_mm)) and np.all(np.isnan(r.epc))
    for name in ("t_mpe_s", "blur_mm", "electrons"):
        assert np.all(np.isfinite(getattr(r, name))), name
    assert np.all(np.isnan(r.share_lens)) and np.all(np.isnan(r.elasticities["f_number"]))
    # it is not invalid: invalid="raise" gives the same
    raised = epc_fast.evaluate(**p, invalid="raise")
    assert np.all(raised.status == Status.BEYOND_TABLE)
    # in dim light the blur sets f50 inside the table: OK
    dim = epc_fast.evaluate(**dict(p, illuminance_lux=np.array([10.0, 30.0])))
    assert dim.status.tolist() == [Status.OK, Status.OK] and np.all(dim.f50_cyc_per_mm < 50.0)


# --- Shares and elasticities ------------------------------------------------------------------

SHARE_NAMES = [f"share_{n}" for n in epc_fast.outputs.SHARE_NAMES]
SOFT = (np.array([0.0, 40.0, 90.0, 150.0, 260.0, 400.0]),
        np.array([1.0, 0.85, 0.62, 0.4, 0.12, 0.0]))


def test_the_eight_shares_sum_to_one_and_the_lens_has_its_own():
    r = epc_fast.evaluate(**POINTS, f_number=2.4, lens_mtf=SOFT,
                          outputs=("f50_cyc_per_mm", "status", *SHARE_NAMES))
    assert np.all(r.status == Status.OK)
    np.testing.assert_allclose(sum(getattr(r, n) for n in SHARE_NAMES), 1.0, rtol=1e-13)
    # share_lens = ln(L / D) / ln c at f50, L the table's interpolant, D aberration-free
    f50 = r.f50_cyc_per_mm
    expected = (np.log(mtf_lens(f50, 0.0, [mtf_table("lens_mtf", SOFT)]))
                - np.log(reference.mtf_diffraction(f50, 550.0, 2.4))) / np.log(0.5)
    np.testing.assert_allclose(r.share_lens, expected, rtol=1e-12)
    assert np.all(r.share_lens > 0.0)  # the soft lens falls below diffraction
    plain = epc_fast.evaluate(**POINTS, f_number=2.4, outputs=("status", *SHARE_NAMES))
    assert np.all(plain.share_lens == 0.0)


def test_the_elasticities_with_a_table_are_the_central_differences_of_ln_epc():
    # central differences at h = 1e-5: truncation h^2 ~ 1e-10 and rounding 1e-16 / h ~ 1e-11 of
    # an elasticity of order 1, and f50 bisected to adjacent floats; held to 1e-6 as the
    # wavefront error's are (tests/reference/test_optics.py)
    p = dict(POINTS, f_number=2.4, lens_mtf=SOFT, snr_db=30.0, wavelength_nm=550.0)
    r = epc_fast.evaluate(**p, outputs=("epc", "status", "elasticities"))
    h = 1e-5
    for name in ("f_number", "wavelength_nm", "pixel_pitch_um", "illuminance_lux",
                 "focal_length_mm", "snr_db", "read_noise_e"):
        v = np.broadcast_to(np.asarray(p[name], dtype=np.float64), (3,))
        up = epc_fast.evaluate(**{**p, name: v * (1 + h)}).epc
        down = epc_fast.evaluate(**{**p, name: v * (1 - h)}).epc
        central = (np.log(up) - np.log(down)) / (2 * h)
        np.testing.assert_allclose(r.elasticities[name], central, rtol=1e-6, atol=1e-9,
                                   err_msg=name)
    # the wavelength no longer reaches the MTF, and the f-number only through the light
    assert np.all(r.elasticities["wavelength_nm"] == 0.0)
    rate = r.elasticities["illuminance_lux"]
    np.testing.assert_allclose(r.elasticities["f_number"], -2.0 * rate, rtol=1e-12)
    assert np.all(np.isnan(r.elasticities["lens"]))  # a whole number has none
