"""A camera design: :class:`Design`, as a data sheet gives it, and :func:`resolve`, a design's
:func:`epc_fast.evaluate` keywords as the model's columns.

:func:`resolve` is the one place where a design's keywords become the model's parameters, for
evaluate, the inverse solvers (:mod:`epc_fast.inverse`), a scan's core plan and the capture
simulator (:mod:`epc_fast.simulate.camera`): the sensor's size given any of four ways and where
the SNR target is met (:mod:`epc_fast.sensor`), the colour sensor (:mod:`epc_fast.cfa`), a
spectrum whose weight is all on one wavelength made the monochromatic model at it, the lens
tables and the defaults, all broadcast to float64 arrays in :data:`epc_fast.params.PARAMETERS`
order.
"""

from __future__ import annotations

import functools
import inspect
import math
import numbers
from collections.abc import Mapping
from dataclasses import InitVar, asdict, dataclass, replace
from typing import NamedTuple

import numpy as np

from . import params
from ._validation import float_arrays, short
from .cfa import SensorColor, sensor_color
from .mtf_table import check_lens_tables, lens_tables_of
from .sensor import (SizeSlot, check_snr_at, physical_pixel_count, sensor_shape,
                     size_and_field_angle, snr_at_text)
from .sensor import corner_field_angle_deg as _corner_angle
from .spectra import DEFAULT_ELECTRONS_PER_LUX_S_M2, Spectrum

__all__ = ["Reading", "READINGS", "PRESET_READING", "IS_FACTOR", "Design",
           "corner_field_angle_deg", "DESIGN_KEYWORDS", "ResolvedDesign", "resolve",
           "resolved_from", "spectrum_of", "one_wavelength"]

#: How a Design can be given its sensor, for error messages.
SIZE_WAYS_OF_DESIGN = ("sensor_width_mm and sensor_height_mm, or sensor_diagonal_mm and "
                       "aspect, or columns and rows")


@dataclass(frozen=True)
class Reading:
    """How a design reads the paper's SNR target: its level and where it must be met.

    Attributes
    ----------
    name : str
    snr_db : dB, the target SNR.
    at_corner : bool, met at the image corner (cos^4 at half the diagonal field of view) rather
        than on the optical axis.
    meaning : str
    """

    name: str
    snr_db: float
    at_corner: bool
    meaning: str


#: The readings of the paper's SNR target, by name (docs/model.md, "The paper's systems").
READINGS = {r.name: r for r in (
    Reading("corner_30db", 30.0, True,
            "30 dB at the image corner (cos^4 falloff): the preset's reading of the paper"),
    Reading("on_axis_30db", 30.0, False, "30 dB on the optical axis: the paper's text, literally"),
    Reading("on_axis_33db", 33.0, False,
            "33 dB on the optical axis: the paper's Table 1, literally"),
)}
#: The reading the presets use unless told otherwise.
PRESET_READING = "corner_30db"
#: 1, the paper's image stabilisation: "4x IS" divides the motion by 4.
IS_FACTOR = 4.0
#: The sensor's and the readout's fields of a Design and evaluate's defaults for them.
_SENSOR_DEFAULTS = {"read_noise_e": 0.0, "dark_current_e_per_s": 0.0, "prnu": 0.0,
                    "full_well_e": math.inf, "fill_factor": 1.0, "binning": 1,
                    "binning_readout": "digital", "frames": 1, "alignment_error_um": 0.0}


def corner_field_angle_deg(width_mm: float, height_mm: float, focal_length_mm: float) -> float:
    """degree: half the diagonal field of view, atan(half-diagonal / focal length)."""
    return float(_corner_angle(width_mm, height_mm, focal_length_mm))


