"""The public entry point: :func:`evaluate`, over NumPy arrays with broadcasting."""

from __future__ import annotations

import math

import numpy as np

from . import elasticity_outputs, params
from ._limits import MAX_THREADS
from ._validation import threads_of
from .core_call import run_core
from .design import ResolvedDesign, resolved_from
from .elasticity_outputs import ELASTICITY_PARAMETERS
from .footprint import check_memory
from .axes import asks_across, core_outputs, evaluate_axes
from .exposure_limits import asks_frames_used, asks_limits, evaluate_limits
from .modes import evaluate_modes
from .call_options import (BACKENDS, BINNING_READOUTS, F50_SOLVERS,  # noqa: F401 (api's names)
                           INVALID_POLICIES, PRECISIONS, T_MPE_SOLVERS, CallOptions, options_of)
from .outputs import (ALL_OUTPUT_DTYPES, OUTPUT_DTYPES, SENSITIVITY_OUTPUTS, attach_snr_target,
                      SHARE_OUTPUTS, Result, new_result, out_arrays, result_of)
from .sensor import size_and_field_angle
from .status import Status

__all__ = ["evaluate", "Result", "MAX_THREADS", "ELASTICITY_PARAMETERS", "OUTPUT_DTYPES",
           "ALL_OUTPUT_DTYPES", "SHARE_OUTPUTS", "SENSITIVITY_OUTPUTS"]

#: max_exposure_s's default, no frame cap: a call tells it by identity, its cheapest test.
_NO_CAP = math.inf
#: Points per call into the core between two checks for Ctrl-C (the GIL is released inside).
CHUNK_POINTS = 1 << 18


def _raise_first_invalid(arrays, names, status, shape, size_parts=None, lens_count=1):
    """A ValueError naming the first argument out of its domain at the first INVALID point;
    for a sensor area made of a width and a height (or a diagonal), ``size_parts`` names
    those and their values; ``lens_count`` lens tables set the domain of ``lens``."""
    flat = int(np.flatnonzero(status.reshape(-1) == Status.INVALID)[0])
    index = np.unravel_index(flat, shape) if shape else ()
    where = f" at index {tuple(int(i) for i in index)}" if shape else ""
    for param, name, arr in zip(params.parameters(lens_count), names, arrays):
        value = np.broadcast_to(arr, shape)[index]
        if params.in_domain(param, value):
            continue
        if param.name == "size" and size_parts:
            parts = ", ".join(f"{k}={float(np.broadcast_to(v, shape)[index])!r}"
                              for k, v in size_parts.items())
            raise ValueError(f"the sensor ({parts}){where} is outside its domain: each length "
                             f"in (0, {params.BIG:g}) mm and their area in "
                             f"{param.domain_text()} mm^2")
        raise ValueError(f"{name}={float(value)!r}{where} is outside its domain "
                         f"{param.domain_text()} ({param.meaning})")
    raise AssertionError("a point is INVALID but every input is in its domain")  # pragma: no cover


def _compute(design: ResolvedDesign, options: CallOptions, threads, given,
             epc_axes="motion", modes=None) -> dict:
    """The flat outputs of the chosen backend; the caller's ``out=`` arrays written. ``modes``
    (the core's readout modes, :func:`_modes_in_core`) adds ``"mode"``."""
    if options.backend == "core":  # threads checked by the caller
        # the core writes the caller's arrays and allocates the others it computes
        flat = {} if given is None else {k: v if v.ndim == 1 else v.reshape(-1)
                                         for k, v in given.items()}
        return run_core(design.arrays, design.shape, design.sensor.is_pixel_count,
                        design.spectrum, options.f50_solver,
                        options.f50_rtol, options.t_mpe_solver, options.t_mpe_rtol, threads,
                        out=flat, precision=options.precision,
                        allocate=options.computed if given is None else
                        [k for k in options.computed
                         if k not in flat and k != elasticity_outputs.ALL],
                        lens_tables=options.lens_tables, demosaic_table=options.demosaic_table,
                        chunk_points=CHUNK_POINTS, columns_ready=design.columns_ready,
                        epc_axes=epc_axes, modes=modes)
    if threads is not None:
        threads_of(threads)
    from .reference.call import run_reference  # the NumPy reference, loaded only when asked

    result = run_reference(design.arrays, design.shape, design.sensor.is_pixel_count,
                           design.spectrum, options.computed, options.lens_tables,
                           options.demosaic_table)
    if given is not None:  # the caller's arrays: every elasticity in one, or one row each
        rows = dict(zip(elasticity_outputs.ROWS, result.get(elasticity_outputs.ALL, ())))
        for name, array in given.items():
            np.copyto(array, rows.get(name, result.get(name)).reshape(array.shape))
    return result


