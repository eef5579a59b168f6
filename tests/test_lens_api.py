"""evaluate's lens_mtf= and lens=: the tables checked with one line naming the argument, the
lens index's domain set by the number of tables (INVALID per point, or a ValueError naming it),
lens_mtf refused with a wavefront error; the default call the same bits with lens=0 given or
not, on both backends, and share_lens and the lens elasticity without tables (0 and NaN).
"""

import re
import warnings

import numpy as np
import pytest

import epc_fast
from epc_fast import Status

DESIGN = dict(illuminance_lux=np.array([10.0, 300.0, 5000.0]), pixel_pitch_um=1.4, f_number=2.4,
              focal_length_mm=4.0, pixel_count=8e6, read_noise_e=2.0)
TABLE = (np.array([0.0, 50.0, 100.0, 200.0, 400.0]), np.array([1.0, 0.8, 0.55, 0.2, 0.0]))


@pytest.mark.parametrize("table, message", [
    ((np.array([0.0]), np.array([1.0])), "lens_mtf has 1 point(s); a table needs at least 2"),
    ((np.array([0.0, 100.0, 50.0]), np.array([1.0, 0.5, 0.4])),
     "lens_mtf's frequencies must increase strictly: 100.0 at index 1 is followed by 50.0"),
    ((np.array([0.0, 50.0, 50.0]), np.array([1.0, 0.5, 0.4])),
     "lens_mtf's frequencies must increase strictly: 50.0 at index 1 is followed by 50.0"),
    ((np.array([0.0, 50.0, 100.0]), np.array([1.0, 0.4, 0.5])),
     "lens_mtf rises from 0.4 to 0.5 between frequencies 50.0 and 100.0"),
    ((np.array([0.0, np.nan]), np.array([1.0, 0.5])),
     "lens_mtf holds a NaN or infinite value at index 1"),
    ((np.array([0.0, 50.0]), np.array([1.0, np.nan])),
     "lens_mtf holds a NaN or infinite value at index 1"),
    ((np.array([10.0, 50.0]), np.array([1.2, 0.5])),
     "lens_mtf's mtf 1.2 at index 0 is outside [0, 1]"),
    ((np.array([0.0, 50.0]), np.array([0.9, 0.5])), "lens_mtf's mtf at frequency 0 is 0.9"),
    ((np.array([-1.0, 50.0]), np.array([1.0, 0.5])), "lens_mtf's first frequency is -1.0"),
    (3.0, "lens_mtf must be a pair (frequencies_cyc_per_mm, mtf) of 1-D arrays or a list"),
])
def test_a_bad_table_is_refused_in_one_line_naming_it(table, message):
    with pytest.raises(ValueError, match=re.escape(message)) as error:
        epc_fast.evaluate(**DESIGN, lens_mtf=table, backend="reference")
    assert "\n" not in str(error.value)


def test_a_bad_table_in_a_list_is_named_by_its_index():
    bad = (np.array([0.0, 50.0]), np.array([1.0, 1.0 + 1e-9]))
    with pytest.raises(ValueError, match=re.escape("lens_mtf[1]'s mtf 1.000000001 at index 1")):
        epc_fast.evaluate(**DESIGN, lens_mtf=[TABLE, bad], backend="reference")
    with pytest.raises(ValueError, match="lens_mtf is an empty list"):
        epc_fast.evaluate(**DESIGN, lens_mtf=[], backend="reference")


def test_a_table_and_a_wavefront_error_are_refused_together():
    with pytest.raises(ValueError, match="give lens_mtf or wavefront_rms_waves, not both"):
        epc_fast.evaluate(**DESIGN, lens_mtf=TABLE, wavefront_rms_waves=[0.0, 0.05, 0.0],
                          backend="reference")
    # 0, the term off, goes with a table
    r = epc_fast.evaluate(**DESIGN, lens_mtf=TABLE, wavefront_rms_waves=0.0, backend="reference")
    assert np.all(r.status == Status.OK)