@dataclass(frozen=True)
class Design:
    """A camera design: everything :func:`epc_fast.evaluate` needs except the illuminance.

    Give the sensor as its data sheet does: ``sensor_width_mm`` and ``sensor_height_mm``, or
    ``sensor_diagonal_mm`` and ``aspect`` (e.g. ``"4:3"``), or the array (``columns`` and
    ``rows``, the sensor then being columns x rows pixels of ``pixel_pitch_um``)::

        Design("50 Mpx 1/1.56-inch", 1.0, sensor_diagonal_mm=10.24, aspect="4:3",
               f_number=1.9, focal_length_mm=5.7)

    EPC uses the sensor's area, width x height (docs/model.md, "EPC"), and so does the physical
    pixel count, :attr:`pixel_count` = area / pitch^2; the array, when not given, is the
    sensor's width and height over the pitch, each rounded to the nearest pixel.

    Attributes
    ----------
    name : str
    pixel_pitch_um : um, pixel pitch.
    columns, rows : pixels, the array (the paper's name for a design: 1600 x 1200); their
        product is not the physical pixel count, :attr:`pixel_count`.
    sensor_width_mm, sensor_height_mm : mm, the sensor's (nominal) format.
    f_number : 1.
    focal_length_mm : mm.
    stabilization : 1, image stabilisation factor k.
    reading : str, a key of :data:`READINGS`: the SNR target and, unless ``snr_at`` says
        otherwise, where it is met.
    snr_at : {"corner", "axis"} or float, optional
        Where the SNR target is met: the image corner, the optical axis, or a field angle in
        degrees. None (the default): where the reading says (the corner for the presets).
    sensor_diagonal_mm, aspect : mm and width:height, the format from its diagonal (used only
        when constructing; the width and height are kept).
    read_noise_e, dark_current_e_per_s, prnu, full_well_e, fill_factor : the sensor, as
        :func:`epc_fast.evaluate` takes them (defaults: the paper's ideal sensor).
    binning, binning_readout, frames, alignment_error_um : how the sensor is read
        (docs/model.md: binning k x k pixels as one, a burst of frames).
    modes : readout modes the camera picks from shot by shot, each a dict of ``binning``,
        ``binning_readout``, ``frames`` and ``alignment_error_um`` (:mod:`epc_fast.modes`);
        kept as tuples of (key, value) pairs so that a Design stays hashable.
    """

    name: str
    pixel_pitch_um: float
    columns: int | None = None
    rows: int | None = None
    sensor_width_mm: float | None = None
    sensor_height_mm: float | None = None
    f_number: float | None = None
    focal_length_mm: float | None = None
    stabilization: float = 1.0
    reading: str = PRESET_READING
    snr_at: str | float | None = None
    sensor_diagonal_mm: InitVar[float | None] = None
    aspect: InitVar[object] = None
    read_noise_e: float = 0.0
    dark_current_e_per_s: float = 0.0
    prnu: float = 0.0
    full_well_e: float = math.inf
    fill_factor: float = 1.0
    binning: int = 1
    binning_readout: str = "digital"
    frames: int = 1
    alignment_error_um: float = 0.0
    modes: tuple | None = None

    def __post_init__(self, sensor_diagonal_mm, aspect):
        if self.reading not in READINGS:
            raise ValueError(f"reading must be one of {', '.join(map(repr, READINGS))}; "
                             f"got {self.reading!r}")
        for name in ("pixel_pitch_um", "f_number", "focal_length_mm"):
            value = getattr(self, name)
            if value is None:
                raise TypeError(f"Design {self.name!r} needs {name}")
            if not (isinstance(value, numbers.Real) and math.isfinite(value) and value > 0):
                raise ValueError(f"Design {self.name!r}: {name}={value!r} must be a positive "
                                 "number")
        if isinstance(self.snr_at, str):
            check_snr_at(self.snr_at)
        elif self.snr_at is not None and not isinstance(self.snr_at, numbers.Real):
            raise ValueError(f"Design {self.name!r}: snr_at={self.snr_at!r}: expected 'corner', "
                             "'axis' or a field angle in degrees")
        self._set_format(sensor_diagonal_mm, aspect)
        if self.modes is not None:
            from .modes import check_modes

            modes = check_modes(self.modes if isinstance(self.modes, Mapping)
                                else [m if isinstance(m, Mapping) else dict(m)
                                      for m in self.modes])
            object.__setattr__(self, "modes", tuple(tuple(m.items()) for m in modes))

    def _set_format(self, sensor_diagonal_mm, aspect):
        """Fills in the format from the diagonal or the array, and the array from the format."""
        pitch_mm = self.pixel_pitch_um * 1e-3
        array = (self.columns, self.rows)
        if (array[0] is None) != (array[1] is None):
            raise TypeError(f"Design {self.name!r}: give both columns and rows, got "
                            f"columns={self.columns!r}, rows={self.rows!r}")
        size = {"sensor_width_mm": self.sensor_width_mm,
                "sensor_height_mm": self.sensor_height_mm,
                "sensor_diagonal_mm": sensor_diagonal_mm, "aspect": aspect}
        if all(v is None for v in size.values()):
            if array[0] is None:
                raise TypeError(f"Design {self.name!r} needs its sensor: {SIZE_WAYS_OF_DESIGN}")
            size = {"sensor_width_mm": self.columns * pitch_mm,
                    "sensor_height_mm": self.rows * pitch_mm}
        try:
            width, height = (float(v) for v in sensor_shape(**size))
        except TypeError as error:
            raise TypeError(f"Design {self.name!r}: {error}") from None
        if not (math.isfinite(width * height) and width > 0 and height > 0):
            raise ValueError(f"Design {self.name!r}: the sensor's width and height must be "
                             f"positive, got {width!r} x {height!r} mm")
        object.__setattr__(self, "sensor_width_mm", width)
        object.__setattr__(self, "sensor_height_mm", height)
        if array[0] is None:
            object.__setattr__(self, "columns", round(width / pitch_mm))
            object.__setattr__(self, "rows", round(height / pitch_mm))

    @property
    def pixel_count(self) -> float:
        """pixels: the physical pixel count N = S / p², the sensor's area over the pitch squared
        (:func:`epc_fast.sensor.physical_pixel_count`, docs/model.md, "EPC"), unrounded: the N
        of EPC = N (f50 / f_Nyq)², the paper's figures' dotted lines and a scan's, and what the
        paper's kept fractions divide by. Not ``columns * rows``: a preset's array is a little
        smaller than its format (1600 x 1200 = 1.92 Mpixel against 2.00 Mpixel for the 1/3.2"
        2.8 um design)."""
        return physical_pixel_count(self.sensor_area_mm2, self.pixel_pitch_um)

    @property
    def sensor_area_mm2(self) -> float:
        """mm^2: the format's nominal area."""
        return self.sensor_width_mm * self.sensor_height_mm

    @property
    def diagonal_field_of_view_deg(self) -> float:
        """degree: the full diagonal field of view, twice the corner's field angle."""
        return 2.0 * corner_field_angle_deg(self.sensor_width_mm, self.sensor_height_mm,
                                            self.focal_length_mm)

    @property
    def where_snr_is_met(self) -> str:
        """"corner", "axis" or "angle": where the SNR target is met."""
        if self.snr_at is None:
            return "corner" if READINGS[self.reading].at_corner else "axis"
        return self.snr_at if isinstance(self.snr_at, str) else "angle"

    @property
    def field_angle_deg(self) -> float:
        """degree: where the SNR target is met: the image corner's field angle, 0 on the axis,
        or the design's ``snr_at`` angle."""
        where = self.where_snr_is_met
        if where == "angle":
            return float(self.snr_at)
        if where == "axis":
            return 0.0
        return corner_field_angle_deg(self.sensor_width_mm, self.sensor_height_mm,
                                      self.focal_length_mm)

    @property
    def snr_at_text(self) -> str:
        """Where the SNR target is met, for people: ``"corner (27.03 deg)"``, ``"axis"``;
        marked "(default)" when it is the preset reading's and nobody chose it."""
        where = self.where_snr_is_met
        default = self.snr_at is None and self.reading == PRESET_READING
        return snr_at_text(None if where == "angle" else where, self.field_angle_deg, default)

    @property
    def snr_db(self) -> float:
        """dB: the target SNR of the design's reading."""
        return READINGS[self.reading].snr_db

    def evaluate_kwargs(self) -> dict:
        """Keyword arguments for :func:`epc_fast.evaluate` (all but the illuminance); the
        sensor's and the readout's only where they differ from evaluate's defaults, and the
        modes as a list of dicts."""
        kwargs = {
            "pixel_pitch_um": self.pixel_pitch_um, "f_number": self.f_number,
            "focal_length_mm": self.focal_length_mm, "sensor_area_mm2": self.sensor_area_mm2,
            "field_angle_deg": self.field_angle_deg, "snr_db": self.snr_db,
            "stabilization": self.stabilization,
        }
        for name, default in _SENSOR_DEFAULTS.items():
            value = getattr(self, name)
            if value != default:
                kwargs[name] = value
        if self.modes is not None:
            kwargs["modes"] = [dict(m) for m in self.modes]
        return kwargs

    def with_(self, **changes) -> "Design":
        """A copy with some fields changed (a new pitch keeps the format and the array)."""
        return replace(self, **changes)

    def read_as(self, reading: str) -> "Design":
        """The same design under another reading of the paper (a key of :data:`READINGS`)."""
        return self.with_(reading=reading)

    def stabilized(self, factor: float = IS_FACTOR) -> "Design":
        """The design with image stabilisation: motion divided by ``factor`` (1)."""
        return self.with_(name=f"{self.name} {factor:g}x IS", stabilization=factor)

    def as_dict(self) -> dict:
        return asdict(self)



