"""The core's lens tables (cpp/include/epc_fast/tabulated.h, lens.h)
against the NumPy reference: every output, the BEYOND_TABLE status, the shares and the
elasticities, one table or several picked per point, every solver, float32 (solved in float64)
and a spectrum (which a table replaces)."""

import numpy as np
import pytest

import epc_fast
from epc_fast import Status
from epc_fast.reference import mtf_diffraction
from epc_fast.spectra import diffraction_spectrum
from helpers.designs import random_design_points

FIELDS = ("electron_rate_e_per_s", "electrons", "t_mpe_s", "blur_mm", "f50_cyc_per_mm", "epc")
SHARES = tuple(f"share_{n}" for n in ("diffraction", "pixel", "motion", "jitter", "alignment",
                                      "aberration", "denoise", "lens"))


def _table(f_number, wavelength_nm=550.0, points=12, soften=0.0, end=1.0):
    """A lens table: the aberration-free MTF at F, times a defocus-like exp(-soften (f/fc)^2),
    at ``points`` frequencies up to ``end`` times the cut-off (past its end: BEYOND_TABLE for a
    sharp enough camera)."""
    cutoff = 1.0 / (wavelength_nm * 1e-6 * f_number)
    f = np.linspace(0.0, end * cutoff, points)
    m = mtf_diffraction(f, wavelength_nm, f_number) * np.exp(-soften * (f / cutoff) ** 2)
    m = np.minimum.accumulate(np.clip(m, 0.0, 1.0))
    return f, m


TABLES = [_table(2.0, soften=1.0), _table(2.8, points=30), _table(1.8, soften=3.0, end=0.06)]


def _designs(n, seed):
    p = random_design_points(n, seed, sensor_terms=True)
    p["lens"] = np.random.default_rng([seed, 41]).integers(0, len(TABLES), n).astype(float)
    p["lens"][::97] = 3.0  # outside the three tables: INVALID
    return p


def _assert_agree(core, ref, rtol=1e-12):
    np.testing.assert_array_equal(core.status, ref.status)
    np.testing.assert_array_equal(core.cause, ref.cause)
    for name in FIELDS:
        a, b = getattr(core, name), getattr(ref, name)
        np.testing.assert_array_equal(np.isnan(a), np.isnan(b), err_msg=name)
        finite = np.isfinite(b) & (b != 0)
        err = np.abs(a[finite] / b[finite] - 1.0)
        # the tables' cubic is the same polynomial in both; f50 to 1e-14 against adjacent
        # doubles, T_MPE's roundings as in tests/test_core_vs_reference.py (PRNU and the tan
        # amplify them on a few points: a looser bound on the 99.9th percentile is not needed
        # here, the worst is asserted)
        assert err.max(initial=0.0) <= rtol * 1e3 and np.quantile(err, 0.99) <= rtol, name


@pytest.mark.parametrize("f50_solver", ["halley", "newton", "brent", "bisection"])
def test_the_core_agrees_with_the_reference_with_lens_tables(f50_solver):
    p = _designs(8_000, 41)
    core = epc_fast.evaluate(**p, lens_mtf=TABLES, f50_solver=f50_solver)
    ref = epc_fast.evaluate(**p, lens_mtf=TABLES, backend="reference")
    _assert_agree(core, ref)
    counts = np.bincount(ref.status, minlength=5)
    assert counts[Status.BEYOND_TABLE] > 100 and counts[Status.OK] > 2_000
    assert counts[Status.INVALID] >= 80


def test_float32_solves_lens_points_in_float64():
    p = _designs(4_000, 42)
    wide = epc_fast.evaluate(**p, lens_mtf=TABLES)
    narrow = epc_fast.evaluate(**p, lens_mtf=TABLES, precision="float32")
    for name in FIELDS + ("status",):
        np.testing.assert_array_equal(getattr(narrow, name), getattr(wide, name), err_msg=name)


def test_a_spectrum_leaves_a_tables_f50_and_moves_only_the_aberration_free_share():
    p = _designs(2_000, 43)
    del p["wavelength_nm"]
    one = epc_fast.evaluate(**p, lens_mtf=TABLES, outputs=FIELDS + ("status",))
    spec = epc_fast.evaluate(**p, lens_mtf=TABLES, spectrum=diffraction_spectrum(8),
                             outputs=FIELDS + ("status",) + SHARES)
    np.testing.assert_array_equal(spec.f50_cyc_per_mm, one.f50_cyc_per_mm)
    ref = epc_fast.evaluate(**p, lens_mtf=TABLES, spectrum=diffraction_spectrum(8),
                            outputs=FIELDS + ("status",) + SHARES, backend="reference")
    ok = ref.status == Status.OK
    for name in SHARES:  # the shares divide logs; both sum them in their own orders
        np.testing.assert_allclose(getattr(spec, name)[ok], getattr(ref, name)[ok], rtol=0,
                                   atol=1e-9, err_msg=name)


def test_the_shares_and_elasticities_with_lens_tables_agree_with_the_reference():
    p = _designs(4_000, 44)
    asked = ("epc", "status", "elasticities") + SHARES
    core = epc_fast.evaluate(**p, lens_mtf=TABLES, outputs=asked)
    ref = epc_fast.evaluate(**p, lens_mtf=TABLES, outputs=asked, backend="reference")
    ok = ref.status == Status.OK
    for name in SHARES:
        np.testing.assert_allclose(getattr(core, name)[ok], getattr(ref, name)[ok], rtol=0,
                                   atol=1e-9, err_msg=name)
    np.testing.assert_allclose(sum(getattr(core, n)[ok] for n in SHARES), 1.0, rtol=1e-12)
    for name in core.elasticities:
        a, b = core.elasticities[name][ok], ref.elasticities[name][ok]
        if name in ("binning", "frames", "lens", "binning_readout"):  # whole numbers: NaN
            assert np.isnan(a).all() and np.isnan(b).all()
            continue
        # as tests/test_sensitivity.py: 1e-9 of the elasticity, or of 1e-3 where it is smaller
        assert np.all(np.abs(a - b) <= 1e-9 * np.maximum(np.abs(b), 1e-3)), name
    # the table's L does not move with the wavelength: that elasticity is 0 at every OK point
    assert np.all(core.elasticities["wavelength_nm"][ok] == 0.0)


def test_a_table_that_ends_above_the_threshold_is_beyond_table_in_the_core():
    # a sharp 1.4 um camera in daylight and a table that stops at 50 cycles/mm at MTF 0.8
    r = epc_fast.evaluate(1e4, pixel_pitch_um=1.4, f_number=2.0, focal_length_mm=4.0,
                          pixel_count=12e6, lens_mtf=([0.0, 50.0], [1.0, 0.8]), invalid="raise")
    assert r.status == Status.BEYOND_TABLE
    assert np.isnan(r.f50_cyc_per_mm) and np.isnan(r.epc) and np.isfinite(r.t_mpe_s)
