"""Whether the C++ core and the NumPy reference agree on a set of points: statuses exactly,
float outputs to RTOL scaled point by point by the condition numbers that amplify a rounding
(the PRNU cap's in T_MPE, the tangent's near a quarter turn in the blur and f50).
"""

import numpy as np

import epc_fast
from epc_fast import Status

# Relative agreement asked of the two backends on well-conditioned points. Each backend rounds
# its own way (libm vs NumPy's SIMD cos/tan/pow/acos, (cos^2)^2 vs cos**4, a bisection to
# 1e-14 vs to adjacent floats), which moves results by ~1e-14 at most; 1e-12 leaves 100x room
# and still catches any formula slip (those show up at 1e-8 or worse).
RTOL = 1e-12

FLOAT_FIELDS = ("electron_rate_e_per_s", "electrons", "t_mpe_s", "blur_mm", "f50_cyc_per_mm",
                "epc")


def prnu_condition(p):
    """T_MPE's condition number from the PRNU term: 1/(1 - s u^2), s = 10^(snr_db/10).

    The quadratic's leading coefficient r^2 (1 - s u^2) loses its digits as u sqrt(s) -> 1, and a
    relative rounding of u or s moves T_MPE by that factor. 1 where PRNU is off or capped. A
    binned pixel's PRNU is u / k.
    """
    with np.errstate(all="ignore"):
        su2 = (p["prnu"] / p.get("binning", 1.0)) ** 2 * 10.0 ** (p["snr_db"] / 10.0)
        kappa = 1.0 / (1.0 - su2)
    return np.where(np.isfinite(kappa) & (kappa > 1.0), kappa, 1.0)


def tan_condition(p, t_mpe_s):
    """The blur's condition number in the shake angle x: d ln tan(x) / d ln x = 2x / sin(2x).

    1 at small angles, it grows as 1/(pi/2 - x) near pi/2. f50 moves at most as fast as the
    blur (|d ln f50 / d ln b| <= 1: f50 scales as 1/b when motion dominates), so this times
    prnu_condition bounds how much a relative rounding of T_MPE is amplified into f50. A frame
    of a burst of n is exposed for T_MPE / n.
    """
    with np.errstate(all="ignore"):
        x = (np.deg2rad(p["shake_deg_per_s"]) / (p["stabilization"] * p.get("frames", 1.0))
             * t_mpe_s)
        kappa = 2.0 * x / np.sin(2.0 * x)
    return np.where(np.isfinite(kappa) & (kappa > 1.0), kappa, 1.0)


def relative_errors(a, b):
    with np.errstate(all="ignore"):
        err = np.abs(a - b) / np.abs(b)
    return np.where(a == b, 0.0, err)  # equal infinities and exact zeros agree exactly


def evaluate_both(p, **kwargs):
    """(core, reference): epc_fast.evaluate of the points ``p`` on each backend."""
    core = epc_fast.evaluate(**p, backend="core", **kwargs)
    ref = epc_fast.evaluate(**p, backend="reference", **kwargs)
    return core, ref


def assert_backends_agree(p, core, ref, label, extra_kappa=1.0):
    """The core's outputs equal the reference's: statuses exactly, finite values to scaled RTOL.

    Rule: electrons and T_MPE within RTOL * prnu_condition; blur, f50 and EPC within
    RTOL * prnu_condition * tan_condition; everything further times ``extra_kappa`` (a
    condition number the caller knows of, 1 by default).
    """
    np.testing.assert_array_equal(core.status, ref.status)
    np.testing.assert_array_equal(core.cause, ref.cause)
    for name in FLOAT_FIELDS:
        a, b = getattr(core, name), getattr(ref, name)
        # NaN and infinity where the other backend has them: same statuses, same conventions.
        np.testing.assert_array_equal(np.isnan(a), np.isnan(b), err_msg=name)
        np.testing.assert_array_equal(np.isposinf(a), np.isposinf(b), err_msg=name)

    ok = ref.status == Status.OK
    kappa_t = prnu_condition(p) * extra_kappa
    kappa_f50 = kappa_t * tan_condition(p, ref.t_mpe_s)
    # The electron rate is a product of inputs and cos^4: no amplification beyond cos near 80
    # degrees (x tan x * 4 ~ 32, i.e. ~1e-14), inside RTOL.
    scaled_tolerances = {
        "electron_rate_e_per_s": np.ones_like(kappa_t) * extra_kappa,
        "electrons": kappa_t,
        "t_mpe_s": kappa_t,
        "blur_mm": kappa_f50,
        "f50_cyc_per_mm": kappa_f50,
        "epc": kappa_f50,
    }
    report = {}
    for name, kappa in scaled_tolerances.items():
        a, b = getattr(core, name), getattr(ref, name)
        finite = np.isfinite(b)
        err = relative_errors(a[finite], b[finite])
        tol = RTOL * kappa[finite]
        bad = np.flatnonzero(err > tol)
        assert bad.size == 0, (
            f"{label}: {name} differs at {bad.size} points, worst relative error "
            f"{err.max():.3g} (tolerance {tol[bad[0]]:.3g} at the first); "
            f"first point index {np.flatnonzero(finite)[bad[0]]}")
        report[name] = float(err.max(initial=0.0))
    kappa_ok = kappa_f50[ok]
    stats = {
        "ok": int(ok.sum()),
        "scaled": int(np.count_nonzero(kappa_ok > 1.0)),
        "scaled_2": int(np.count_nonzero(kappa_ok >= 2.0)),
        "scaled_10": int(np.count_nonzero(kappa_ok >= 10.0)),
        "max_kappa": float(kappa_ok.max(initial=1.0)),
        "max_error": report,
    }
    print(f"\n{label}: {stats['ok']} OK points; tolerance scaled on {stats['scaled']} "
          f"(kappa >= 2 on {stats['scaled_2']}, >= 10 on {stats['scaled_10']}, "
          f"max kappa {stats['max_kappa']:.3g}); max relative errors: "
          + ", ".join(f"{k} {v:.2e}" for k, v in report.items()))
    return stats