# --- A design's keywords as the model's columns ---------------------------------------------


def spectrum_of(spectrum, wavelength_nm=550.0) -> Spectrum | None:
    """``spectrum`` (a :class:`~epc_fast.spectra.Spectrum` or a pair (wavelengths_nm, weights))
    as a Spectrum, None for None; a TypeError for anything else, a ValueError when
    ``wavelength_nm`` (nm) is given too (not its default 550)."""
    if spectrum is None:
        return None
    if not isinstance(spectrum, Spectrum):
        try:
            wavelengths, weights = spectrum
        except (TypeError, ValueError):
            raise TypeError("spectrum must be an epc_fast.Spectrum or a pair "
                            f"(wavelengths_nm, weights), got {short(spectrum)}") from None
        spectrum = Spectrum(wavelengths, weights)
    if not np.all(np.asarray(wavelength_nm) == 550.0):
        raise ValueError("pass either wavelength_nm or spectrum, not both "
                         f"(wavelength_nm={short(wavelength_nm)})")
    return spectrum


def one_wavelength(spec: Spectrum | None):
    """nm: the wavelength (a 0-d float64 array) of a spectrum whose weight is all on that one
    wavelength, in the domain of ``wavelength_nm``; None for no spectrum or any other.

    Such a spectrum is the monochromatic model at that wavelength, exactly (1 D + 0 D' = D,
    and the bracket's shortest wavelength is that one), so that the core takes its
    monochromatic path (no loop over the spectrum, the accurate f50 start)."""
    if spec is None:
        return None
    positive = np.flatnonzero(spec.weights > 0)
    if positive.size != 1 or not params.in_domain(params.PARAMETERS[_WAVELENGTH],
                                                   spec.wavelengths_nm[positive[0]]):
        return None
    return np.asarray(spec.wavelengths_nm[positive[0]], dtype=np.float64)


