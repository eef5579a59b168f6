"""A capture of a chart by one design at one light level, simulated from the physics of the
image: the scene's irradiance on the sensor, the lens's OTF from its pupil, the image moving
during the exposure, jitter, each pixel integrating the image over its aperture, and the
sensor's noise drawn from a seed.

The continuous image is carried on a fine grid of spacing p/q. The lens passes no frequency
above its cut-off 1/(lambda F), so once 1/spacing exceeds that cut-off plus the chart's own
band, the grid's samples hold the image without loss: every later step (moving, averaging over
the aperture, sampling at the pixels' centres) is then exact, and the grid adds no error at
all, not merely a small one. q is the smallest odd integer that does it (odd, so that the
pixels' centres are grid points and the grid's cells tile the pixels).
"""

from __future__ import annotations

import inspect
import math
import dataclasses
from dataclasses import dataclass

import numpy as np

from .. import _limits
from .._validation import as_float_array, short, threads_of
from ..api import evaluate
from ..design import DESIGN_KEYWORDS, resolve
from ..exposure_limits import sets_limits
from ..cfa import check_cfa, check_demosaic
from ..cfa import color_noise_gain as cfa_color_noise_gain
from ..status import Status
from .charts import Chart
from .focal_plane import Optics, frame_irradiance, motion_angle_rad
from .pupil import cutoff_cyc_per_mm, table_cutoff_cyc_per_mm
from .processing import denoise, kernel_reach_px
from . import bayer as _bayer
from . import remosaic as _remosaic
from .noise import bin_sum, read_out, readout_parameters

__all__ = ["Capture", "capture", "grid_oversample", "picked_mode", "mode_text", "BAND_FACTOR",
           "MAX_FRAMES"]

#: The grid's sampling rate over the lens's cut-off: 1/spacing >= BAND_FACTOR / (lambda F).
#: Above 2 the chart's band (1/spacing - cut-off) exceeds the cut-off, as the slanted edge's
#: exact rendering needs (charts.Chart.reflectance_at).
BAND_FACTOR = 2.05
#: The most frames a capture images: each is an FFT of the whole grid.
MAX_FRAMES = 1024
#: The relative difference within which a given ``color_noise_gain`` is the capture's own.
GAIN_RTOL = 1e-3
_EVALUATE = inspect.signature(evaluate).parameters
_NOT_DESIGN = {"out", "outputs", "illuminance_lux"}


@dataclass(frozen=True, eq=False)
class Capture:
    """One simulated capture.

    Attributes
    ----------
    image_e : 2-D float64, e- per output pixel: the linear signal with its noise, the mean
        dark signal subtracted.
    expected_e : 2-D float64, e-: the photo-electrons each output pixel expects (no noise).
    pitch_um : µm, the output pixel pitch: the sensor's pitch times the binning.
    exposure_s : s, the exposure (T_MPE unless one was given).
    illuminance_lux : lux, the scene's illuminance.
    field_angle_deg : degrees, where on the sensor the chart sits (cos^4 falloff).
    blur_mm : mm, how far the image travels during the exposure.
    oversample : the fine grid's samples per pixel a side.
    seed : the seed the noise was drawn from.
    chart : the chart captured.
    result : :class:`epc_fast.Result`, ``evaluate``'s outputs for this design and light.
    readout : the sensor's noise parameters the image was read out with.
    frames_e : each frame's expected photo-electrons per sensor pixel (before binning),
        with ``border_px`` output pixels of scene round the chart.
    denoise_sigma_px : output pixels, the sigma of the denoising filter applied (0: none).
    border_px : output pixels of scene imaged round the chart for the filter and the
        demosaicker, cropped after.
    cfa : "none", "bayer" or "quad_bayer"; bayer : the :class:`~epc_fast.simulate.bayer.Bayer`
        sensor and its development for a Bayer capture (a
        :class:`~epc_fast.simulate.remosaic.QuadBayer` for a quad Bayer one read full size;
        None for "none"). A Bayer capture's
        ``image_e`` and ``expected_e`` are its luminance on the cell's scale (a flat patch of
        S monochrome electrons gives t S).
    """

    image_e: np.ndarray
    expected_e: np.ndarray
    pitch_um: float
    exposure_s: float
    illuminance_lux: float
    field_angle_deg: float
    blur_mm: float
    oversample: int
    seed: object
    chart: Chart
    result: object
    readout: dict = None
    frames_e: list = None
    recapture: object = None
    denoise_sigma_px: float = 0.0
    border_px: int = 0
    cfa: str = "none"
    bayer: object = None

    def redraw(self, seed) -> "Capture":
        """The same capture with the noise drawn again from ``seed``: the expected image is
        reused, so repeats over seeds cost only their noise (unless the frames' alignment
        errors, which the seed draws too, move the image: then it is captured again)."""
        if self.recapture is not None:
            return self.recapture(seed)
        rng = np.random.default_rng(seed)
        image_e = read_out(self.frames_e, exposure_s=self.exposure_s, rng=rng, **self.readout)
        image_e = _processed(image_e, self.denoise_sigma_px, self.border_px, self.bayer)
        return dataclasses.replace(self, image_e=image_e, seed=seed)


