"""The exact image of a straight edge, computed in one dimension, to hold the capture's 2-D
image against.

An infinite straight edge imaged by a shift-invariant system is a function of the distance d
to the edge alone: lo + (hi - lo) ESF(d), the ESF the integral of the line spread function,
whose spectrum is the system's 2-D transfer on the edge's normal (the projection-slice
theorem). On a 1-D grid the line spread can be given a period of 40 mm, where the Airy pattern's tail
beyond half of it holds under 1e-5 of the light (2 lambda F / (pi^3 x) at x = 20 mm), which
the 2-D grid cannot afford.
"""

import math

import numpy as np

from epc_fast.simulate import blur, optics


def edge_spread(d_mm, *, angle_deg, f_number, wavelength_nm, pitch_um, fill_factor=1.0,
                jitter_mm=0.0, motion=None, period_mm=40.0, spacing_mm=5e-5):
    """The ESF (0 to 1) at normal distances ``d_mm`` of the simulator's own transfers on the
    normal of an edge ``angle_deg`` from the vertical; ``motion`` = (T, f_L, omega) or None."""
    n = int(period_mm / spacing_mm)
    n += n % 2
    f = np.fft.rfftfreq(n, spacing_mm)
    a = math.radians(angle_deg)
    h = optics.diffraction_transfer(f, f_number, [wavelength_nm], [1.0]).astype(complex)
    width = math.sqrt(fill_factor) * pitch_um * 1e-3
    h *= blur.aperture_transfer(f * math.cos(a), width)
    h *= blur.aperture_transfer(f * math.sin(a), width)
    h *= blur.jitter_transfer(f * math.cos(a), jitter_mm)
    h *= blur.jitter_transfer(f * math.sin(a), jitter_mm)
    if motion is not None:
        h *= blur.motion_transfer(f * math.cos(a), *motion)[0]
    lsf = np.roll(np.fft.irfft(h, n), n // 2)  # the line spread times the spacing, centred
    x = (np.arange(n) - n // 2 + 0.5) * spacing_mm  # the right edge of each sample's cell
    return np.interp(d_mm, x, np.cumsum(lsf))