_WAVELENGTH = params.PARAMETER_NAMES.index("wavelength_nm")
_F_NUMBER, _PITCH, _LENS = (params.PARAMETER_NAMES.index(n)
                             for n in ("f_number", "pixel_pitch_um", "lens"))


class ResolvedDesign(NamedTuple):
    """A design's keywords as the model takes them (:func:`resolve`).

    Attributes
    ----------
    names : the parameters' names as the caller gave them (the size under its own name), in
        :data:`epc_fast.params.PARAMETERS` order, for messages.
    arrays : list of the parameters' float64 arrays in that order, as the core takes them (a
        spectrum on one wavelength made that ``wavelength_nm``).
    shape : their broadcast shape.
    columns_ready : whether the arrays are the core's columns as they are (0-d, or
        C-contiguous of ``shape``).
    sensor : :class:`~epc_fast.sensor.SizeSlot`, the size slot: a pixel count or an area, and
        the lengths it was made of.
    field_angle_deg : degree, where the SNR target is met (``snr_at`` resolved).
    spectrum : the :class:`~epc_fast.spectra.Spectrum` the model runs, None for the
        monochromatic model (a spectrum on one wavelength included).
    given_spectrum : the caller's spectrum as a Spectrum (its zero weights kept), or None.
    color : :class:`~epc_fast.cfa.SensorColor`, the colour sensor: transmittance, noise gain
        and demosaicker's table.
    lens_tables : the checked ``lens_mtf`` tables (:class:`~epc_fast.mtf_table.MtfTable`),
        or None.
    """

    names: tuple
    arrays: list
    shape: tuple
    columns_ready: bool
    sensor: SizeSlot
    field_angle_deg: object
    spectrum: Spectrum | None
    given_spectrum: Spectrum | None
    color: SensorColor
    lens_tables: tuple | None

    def parameter(self, name: str) -> np.ndarray:
        """The float64 array of the parameter ``name`` (:data:`epc_fast.params.PARAMETERS`)."""
        return self.arrays[params.PARAMETER_NAMES.index(name)]

    def wavelengths(self) -> tuple:
        """(nm, 1): the wavelengths the lens images and their weights: the caller's spectrum,
        or ``wavelength_nm`` with weight 1."""
        if self.given_spectrum is None:
            return np.reshape(self.parameter("wavelength_nm"), (-1,)), np.array([1.0])
        return (np.asarray(self.given_spectrum.wavelengths_nm),
                np.asarray(self.given_spectrum.weights))

    def lens_table(self):
        """The lens table of a design of one point, ``lens_mtf[lens]``, or None."""
        if self.lens_tables is None:
            return None
        return self.lens_tables[int(self.parameter("lens"))]



