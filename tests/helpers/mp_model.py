"""One independent model of the contract (docs/model.md) in mpmath, for every test that needs
the exact answer: MP_DPS digits, from the float64 inputs taken exactly (floats or mpf values).

:func:`mp_model` gives every output of the model's sections Exposure to EPC with the per-point
status and its cause, for a monochromatic design or a spectrum, a lens table, a Bayer sensor
and its demosaicker, and the MTF's factors at f50; :func:`expected_status` is the (Status,
Cause) the engine owes a point, with its documented conventions; :func:`relative_error`
measures a float against the model. :func:`mp_diffraction` and :func:`mp_t_mpe`
(:func:`mp_signal_electrons`) are two of its formulas alone, at the caller's working precision;
the wavefront error's ATF, denoising and the monotone table interpolant are in
helpers/mp_optics.py.

The model leans on the package for nothing but the codes of Status and Cause: the defaults are
restated below, every formula is written from docs/model.md, and the demosaickers' table is read
from the shipped CSV (python/epc_fast/data/demosaic_mtf.csv), the data docs/model.md names.
"""

import functools
import math
import sys

import mpmath as mp

from epc_fast import Cause, Status
from helpers.mp_optics import (demosaic_table, mp_atf, mp_denoise_kernel, mp_mtf_denoise,
                               mp_noise_gain_denoise, mp_table_end, mp_table_interpolant)

MP_DPS = 50

#: docs/model.md's defaults, restated here so that the model does not lean on the package.
MODEL_DEFAULTS = dict(reflectance=0.4, lens_transmittance=1.0, field_angle_deg=0.0,
                      fill_factor=1.0, read_noise_e=0.0, dark_current_e_per_s=0.0, prnu=0.0,
                      full_well_e=math.inf, snr_db=30.0, shake_deg_per_s=4.39, stabilization=1.0,
                      jitter_um=0.0, wavelength_nm=550.0, mtf_threshold=0.5, binning=1.0,
                      frames=1.0, alignment_error_um=0.0, cfa_transmittance=1.0,
                      color_noise_gain=1.0, wavefront_rms_waves=0.0, denoise_sigma_px=0.0)

#: A Bayer sensor's (cfa="bayer") defaults of t and g_c, and each demosaicker's noise gain g_d
#: (docs/model.md, "The colour filter array").
BAYER_DEFAULTS = dict(cfa_transmittance=0.8433, color_noise_gain=0.9146)
DEMOSAIC_NOISE_GAIN = {"bilinear": 0.617, "malvar2004": 0.836, "menon2007": 1.001}

#: The smallest normal double and the largest double (the engine's conventions at its ends).
SMALLEST_NORMAL = sys.float_info.min
LARGEST = sys.float_info.max


def mp_diffraction(nu):
    """The diffraction MTF D(nu) of a circular pupil at nu = f lambda F, at the working
    precision: (2/pi) (acos nu - nu sqrt(1 - nu^2)) below the cut-off nu = 1, 0 from it on."""
    nu = mp.mpf(nu)
    return 2 / mp.pi * (mp.acos(nu) - nu * mp.sqrt(1 - nu * nu)) if nu < 1 else mp.mpf(0)


def mp_t_mpe(rate, snr_db, read_noise_e, dark_current_e_per_s, prnu):
    """T_MPE, the positive root (b + sqrt(b^2 + 4ac)) / 2a of a T^2 - b T - c = 0 (docs/model.md,
    Exposure), at the working precision, for inputs taken exactly."""
    r, snr_db, read, dark, u = (mp.mpf(v) for v in (rate, snr_db, read_noise_e,
                                                      dark_current_e_per_s, prnu))
    s = mp.mpf(10) ** (snr_db / 10)
    a = r * r * (1 - s * u * u)
    b = s * (r + dark)
    c = s * read * read
    return (b + mp.sqrt(b * b + 4 * a * c)) / (2 * a)


def mp_signal_electrons(rate, snr_db, read_noise_e, dark_current_e_per_s, prnu):
    """The photo-electrons r T_MPE needed at the target, at the working precision."""
    return mp.mpf(rate) * mp_t_mpe(rate, snr_db, read_noise_e, dark_current_e_per_s, prnu)