def grid_oversample(pixel_pitch_um: float, f_number: float,
                    shortest_wavelength_nm: float, lens_cutoff_cyc_per_mm=None) -> int:
    """The smallest odd q with q / p >= BAND_FACTOR / (lambda F), or BAND_FACTOR times a lens
    table's end (``lens_cutoff_cyc_per_mm``): the fine grid's samples per pixel a side that
    carry the image without loss."""
    cutoff = (cutoff_cyc_per_mm(f_number, shortest_wavelength_nm)
              if lens_cutoff_cyc_per_mm is None else lens_cutoff_cyc_per_mm)
    q = max(1, math.ceil(BAND_FACTOR * cutoff * pixel_pitch_um * 1e-3 - 1e-9))
    return q if q % 2 == 1 else q + 1


def capture_inputs(design: dict) -> dict:
    """Every parameter of the design, the caller's or evaluate's default."""
    unknown = sorted(set(design) - set(_EVALUATE) | (set(design) & _NOT_DESIGN))
    if unknown:
        raise TypeError(f"capture() got keyword(s) it does not take: {', '.join(unknown)} "
                        "(it takes the design's keywords of epc_fast.evaluate)")
    values = {k: p.default for k, p in _EVALUATE.items()
              if p.default is not inspect.Parameter.empty}
    values.update(design)
    return values


def _scalar(name, value) -> float:
    a = as_float_array(name, value)
    if a.size != 1:
        raise ValueError(f"{name}: capture simulates one design, got shape {a.shape}")
    return float(a.reshape(()))


def picked_mode(design: dict, result) -> dict:
    """The design's keywords read as the mode ``evaluate`` picked (``result.mode``): its
    ``modes`` replaced by that mode's keys (the first mode where none has an EPC, whose
    status says why). A design without ``modes`` is returned as it is."""
    modes = design.get("modes")
    if modes is None:
        return design
    picked = {k: v for k, v in design.items() if k != "modes"}
    picked.update(modes[max(int(np.asarray(result.mode)), 0)])
    return picked


def mode_text(design: dict, result) -> str:
    """The mode ``evaluate`` picked for a design with ``modes``, for people
    (``"binning=4, binning_readout=charge"``); "" for a design without modes."""
    modes = design.get("modes")
    if modes is None:
        return ""
    mode = modes[max(int(np.asarray(result.mode)), 0)]
    return ", ".join(f"{k}={v:g}" if not isinstance(v, str) else f"{k}={v}"
                     for k, v in mode.items()) or "the design's own readout"


def _check_seed(seed) -> None:
    if seed is None or isinstance(seed, np.random.SeedSequence):
        return
    if isinstance(seed, (bool, np.bool_)) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise ValueError(f"seed: None, an integer >= 0 or a numpy.random.SeedSequence, got "
                         f"{short(seed)}")


def _own_noise_gain(given, sensor_cfa) -> None:
    """A ValueError for a ``color_noise_gain`` other than the capture's own: its filters' (1
    without a CFA; a Bayer sensor's from its channels and luminance weights)."""
    if given is None:
        return
    own = 1.0 if sensor_cfa is None else cfa_color_noise_gain(sensor_cfa.channels,
                                                              sensor_cfa.weights)
    value = _scalar("color_noise_gain", given)
    if not abs(value - own) <= GAIN_RTOL * own:
        raise ValueError(f"color_noise_gain: {short(given)} is not the capture's own, {own:.4g}: "
                         "a capture's colour noise gain is that of its filters (1 without a "
                         "CFA; a Bayer sensor's channel_transmittances and luminance_weights "
                         "give its own); leave it out, or give those")