@pytest.mark.parametrize("lens_mtf, bad, backend", [
    (None, [1.0, -1.0, 0.5, np.nan, np.inf], "reference"),  # without tables only 0 is valid
    (None, [1.0, -1.0, 0.5, np.nan, np.inf], "core"),
    ([TABLE, TABLE], [2.0, -1.0, 0.5, np.nan, -np.inf], "reference"),  # two tables: 0 and 1
])
def test_a_lens_index_outside_its_tables_is_invalid_or_raises_naming_it(lens_mtf, bad, backend):
    p = dict(DESIGN, illuminance_lux=300.0, lens_mtf=lens_mtf, backend=backend)
    r = epc_fast.evaluate(**p, lens=bad)
    assert np.all(r.status == Status.INVALID) and np.all(np.isnan(r.epc))
    top = 0 if lens_mtf is None else len(lens_mtf) - 1
    valid = epc_fast.evaluate(**p, lens=np.arange(top + 1.0))
    assert np.all(valid.status == Status.OK)
    for value in bad:
        message = (f"lens={value!r} at index (1,) is outside its domain [0, {top}] integers")
        with pytest.raises(ValueError, match=re.escape(message)):
            epc_fast.evaluate(**p, lens=[0.0, value], invalid="raise")


@pytest.mark.parametrize("backend", ["reference", "core"])
def test_lens_0_and_no_lens_give_the_same_bits(backend):
    names = ("electron_rate_e_per_s", "electrons", "t_mpe_s", "blur_mm", "f50_cyc_per_mm",
             "epc", "status", "cause")
    plain = epc_fast.evaluate(**DESIGN, backend=backend)
    zero = epc_fast.evaluate(**DESIGN, lens=np.zeros(3), backend=backend)
    for name in names:
        assert np.array_equal(getattr(plain, name), getattr(zero, name)), name


def test_the_core_gives_share_lens_0_and_a_lens_elasticity_of_nan_as_the_reference():
    asked = ("epc", "status", "share_lens", "share_aberration", "elasticities")
    p = dict(DESIGN, illuminance_lux=np.array([10.0, 300.0, 0.0]))  # the last: no light
    core = epc_fast.evaluate(**p, outputs=asked)
    ref = epc_fast.evaluate(**p, outputs=asked, backend="reference")
    for r in (core, ref):
        assert r.status.tolist() == [Status.OK, Status.OK, Status.UNREACHABLE]
        assert r.share_lens[:2].tolist() == [0.0, 0.0] and np.isnan(r.share_lens[2])
        assert np.all(np.isnan(r.elasticities["lens"]))
    np.testing.assert_allclose(core.elasticities["f_number"], ref.elasticities["f_number"],
                               rtol=1e-9)
    # one elasticity row, and out= arrays for every one of them
    single = epc_fast.evaluate(**p, outputs=("elasticity_lens", "elasticity_f_number"))
    assert np.all(np.isnan(single.elasticities["lens"]))
    assert np.array_equal(single.elasticities["f_number"], core.elasticities["f_number"],
                          equal_nan=True)
    out = {name: np.full(3, 7.0) for name in ("share_lens",)}
    given = epc_fast.evaluate(**p, outputs=("share_lens",), out=out)
    assert given.share_lens is out["share_lens"]
    assert np.array_equal(out["share_lens"], core.share_lens, equal_nan=True)


@pytest.mark.parametrize("table, message", [
    ((["0", "100", "200"], [1.0, 0.5, 0.1]),
     "lens_mtf's frequencies must be real numbers, got ['0', '100', '200']"),
    ((np.array([0.0, 100.0]), ["1", "0.5"]), "lens_mtf's mtf must be real numbers, got ['1', '0.5']"),
    (([0.0, 100.0], [True, False]), "lens_mtf's mtf must be real numbers, got [True, False]"),
])
def test_a_table_of_strings_or_booleans_is_refused_naming_the_argument_and_value(table, message):
    # Strings were read as the numbers they spell: "100" became 100 cycles/mm.
    for backend in ("core", "reference"):
        with pytest.raises(ValueError, match=re.escape(message)):
            epc_fast.evaluate(**DESIGN, lens_mtf=table, backend=backend)


