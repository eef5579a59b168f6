"""The image on the sensor: the chart's irradiance carried on a fine grid, imaged by the lens,
moved during each frame's exposure, jittered, registered with its alignment error, integrated
over each sensor pixel's aperture and sampled at the pixels' centres.

The grid has q samples per sensor pixel a side (q odd, so that the pixels' centres are grid
points and the grid's cells tile the pixels). The lens passes no frequency above its cut-off
1/(lambda F); once 1/spacing exceeds that cut-off plus the chart's own band, the samples hold
the image without loss and every later step is exact (:mod:`~epc_fast.simulate.camera`).
With binning k, a chart's output pixel covers k x k sensor pixels.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._validation import short
from .blur import aperture_transfer, jitter_transfer, motion_transfer, motion_transfer_2d
from .pupil import cutoff_cyc_per_mm, diffraction_transfer, table_cutoff_cyc_per_mm, table_transfer

__all__ = ["Optics", "frame_irradiance", "motion_angle_rad", "BYTES_PER_SAMPLE", "MARGIN_PX", "PSF_REACH"]

#: Bytes a fine-grid sample costs at the peak (the reflectance, its spectrum, the transfer and
#: the image at once, in float64 and complex128).
BYTES_PER_SAMPLE = 56
#: Sensor pixels added round the chart on each side beyond the blur's reach, so that the FFT's
#: wrapping round the grid never reaches the chart.
MARGIN_PX = 4
#: The lens's reach counted into the margin, in units of lambda F, by chart. The FFT's grid
#: wraps round, so the chart's far side meets its near side across the margin, and the Airy
#: pattern's line spread falls only as 2 lambda F / (pi^3 x^2): a step of the chart leaks
#: 2 lambda F / (pi^3 x) of itself to a distance x. For the slanted edge, whose MTF is measured,
#: 200 lambda F keeps that leak under 3.3e-4 of the edge's contrast; pictures and flat patches
#: (where the wrap joins equal values) take 16.
PSF_REACH = {"slanted_edge": 200.0, "image": 16.0, "flat": 16.0}


@dataclass(frozen=True)
class Optics:
    """What images the chart: lengths in mm, angles in radians.

    pitch_mm : the sensor pixel's pitch; binning : k, sensor pixels a side of an output pixel;
    q : grid samples per sensor pixel a side; f_number; wavelengths_nm, weights : the
    spectrum; focal_mm; shake_rad_per_s : the camera's turn over the stabilisation;
    jitter_mm : rms a side; aperture_mm : the side of the pixel's square aperture;
    irradiance_lux : the focal-plane illuminance of reflectance 1; wavefront_rms_waves and
    aberration : the lens's wavefront error, waves rms of a Zernike defocus or spherical
    aberration (:data:`~epc_fast.simulate.pupil.ABERRATIONS`); lens_table : an
    :class:`epc_fast.mtf_table.MtfTable`, the lens's MTF in place of its pupil's (None: the
    pupil's); motion_angle_rad : the direction the image moves in, from the rows (towards
    larger rows for a positive angle; 0, along the rows).
    """

    pitch_mm: float
    binning: int
    q: int
    f_number: float
    wavelengths_nm: np.ndarray
    weights: np.ndarray
    focal_mm: float
    shake_rad_per_s: float
    jitter_mm: float
    aperture_mm: float
    irradiance_lux: float
    wavefront_rms_waves: float = 0.0
    aberration: str = "defocus"
    lens_table: object = None
    motion_angle_rad: float = 0.0

    @property
    def cutoff(self) -> float:
        """cycles/mm, the frequency above which the lens passes nothing."""
        if self.lens_table is not None:
            return table_cutoff_cyc_per_mm(self.lens_table)
        return cutoff_cyc_per_mm(self.f_number, float(np.min(self.wavelengths_nm)))

    def transfer(self, frequency_cyc_per_mm) -> np.ndarray:
        """The lens's OTF at frequencies of magnitude ``frequency_cyc_per_mm``: its table's,
        or its pupil's over the spectrum."""
        if self.lens_table is not None:
            return table_transfer(frequency_cyc_per_mm, self.lens_table)
        return diffraction_transfer(frequency_cyc_per_mm, self.f_number, self.wavelengths_nm,
                                    self.weights, self.wavefront_rms_waves, self.aberration)