@functools.lru_cache(maxsize=None)
def _argument_names(size_name: str) -> tuple:
    """The model parameters' names as the caller gave them (the size under ``size_name``), in
    the core's order."""
    return tuple(size_name if n == "size" else n for n in params.PARAMETER_NAMES)


def _broadcast_inputs(values: tuple, size_name: str) -> tuple:
    """(names, float64 arrays, broadcast shape, whether the arrays are the core's columns as
    they are) of the model parameters' ``values`` in the core's order."""
    names = _argument_names(size_name)
    arrays, shapes, contiguous = float_arrays(names, values)
    ready = contiguous and len(shapes) <= 1
    try:  # most calls: a few arrays of one shape, and scalars
        shape = (shapes.pop() if len(shapes) == 1 else
                 np.broadcast_shapes(*shapes) if shapes else ())
    except ValueError:
        shapes = ", ".join(f"{n}{a.shape}" for n, a in zip(names, arrays) if a.ndim)
        raise ValueError(f"the arguments' shapes do not broadcast: {shapes}") from None
    return names, arrays, shape, ready


def resolve(illuminance_lux, pixel_pitch_um, f_number, focal_length_mm, *,
            pixel_count=None, sensor_area_mm2=None, sensor_width_mm=None,
            sensor_height_mm=None, sensor_diagonal_mm=None, aspect=None, snr_at=None,
            reflectance=0.4, lens_transmittance=1.0,
            field_angle_deg=0.0, fill_factor=1.0, electrons_per_lux_s_m2=None,
            read_noise_e=0.0, dark_current_e_per_s=0.0, prnu=0.0, full_well_e=math.inf,
            snr_db=30.0, shake_deg_per_s=4.39, stabilization=1.0, jitter_um=0.0,
            wavelength_nm=550.0, mtf_threshold=0.5, binning=1.0, frames=1.0,
            alignment_error_um=0.0, wavefront_rms_waves=0.0, denoise_sigma_px=0.0, lens=0.0,
            lens_mtf=None, cfa="none", demosaic="malvar2004", cfa_transmittance=None,
            color_noise_gain=None, binning_readout="digital",
            spectrum=None) -> ResolvedDesign:
    """A design's :func:`epc_fast.evaluate` keywords (the same, with the same defaults and
    units) as :class:`ResolvedDesign`: the model's float64 arrays broadcast against each other.

    Raises TypeError for a sensor size given no way or more than one way, or ``snr_at`` with
    ``field_angle_deg``, or a bad spectrum; ValueError for shapes that do not broadcast, a
    wavelength with a spectrum, a bad colour sensor, lens table or ``binning_readout``; every
    message names the argument and its value.
    """
    return resolved_from((
        illuminance_lux, pixel_pitch_um, f_number, focal_length_mm, pixel_count, sensor_area_mm2,
        sensor_width_mm, sensor_height_mm, sensor_diagonal_mm, aspect, snr_at, reflectance,
        lens_transmittance, field_angle_deg, fill_factor, electrons_per_lux_s_m2, read_noise_e,
        dark_current_e_per_s, prnu, full_well_e, snr_db, shake_deg_per_s, stabilization, jitter_um,
        wavelength_nm, mtf_threshold, binning, frames, alignment_error_um, wavefront_rms_waves,
        denoise_sigma_px, lens, lens_mtf, cfa, demosaic, cfa_transmittance, color_noise_gain,
        binning_readout, spectrum))