def mp_model(inputs, spectrum=None, lens_mtf=None, demosaic=None):
    """docs/model.md from Exposure to EPC at MP_DPS digits, from `inputs` (evaluate's keywords:
    floats, or mpf values such as a central difference's steps) taken exactly; `spectrum` is
    (wavelengths_nm, weights) or None for inputs["wavelength_nm"]. ``inputs["binning_readout"]``
    ("digital" or "charge") is binning's read-out, digital when not given. `lens_mtf` is the
    point's lens table (frequencies_cyc_per_mm, mtf), which replaces diffraction, or None;
    `demosaic` the demosaicker of a Bayer sensor (cfa="bayer", with its defaults of t and g_c
    where inputs do not give them) or None for cfa="none".

    Returns a dict with "status" ("ok", "unreachable", "blur_unbounded", "beyond_table"),
    "cause" for unreachable points ("no_light", "prnu", "full_well"), and the mpf outputs as
    far as the status defines them: "electron_rate_e_per_s", "electrons", "t_mpe_s", then
    "blur_mm", and for OK points "f50_cyc_per_mm", "epc" and "mtf_factors" (diffraction with
    the wavefront error's ATF, or the lens table; the binned pixel aperture, motion, jitter,
    alignment, denoising and the demosaicker at f50). Cached: the backends of a parametrised
    test share one evaluation.
    """
    inputs = dict(inputs)
    charge = inputs.pop("binning_readout", "digital") in ("charge", 1.0)  # its name or code
    if demosaic is not None:
        inputs = {**BAYER_DEFAULTS, **inputs}
    items = tuple(sorted((name, value if isinstance(value, mp.mpf) else float(value))
                         for name, value in inputs.items()))
    lines = None if spectrum is None else (tuple(spectrum[0]), tuple(spectrum[1]))
    table = None if lens_mtf is None else (tuple(map(float, lens_mtf[0])),
                                           tuple(map(float, lens_mtf[1])))
    return _mp_model(items, lines, charge, table, demosaic)


@functools.lru_cache(maxsize=4096)
def _mp_model(items, spectrum, charge, lens_mtf=None, demosaic=None):
    with mp.workdps(MP_DPS):
        v = {**MODEL_DEFAULTS, **dict(items)}
        x = {name: mp.mpf(value) for name, value in v.items() if name != "full_well_e"}
        pi = mp.pi

        # Exposure of one output pixel (k x k pixels) over the burst of n frames: the electron
        # rate, the statuses that need no T_MPE, then T_MPE.
        k, n = x["binning"], x["frames"]
        cos = mp.cos(x["field_angle_deg"] * pi / 180)
        rate = (x["illuminance_lux"] * x["reflectance"] * x["lens_transmittance"] * cos**4
                / (4 * x["f_number"] ** 2) * x["electrons_per_lux_s_m2"] * x["fill_factor"]
                * (x["pixel_pitch_um"] / 10**6) ** 2) * x["cfa_transmittance"] * k**2
        out = {"electron_rate_e_per_s": rate}
        # a colour sensor's noise gains g_c g_d and denoising's g multiply every variance: the
        # target s g_c g_d g
        sigma_d = x["denoise_sigma_px"]
        gain = (x["color_noise_gain"] * mp_noise_gain_denoise(sigma_d)
                * (DEMOSAIC_NOISE_GAIN[demosaic] if demosaic else 1))
        snr_db = x["snr_db"] + 10 * mp.log10(gain)
        s, u = mp.mpf(10) ** (snr_db / 10), x["prnu"] / k
        if rate == 0:
            return dict(out, status="unreachable", cause="no_light")
        if u * mp.sqrt(s) >= 1:
            return dict(out, status="unreachable", cause="prnu")
        read = x["read_noise_e"] * mp.sqrt(n * (1 if charge else k**2))
        t = mp_t_mpe(rate, snr_db, read, x["dark_current_e_per_s"] * k**2, u)
        out.update(t_mpe_s=t, electrons=rate * t)
        if rate * t / n > v["full_well_e"] * k**2:  # the full well of each frame
            return dict(out, status="unreachable", cause="full_well")

        # Blur during each frame, T/n: the tangent, unbounded from a quarter turn on.
        angle = x["shake_deg_per_s"] * pi / 180 / x["stabilization"] * t / n
        if angle >= pi / 2:
            return dict(out, status="blur_unbounded")
        blur = x["focal_length_mm"] * mp.tan(angle)
        out["blur_mm"] = blur

        # System MTF: lambda F in mm per wavelength, with its weight (normalised to sum 1).
        if spectrum is None:
            lines = [(x["wavelength_nm"] / 10**6 * x["f_number"], mp.mpf(1))]
        else:
            total = sum(mp.mpf(w) for w in spectrum[1])
            lines = [(mp.mpf(lam) / 10**6 * x["f_number"], mp.mpf(w) / total)
                     for lam, w in zip(*spectrum)]
        pitch = x["pixel_pitch_um"] / 1000
        aperture = mp.sqrt(x["fill_factor"]) * pitch
        sigma = x["jitter_um"] / 1000
        residual = x["alignment_error_um"] / 1000 * mp.sqrt(1 - 1 / n)
        w = x["wavefront_rms_waves"]
        p_out = k * pitch  # the output pixel, mm
        kernel = mp_denoise_kernel(sigma_d)
        lens = None if lens_mtf is None else mp_table_interpolant(*lens_mtf)
        dem = None if demosaic is None else mp_table_interpolant(*demosaic_table(demosaic))

        def optics(f):  # D(f) = sum_i w_i D_i ATF_i, or the lens table's L(f)
            if lens is not None:
                return lens(f)
            return sum(wt * mp_diffraction(f * lam_f) * mp_atf(f * lam_f, w)
                       for lam_f, wt in lines)

        def binned(f):  # sin(k pi p f) / (k sin(pi p f)), +-1 where sin(pi p f) = 0; 1 at k = 1
            if k == 1:
                return mp.mpf(1)
            one = mp.sinpi(pitch * f)
            if one == 0:
                return mp.cospi(k * pitch * f) / mp.cospi(pitch * f)
            return mp.sinpi(k * pitch * f) / (k * one)

        def factors(f):
            return (optics(f), abs(mp.sincpi(aperture * f) * binned(f)), abs(mp.sincpi(blur * f)),
                    mp.exp(-2 * pi**2 * (sigma * f) ** 2), mp.exp(-2 * pi**2 * (residual * f) ** 2),
                    mp_mtf_denoise(f * p_out, kernel), 1 if dem is None else dem(f * p_out))

        # the binned pixel's first zero: 1 / (k p) for k >= 2
        pixel_zero = 1 / (k * pitch) if k > 1 else 1 / aperture
        gaussian = mp.sqrt(sigma**2 + residual**2)
        # the optics' first zero: diffraction's at the shortest wavelength, or the table's end
        optics_zero = (1 / min(lam_f for lam_f, wt in lines if wt > 0) if lens is None
                       else mp_table_end(*lens_mtf))
        f50 = _mp_f50(factors, x["mtf_threshold"], optics_zero, pixel_zero, blur, gaussian,
                      table=lens is not None)
        if f50 is None:
            return dict(out, status="beyond_table")

        # EPC.
        if "pixel_count" in x:
            area = x["pixel_count"] * (x["pixel_pitch_um"] / 1000) ** 2
        else:
            area = x["sensor_area_mm2"]
        return dict(out, status="ok", blur_mm=blur, f50_cyc_per_mm=f50, epc=4 * area * f50**2,
                    mtf_factors=factors(f50))


