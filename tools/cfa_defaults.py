"""Derives the colour filter array's default constants of epc_fast.cfa from a real camera's
spectral sensitivities, and prints them as the module writes them.

The camera: the Nikon D5100 of colour-science's ``MSDS_CAMERA_SENSITIVITIES["Nikon 5100
(NPL)"]`` (a Bayer DSLR's red, green and blue responsivities, silicon, filters and infrared
cut together, measured at the UK National Physical Laboratory: M. M. Darrodi, G. Finlayson,
T. Goodman and M. Mackiewicz, "Reference data set for camera spectral sensitivity estimation",
J. Opt. Soc. Am. A 32 (2015) 381-391; 380..780 nm in 5 nm steps, each channel scaled to a peak
of 1). The light: CIE D50 (``SDS_ILLUMINANTS["D50"]``), the illuminant behind the model's K.
The colour chart: the 24 patches of ``SDS_COLOURCHECKERS["ColorChecker N Ohta"]``, with the
CIE 1931 2 degree observer for their XYZ under D50.

1. Channel transmittances t_c: channel c's electrons over those of the monochrome sensor that
   K describes (epc_fast.spectra: quantum efficiency 0.7 on 480..580 nm only), under D50,
   computed by epc_fast.cfa.bayer_light. The responsivities are per unit radiant power (a
   camera's response to monochromator light of measured spectral radiance), so channel c's
   quantum efficiency has the shape S_c(lambda) / lambda; each channel's is scaled to the same
   peak, 0.7, as K's sensor's. The data carry silicon's response over the whole 380..780 nm,
   so the silicon response assumed outside 480..580 nm is the D5100's own. Linearly
   interpolated onto epc_fast.spectra's 1 nm grid, where K is the shipped
   DEFAULT_ELECTRONS_PER_LUX_S_M2 exactly. The cell's mean transmittance is
   t = (t_R + 2 t_G + t_B) / 4 (RGGB).
2. White balance divides channel c by t_c, so that a grey patch gives equal values.
3. The colour correction: the 3x3 matrix M from white-balanced camera RGB to XYZ (white's Y
   = 1) fitted to the chart by least squares with the white point held exactly (each row's
   sum fixed by a Lagrange multiplier). Its Y row gives the luminance weights y_c, sum 1.
   White balance removes each channel's scale, so the fit reads the responsivities as they are.
4. color_noise_gain for shot noise: a flat patch of S monochrome electrons gives channel c
   t_c S electrons, variance t_c S, luminance Y = sum_c y_c (value_c / t_c) of mean S and
   variance S sum_c y_c^2 / t_c. On the cell's scale (signal t S, the model's) the variance
   is g (t S) with g = t sum_c y_c^2 / t_c, which one factor on every t_c leaves as it is.
   Read noise of variance sigma^2 per pixel, independent of t_c, gives Y the variance
   sigma^2 sum_c y_c^2 / t_c^2, on the cell's scale g_read sigma^2 with
   g_read = t^2 sum_c y_c^2 / t_c^2. The model uses g for both; the script prints the
   ratio g_read / g, the error of that choice on the read-noise variance.

    python tools/cfa_defaults.py
"""

from __future__ import annotations

import numpy as np

CAMERA = "Nikon 5100 (NPL)"
ILLUMINANT = "D50"
CHART = "ColorChecker N Ohta"
OBSERVER = "CIE 1931 2 Degree Standard Observer"


def _on(sd_or_msds, shape):
    return np.asarray(sd_or_msds.copy().align(shape).values, dtype=float)


def spectra_():
    """(wavelengths, E, S (n, 3), chart reflectances (24, n), cmfs (n, 3)) on the camera's grid."""
    import colour

    camera = colour.MSDS_CAMERA_SENSITIVITIES[CAMERA]
    shape = camera.shape
    wavelengths = np.asarray(camera.wavelengths, dtype=float)
    light = _on(colour.SDS_ILLUMINANTS[ILLUMINANT], shape)
    chart = np.array([_on(sd, shape) for sd in colour.SDS_COLOURCHECKERS[CHART].values()])
    cmfs = _on(colour.MSDS_CMFS[OBSERVER], shape)
    return wavelengths, light, np.asarray(camera.values, dtype=float), chart, cmfs


def channel_quantum_efficiency_shapes(wavelengths_nm, sensitivities) -> np.ndarray:
    """(3, n): each channel's quantum efficiency on epc_fast.spectra's grid, scaled to a peak
    of 1: the responsivity per unit power, linearly interpolated, over the wavelength."""
    from epc_fast import spectra

    grid = spectra.GRID_NM
    shapes = np.array([np.interp(grid, wavelengths_nm, sensitivities[:, c]) / grid
                       for c in range(3)])
    return shapes / shapes.max(axis=1, keepdims=True)