def _assembled(result: dict, design: ResolvedDesign, options: CallOptions, given) -> Result:
    """The Result of a call, after the ValueError ``invalid="raise"`` asks for."""
    shape, is_pixel_count = design.shape, design.sensor.is_pixel_count
    if options.invalid == "raise" and "status" in result:
        status = result["status"].reshape(shape)
        if np.any(status == Status.INVALID):
            _raise_first_invalid(design.arrays, design.names, status, shape,
                                 design.sensor.parts, options.lens_count)
    if given is not None:
        kept = {name: array for name, array in given.items() if name in ALL_OUTPUT_DTYPES}
        if elasticity_outputs.ALL in given:
            kept["elasticities"] = elasticity_outputs.every_by_key(
                given[elasticity_outputs.ALL], shape, is_pixel_count, arrays=True)
        elif elasticity_outputs.rows_in(given):
            kept["elasticities"] = elasticity_outputs.by_key(given, is_pixel_count)
        return new_result(kept)
    rows = elasticity_outputs.rows_in(options.selected)
    return result_of({k: v for k, v in result.items() if k in options.selected or k in rows},
                     shape, is_pixel_count)


#: design.resolve's keywords, in its order, as evaluate passes its own.
_DESIGN_KEYWORDS = (
    "illuminance_lux", "pixel_pitch_um", "f_number", "focal_length_mm", "pixel_count",
    "sensor_area_mm2", "sensor_width_mm", "sensor_height_mm", "sensor_diagonal_mm", "aspect",
    "snr_at", "reflectance", "lens_transmittance", "field_angle_deg", "fill_factor",
    "electrons_per_lux_s_m2", "read_noise_e", "dark_current_e_per_s", "prnu", "full_well_e",
    "snr_db", "shake_deg_per_s", "stabilization", "jitter_um", "wavelength_nm", "mtf_threshold",
    "binning", "frames", "alignment_error_um", "wavefront_rms_waves", "denoise_sigma_px", "lens",
    "lens_mtf", "cfa", "demosaic", "cfa_transmittance", "color_noise_gain", "binning_readout",
    "spectrum")


def _modes_in_core(call: dict, modes: list, outputs) -> Result:
    """evaluate's Result over ``call`` (its keywords) for readout ``modes`` ((binning,
    binning_readout code, frames, alignment_error_um) each, None for the call's own) in the
    core's one pass (modes.h evaluate_modes), with the mode of each point (modes.py decides
    which calls come here)."""
    design = resolved_from(tuple(call[name] for name in _DESIGN_KEYWORDS))
    options = options_of(call["backend"], call["invalid"], call["f50_solver"], call["f50_rtol"],
                         call["t_mpe_solver"], call["t_mpe_rtol"], call["precision"], outputs,
                         design.sensor.is_pixel_count, design.lens_tables,
                         design.color.demosaic_table)
    threads = threads_of(call["threads"])
    check_memory(design.shape, design.arrays, "core", False, options.computed, threads=threads)
    flat = _compute(design, options, threads, None, call["epc_axes"], modes)
    mode = flat.pop("mode")
    fields = dict(vars(_assembled(flat, design, options, None)))
    fields["mode"] = mode.reshape(design.shape) if design.shape else int(mode[0])
    return new_result(fields)