def _mp_f50(factors, threshold, optics_zero, pixel_zero, blur, sigma, table=False):
    """The first f with MTF_sys(f) = c, bracketed as docs/model.md says (f_hi the smallest
    first zero of the factors, a lens table's end, or the Gaussians' (jitter and alignment) own
    crossing); None where f_hi is a lens table's end (`table`) and MTF_sys is still above c
    there (BEYOND_TABLE)."""
    pi = mp.pi

    def excess(f):
        return mp.fprod(factors(f)) - threshold

    zeros = [optics_zero, pixel_zero]
    if blur > 0:
        zeros.append(1 / blur)
    if sigma > 0:
        zeros.append(mp.sqrt(mp.log(1 / threshold) / (2 * pi**2)) / sigma)
    lo, hi = min(zeros) / 2, min(zeros)
    if table and hi == optics_zero and excess(hi) > 0:
        return None
    while excess(lo) <= 0:
        lo /= 2
    for _ in range(8):  # narrow the bracket before the secant-type solver
        mid = (lo + hi) / 2
        lo, hi = (mid, hi) if excess(mid) > 0 else (lo, mid)
    try:
        root = mp.findroot(excess, (lo, hi), solver="anderson")
        if lo <= root <= hi and abs(excess(root)) <= threshold * mp.mpf(10) ** (15 - MP_DPS):
            return root
    except (ValueError, ZeroDivisionError):
        pass
    for _ in range(4 * MP_DPS):  # the slow, sure way
        mid = (lo + hi) / 2
        lo, hi = (mid, hi) if excess(mid) > 0 else (lo, mid)
    return (lo + hi) / 2