def test_a_scan_config_lens_table_of_strings_is_a_config_error_with_exit_code_2(tmp_path, capsys):
    from epc_fast.__main__ import main

    config = tmp_path / "scan.toml"
    config.write_text('[scan]\npoints = 65536\n[design]\npresets = ["HIGH_TIER"]\n'
                      '[parameters]\nilluminance_lux = 100.0\n'
                      '[evaluate]\nlens_mtf = [["0", "100"], [1.0, 0.5]]\n'
                      '[reductions.s]\nkind = "summary"\n')
    code = main(["scan", str(config), "--out", str(tmp_path / "out"), "--no-progress"])
    err = capsys.readouterr().err
    assert code == 2 and "lens_mtf" in err and "['0', '100']" in err, err
    assert err.count("\n") == 1


# --- Lens tables against the mpmath model (helpers/mp_model.py) ---------------------------------

#: The paper's 1.4 um design in daylight (K passed exactly), where the lens limits f50.
MP_DESIGN = dict(illuminance_lux=10000.0, pixel_pitch_um=1.4, f_number=2.8, focal_length_mm=5.6,
                 sensor_area_mm2=15.6751, electrons_per_lux_s_m2=2557705539053827.5)


def _soft_table(points, end=1.0):
    """A lens table: the aberration-free MTF at F/2.8 and 550 nm times exp(-(f/f_c)^2) (an
    aberration's softening), at `points` frequencies up to `end` times the cut-off f_c."""
    cutoff = 1.0 / (550e-6 * 2.8)
    f = np.linspace(0.0, end * cutoff, points)
    nu = f / cutoff
    d = 2.0 / np.pi * (np.arccos(nu) - nu * np.sqrt(1.0 - nu * nu))
    return f, np.minimum.accumulate(np.clip(d * np.exp(-nu * nu), 0.0, 1.0))


SOFT = _soft_table(15)
#: name -> (inputs, table, lens_mtf as evaluate takes it): the table a point picks is `table`.
MP_LENS_CASES = {
    "fifteen_points_to_the_cut_off": (MP_DESIGN, SOFT, SOFT),
    "starting_above_zero": (dict(MP_DESIGN, f_number=2.0), (SOFT[0][1:9], SOFT[1][1:9]),
                            (SOFT[0][1:9], SOFT[1][1:9])),
    "two_points": (MP_DESIGN, (np.array([0.0, 600.0]), np.array([1.0, 0.02])),
                   (np.array([0.0, 600.0]), np.array([1.0, 0.02]))),
    "beyond_its_end": (dict(MP_DESIGN, illuminance_lux=1e5), (SOFT[0][:4], SOFT[1][:4]),
                       (SOFT[0][:4], SOFT[1][:4])),
    "picked_by_lens_1_with_denoising_and_a_burst": (
        dict(MP_DESIGN, illuminance_lux=300.0, read_noise_e=2.0, denoise_sigma_px=1.0,
             frames=4.0, alignment_error_um=0.5, lens=1.0), SOFT, [TABLE, SOFT]),
}


@pytest.mark.parametrize("backend", ["core", "reference"])
@pytest.mark.parametrize("case", MP_LENS_CASES)
def test_a_lens_table_matches_the_mpmath_model(case, backend):
    from helpers.mp_model import assert_matches_model, mp_model

    inputs, table, lens_mtf = MP_LENS_CASES[case]
    model = mp_model(inputs, lens_mtf=table)
    if model["status"] == "ok":  # the table is a sizeable factor at f50
        assert model["mtf_factors"][0] < 0.9, model["mtf_factors"]
    result = epc_fast.evaluate(**inputs, lens_mtf=lens_mtf, backend=backend)
    # The model takes the float64 table and inputs exactly; both backends evaluate the same
    # interpolant as a cubic whose coefficients they round (~1e-16 of L), on a steep MTF at f50:
    # their float64 accuracy (measured <= 2e-15) owes 1e-12, the suite's target, with 500x room,
    # and other knot slopes (centred differences, measured) move f50 by 1e-6 and more.
    assert_matches_model(result, model, rtol=1e-12, label=case)