def resolved_from(keywords: tuple) -> ResolvedDesign:
    """:func:`resolve` of its keywords' values as one tuple, in :data:`DESIGN_KEYWORDS`' order:
    :func:`epc_fast.evaluate` hands them over so, which costs a tenth of passing forty keyword
    arguments or a dict of them."""
    (
        illuminance_lux, pixel_pitch_um, f_number, focal_length_mm, pixel_count, sensor_area_mm2,
        sensor_width_mm, sensor_height_mm, sensor_diagonal_mm, aspect, snr_at, reflectance,
        lens_transmittance, field_angle_deg, fill_factor, electrons_per_lux_s_m2, read_noise_e,
        dark_current_e_per_s, prnu, full_well_e, snr_db, shake_deg_per_s, stabilization, jitter_um,
        wavelength_nm, mtf_threshold, binning, frames, alignment_error_um, wavefront_rms_waves,
        denoise_sigma_px, lens, lens_mtf, cfa, demosaic, cfa_transmittance, color_noise_gain,
        binning_readout, spectrum) = keywords
    sensor, field_angle_deg = size_and_field_angle(
        pixel_count, sensor_area_mm2, sensor_width_mm, sensor_height_mm, sensor_diagonal_mm,
        aspect, snr_at, field_angle_deg, focal_length_mm)
    if electrons_per_lux_s_m2 is None:
        electrons_per_lux_s_m2 = DEFAULT_ELECTRONS_PER_LUX_S_M2
    color = sensor_color(cfa, demosaic, cfa_transmittance, color_noise_gain, binning)
    readout = params.readout_codes(binning_readout)
    values = (  # the model's parameters in params.PARAMETER_NAMES' order
        illuminance_lux, pixel_pitch_um, f_number, focal_length_mm, sensor.value, reflectance,
        lens_transmittance, field_angle_deg, fill_factor, electrons_per_lux_s_m2,
        read_noise_e, dark_current_e_per_s, prnu, full_well_e, snr_db, shake_deg_per_s,
        stabilization, jitter_um, wavelength_nm, mtf_threshold, binning, frames,
        alignment_error_um, wavefront_rms_waves, denoise_sigma_px, lens, color.transmittance,
        color.noise_gain, readout)
    names, arrays, shape, ready = _broadcast_inputs(values, sensor.name)
    given = spectrum_of(spectrum, wavelength_nm)
    model_spectrum, wavelength = given, one_wavelength(given)
    if wavelength is not None:  # the monochromatic model at it
        arrays = list(arrays)
        arrays[_WAVELENGTH] = wavelength
        model_spectrum = None
    tables = None if lens_mtf is None else lens_tables_of(lens_mtf, wavefront_rms_waves)
    if tables is not None:  # against diffraction at the points' f-numbers and wavelengths
        shortest = (arrays[_WAVELENGTH] if given is None
                    else np.min(given.wavelengths_nm[given.weights > 0.0]))
        check_lens_tables(tables, arrays[_F_NUMBER], shortest, arrays[_PITCH], arrays[_LENS])
    return ResolvedDesign(names, arrays, shape, ready, sensor, field_angle_deg,
                          model_spectrum, given, color, tables)


#: The keywords :func:`resolve` takes: a design's, evaluate's without its options.
DESIGN_KEYWORDS = tuple(inspect.signature(resolve).parameters)