def frame_irradiance(chart, optics: Optics, exposure_s: float, frames: int, offsets_mm,
                     threads: int, border_px: int = 0):
    """lux: each frame's focal-plane illuminance averaged over each sensor pixel's aperture and
    the frame's exposure, shape (rows k, columns k) a frame; and the distance the image travels
    over the whole exposure, mm.

    Frame j is exposed from j T/n to (j + 1) T/n; its image is registered on its own mean
    position during that time, off by ``offsets_mm[j]`` = (dy, dx), its alignment error.
    ``border_px`` output pixels of the scene round the chart are imaged too (a denoising
    filter reaches into them).
    """
    from scipy import fft

    o = optics
    k, q = o.binning, o.q
    dx = o.pitch_mm / q
    cutoff = o.cutoff
    blur = abs(float(o.focal_mm * math.tan(o.shake_rad_per_s * exposure_s)))
    lambda_f = float(np.max(o.wavelengths_nm)) * 1e-6 * o.f_number
    offsets = np.asarray(offsets_mm, dtype=float).reshape(frames, 2)
    reach = (PSF_REACH[chart.kind] * lambda_f + 6.0 * o.jitter_mm + 2.0 * o.pitch_mm
             + float(np.max(np.abs(offsets), initial=0.0)))
    b = int(border_px)
    rows, cols = (chart.shape[0] + 2 * b) * k, (chart.shape[1] + 2 * b) * k  # sensor pixels
    angle = o.motion_angle_rad
    margin_y = MARGIN_PX + math.ceil((reach + blur * abs(math.sin(angle))) / o.pitch_mm)
    margin_x = MARGIN_PX + math.ceil((reach + blur * abs(math.cos(angle))) / o.pitch_mm)
    ny = fft.next_fast_len(q * (rows + 2 * margin_y), real=True)
    nx = fft.next_fast_len(q * (cols + 2 * margin_x), real=True)
    _check_memory(ny * nx, chart)

    # Sensor pixel i is centred on grid sample q (i + margin) + (q - 1) / 2; output pixel I on
    # the centre of its sensor pixels k I ... k I + k - 1, the chart's point I.
    offset = (np.arange(max(ny, nx), dtype=float) - (q - 1) / 2.0) / q
    y = ((offset[:ny] - margin_y - (k - 1) / 2.0) / k - b)[:, None]
    x = ((offset[:nx] - margin_x - (k - 1) / 2.0) / k - b)[None, :]
    reflectance = chart.reflectance_at(y, x, pitch_um=k * o.pitch_mm * 1e3,
                                       band_cyc_per_mm=1.0 / dx - cutoff)
    spectrum = fft.rfft2(reflectance, workers=threads)
    del reflectance

    fy = fft.fftfreq(ny, dx)
    fx = fft.rfftfreq(nx, dx)
    iy, ix = np.nonzero(np.abs(fy) < cutoff)[0], np.nonzero(fx < cutoff)[0]
    fyk, fxk = fy[iy], fx[ix]
    common = o.transfer(np.hypot(fyk[:, None], fxk[None, :])).astype(complex)
    common *= (aperture_transfer(fyk, o.aperture_mm) * jitter_transfer(fyk, o.jitter_mm))[:, None]
    common *= (aperture_transfer(fxk, o.aperture_mm) * jitter_transfer(fxk, o.jitter_mm))[None, :]
    common *= spectrum[np.ix_(iy, ix)]
    del spectrum
    start_y = q * margin_y + (q - 1) // 2
    start_x = q * margin_x + (q - 1) // 2
    images = []
    t_frame = exposure_s / frames
    for j in range(frames):
        dy, dxj = offsets[j]
        if angle == 0.0:  # along the rows: the motion's factor is a function of fx alone
            moving, _, _ = motion_transfer(fxk, t_frame, o.focal_mm, o.shake_rad_per_s,
                                           start_s=j * t_frame)
            shift = (np.exp(-2j * math.pi * fyk * dy)[:, None]
                     * (moving * np.exp(-2j * math.pi * fxk * dxj))[None, :])
        else:
            shift = motion_transfer_2d(fyk, fxk, t_frame, o.focal_mm, o.shake_rad_per_s,
                                       angle, start_s=j * t_frame)
            shift *= np.exp(-2j * math.pi * fyk * dy)[:, None]
            shift *= np.exp(-2j * math.pi * fxk * dxj)[None, :]
        filtered = np.zeros((ny, nx // 2 + 1), dtype=complex)
        filtered[np.ix_(iy, ix)] = common * shift
        image = fft.irfft2(filtered, s=(ny, nx), workers=threads)
        del filtered
        pixels = image[start_y:start_y + q * rows:q, start_x:start_x + q * cols:q]
        images.append(np.ascontiguousarray(pixels) * o.irradiance_lux)
    return images, blur


def motion_angle_rad(motion_angle_deg) -> float:
    """Radians: a capture's ``motion_angle_deg`` (the motion's direction from the rows), or a
    ValueError naming it unless a real number in [-90, 90]."""
    try:
        angle = float(motion_angle_deg)
    except (TypeError, ValueError):
        angle = math.nan
    if (isinstance(motion_angle_deg, (bool, np.bool_, str, bytes))
            or np.ndim(motion_angle_deg) != 0 or not -90.0 <= angle <= 90.0):
        raise ValueError(f"motion_angle_deg: the motion's direction from the rows, -90 to 90 "
                         f"degrees, got {short(motion_angle_deg)}")
    return math.radians(angle)


def _check_memory(samples: int, chart) -> None:
    from .. import _limits

    limit = _limits.memory_limit_bytes()
    needed = samples * BYTES_PER_SAMPLE
    if limit is not None and needed > limit:
        raise MemoryError(f"a capture of a {chart.shape[0]} x {chart.shape[1]} chart needs a "
                          f"fine grid of {samples:,} samples, about {needed / 2**30:.1f} GiB, "
                          f"more than the {limit / 2**30:.1f} GiB of memory here: capture a "
                          "smaller chart")