# --- Tables no lens can have: above diffraction, or in cycles/pixel ------------------------------

def _diffraction(f_cyc_per_mm, wavelength_nm, f_number):
    """The aberration-free circular pupil's MTF, (2/pi)(acos nu - nu sqrt(1 - nu^2)), nu = f
    lambda N, written out here (not the package's mtf_diffraction) for the tests to hold."""
    nu = min(f_cyc_per_mm * wavelength_nm * 1e-6 * f_number, 1.0)
    return (2.0 / np.pi) * (np.arccos(nu) - nu * np.sqrt(1.0 - nu * nu))


#: cycles/mm: knots of a table up to f/2.8's cut-off at 550 nm (649.35 cycles/mm).
KNOTS = np.array([0.0, 100.0, 200.0, 300.0, 400.0, 500.0, 600.0])


def _diffraction_table(wavelength_nm=550.0, f_number=2.8, frequencies=KNOTS):
    return frequencies, np.array([_diffraction(f, wavelength_nm, f_number) for f in frequencies])


def test_a_table_above_diffraction_is_refused_naming_the_frequency_its_mtf_and_the_limit():
    f, m = _diffraction_table()
    ok = epc_fast.evaluate(**DESIGN, lens_mtf=(f, m), backend="reference")  # f/2.4: room above
    assert np.all(ok.status == Status.OK)
    # the same lens's table with its frequencies in lines/mm (2 lines a cycle) read as cycles/mm
    lines = dict(DESIGN, f_number=2.8)
    with pytest.raises(ValueError) as error:
        epc_fast.evaluate(**lines, lens_mtf=(2.0 * f, m))
    text = str(error.value)
    assert "\n" not in text
    # the largest excess, at 600 cycles/mm: the table's MTF there is D(300) = 0.4334 at f/2.8
    # and 550 nm, diffraction's D(600) = 0.02486 (the cut-off is 649 cycles/mm)
    assert text.startswith(
        "lens_mtf lies above diffraction: its MTF at 600 cycles/mm is 0.4334, the diffraction "
        "MTF there at f/2.8 and 550 nm (the smallest f-number times wavelength among its points) "
        "is 0.02486, and no lens exceeds it by more than 0.02: are its frequencies in "
        "lines/mm?"), text
    assert (round(m[3], 4), round(_diffraction(600.0, 550.0, 2.8), 5)) == (0.4334, 0.02486)


@pytest.mark.parametrize("excess, refused", [(0.019, False), (0.021, True)])
def test_a_table_may_lie_above_diffraction_by_the_tolerance_of_a_measurement(excess, refused):
    # 0.02 of MTF (epc_fast.mtf_table.DIFFRACTION_TOLERANCE) at 300 cycles/mm, where the
    # neighbours are 0.1 away (the table still falls)
    f, m = _diffraction_table()
    m = m.copy()
    m[3] += excess
    design = dict(DESIGN, f_number=2.8)
    if not refused:
        assert np.all(epc_fast.evaluate(**design, lens_mtf=(f, m)).status == Status.OK)
        return
    limit = _diffraction(300.0, 550.0, 2.8)
    message = (f"its MTF at 300 cycles/mm is {m[3]:.4g}, the diffraction MTF there at f/2.8 "
               f"and 550 nm (the smallest f-number times wavelength among its points) is "
               f"{limit:.4g}")
    with pytest.raises(ValueError, match=re.escape(message)):
        epc_fast.evaluate(**design, lens_mtf=(f, m))


