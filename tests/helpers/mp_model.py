"""An independent mpmath model of MODEL.md at 40 digits, for the tests: every output of sections
3-7 and the MTF's factors at f50, from inputs taken exactly (floats or mpf values)."""

import mpmath

MP_DPS = 40

#: MODEL.md section 1's defaults, restated here so that the model does not lean on the package.
MODEL_DEFAULTS = dict(reflectance=0.4, lens_transmittance=1.0, field_angle_deg=0.0,
                      fill_factor=1.0, read_noise_e=0.0, dark_current_e_per_s=0.0, prnu=0.0,
                      snr_db=30.0, shake_deg_per_s=4.39, stabilization=1.0, jitter_um=0.0,
                      wavelength_nm=550.0, mtf_threshold=0.5)


def mp_model(inputs, spectrum=None):
    """Every output of MODEL.md sections 3-7 at MP_DPS digits, from the float64 inputs taken
    exactly; `spectrum` is (wavelengths_nm, weights) or None for inputs["wavelength_nm"]."""
    with mpmath.workdps(MP_DPS):
        x = {name: mpmath.mpf(value) for name, value in {**MODEL_DEFAULTS, **inputs}.items()
             if name != "full_well_e"}
        pi = mpmath.pi
        um, nm = mpmath.mpf(10) ** -3, mpmath.mpf(10) ** -6  # in mm

        # Section 3: the electron rate and the positive root of a T^2 - b T - c = 0.
        focal_plane_lux = (x["illuminance_lux"] * x["reflectance"] * x["lens_transmittance"]
                           * mpmath.cos(x["field_angle_deg"] * pi / 180) ** 4
                           / (4 * x["f_number"] ** 2))
        rate = (focal_plane_lux * x["electrons_per_lux_s_m2"] * x["fill_factor"]
                * (x["pixel_pitch_um"] * mpmath.mpf(10) ** -6) ** 2)
        s = mpmath.mpf(10) ** (x["snr_db"] / 10)
        a = rate**2 * (1 - s * x["prnu"] ** 2)
        b = s * (rate + x["dark_current_e_per_s"])
        c = s * x["read_noise_e"] ** 2
        t_mpe = (b + mpmath.sqrt(b * b + 4 * a * c)) / (2 * a)

        # Section 4: blur with tan (the cases below stay far below a quarter turn).
        angle = x["shake_deg_per_s"] * pi / 180 / x["stabilization"] * t_mpe
        assert angle < pi / 2
        blur = x["focal_length_mm"] * mpmath.tan(angle)

        # Section 5: the system MTF.
        if spectrum is None:
            lines = [(x["wavelength_nm"], mpmath.mpf(1))]
        else:
            total = sum(mpmath.mpf(w) for w in spectrum[1])
            lines = [(mpmath.mpf(lam), mpmath.mpf(w) / total) for lam, w in zip(*spectrum)]
        aperture = mpmath.sqrt(x["fill_factor"]) * x["pixel_pitch_um"] * um
        sigma = x["jitter_um"] * um

        def diffraction(f, lam):
            nu = f * lam * nm * x["f_number"]
            return 2 / pi * (mpmath.acos(nu) - nu * mpmath.sqrt(1 - nu * nu)) if nu < 1 else 0

        def mtf(f):
            return (sum(w * diffraction(f, lam) for lam, w in lines)
                    * abs(mpmath.sincpi(aperture * f)) * abs(mpmath.sincpi(blur * f))
                    * mpmath.exp(-2 * pi**2 * sigma**2 * f**2))

        # Section 6: the first crossing, in (0, f_hi], f_hi the smallest first zero.
        threshold = x["mtf_threshold"]
        zeros = [1 / (min(lam for lam, w in lines if w > 0) * nm * x["f_number"]), 1 / aperture]
        if blur > 0:
            zeros.append(1 / blur)
        if sigma > 0:
            zeros.append(mpmath.sqrt(mpmath.log(1 / threshold) / (2 * pi**2)) / sigma)
        f_hi = min(zeros)
        f50 = mpmath.findroot(lambda f: mtf(f) - threshold, (f_hi * mpmath.mpf(10) ** -9, f_hi),
                              solver="anderson")
        # The root is the crossing: MTF - c changes sign across f50 (1 -+ 1e-30).
        assert mtf(f50 * (1 - mpmath.mpf(10) ** -30)) > threshold > mtf(
            f50 * (1 + mpmath.mpf(10) ** -30))

        # Section 7.
        if "pixel_count" in x:
            area = x["pixel_count"] * (x["pixel_pitch_um"] * um) ** 2
        else:
            area = x["sensor_area_mm2"]
        epc = 4 * area * f50**2
        factors = (sum(w * diffraction(f50, lam) for lam, w in lines),
                   abs(mpmath.sincpi(aperture * f50)), abs(mpmath.sincpi(blur * f50)),
                   mpmath.exp(-2 * pi**2 * sigma**2 * f50**2))
        return {"electron_rate_e_per_s": rate, "electrons": rate * t_mpe, "t_mpe_s": t_mpe,
                "blur_mm": blur, "f50_cyc_per_mm": f50, "epc": epc, "mtf_factors": factors}


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