def _check_frames(frames: int, shape, border: int, binning: int) -> None:
    """A ValueError for more than MAX_FRAMES frames; a MemoryError for frames whose images
    (float64, of every sensor pixel) exceed the memory."""
    if frames > MAX_FRAMES:
        raise ValueError(f"frames: a capture images each frame (an FFT of its whole grid), at "
                         f"most {MAX_FRAMES:,} frames, got {frames:,}")
    held = frames * (shape[0] + 2 * border) * (shape[1] + 2 * border) * binning ** 2 * 8
    limit = _limits.memory_limit_bytes()
    if limit is not None and held > limit:
        raise MemoryError(f"frames: {frames:,} frames of a {shape[0]} x {shape[1]} chart hold "
                          f"{held / 2**30:.1f} GiB of images, more than the "
                          f"{limit / 2**30:.1f} GiB of memory here: capture fewer frames or a "
                          "smaller chart")


def _exposure(exposure_s, result, shake_rad_per_s) -> float:
    if exposure_s is None:
        status = Status(int(np.asarray(result.status)))
        if status == Status.UNREACHABLE:
            raise ValueError(f"the design cannot reach its SNR target here "
                             f"({np.asarray(result.cause).item()!r}): there is no T_MPE to "
                             "capture at; give exposure_s")
        if status == Status.BLUR_UNBOUNDED:
            raise ValueError("the camera turns through 90 degrees or more during T_MPE "
                             f"({float(result.t_mpe_s):.4g} s): no image to capture")
        return float(result.t_mpe_s)
    t = np.asarray(exposure_s)
    if t.size != 1 or t.dtype.kind not in "iuf" or not (math.isfinite(float(t)) and float(t) >= 0):
        raise ValueError(f"exposure_s: a finite time >= 0 in seconds, got {short(exposure_s)}")
    t = float(t)
    if shake_rad_per_s * t >= math.pi / 2:
        raise ValueError(f"exposure_s: the camera turns through 90 degrees or more in "
                         f"{t!r} s: no image to capture")
    return t


