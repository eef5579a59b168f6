"""Derives the colour filter array's default constants of epc_fast.cfa from a real camera's
spectral sensitivities, and prints them as the module writes them.

The camera: the Nikon D5100 of colour-science's ``MSDS_CAMERA_SENSITIVITIES["Nikon 5100
(NPL)"]`` (a Bayer DSLR's red, green and blue responsivities, measured at the UK National
Physical Laboratory, 380..780 nm in 5 nm steps, each channel scaled to a peak of 1). The light:
CIE D50 (``SDS_ILLUMINANTS["D50"]``), the illuminant behind the model's K. The colour chart:
the 24 patches of ``SDS_COLOURCHECKERS["ColorChecker N Ohta"]``, with the CIE 1931 2 degree
observer for their XYZ under D50.

1. Channel transmittances t_c = integral(E S_c) / integral(E (S_R + S_G + S_B)). The monochrome
   reference is the sum of the three channels: with each filter's peak transmittance 1 (the
   dataset's per-channel scale) the three filters split the spectrum among them, and the bare
   sensor behind them sees the sum. Where the filters overlap the sum exceeds the bare sensor
   and t_c errs low; where they leave a gap it errs high. The cell's mean transmittance is
   t = (t_R + 2 t_G + t_B) / 4 (RGGB).
2. White balance divides channel c by t_c, so that a grey patch gives equal values.
3. The colour correction: the 3x3 matrix M from white-balanced camera RGB to XYZ (white's Y
   = 1) fitted to the chart by least squares with the white point held exactly (each row's
   sum fixed by a Lagrange multiplier). Its Y row gives the luminance weights y_c, sum 1.
4. color_noise_gain for shot noise: a flat patch of S monochrome electrons gives channel c
   t_c S electrons, variance t_c S, luminance Y = sum_c y_c (value_c / t_c) of mean S and
   variance S sum_c y_c^2 / t_c. On the cell's scale (signal t S, the model's) the variance
   is g (t S) with g = t sum_c y_c^2 / t_c.
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


def spectra():
    """(wavelengths, E, S (n, 3), chart reflectances (24, n), cmfs (n, 3)) on the camera's grid."""
    import colour

    camera = colour.MSDS_CAMERA_SENSITIVITIES[CAMERA]
    shape = camera.shape
    wavelengths = np.asarray(camera.wavelengths, dtype=float)
    light = _on(colour.SDS_ILLUMINANTS[ILLUMINANT], shape)
    chart = np.array([_on(sd, shape) for sd in colour.SDS_COLOURCHECKERS[CHART].values()])
    cmfs = _on(colour.MSDS_CMFS[OBSERVER], shape)
    return wavelengths, light, np.asarray(camera.values, dtype=float), chart, cmfs


def channel_transmittances(light, sensitivities) -> np.ndarray:
    """t_c, (R, G, B): each channel's response to the light over the three channels' sum's."""
    response = light @ sensitivities
    return response / response.sum()


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
    _, light, sens, chart, cmfs = spectra()
    t_c = channel_transmittances(light, sens)
    t = (t_c[0] + 2.0 * t_c[1] + t_c[2]) / 4.0
    rgb = (chart * light) @ sens
    rgb_white = light @ sens
    rgb_wb = rgb / rgb_white          # white balanced: the perfect white is (1, 1, 1)
    white_xyz = light @ cmfs
    xyz = (chart * light) @ cmfs / white_xyz[1]
    m = white_preserving_fit(rgb_wb, xyz, white_xyz / white_xyz[1])
    y = m[1]
    g_shot = t * float(np.sum(y * y / t_c))
    g_read = t * t * float(np.sum(y * y / (t_c * t_c)))
    fitted = rgb_wb @ m.T
    return {"channel_transmittances": t_c, "cfa_transmittance": t, "ccm": m,
            "luminance_weights": y, "color_noise_gain": g_shot, "read_noise_gain": g_read,
            "fit_rms_y": float(np.sqrt(np.mean((fitted[:, 1] - xyz[:, 1]) ** 2))),
            "fit_rms_xyz": float(np.sqrt(np.mean((fitted - xyz) ** 2)))}


def main() -> None:
    d = derive()
    np.set_printoptions(precision=4, suppress=True)
    print(f"camera {CAMERA!r}, light {ILLUMINANT}, chart {CHART!r}")
    print("channel transmittances t_c (R, G, B):", d["channel_transmittances"])
    print(f"DEFAULT_CFA_TRANSMITTANCE = {d['cfa_transmittance']:.4f}")
    print("colour correction M (white-balanced RGB -> XYZ, white Y = 1):\n", d["ccm"])
    print("luminance weights y_c:", d["luminance_weights"], "sum", d["luminance_weights"].sum())
    print(f"fit rms on the chart: Y {d['fit_rms_y']:.4f}, XYZ {d['fit_rms_xyz']:.4f}")
    print(f"DEFAULT_COLOR_NOISE_GAIN = {d['color_noise_gain']:.4f} (shot noise)")
    print(f"read-noise gain {d['read_noise_gain']:.4f}, ratio to the shot-noise gain "
          f"{d['read_noise_gain'] / d['color_noise_gain']:.4f}")


if __name__ == "__main__":
    main()
