"""Sobol' indices over a space (epc_fast.scan.sobol_indices) against a case with a closed form.

The closed form: a camera whose EPC is a pure power law in light and shake,
EPC = C (L R k / omega)^2 (L illuminance, R reflectance, k stabilisation, omega shake). Shot
noise only makes T_MPE = s / r with r proportional to L R; the blur is b = f_L tan(omega T / k);
a huge k (1e19) keeps that angle below 2e-6 rad, where tan(x) = x to 1.3e-12; a focal length of
1e10 mm then keeps b above 0.05 mm, so that f50 = x50 / b (sinc(x50) = 1/2) while a pixel
pitch of 1e-6 um (p f50 < 2e-8) and a wavelength of 1e-12 nm (f50 lambda F < 1e-13) leave the
pixel-aperture and diffraction factors within 1e-12 of 1. The first test measures the power law
at the corners of every space used here.

With independent ln L, ln omega, ln k and ln R, log EPC is additive, so each parameter's S1
and ST are both its term's share of the variance, 4 Var(ln X) / Var(log EPC). EPC itself is a
product of independent factors Y = prod X_i (X_1 = L^2, X_2 = omega^-2, ...): with
m_i = E[X_i] and q_i = E[X_i^2], Var Y = prod q - prod m^2, the first-order variance of X_i is
(q_i - m_i^2) prod_{j != i} m_j^2 and its total (q_i - m_i^2) prod_{j != i} q_j; the
second-order variance of a pair is (q_i - m_i^2)(q_j - m_j^2) prod_{k != i, j} m_k^2. The
moments are closed: E[X^n] = (b^n - a^n) / (n ln(b / a)) for X log-uniform on [a, b], and
median^n exp(n^2 sigma^2 / 2) for a log-normal.
"""

from __future__ import annotations

import math
import subprocess
import sys

import numpy as np
import pytest

from epc_fast import Status, evaluate, scan
from epc_fast.presets import HIGH_TIER
from epc_fast.scan import indices as indices_module

#: The fixed parameters of the power-law camera (module docstring).
POWER_LAW = dict(pixel_pitch_um=1e-6, f_number=2.8, focal_length_mm=1e10, sensor_area_mm2=1.0,
                 wavelength_nm=1e-12)
LUX = (100.0, 1000.0)
SHAKE_MEDIAN, SHAKE_SIGMA = 4.39, 0.5
SHAKE_RANGE = (2.0, 8.0)
STABILIZATION = (1e19, 2e19)
STABILIZATION_WEIGHTS = (0.25, 0.75)
REFLECTANCE = (0.2, 0.4)
#: A full well the 1000 electrons of 30 dB never reach: a parameter the model ignores.
IGNORED_FULL_WELL = (1e6, 1e7)


def paper_design():
    """The paper's 1/3.2" 1.4 um design."""
    return HIGH_TIER[3]


def additive_space() -> scan.Space:
    """The power-law camera over log-uniform light, log-normal shake, a weighted choice of
    stabilisation and a grid of reflectance, and a full well it never reaches."""
    return scan.Space(illuminance_lux=scan.LogUniform(*LUX),
                      shake_deg_per_s=scan.LogNormal(SHAKE_MEDIAN, SHAKE_SIGMA),
                      stabilization=scan.Choice(STABILIZATION, STABILIZATION_WEIGHTS),
                      reflectance=scan.Grid(REFLECTANCE),
                      full_well_e=scan.Uniform(*IGNORED_FULL_WELL), **POWER_LAW)


def product_space(full_well=IGNORED_FULL_WELL) -> scan.Space:
    """The power-law camera over log-uniform light and shake (every moment of EPC finite and
    small: a log-normal shake's omega^-2 has a heavy tail, which widens EPC's intervals), an
    unweighted choice of stabilisation and a uniform full well."""
    return scan.Space(illuminance_lux=scan.LogUniform(*LUX),
                      shake_deg_per_s=scan.LogUniform(*SHAKE_RANGE),
                      stabilization=scan.Choice(STABILIZATION),
                      full_well_e=scan.Uniform(*full_well), **POWER_LAW)


def log_uniform_moment(low: float, high: float, n: float) -> float:
    """E[X^n] of X log-uniform on [low, high]."""
    return (high**n - low**n) / (n * math.log(high / low))