def capture(chart: Chart, *, illuminance_lux, seed=None, exposure_s=None, oversample=None,
            aberration="defocus", motion_angle_deg=0.0, cfa="none", demosaic="malvar2004",
            cfa_transmittance=None, channel_transmittances=None, luminance_weights=None,
            **design) -> Capture:
    """Simulate ``chart`` captured by one design at ``illuminance_lux``.

    Parameters
    ----------
    chart : :class:`Chart`, from :func:`slanted_edge`, :func:`flat` or :func:`image`.
    illuminance_lux : lux, the scene's illuminance, a scalar.
    seed : int >= 0 or numpy.random.SeedSequence, optional
        The noise's seed: the same seed gives the same image.
    exposure_s : s, optional. Default: T_MPE from :func:`epc_fast.evaluate`, the exposure at
        which a flat patch of the design's ``reflectance`` at its field angle has the target
        SNR.
    oversample : odd int, optional
        The fine grid's samples per pixel a side; default and minimum
        :func:`grid_oversample`, the least that carries the image without loss.
    aberration : {"defocus", "spherical"}
        The shape of the lens's wavefront error when the design has one
        (``wavefront_rms_waves``): its pupil's phase is that Zernike polynomial, of that rms.
        A design with ``lens_mtf`` (and ``backend="reference"``, which computes it) images
        through its table's MTF instead of a pupil: the table's interpolant at the radial
        frequency, 0 past the table's end.
    motion_angle_deg : degrees in [-90, 90], the direction the image moves in during the
        exposure, from the rows (towards larger rows for a positive angle). 0, the default,
        moves it along the rows: a near-vertical edge's normal then sees the motion (times the
        cosine of its slant). An edge parallel to the motion sees none of it: a
        near-horizontal :func:`slanted_edge` at ``angle_deg`` a > 0 from the vertical with
        the motion at 90 - a (-90 - a for a < 0) gives the MTF across the motion.
    cfa : {"none", "bayer", "quad_bayer"}
        "bayer": each pixel sits under a filter of the RGGB cell (with binning k, each output
        pixel's k x k sensor pixels under one), its expected electrons times the filter's
        transmittance, read out as any pixel; the mosaic is demosaicked by ``demosaic`` (the
        colour-demosaicing package's algorithm), white-balanced, and its luminance taken by
        the colour correction's luminance row (:mod:`~epc_fast.simulate.bayer`); denoising
        then filters the luminance. The exposure is ``evaluate``'s for that sensor: its
        ``cfa_transmittance`` and the ``color_noise_gain`` of its channels and weights.
        "quad_bayer": at binning 2 the Bayer capture (each 2 x 2 block under one filter,
        binned); at binning 1 each pixel under its block's filter, the mosaic white-balanced,
        remosaicked to RGGB (:mod:`~epc_fast.simulate.remosaic`) and developed as a Bayer
        capture; other binnings raise ValueError, as ``evaluate`` does.
    demosaic : {"bilinear", "malvar2004", "menon2007"}
    cfa_transmittance : 1, optional, the cell's mean transmittance t relative to the
        monochrome sensor; the channels are scaled by one factor to it. Default: the
        channels' own mean (:data:`epc_fast.cfa.DEFAULT_CFA_TRANSMITTANCE` for the default).
        With ``cfa="none"``, a neutral filter's: every pixel collects t of the light, as the
        model's monochrome sensor behind a filter does.
    channel_transmittances : (t_R, t_G, t_B), optional; default
        :data:`epc_fast.cfa.DEFAULT_CHANNEL_TRANSMITTANCES`.
    luminance_weights : (y_R, y_G, y_B) summing to 1, optional; default
        :data:`epc_fast.cfa.DEFAULT_LUMINANCE_WEIGHTS`.
    **design
        Every keyword of :func:`epc_fast.evaluate` for one design (scalars), e.g. a preset's
        ``evaluate_kwargs()``. The chart sits at the design's field angle (where its SNR target
        is met), and the image moves along the rows. A design with ``modes`` is captured in
        the mode ``evaluate`` picks (``result.mode``), at its binning, frames, readout and
        T_MPE. ``color_noise_gain`` is the capture's own, its filters' (1 without a CFA; a
        Bayer sensor's from ``channel_transmittances`` and ``luminance_weights``), and may be
        given only as that. ``frames`` is at most :data:`MAX_FRAMES`.

    Returns
    -------
    Capture

    Raises
    ------
    ValueError, TypeError
        For a bad chart or argument, naming it and its value; for a design that cannot reach
        its SNR target (no T_MPE) unless ``exposure_s`` is given; for an exposure during
        which the camera turns 90 degrees; MemoryError for a grid larger than the memory.
    """
    if not isinstance(chart, Chart):
        raise TypeError(f"chart: an epc_fast.simulate chart (slanted_edge, flat or image), "
                        f"got {type(chart).__name__}")
    lux = _scalar("illuminance_lux", illuminance_lux)
    _check_seed(seed)
    sensor_cfa = _color_sensor(cfa, demosaic, cfa_transmittance, channel_transmittances,
                                luminance_weights, design.get("color_noise_gain"))
    result, picked = _evaluated(lux, design, _cfa_terms(cfa, demosaic, cfa_transmittance,
                                                        sensor_cfa))
    resolved = resolve(lux, **{k: v for k, v in picked.items() if k in DESIGN_KEYWORDS})
    if cfa == "quad_bayer" and int(resolved.parameter("binning")) == 1:  # full size: remosaicked
        sensor_cfa = _remosaic.quad_bayer(sensor_cfa)
    t = _exposure(exposure_s, result, _shake_rad_per_s(resolved))
    optics = dataclasses.replace(_optics(resolved, lux, aberration, oversample),
                                 motion_angle_rad=motion_angle_rad(motion_angle_deg))
    sigma = float(resolved.parameter("denoise_sigma_px"))
    border = _border_px(sigma, sensor_cfa)
    frames_e, blur = _frames_e(chart, optics, resolved, t, seed, border, sensor_cfa,
                               threads_of(picked.get("threads")))
    readout = readout_parameters(resolved)
    image_e = read_out(frames_e, exposure_s=t, rng=np.random.default_rng(seed), **readout)
    image_e = _processed(image_e, sigma, border, sensor_cfa)
    expected = _processed(sum(bin_sum(f, optics.binning) for f in frames_e), sigma, border,
                          sensor_cfa)
    recapture = None
    if len(frames_e) > 1 and float(resolved.parameter("alignment_error_um")) > 0.0:
        def recapture(new_seed):  # the frames' alignment errors are drawn from the seed too
            return capture(chart, illuminance_lux=illuminance_lux, seed=new_seed,
                           exposure_s=exposure_s, oversample=oversample,
                           aberration=aberration, motion_angle_deg=motion_angle_deg,
                           cfa=cfa, demosaic=demosaic,
                           cfa_transmittance=cfa_transmittance,
                           channel_transmittances=channel_transmittances,
                           luminance_weights=luminance_weights, **design)
    return Capture(image_e=image_e, expected_e=expected,
                   pitch_um=float(resolved.parameter("pixel_pitch_um")) * optics.binning,
                   exposure_s=t,
                   illuminance_lux=lux, field_angle_deg=_scalar("field_angle_deg",
                                                                resolved.field_angle_deg),
                   blur_mm=blur, oversample=optics.q, seed=seed, chart=chart, result=result,
                   readout=readout, frames_e=frames_e, recapture=recapture,
                   denoise_sigma_px=sigma, border_px=border, cfa=cfa, bayer=sensor_cfa)