def expected_status(model):
    """The (Status, Cause) the engine owes a point: mpmath's exact status with the engine's
    documented conventions, a rate below the smallest normal double or a T_MPE beyond the
    largest is no light (docs/numerics.md)."""
    if (model["electron_rate_e_per_s"] < SMALLEST_NORMAL
            or model.get("t_mpe_s", 0) > LARGEST):
        return Status.UNREACHABLE, Cause.NO_LIGHT
    status = {"ok": Status.OK, "unreachable": Status.UNREACHABLE,
              "blur_unbounded": Status.BLUR_UNBOUNDED,
              "beyond_table": Status.BEYOND_TABLE}[model["status"]]
    cause = {"no_light": Cause.NO_LIGHT, "prnu": Cause.PRNU,
             "full_well": Cause.FULL_WELL}.get(model.get("cause"), Cause.NONE)
    return status, cause


def relative_error(value, exact):
    """|value / exact - 1| as a float, formed at MP_DPS digits; 0 for 0 against an exact 0, inf
    for anything else against it."""
    if exact == 0:
        return 0.0 if value == 0 else math.inf
    with mp.workdps(MP_DPS):
        return float(abs(mp.mpf(value) / exact - 1))


#: The outputs the model gives, as evaluate's Result names them.
OUTPUTS = ("electron_rate_e_per_s", "electrons", "t_mpe_s", "blur_mm", "f50_cyc_per_mm", "epc")


def assert_matches_model(result, model, rtol, label=""):
    """A one-point Result of epc_fast.evaluate against :func:`mp_model`'s dict: the status and
    cause :func:`expected_status` owes it, every output the model defines within `rtol`
    (relative), and NaN f50 and EPC where the model's status leaves them undefined."""
    status, cause = expected_status(model)
    assert (int(result.status), int(result.cause)) == (status, cause), label
    for name in OUTPUTS:
        value = float(getattr(result, name))
        if name not in model:
            if name in ("f50_cyc_per_mm", "epc") and model["status"] == "beyond_table":
                assert math.isnan(value), (label, name, value)
            continue
        error = relative_error(value, model[name])
        assert error <= rtol, f"{label}: {name} {value!r} off the model by {error:.3g} (> {rtol})"


K = 2557705539053827.5  # e-/(lux s m^2): the golden set's K, passed explicitly
CORNER_DEG = 27.02970193087426  # half diagonal of the 1/3.2" format at f = 5.6 mm

#: name -> (evaluate inputs, spectrum or None). Each exercises terms the golden set keeps apart.
OWN_CASES = {
    "read_dark_prnu_combined": (dict(
        illuminance_lux=300.0, pixel_pitch_um=1.75, f_number=2.8, focal_length_mm=5.6,
        sensor_area_mm2=15.6751, field_angle_deg=20.0, electrons_per_lux_s_m2=K,
        read_noise_e=5.0, dark_current_e_per_s=200.0, prnu=0.02), None),
    "fill_factor_0_3_with_jitter_and_motion": (dict(
        illuminance_lux=2000.0, pixel_pitch_um=1.4, f_number=2.8, focal_length_mm=5.6,
        pixel_count=7680000.0, fill_factor=0.3, jitter_um=0.8, field_angle_deg=CORNER_DEG,
        electrons_per_lux_s_m2=K), None),
    "f_16_diffraction_dominated": (dict(
        illuminance_lux=100000.0, pixel_pitch_um=2.2, f_number=16.0, focal_length_mm=20.0,
        sensor_area_mm2=15.6751, electrons_per_lux_s_m2=K), None),
    "mtf_threshold_0_1": (dict(
        illuminance_lux=5000.0, pixel_pitch_um=1.75, f_number=2.8, focal_length_mm=5.6,
        sensor_area_mm2=15.6751, field_angle_deg=CORNER_DEG, mtf_threshold=0.1,
        electrons_per_lux_s_m2=K), None),
    "stabilization_4_at_33_db": (dict(
        illuminance_lux=50.0, pixel_pitch_um=1.4, f_number=2.8, focal_length_mm=5.6,
        sensor_area_mm2=15.6751, stabilization=4.0, snr_db=33.0,
        electrons_per_lux_s_m2=K), None),
    "polychromatic_unequal_weights_dim_lens": (dict(
        illuminance_lux=800.0, pixel_pitch_um=1.75, f_number=4.9, focal_length_mm=16.8,
        sensor_area_mm2=15.6751, reflectance=0.18, lens_transmittance=0.9,
        field_angle_deg=9.651360532708715, electrons_per_lux_s_m2=K),
        ([450.0, 530.0, 610.0], [1.0, 3.0, 2.0])),
}