def test_the_limit_is_the_smallest_f_number_among_the_points_using_the_table():
    f28 = _diffraction_table(f_number=2.8)
    design = {k: v for k, v in DESIGN.items() if k != "f_number"}
    design["illuminance_lux"] = 300.0
    # f/2.8's table under f/2.8 and f/4 points: the f/2.8 point allows it
    r = epc_fast.evaluate(**design, f_number=np.array([4.0, 2.8]), lens_mtf=f28)
    assert np.all(r.status == Status.OK)
    with pytest.raises(ValueError, match=re.escape("lens_mtf lies above diffraction: its MTF "
                                                   "at 400 cycles/mm is 0.2686, the diffraction "
                                                   "MTF there at f/4 and 550 nm")):
        epc_fast.evaluate(**design, f_number=np.array([4.0, 5.6]), lens_mtf=f28)
    # two tables: each against its own points; a point with an invalid lens index uses none
    two = [f28, _diffraction_table(f_number=5.6)]
    r = epc_fast.evaluate(**design, f_number=np.array([2.8, 5.6, 2.0]), lens=[0.0, 1.0, 7.0],
                          lens_mtf=two)
    assert r.status.tolist() == [Status.OK, Status.OK, Status.INVALID]
    with pytest.raises(ValueError, match=re.escape("lens_mtf[0] lies above diffraction")):
        epc_fast.evaluate(**design, f_number=np.array([5.6, 2.8]), lens=[0.0, 1.0],
                          lens_mtf=two)
    # a point's wavelength counts with its f-number: f/2.8 at 600 nm is not f/2.8 at 550 nm
    with pytest.raises(ValueError, match=re.escape("at f/2.8 and 600 nm")):
        epc_fast.evaluate(**design, f_number=np.array([2.8, 4.0]),
                          wavelength_nm=np.array([600.0, 450.0]), lens_mtf=f28)


def test_under_a_spectrum_the_limit_is_at_its_shortest_wavelength_of_positive_weight():
    table = _diffraction_table(wavelength_nm=450.0)
    design = dict(DESIGN, illuminance_lux=300.0, f_number=2.8)
    r = epc_fast.evaluate(**design, spectrum=([450.0, 650.0], [0.5, 0.5]), lens_mtf=table)
    assert np.all(r.status == Status.OK)
    for spectrum in (([500.0, 650.0], [0.5, 0.5]), ([450.0, 500.0, 650.0], [0.0, 0.5, 0.5])):
        with pytest.raises(ValueError, match=re.escape("at f/2.8 and 500 nm")):
            epc_fast.evaluate(**design, spectrum=spectrum, lens_mtf=table)


def test_a_table_ending_below_a_hundredth_of_nyquist_is_warned_of_naming_the_unit():
    # a demosaicker-like table in cycles/pixel: it ends at 0.5, the pixels' Nyquist frequency
    # is 1/(2 * 0.0014 mm) = 357.14 cycles/mm at the smallest pitch
    per_pixel = (np.array([0.0, 0.25, 0.5]), np.array([1.0, 0.6, 0.2]))
    design = dict(DESIGN, pixel_pitch_um=np.array([2.0, 1.4, 3.0]))
    with pytest.warns(UserWarning) as record:
        epc_fast.evaluate(**design, lens_mtf=per_pixel)
    assert [str(w.message) for w in record] == [
        "lens_mtf ends at 0.5 cycles/mm, below 1/100 of the pixels' Nyquist frequency 357.143 "
        "cycles/mm: are its frequencies in cycles/pixel? they must be cycles/mm"]
    assert record[0].filename == __file__  # the warning points at the caller's line
    # a table in cycles/mm that ends at 3.6 cycles/mm or more, and a call without one: silent
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        epc_fast.evaluate(**design, lens_mtf=(per_pixel[0] * 7.2, per_pixel[1]))
        epc_fast.evaluate(**design)