def discrete_moment(values, weights, n: float) -> float:
    weights = np.asarray(weights, dtype=float) / np.sum(weights)
    return float(np.sum(weights * np.asarray(values, dtype=float) ** n))


def additive_shares() -> np.ndarray:
    """S1 = ST of log EPC for each parameter of :func:`additive_space`: the shares of
    Var(log EPC) = 4 (Var ln L + Var ln omega + Var ln k + Var ln R)."""
    ln_k = np.log(np.asarray(STABILIZATION) / STABILIZATION[0])
    w = np.asarray(STABILIZATION_WEIGHTS) / sum(STABILIZATION_WEIGHTS)
    variances = np.array([math.log(LUX[1] / LUX[0]) ** 2 / 12, SHAKE_SIGMA**2,
                          float(np.sum(w * ln_k**2) - np.sum(w * ln_k) ** 2),
                          math.log(REFLECTANCE[1] / REFLECTANCE[0]) ** 2 / 4, 0.0])
    return variances / variances.sum()


def product_factor_moments(p_reachable: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """(E[X_i], E[X_i^2]) of EPC's factors in :func:`product_space`: L^2, omega^-2, k^2 (k in
    units of 1e19) and the full well's factor, 1 where the target is reached and 0 (EPC
    counted as 0) where not, with probability ``p_reachable`` of 1."""
    k = np.asarray(STABILIZATION) / STABILIZATION[0]
    first = [log_uniform_moment(*LUX, 2), log_uniform_moment(*SHAKE_RANGE, -2),
             discrete_moment(k, [1, 1], 2), p_reachable]
    second = [log_uniform_moment(*LUX, 4), log_uniform_moment(*SHAKE_RANGE, -4),
              discrete_moment(k, [1, 1], 4), p_reachable]
    return np.array(first), np.array(second)


def product_indices(m: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Closed-form S1, ST and S2 of a product of independent factors with E[X] = m and
    E[X^2] = q (module docstring)."""
    variance = np.prod(q) - np.prod(m**2)
    own = q - m**2
    n = m.size
    s1 = np.array([own[i] * np.prod(np.delete(m**2, i)) for i in range(n)]) / variance
    st = np.array([own[i] * np.prod(np.delete(q, i)) for i in range(n)]) / variance
    s2 = np.full((n, n), np.nan)
    for i in range(n):
        for j in range(i + 1, n):
            s2[i, j] = own[i] * own[j] * np.prod(np.delete(m**2, [i, j])) / variance
    return s1, st, s2


def assert_covered(estimate, half_width, exact, widest):
    """Each estimate within its confidence interval of the exact value, and the interval no
    wider than ``widest``."""
    estimate, half_width, exact = map(np.asarray, (estimate, half_width, exact))
    assert np.all(np.abs(estimate - exact) <= half_width), (estimate, half_width, exact)
    assert np.all(half_width <= widest), half_width


def test_the_constructed_camera_is_a_power_law_in_light_reflectance_stabilisation_and_shake():
    # The corners of every space below: light, reflectance and stabilisation at their ends,
    # shake at the smallest and largest value a design coordinate in (0, 1) gives (the
    # log-normal's 2^-31 and 1 - 2^-31 quantiles, beyond the log-uniform's ends).
    u = np.array([2.0**-31, 1.0 - 2.0**-31])
    shake = scan.LogNormal(SHAKE_MEDIAN, SHAKE_SIGMA).from_uniform(u)
    grid = np.meshgrid(LUX, shake, STABILIZATION, REFLECTANCE, indexing="ij")
    lux, omega, k, reflectance = (g.reshape(-1) for g in grid)
    r = evaluate(lux, shake_deg_per_s=omega, stabilization=k, reflectance=reflectance,
                 **POWER_LAW)
    assert np.all(r.status == 0)
    constant = r.epc * omega**2 / (lux * reflectance * k) ** 2
    # 1e-9: six decades above the 2e-12 measured (tan, sinc and diffraction as the module
    # docstring bounds them), six below any index's interval.
    np.testing.assert_allclose(constant, constant[0], rtol=1e-9)


def test_log_epc_indices_cover_the_closed_form_shares_of_an_additive_model():
    result = scan.sobol_indices(additive_space(), points=2**13, seed=1, of="log_epc")
    assert result.parameters == ("illuminance_lux", "shake_deg_per_s", "stabilization",
                                 "reflectance", "full_well_e")
    shares = additive_shares()
    np.testing.assert_allclose(shares, [0.4898, 0.2772, 0.0999, 0.1332, 0.0], atol=5e-5)
    # Coverage is measured, not hoped for: over seeds 0..19 the worst |estimate - exact| was
    # 0.056 of the interval's half-width (Sobol' points integrate an additive model far better
    # than the bootstrap, which assumes independent points, allows for). 0.03: the widest
    # half-width measured was 0.022.
    assert_covered(result.s1[0, 0], result.s1_conf[0, 0], shares, widest=0.03)
    assert_covered(result.st[0, 0], result.st_conf[0, 0], shares, widest=0.03)


def test_epc_indices_cover_the_closed_form_of_a_product_of_independent_powers():
    result = scan.sobol_indices(product_space(), points=2**13, seed=1, of="epc")
    s1, st, _ = product_indices(*product_factor_moments())
    np.testing.assert_allclose(s1, [0.3356, 0.1421, 0.0896, 0.0], atol=5e-5)
    np.testing.assert_allclose(st, [0.7172, 0.4540, 0.3306, 0.0], atol=5e-5)
    # The closed form's terms add up to 1: first, second and the third order of L, omega, k.
    _, _, s2 = product_indices(*product_factor_moments())
    s123 = st[0] - s1[0] - s2[0, 1] - s2[0, 2]
    assert s1.sum() + np.nansum(s2) + s123 == pytest.approx(1.0, abs=1e-12)
    # Over seeds 0..19 the worst |estimate - exact| was 0.66 of the half-width, the widest
    # half-width 0.075: 0.1 leaves room for another seed, and is still far narrower than the
    # gaps between the parameters' indices the test tells apart.
    assert_covered(result.s1[0, 0], result.s1_conf[0, 0], s1, widest=0.1)
    assert_covered(result.st[0, 0], result.st_conf[0, 0], st, widest=0.1)
    assert np.all(st[:3] > s1[:3] + 0.2)  # the interactions the product makes are there


def test_second_order_indices_cover_the_closed_form_of_the_product():
    result = scan.sobol_indices(product_space(), points=2**13, seed=1, second_order=True)
    _, _, s2 = product_indices(*product_factor_moments())
    assert result.evaluations == 2**13 * (2 * 4 + 2)
    upper = np.triu_indices(4, 1)
    assert s2[0, 1] == pytest.approx(0.1917, abs=5e-5)
    # Over seeds 0..19 the worst |estimate - exact| was 0.54 of the half-width and the widest
    # half-width 0.104: the second-order estimator is the noisiest, hence the wider bound.
    assert_covered(result.s2[0, 0][upper], result.s2_conf[0, 0][upper], s2[upper], widest=0.2)
    assert np.isnan(result.s2[0, 0][np.tril_indices(4)]).all()


def test_a_parameter_the_model_ignores_has_indices_of_exactly_zero():
    result = scan.sobol_indices(additive_space(), points=2**6, seed=3, of=("epc", "log_epc"))
    # The full well is never reached: a point and its copy with only the full well changed
    # give the same EPC bit for bit, so both estimators' sums are sums of zeros.
    column = result.parameters.index("full_well_e")
    for values in (result.s1, result.st, result.s1_conf, result.st_conf):
        assert np.all(values[:, 0, column] == 0.0)
    assert np.all(result.st[:, 0, :column] > 0.05)


def test_unreachable_points_counted_as_zero_pixels_follow_the_closed_form():
    # A full well uniform on [500, 2000] e-: a third of the points cannot hold the 1000
    # electrons of 30 dB. Counted as 0 pixels, EPC is the product times a factor that is 1 with
    # probability 2/3 and 0 otherwise.
    space = product_space(full_well=(500.0, 2000.0))
    result = scan.sobol_indices(space, points=2**13, seed=1, not_ok="zero")
    parameters = indices_module.random_parameters(space)
    inputs = indices_module.design_inputs(space, parameters, indices_module.unit_design(
        parameters, 2**13, 1))
    assert result.unreachable[0] == np.count_nonzero(inputs["full_well_e"] < 1000.0)
    assert result.unreachable[0] / result.evaluations == pytest.approx(1 / 3, abs=0.01)
    s1, st, _ = product_indices(*product_factor_moments(p_reachable=2 / 3))
    # Over seeds 0..19 the worst |estimate - exact| was 0.71 of the half-width, the widest
    # half-width 0.078.
    assert_covered(result.s1[0, 0], result.s1_conf[0, 0], s1, widest=0.1)
    assert_covered(result.st[0, 0], result.st_conf[0, 0], st, widest=0.1)
    table = result.table()
    assert set(table["unreachable points"]) == {int(result.unreachable[0])}


def test_unreachable_points_raise_by_default_naming_their_count_cause_and_the_policy():
    with pytest.raises(ValueError, match=r"of 98,304 points cannot meet the SNR target \(full "
                                         r"well\).*not_ok='zero'"):
        scan.sobol_indices(product_space(full_well=(500.0, 2000.0)), points=2**14)


def test_the_log_of_an_unbounded_blur_raises_and_epc_counts_it():
    # The paper's 1.4 um design at 1 to 10 lux with 20 to 80 deg/s: some exposures turn the
    # camera past 90 degrees.
    space = scan.Space(design=[paper_design()], illuminance_lux=scan.LogUniform(1, 10),
                       shake_deg_per_s=scan.LogUniform(20, 80))
    with pytest.raises(ValueError, match=r"points have EPC = 0 \(the blur is unbounded"):
        scan.sobol_indices(space, points=2**6, of="log_epc")
    result = scan.sobol_indices(space, points=2**6)
    assert result.blur_unbounded[0] > 0 and result.unreachable[0] == 0
    assert "blur unbounded points" in result.table()


def test_a_draw_outside_a_parameters_domain_names_the_parameter_and_value():
    space = scan.Space(illuminance_lux=scan.LogUniform(100, 1000),
                       shake_deg_per_s=scan.Normal(1.0, 1.0), **POWER_LAW)
    with pytest.raises(ValueError, match=r"shake_deg_per_s=-[0-9.e-]+ is outside its domain "
                                         r"\[0, 1e\+30\).*truncate its distribution"):
        scan.sobol_indices(space, points=2**6)


def test_the_same_seed_gives_the_same_indices_and_another_seed_others():
    first = scan.sobol_indices(product_space(), points=2**8, seed=5, threads=1)
    again = scan.sobol_indices(product_space(), points=2**8, seed=5, threads=2)
    other = scan.sobol_indices(product_space(), points=2**8, seed=6)
    for name in ("s1", "s1_conf", "st", "st_conf", "mean", "std"):
        np.testing.assert_array_equal(getattr(first, name), getattr(again, name))
    assert not np.array_equal(first.s1, other.s1)
    assert not np.array_equal(first.s1_conf, other.s1_conf)


def test_each_design_gets_the_indices_of_a_space_holding_that_design_alone():
    designs = [paper_design(), paper_design().stabilized()]
    axes = dict(illuminance_lux=scan.LogUniform(10, 1e5),
                shake_deg_per_s=scan.LogNormal(SHAKE_MEDIAN, SHAKE_SIGMA))
    both = scan.sobol_indices(scan.Space(design=designs, **axes), points=2**8, seed=2,
                              of=("epc", "log_epc"))
    assert both.designs == ('1/3.2" 1.4 um', '1/3.2" 1.4 um 4x IS')
    for d, design in enumerate(designs):
        alone = scan.sobol_indices(scan.Space(design=[design], **axes), points=2**8, seed=2,
                                   of=("epc", "log_epc"))
        np.testing.assert_array_equal(both.st[:, d], alone.st[:, 0])
        np.testing.assert_array_equal(both.mean[:, d], alone.mean[:, 0])
    assert not np.array_equal(both.st[:, 0], both.st[:, 1])


@pytest.mark.parametrize("axis, mean, std", [
    (scan.Uniform(2.0, 5.0), 3.5, 3.0 / math.sqrt(12)),
    (scan.LogUniform(1.0, math.e**2), (math.e**2 - 1) / 2,
     math.sqrt((math.e**4 - 1) / 4 - ((math.e**2 - 1) / 2) ** 2)),
    (scan.Normal(3.0, 0.5), 3.0, 0.5),
    (scan.LogNormal(2.0, 0.3), 2.0 * math.exp(0.045),
     2.0 * math.exp(0.045) * math.sqrt(math.exp(0.09) - 1)),
    (scan.Truncated(scan.Normal(0.0, 1.0), 0.0, math.inf), math.sqrt(2 / math.pi),
     math.sqrt(1 - 2 / math.pi)),
    (scan.Empirical([1.0, 2.0, 2.0, 5.0]), 2.5, math.sqrt(2.25)),
    (scan.Choice([1.0, 3.0], weights=[1, 3]), 2.5, math.sqrt(0.75)),
    (scan.Grid([1.0, 2.0, 3.0, 4.0]), 2.5, math.sqrt(1.25)),
], ids=["uniform", "log_uniform", "normal", "lognormal", "truncated", "empirical", "choice",
        "grid"])
def test_the_design_draws_every_kind_of_parameter_from_its_distribution(axis, mean, std):
    space = scan.Space(illuminance_lux=scan.LogUniform(100, 1000), read_noise_e=axis, **POWER_LAW)
    parameters = indices_module.random_parameters(space)
    unit = indices_module.unit_design(parameters, 2**12, 4)
    assert unit.min() > 0.0 and unit.max() < 1.0
    values = indices_module.design_inputs(space, parameters, unit)["read_noise_e"]
    # The first 2^12 rows are Saltelli's matrix A, a scrambled Sobol' net: its moments are
    # within 1e-3 of the distribution's (Monte Carlo on 4096 points would give ~1.6e-2).
    a = values[::len(parameters) + 2]
    assert a.mean() == pytest.approx(mean, abs=1e-3 * std)
    assert a.std() == pytest.approx(std, rel=1e-2)


@pytest.mark.parametrize("arguments, message", [
    ({"points": 1000}, r"points must be a power of 2, at least 16 .*got 1000"),
    ({"points": 8}, r"points must be a power of 2.*got 8"),
    ({"points": 1024.0}, r"points must be a power of 2.*got 1024.0"),
    ({"seed": -1}, r"seed must be an integer in \[0, 2\*\*64\), got -1"),
    ({"seed": "1"}, r"seed must be an integer .*got '1'"),
    ({"of": "lux"}, r"of must be one of 'epc', 'log_epc' or a sequence of them, got 'lux'"),
    ({"of": ("epc", "epc")}, r"of must be .*got \('epc', 'epc'\)"),
    ({"confidence": 1.0}, r"confidence must be a number in \(0, 1\), got 1.0"),
    ({"confidence": 95}, r"confidence must be a number in \(0, 1\), got 95"),
    ({"resamples": 1}, r"resamples must be an integer >= 2, got 1"),
    ({"points": 2**16, "resamples": 1000}, r"points x resamples = 65,536 x 1,000 exceeds"),
    ({"not_ok": "drop"}, r"not_ok must be one of 'raise', 'zero', got 'drop'"),
    ({"not_ok": "zero", "of": "log_epc"}, r"not_ok='zero' .* cannot go with of='log_epc'"),
    ({"points": 2**22, "resamples": 2}, r"points=4,194,304 with 4 random parameters makes a "
                                        r"design of 100,663,296 values"),
])
def test_a_bad_argument_is_named_with_its_value(arguments, message):
    with pytest.raises(ValueError, match=message):
        scan.sobol_indices(product_space(), **arguments)


def test_a_space_without_random_parameters_is_refused():
    space = scan.Space(design=[paper_design()], illuminance_lux=100.0)
    with pytest.raises(ValueError, match="the space has no random parameter"):
        scan.sobol_indices(space)
    with pytest.raises(TypeError, match="space must be an epc_fast.scan.Space, got 3"):
        scan.sobol_indices(3)


def test_the_table_has_one_row_per_output_design_and_parameter():
    result = scan.sobol_indices(scan.Space(design=[paper_design()],
                                           illuminance_lux=scan.LogUniform(10, 1e5),
                                           shake_deg_per_s=scan.LogNormal(4.39, 0.5)),
                                points=2**6, seed=1, of=("epc", "log_epc"), confidence=0.9)
    table = result.table()
    assert list(table) == ["of", "design", "parameter", "S1", "S1 +-90%", "ST", "ST +-90%"]
    assert table["of"] == ["epc", "epc", "log_epc", "log_epc"]
    assert table["parameter"] == ["illuminance_lux", "shake_deg_per_s"] * 2
    assert table["ST"][3] == result.index("ST", "shake_deg_per_s", of="log_epc")
    assert result.markdown().splitlines()[0] == "| " + " | ".join(table) + " |"
    with pytest.raises(ValueError, match="of must be one of 'epc', 'log_epc'; got None"):
        result.index("S1", "illuminance_lux")
    without_designs = scan.sobol_indices(additive_space(), points=2**6)
    assert "design" not in without_designs.table()


def test_sobol_indices_without_salib_name_the_extra(monkeypatch):
    monkeypatch.setitem(sys.modules, "SALib", None)
    monkeypatch.setitem(sys.modules, "SALib.sample", None)
    monkeypatch.setitem(sys.modules, "SALib.analyze", None)
    with pytest.raises(ImportError, match=r"pip install 'epc-fast\[sensitivity\]'"):
        scan.sobol_indices(product_space(), points=2**6)


def test_importing_the_scan_package_does_not_import_salib():
    code = ("import sys, epc_fast.scan, epc_fast.scan.indices, epc_fast.scan.config, "
            "epc_fast.commands.sobol; "
            "sys.exit(1 if any(m.split('.')[0] == 'SALib' for m in sys.modules) else 0)")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=60)
    assert done.returncode == 0, done.stdout + done.stderr


def test_a_bursts_alignment_error_has_indices_of_its_own():
    space = scan.Space(design=[paper_design().with_(frames=4)],
                       illuminance_lux=scan.LogUniform(10, 1e5),
                       alignment_error_um=scan.Uniform(0.0, 3.0))
    result = scan.sobol_indices(space, points=2**8, seed=2, of="log_epc")
    column = result.parameters.index("alignment_error_um")
    assert result.st[0, 0, column] > 0.01, result.st[0, 0]


def test_a_design_with_one_readout_mode_is_that_readout():
    axes = dict(illuminance_lux=scan.LogUniform(10, 1e5),
                shake_deg_per_s=scan.LogNormal(SHAKE_MEDIAN, SHAKE_SIGMA))
    binned = paper_design().with_(read_noise_e=2.0, binning=2, binning_readout="charge")
    moded = paper_design().with_(read_noise_e=2.0, modes=(
        {"binning": 2, "binning_readout": "charge"},))
    one, other = (scan.sobol_indices(scan.Space(design=[d], **axes), points=2**6, seed=2,
                                     of="log_epc") for d in (binned, moded))
    np.testing.assert_array_equal(one.st, other.st)
    np.testing.assert_array_equal(one.mean, other.mean)
    plain = scan.sobol_indices(scan.Space(design=[paper_design().with_(read_noise_e=2.0)],
                                          **axes), points=2**6, seed=2, of="log_epc")
    assert not np.array_equal(plain.mean, one.mean)


def test_a_frame_the_camera_cannot_take_is_no_image_raised_or_counted_as_zero():
    # The paper's 1.4 um design over 1 to 1000 lux with a 1/10 s frame cap: the dim draws need
    # a longer frame (EXPOSURE_LIMIT, EPC NaN), named as the frame cap, or 0 pixels.
    capped = scan.Space(design=[paper_design()], illuminance_lux=scan.LogUniform(1, 1000),
                        shake_deg_per_s=scan.LogUniform(2, 8),
                        evaluate_options={"max_exposure_s": 0.1})
    with pytest.raises(ValueError, match=r"points cannot meet the SNR target \(the frame "
                                         r"cap\).*not_ok='zero'"):
        scan.sobol_indices(capped, points=2**6)
    result = scan.sobol_indices(capped, points=2**6, not_ok="zero")
    parameters = indices_module.random_parameters(capped)
    inputs = indices_module.design_inputs(capped, parameters, indices_module.unit_design(
        parameters, 2**6, result.seed))
    status = evaluate(**{**paper_design().evaluate_kwargs(), **inputs},
                      max_exposure_s=0.1).status
    assert result.unreachable[0] == np.count_nonzero(status == Status.EXPOSURE_LIMIT) > 0