def light(luminance_weights=None):
    """epc_fast.cfa.bayer_light of the D5100 (each channel's peak QE 0.7) against K's sensor
    under D50."""
    from epc_fast import cfa, spectra

    wavelengths, _, sens, _, _ = spectra_()
    return cfa.bayer_light(channel_quantum_efficiency_shapes(wavelengths, sens), ILLUMINANT,
                           quantum_efficiency=spectra.QE_PEAK,
                           reference_quantum_efficiency=spectra.default_qe,
                           luminance_weights=luminance_weights)


def bare_silicon_at_least() -> float:
    """The least K of the D5100's own silicon without filters, in units of the model's K: each
    filter passes at most all the light, so the bare silicon's quantum efficiency is at least
    the largest of the three channels' at every wavelength (each channel's peak 0.7)."""
    from epc_fast import spectra

    wavelengths, _, sens, _, _ = spectra_()
    envelope = spectra.QE_PEAK * channel_quantum_efficiency_shapes(wavelengths, sens).max(axis=0)
    return (spectra.electrons_per_lux_s_m2(ILLUMINANT, envelope)
            / spectra.electrons_per_lux_s_m2(ILLUMINANT))


def white_preserving_fit(rgb, xyz, white_xyz) -> np.ndarray:
    """M (3x3), least squares xyz ~ rgb M^T with M (1, 1, 1) = white_xyz exactly: per row r,
    minimise |rgb m - xyz_r|^2 subject to sum(m) = white_r, by the KKT system."""
    a = rgb.T @ rgb
    kkt = np.zeros((4, 4))
    kkt[:3, :3] = 2.0 * a
    kkt[:3, 3] = kkt[3, :3] = 1.0
    rows = []
    for r in range(3):
        rhs = np.concatenate((2.0 * rgb.T @ xyz[:, r], [white_xyz[r]]))
        rows.append(np.linalg.solve(kkt, rhs)[:3])
    return np.array(rows)


def derive() -> dict:
    """Every constant and the numbers behind it."""
    wavelengths, power, sens, chart, cmfs = spectra_()
    rgb = (chart * power) @ sens
    rgb_white = power @ sens
    rgb_wb = rgb / rgb_white          # white balanced: the perfect white is (1, 1, 1)
    white_xyz = power @ cmfs
    xyz = (chart * power) @ cmfs / white_xyz[1]
    m = white_preserving_fit(rgb_wb, xyz, white_xyz / white_xyz[1])
    y = m[1]
    bayer = light(tuple(y / y.sum()))  # y sums to 1 to rounding; bayer_light checks 1e-9
    t_c = np.array(bayer.channel_transmittances)
    t = bayer.transmittance
    g_read = t * t * float(np.sum(y * y / (t_c * t_c)))
    fitted = rgb_wb @ m.T
    return {"channel_transmittances": t_c, "cfa_transmittance": t, "ccm": m,
            "luminance_weights": y, "color_noise_gain": bayer.color_noise_gain,
            "read_noise_gain": g_read, "white_balance": np.array(bayer.white_balance),
            "electrons_per_lux_s_m2": bayer.electrons_per_lux_s_m2,
            "channels_sum_over_k": float(t_c.sum()),
            "bare_silicon_at_least": bare_silicon_at_least(),
            "fit_rms_y": float(np.sqrt(np.mean((fitted[:, 1] - xyz[:, 1]) ** 2))),
            "fit_rms_xyz": float(np.sqrt(np.mean((fitted - xyz) ** 2)))}


def main() -> None:
    d = derive()
    np.set_printoptions(precision=4, suppress=True)
    print(f"camera {CAMERA!r}, light {ILLUMINANT}, chart {CHART!r}")
    print(f"reference: K's sensor (QE 0.7 on 480..580 nm), K = "
          f"{d['electrons_per_lux_s_m2']!r} e-/(lux s m^2)")
    print("channel transmittances t_c (R, G, B):", d["channel_transmittances"])
    print(f"DEFAULT_CFA_TRANSMITTANCE = {d['cfa_transmittance']:.4f}")
    print("white balance (R, G, B):", d["white_balance"])
    print(f"the three channels together collect {d['channels_sum_over_k']:.4f} K; the bare "
          f"silicon at least {d['bare_silicon_at_least']:.4f} K (the channels' envelope)")
    print("colour correction M (white-balanced RGB -> XYZ, white Y = 1):\n", d["ccm"])
    print("luminance weights y_c:", d["luminance_weights"], "sum", d["luminance_weights"].sum())
    print(f"fit rms on the chart: Y {d['fit_rms_y']:.4f}, XYZ {d['fit_rms_xyz']:.4f}")
    print(f"DEFAULT_COLOR_NOISE_GAIN = {d['color_noise_gain']:.4f} (shot noise)")
    print(f"read-noise gain {d['read_noise_gain']:.4f}, ratio to the shot-noise gain "
          f"{d['read_noise_gain'] / d['color_noise_gain']:.4f}")


if __name__ == "__main__":
    main()