def _color_sensor(cfa, demosaic, cfa_transmittance, channel_transmittances,
                   luminance_weights, color_noise_gain):
    """The capture's Bayer sensor (:func:`~epc_fast.simulate.bayer.bayer`), or None for
    ``cfa="none"``; a ValueError for a ``color_noise_gain`` other than its own."""
    sensor_cfa = None
    if check_cfa(cfa) != "none":  # a quad Bayer sensor's filters and development are Bayer's
        sensor_cfa = _bayer.bayer(demosaic, cfa_transmittance, channel_transmittances,
                                  luminance_weights)
    else:
        check_demosaic(demosaic)
    _own_noise_gain(color_noise_gain, sensor_cfa)
    return sensor_cfa


def _cfa_terms(cfa, demosaic, cfa_transmittance, sensor_cfa) -> dict:
    """evaluate's keywords of the capture's colour sensor: a Bayer sensor's transmittance and
    the colour noise gain of its channels and weights, for the model's exposure."""
    terms = {k: v for k, v in (("cfa", cfa), ("demosaic", demosaic),
                               ("cfa_transmittance", cfa_transmittance)) if v is not None}
    if sensor_cfa is not None:
        terms["cfa_transmittance"] = sensor_cfa.transmittance
        terms["color_noise_gain"] = cfa_color_noise_gain(sensor_cfa.channels,
                                                         sensor_cfa.weights)
    return terms


def _evaluated(lux: float, design: dict, cfa_terms: dict) -> tuple:
    """(evaluate's Result for the design at ``lux``, which raises for any input outside its
    domain; the design's keywords with its colour sensor, read as the mode evaluate picked)."""
    capture_inputs(design)  # the keywords capture takes
    call = {k: v for k, v in design.items() if k != "invalid"}
    call.update(cfa_terms)
    result = evaluate(lux, **call, invalid="raise")
    if np.ndim(result.epc) != 0:
        raise ValueError(f"capture simulates one design, got arrays broadcasting to "
                         f"{np.shape(result.epc)}")
    if result.status == Status.EXPOSURE_LIMIT:
        raise ValueError(f"max_exposure_s: every frame the design can take is longer than "
                         f"max_exposure_s = {call['max_exposure_s']!r} s (status "
                         f"EXPOSURE_LIMIT): there is no image to capture")
    picked = picked_mode(call, result)  # with modes: its binning, frames and readout
    if sets_limits(picked):  # night mode: the frames evaluate takes; the cap is met
        frames = evaluate(lux, **picked, outputs="frames_used").frames_used
        picked = {k: v for k, v in picked.items() if k not in ("max_exposure_s", "max_frames")}
        picked["frames"] = float(frames)
    return result, picked


def _shake_rad_per_s(resolved) -> float:
    """rad/s: the camera's turn over the stabilisation."""
    return (float(resolved.parameter("shake_deg_per_s")) * math.pi / 180.0
            / float(resolved.parameter("stabilization")))


def _optics(resolved, lux: float, aberration, oversample) -> Optics:
    """What images the chart (:class:`~epc_fast.simulate.focal_plane.Optics`), on the grid of
    ``oversample`` samples per pixel a side (default :func:`grid_oversample`)."""
    p = float(resolved.parameter("pixel_pitch_um"))
    f_number = float(resolved.parameter("f_number"))
    wavelengths, weights = resolved.wavelengths()
    table = resolved.lens_table()
    q_min = grid_oversample(p, f_number, float(wavelengths.min()),
                            None if table is None else table_cutoff_cyc_per_mm(table))
    angle = _scalar("field_angle_deg", resolved.field_angle_deg)
    return Optics(pitch_mm=p * 1e-3, binning=int(resolved.parameter("binning")),
                  q=q_min if oversample is None else _oversample(oversample, q_min),
                  f_number=f_number, wavelengths_nm=wavelengths, weights=weights,
                  focal_mm=float(resolved.parameter("focal_length_mm")),
                  shake_rad_per_s=_shake_rad_per_s(resolved),
                  jitter_mm=float(resolved.parameter("jitter_um")) * 1e-3,
                  aperture_mm=math.sqrt(float(resolved.parameter("fill_factor"))) * p * 1e-3,
                  irradiance_lux=(lux * float(resolved.parameter("lens_transmittance"))
                                  * math.cos(math.radians(angle)) ** 4 / (4.0 * f_number ** 2)),
                  wavefront_rms_waves=float(resolved.parameter("wavefront_rms_waves")),
                  aberration=_aberration(aberration), lens_table=table)