def _asks_axes(outputs, epc_axes) -> bool:
    """Whether a call counts EPC in both directions or asks for an output across the motion."""
    return epc_axes != "motion" or (outputs is not None and asks_across(outputs))


def _two_passes(backend, out, outputs, epc_axes) -> bool:
    """Whether a call across the motion takes evaluate_axes' two passes: the reference
    backend, out=, or a share or elasticity asked for; the core solves the rest in one."""
    return backend != "core" or out is not None or core_outputs(outputs, epc_axes) is None


def evaluate(illuminance_lux, pixel_pitch_um, f_number, focal_length_mm, *,
             pixel_count=None, sensor_area_mm2=None, sensor_width_mm=None,
             sensor_height_mm=None, sensor_diagonal_mm=None, aspect=None, snr_at=None,
             reflectance=0.4, lens_transmittance=1.0,
             field_angle_deg=0.0, fill_factor=1.0, electrons_per_lux_s_m2=None,
             read_noise_e=0.0, dark_current_e_per_s=0.0, prnu=0.0, full_well_e=math.inf,
             snr_db=30.0, shake_deg_per_s=4.39, stabilization=1.0, jitter_um=0.0,
             wavelength_nm=550.0, mtf_threshold=0.5, binning=1.0, frames=1.0,
             alignment_error_um=0.0, wavefront_rms_waves=0.0, denoise_sigma_px=0.0, lens=0.0,
             lens_mtf=None, cfa="none", demosaic="malvar2004", cfa_transmittance=None,
             color_noise_gain=None, binning_readout="digital", spectrum=None, threads=None,
             backend="core", invalid="status", f50_solver="halley", f50_rtol=1e-14,
             t_mpe_solver="closed_form",
             t_mpe_rtol=1e-15, precision="float64", out=None, outputs=None, modes=None,
             epc_axes="motion", max_exposure_s=_NO_CAP, max_frames=None) -> Result:
    """Effective pixel count and its intermediates for camera designs (docs/model.md).

    Every model parameter is a float or an array_like of floats; all of them broadcast against
    each other, NumPy style. Domains are in :data:`epc_fast.params.PARAMETERS`; what the engine
    returns at their extremes, and how accurately, is in docs/numerics.md.

    Parameters
    ----------
    illuminance_lux : lux, illuminance on the scene's gray target (>= 0).
    pixel_pitch_um : um, pixel pitch.
    f_number : 1, working f-number.
    focal_length_mm : mm, focal length.
    sensor_width_mm, sensor_height_mm : mm, the sensor's active area, as its data sheet gives
        it; or
    sensor_diagonal_mm, aspect : mm and width:height (``"4:3"``, ``(4, 3)`` or 4/3), the same
        from a diagonal (``aspect`` is one value for the call); or
    sensor_area_mm2 : mm^2, the sensor's area; or
    pixel_count : pixels, the pixel count N (area N p^2).
        The sensor's size: give it one of these four ways. The model takes the area
        S = width x height exactly; the pixel count is S / p^2, not rounded (docs/sensor.md).
    snr_at : {"axis", "corner"}, optional
        Where the SNR target is met: on the optical axis (field angle 0) or at the image corner
        (field angle atan(half-diagonal / focal length), which needs the sensor's width and
        height or diagonal). None (the default): at ``field_angle_deg``.
    reflectance : 1, reflectance of the Lambertian gray target, in [0, 1].
    lens_transmittance : 1, lens and filter transmittance, in [0, 1].
    field_angle_deg : degree, field angle of the image point where the SNR target is met (cos^4
        falloff), in (-90, 90); 0, the axis, by default. Not with ``snr_at``.
    fill_factor : 1, light-collecting fraction of the pixel area, in (0, 1].
    electrons_per_lux_s_m2 : e-/(lux s m^2), K; None for the D50 + rect-QE default
        (:data:`epc_fast.spectra.DEFAULT_ELECTRONS_PER_LUX_S_M2`).
    read_noise_e : e- rms, read noise.
    dark_current_e_per_s : e-/s, dark current.
    prnu : 1, photo-response non-uniformity, rms fraction of the signal.
    full_well_e : e-, full-well capacity (inf: none).
    snr_db : dB, target SNR 20 log10(signal/noise).
    shake_deg_per_s : degree/s, camera angular velocity during the exposure (4.39, the
        paper's, by default).
    stabilization : 1, image stabilisation factor k (motion divided by k).
    jitter_um : um, rms Gaussian jitter (0: off).
    wavelength_nm : nm, wavelength for monochromatic diffraction.
    mtf_threshold : 1, MTF level defining the cut-off frequency, in (0, 1).
    binning : 1, pixel binning k, a whole number >= 1: k x k pixels read as one output pixel
        (1: off; docs/model.md, "Exposure: T_MPE" and "System MTF").
    frames : 1, burst capture n, a whole number >= 1: the exposure split into n frames,
        aligned and summed (1: off); or ``"auto"``, night mode (``max_frames``).
    alignment_error_um : um, rms alignment error of each frame of a burst (0: off).
    wavefront_rms_waves : waves, rms wavefront error at every wavelength (0: off; <= 0.16).
    denoise_sigma_px : output pixels, sigma of a Gaussian denoising filter (0: off; <= 100).
    lens : 1, the index of each point's table in ``lens_mtf``, a whole number in
        0 .. len(lens_mtf) - 1 (0, the only valid value without ``lens_mtf``).
    lens_mtf : (frequencies_cyc_per_mm, mtf) or list of them, optional
        A lens's measured or designed MTF, two 1-D arrays (cycles/mm and 1; 1 at frequency 0,
        never rising), interpolated monotonically and used in place of the aberration-free
        diffraction factor (docs/model.md, "Tabulated MTFs"); a list of tables for a per-point
        ``lens`` index. Not with ``wavefront_rms_waves`` (the table has the lens's
        aberrations). A point whose f50 lies past its table's last frequency has status
        BEYOND_TABLE.
    cfa : {"none", "bayer", "quad_bayer"}
        The monochrome sensor, a Bayer colour filter array, or a quad Bayer one (2 x 2
        same-colour cells: read at ``binning`` 1, remosaicked to Bayer, or 2, a Bayer sensor of
        twice the pitch; one binning a call) (docs/model.md, "The colour filter array"): the
        rate times ``cfa_transmittance``, every noise variance times ``color_noise_gain`` and
        the demosaicker's (or remosaic's) noise gain, the MTF times its luminance MTF.
    demosaic : {"malvar2004", "bilinear", "menon2007"}
        The colour sensor's demosaicker (:mod:`epc_fast.cfa`).
    cfa_transmittance : 1, the colour cell's electrons against those of the monochrome sensor
        that ``electrons_per_lux_s_m2`` describes, under the same light, in (0, 1];
        default :data:`epc_fast.cfa.DEFAULT_CFA_TRANSMITTANCE` with a colour filter
        (:func:`epc_fast.cfa.bayer_light` computes it from spectra).
    color_noise_gain : 1, the colour correction's noise variance gain to luminance, in
        [0.01, 100] (times the demosaicker's or the remosaic's);
        default :data:`epc_fast.cfa.DEFAULT_COLOR_NOISE_GAIN` with a colour filter.
    binning_readout : {"digital", "charge"} or array_like of them
        How a binned pixel is read, per point: k^2 reads summed digitally (read noise
        variance k^2 sigma_r^2, the default), or the k x k pixels' charge summed before one
        read (sigma_r^2). Broadcast like the parameters (as 0 and 1, its codes in
        :data:`epc_fast.params.READOUT_CODES`, which it also takes).
    spectrum : Spectrum or (wavelengths_nm, weights), optional
        Polychromatic diffraction, D(f) = sum_i w_i D_i(f), shared by every point (weights
        normalised to sum 1); see :func:`epc_fast.spectra.diffraction_spectrum`. Replaces
        ``wavelength_nm``.
    threads : int, optional
        Core threads, 1 to 1024; default ``OMP_NUM_THREADS`` or the number of cores. Results
        are identical for every thread count. Each thread maps a stack (``OMP_STACKSIZE``, or
        ``ulimit -s``): under an address-space limit (``RLIMIT_AS``, ``ulimit -v``) a
        ``threads=`` above what the process can start is a ValueError saying how many it can,
        and the default is capped to the threads whose stacks take at most half the address
        space left.
    backend : {"core", "reference"}
        The compiled core, or the NumPy reference (which ignores the solver knobs: it uses the
        closed-form T_MPE and bisects f50 to adjacent floats).
    invalid : {"status", "raise"}
        Out-of-domain inputs give status INVALID and NaN outputs, or a ValueError naming the
        first offending argument, value and index.
    f50_solver : {"halley", "newton", "brent", "bisection"}
        f50's root finder; every one keeps its iterates inside the bisection bracket of
        docs/model.md, "The cut-off frequency f50". Halley (the default) and Newton use the
        MTF's analytic slopes from a starting guess and stop once their last step predicts an
        error far below ``f50_rtol``, or take no step where the guess is certified within
        ``f50_rtol`` (at MTF50 without jitter from 1e-7: f50 within 4.2e-8 for the guess's
        price alone); Brent and bisection narrow the bracket to ``f50_rtol``. docs/numerics.md
        has their measured errors and speeds.
    f50_rtol : 1, relative tolerance on f50.
    t_mpe_solver : {"closed_form", "brent"}
        The closed-form quadratic root, or Brent's method on ln SNR(T) = ln SNR_target.
    t_mpe_rtol : 1, Brent's relative tolerance on T_MPE.
    precision : {"float64", "float32"}
        The type f50 is solved in by the core. ``"float32"`` raises ``f50_rtol`` to at least
        2^-21 = 4.8e-7: with Halley or Newton an MTF50 point without jitter takes its
        certified starting guess (float64, rounded once: within 1e-7), and every other point
        is solved in float32 on twice the vector lanes, for f50 to about 5e-7 relative
        (docs/numerics.md has the measured errors and speeds). Statuses, T_MPE, blur and the
        electron counts are float64 in both, so they are the same in both;
        a point whose lengths float32 cannot hold (outside 2^-40..2^40 mm) is solved in float64.
        Outputs are float64 arrays either way. The reference backend ignores it.
    out : Result or mapping of its field names to arrays, optional
        Arrays to write the outputs into, one per :class:`Result` field: each of the broadcast
        shape, C-contiguous, writeable, native float64 (``status`` and ``cause``: uint8), none
        overlapping another. A large call streams its outputs past the caches (README); arrays
        aligned to 64 bytes, as the core's own are, stream every line. The returned Result
        holds these same arrays (0-d arrays, not scalars, for scalar input). With
        ``invalid="raise"`` they are written before the error. With ``outputs=``, exactly the
        fields it names.
    outputs : str or iterable of str, optional
        The :class:`Result` fields to compute (default: all); the others are None in the
        Result. The core writes only these, and skips f50's solve when neither
        ``f50_cyc_per_mm`` nor ``epc`` is asked for: e.g. ``("epc", "status")`` for a scan that
        keeps only those, ``("t_mpe_s",)`` for exposures alone.
    modes : list of dict, optional
        Readout modes (:mod:`epc_fast.modes`), e.g. ``[{"binning": 1}, {"binning": 4}]``:
        each point gets the outputs of the mode with the highest EPC, its index in
        :attr:`Result.mode`.
    epc_axes : {"motion", "both"}
        How EPC counts the resolution (docs/model.md, "Resolution in both directions"):
        ``"motion"`` (the default), the paper's 4 S f50^2 with f50 along the motion; ``"both"``,
        4 S f50 f50_across, each direction once (f50_across, the system MTF's f50 without the
        motion blur, then a default output). The modes' pick, the elasticities and everything
        else that reads EPC read it. ``"both"`` solves f50 a second time.
    max_exposure_s : s, the longest single frame the camera takes, in (0, inf], per point
        (broadcast like the parameters; inf, the default: no cap). A point whose frame
        T_MPE / frames is longer has status EXPOSURE_LIMIT: T_MPE and the electron counts
        finite, blur, f50 and EPC NaN (docs/model.md, "Exposure limits and night mode").
    max_frames : whole number in 1 .. 1024, with ``frames="auto"`` only (night mode): each
        point takes the least n <= max_frames whose frame T_MPE(n) / n is within
        ``max_exposure_s`` (max_frames, and EXPOSURE_LIMIT, where none is); the n taken is the
        output ``frames_used``, then a default output.

    Returns
    -------
    Result
        The outputs in new arrays (except those of ``out``). The core takes the memory of
        arrays of 1 MiB and more from memory kept from earlier calls' dropped results where it
        can (:func:`epc_fast.output_cache`: no zeroing of new pages by the OS), so such an
        array's ``base`` chain ends in a capsule instead of owning its data; it behaves as any
        array otherwise.

    Raises
    ------
    TypeError
        For a sensor size given no way or more than one way, or ``snr_at`` with
        ``field_angle_deg``; the message names the arguments and their values.
    MemoryError
        Before anything is allocated, when the call would need more memory than the machine
        (or its container) has: evaluate such a grid in pieces.
    """
    if (modes is not None or max_exposure_s is not _NO_CAP or max_frames is not None
            or (outputs is not None and asks_frames_used(outputs))
            or (_asks_axes(outputs, epc_axes) and _two_passes(backend, out, outputs, epc_axes))):
        # evaluate's own keywords to each mode, to the frame cap's passes, or to the passes
        # along and across the motion
        call = dict(locals())
        result = (evaluate_modes(evaluate, call, _modes_in_core) if modes is not None
                  else evaluate_limits(evaluate, call) if asks_limits(call)
                  else evaluate_axes(evaluate, call))
        _, angle = size_and_field_angle(pixel_count, sensor_area_mm2, sensor_width_mm,
                                        sensor_height_mm, sensor_diagonal_mm, aspect, snr_at,
                                        field_angle_deg, focal_length_mm)
        return attach_snr_target(result, snr_db, snr_at, angle)
    if _asks_axes(outputs, epc_axes):  # the f50 across the motion in the core's one pass
        outputs = core_outputs(outputs, epc_axes)
    design = resolved_from((  # design.resolve's keywords, in its order
        illuminance_lux, pixel_pitch_um, f_number, focal_length_mm, pixel_count, sensor_area_mm2,
        sensor_width_mm, sensor_height_mm, sensor_diagonal_mm, aspect, snr_at, reflectance,
        lens_transmittance, field_angle_deg, fill_factor, electrons_per_lux_s_m2, read_noise_e,
        dark_current_e_per_s, prnu, full_well_e, snr_db, shake_deg_per_s, stabilization, jitter_um,
        wavelength_nm, mtf_threshold, binning, frames, alignment_error_um, wavefront_rms_waves,
        denoise_sigma_px, lens, lens_mtf, cfa, demosaic, cfa_transmittance, color_noise_gain,
        binning_readout, spectrum))
    options = options_of(backend, invalid, f50_solver, f50_rtol, t_mpe_solver, t_mpe_rtol,
                         precision, outputs, design.sensor.is_pixel_count,
                         design.lens_tables, design.color.demosaic_table)
    given = (None if out is None
             else out_arrays(out, design.shape, options.selected, design.sensor.is_pixel_count,
                             core=options.backend == "core"))
    if options.backend == "core":  # the threads first: their stacks take memory too
        threads = threads_of(threads)
    check_memory(design.shape, design.arrays, options.backend, given is not None,
                 options.computed, threads=threads if options.backend == "core" else 1)
    result = _assembled(_compute(design, options, threads, given, epc_axes), design, options,
                        given)
    return attach_snr_target(result, snr_db, snr_at, design.field_angle_deg)