def _border_px(sigma_px: float, sensor_cfa) -> int:
    """Output pixels of scene imaged round the chart: the denoising filter's reach, and a
    Bayer sensor's demosaicker's, to a whole cell."""
    border = kernel_reach_px(sigma_px)
    if sensor_cfa is not None:
        border += sensor_cfa.border_px + border % 2
    return border


def _frames_e(chart: Chart, optics: Optics, resolved, exposure_s: float, seed, border: int,
              sensor_cfa, threads: int) -> tuple:
    """(each frame's expected photo-electrons per sensor pixel, behind its filter; mm, the
    distance the image travels over the exposure)."""
    n = int(resolved.parameter("frames"))
    offsets = _alignment_offsets(seed, n,
                                 float(resolved.parameter("alignment_error_um")) * 1e-3)
    _check_frames(n, chart.shape, border, optics.binning)
    images, blur = frame_irradiance(chart, optics, exposure_s, n, offsets, threads,
                                    border_px=border)
    # a monochrome sensor behind a filter (cfa="none" with cfa_transmittance) collects t of
    # the light; a Bayer sensor's filters are its mosaic's
    t_filter = 1.0 if sensor_cfa is not None else float(resolved.color.transmittance)
    p = float(resolved.parameter("pixel_pitch_um"))
    yield_e = (float(resolved.parameter("electrons_per_lux_s_m2")) * (exposure_s / n)
               * float(resolved.parameter("fill_factor")) * (p * 1e-6) ** 2 * t_filter)
    frames_e = [image * yield_e for image in images]
    if sensor_cfa is not None:
        shape = (chart.shape[0] + 2 * border, chart.shape[1] + 2 * border)
        filters = sensor_cfa.mosaic(shape, optics.binning)
        frames_e = [frame * filters for frame in frames_e]
    return frames_e, blur


def _processed(image, sigma_px: float, border_px: int, sensor_cfa=None) -> np.ndarray:
    """The read-out image developed (a Bayer mosaic into its luminance), denoised
    (:mod:`~epc_fast.simulate.processing`) and cropped to the chart."""
    if sensor_cfa is not None:
        image = sensor_cfa.luminance(image)
    if border_px == 0:
        return image
    filtered = denoise(image, sigma_px)
    b = border_px
    return np.ascontiguousarray(filtered[b:filtered.shape[0] - b, b:filtered.shape[1] - b])


def _aberration(value) -> str:
    from .pupil import ABERRATIONS

    if not isinstance(value, str) or value not in ABERRATIONS:
        raise ValueError(f"aberration: one of {', '.join(map(repr, ABERRATIONS))}, got "
                         f"{short(value)}")
    return value


def _alignment_offsets(seed, frames: int, alignment_mm: float) -> np.ndarray:
    """mm, (dy, dx) of each frame: its alignment error, Gaussian of rms ``alignment_mm`` a
    side, taken about the frames' mean (the stack's position is arbitrary; its frames' spread
    about it is what blurs). Drawn from its own stream of ``seed``, so that the noise's stream
    is the same with and without a burst."""
    if frames == 1 or alignment_mm == 0.0:
        return np.zeros((frames, 2))
    root = seed if isinstance(seed, np.random.SeedSequence) else np.random.SeedSequence(seed)
    stream = np.random.SeedSequence(root.entropy, spawn_key=tuple(root.spawn_key) + (1,))
    drawn = np.random.default_rng(stream).normal(0.0, alignment_mm, (frames, 2))
    return drawn - drawn.mean(axis=0)


def _oversample(value, minimum: int) -> int:
    if (isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer))
            or value < minimum or value % 2 == 0):
        raise ValueError(f"oversample: an odd integer >= {minimum} (the least that carries "
                         f"this design's image without loss), got {short(value)}")
    return int(value)
