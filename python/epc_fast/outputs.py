"""evaluate's outputs: the :class:`Result`, every output's name and dtype, which outputs a call
asks for (``outputs=``), the caller's arrays for them (``out=``), checked, and the Result of the
flat arrays the backends return."""

from __future__ import annotations

import warnings
from collections.abc import Mapping
from dataclasses import dataclass, fields

import numpy as np

from . import elasticity_outputs
from ._validation import short
from .elasticity_outputs import ELASTICITY_PARAMETERS
from .status import Cause, Status

__all__ = ["Result", "SHARE_NAMES", "SHARE_OUTPUTS", "SHARE_ACROSS_OUTPUTS", "ACROSS_OUTPUTS",
           "LIMIT_OUTPUTS", "SENSITIVITY_OUTPUTS", "OUTPUT_DTYPES",
           "ALL_OUTPUT_DTYPES", "DTYPES", "selected_outputs", "out_arrays", "result_arrays",
           "output_shape", "output_bytes", "result_of", "new_result", "attach_snr_target",
           "names_any", "scalar_fields"]


@dataclass(frozen=True, repr=False)
class Result:
    """The model's outputs, each shaped like the broadcast inputs (scalars for scalar input).

    A field left out of ``evaluate(outputs=...)`` is None.

    Attributes
    ----------
    electron_rate_e_per_s : e-/s, photo-electron rate of one pixel.
    electrons : e-, photo-electrons collected during T_MPE (r T_MPE); NaN where no light or
        PRNU makes the target unreachable, the electrons needed where the full well does.
    t_mpe_s : s, minimum photometric exposure; +inf where the target is unreachable.
    blur_mm : mm, blur length on the sensor; +inf where the blur is unbounded.
    f50_cyc_per_mm : cycles/mm, where the system MTF falls to ``mtf_threshold``, along the
        motion.
    epc : pixels, effective pixel count: 4 S f50^2 (``epc_axes="motion"``, the default), or
        4 S f50 f50_across (``epc_axes="both"``; docs/model.md, "Resolution in both directions").
    status : :class:`Status` codes (uint8 array).
    cause : :class:`Cause` codes (uint8 array), why a point is unreachable.
    f50_across_cyc_per_mm : cycles/mm, where the system MTF without the motion blur falls to
        ``mtf_threshold`` (every other factor, jitter and a burst's alignment included): the
        f50 across the motion. NaN where f50 is (but finite where the blur is unbounded); with
        ``epc_axes="both"`` a default output, else computed only when ``outputs=`` names it.
    frames_used : 1, the frames each point's burst takes: with ``frames="auto"`` (night mode,
        a default output then) the least n up to ``max_frames`` whose frame T_MPE / n is within
        ``max_exposure_s`` (``max_frames`` where none is; NaN where the status is INVALID);
        else the broadcast ``frames``, computed only when ``outputs=`` names it
        (:mod:`epc_fast.exposure_limits`).
    share_diffraction, share_pixel, share_motion, share_jitter, share_alignment,
    share_aberration, share_denoise, share_lens, share_demosaic : 1, each MTF factor's share
        ln MTF_i(f50) / ln MTF_sys(f50) of the loss at f50 (the denominator is ln c at the
        root); the nine sum to 1. The binned pixel (``binning``) is the pixel's share; a burst's
        alignment residual, the wavefront error's ATF, denoising's filter, a lens table's
        L(f50) / D(f50) (the lens against aberration-free diffraction) and a Bayer sensor's
        demosaicker have their own (0 without them). NaN
        where the status is not OK, except where the blur is unbounded: motion's is 1, the
        others 0. Computed only when ``outputs=`` names them.
    share_diffraction_across ... share_demosaic_across : 1, the same shares at
        f50_across_cyc_per_mm, of the system MTF across the motion (motion's is 0). Computed
        only when ``outputs=`` names them.
    elasticities : dict of parameter name to 1, the elasticity d ln EPC / d ln theta of every
        model parameter (:data:`ELASTICITY_PARAMETERS`; the sensor's size under the keyword
        that gave it, ``sensor_area_mm2`` for a width and a height or a diagonal), each the
        broadcast shape; NaN where the status is not OK. Computed only when ``outputs=``
        names ``"elasticities"`` (all of them) or some of them one by one
        (``"elasticity_f_number"`` ..., :mod:`epc_fast.elasticity_outputs`): the dict holds
        those.
    mode : int16 array, with ``modes=``: the index of the readout mode the camera picks at
        each point (the highest EPC; every other output is that mode's), -1 where no mode has
        an EPC (the first mode's outputs then say why). None without ``modes=``.
    snr_target : str (not an output array; a property), the SNR target and where
        :func:`epc_fast.evaluate` met it, as a scan's tables and the figures say it:
        ``"30 dB at axis (default)"``, ``"30 dB at corner (27.03 deg)"``, ``"30 dB at field
        angle 12 deg"``, ranges for arrays; None for a Result evaluate did not make.
    """

    electron_rate_e_per_s: np.ndarray | float | None
    electrons: np.ndarray | float | None
    t_mpe_s: np.ndarray | float | None
    blur_mm: np.ndarray | float | None
    f50_cyc_per_mm: np.ndarray | float | None
    epc: np.ndarray | float | None
    status: np.ndarray | Status | None
    cause: np.ndarray | Cause | None
    f50_across_cyc_per_mm: np.ndarray | float | None = None
    frames_used: np.ndarray | float | None = None
    share_diffraction: np.ndarray | float | None = None
    share_pixel: np.ndarray | float | None = None
    share_motion: np.ndarray | float | None = None
    share_jitter: np.ndarray | float | None = None
    share_alignment: np.ndarray | float | None = None
    share_aberration: np.ndarray | float | None = None
    share_denoise: np.ndarray | float | None = None
    share_lens: np.ndarray | float | None = None
    share_demosaic: np.ndarray | float | None = None
    share_diffraction_across: np.ndarray | float | None = None
    share_pixel_across: np.ndarray | float | None = None
    share_motion_across: np.ndarray | float | None = None
    share_jitter_across: np.ndarray | float | None = None
    share_alignment_across: np.ndarray | float | None = None
    share_aberration_across: np.ndarray | float | None = None
    share_denoise_across: np.ndarray | float | None = None
    share_lens_across: np.ndarray | float | None = None
    share_demosaic_across: np.ndarray | float | None = None
    elasticities: dict | None = None
    mode: np.ndarray | int | None = None

    def as_dict(self) -> dict:
        """The outputs by name: the default ones, and the others that were computed."""
        return {f.name: getattr(self, f.name) for f in fields(self)
                if f.name in OUTPUT_DTYPES or getattr(self, f.name) is not None}

    @property
    def snr_target(self) -> str | None:
        """The SNR target and where evaluate met it (see the class), made when first read."""
        where = self.__dict__.get("_snr_target")
        if where is None or isinstance(where, str):
            return where
        text = _snr_target_text(*where)
        object.__setattr__(self, "_snr_target", text)
        return text

    def __repr__(self) -> str:
        items = [f"{name}={value!r}" for name, value in self.as_dict().items()]
        if self.snr_target is not None:
            items.append(f"snr_target={self.snr_target!r}")
        return f"Result({', '.join(items)})"


def attach_snr_target(result: Result, snr_db, snr_at, field_angle_deg) -> Result:
    """``result`` with the SNR target and where evaluate met it (:attr:`Result.snr_target`),
    whose text is made when first read."""
    object.__setattr__(result, "_snr_target", (snr_db, snr_at, field_angle_deg))
    return result


def _range_text(values, digits: str = "g") -> str:
    """``"30"`` for one value, ``"20 to 30"`` for an array's least and greatest (NaN left
    out)."""
    array = np.asarray(values, dtype=float)
    with np.errstate(invalid="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # an all-NaN array gives nan
        low, high = float(np.nanmin(array)), float(np.nanmax(array))
    return f"{low:{digits}}" if low == high else f"{low:{digits}} to {high:{digits}}"


def _snr_target_text(snr_db, snr_at, field_angle_deg) -> str:
    """The SNR target and where a call met it (:attr:`Result.snr_target`): the place as
    :func:`epc_fast.sensor.snr_at_text` writes it, "(default)" on the axis when neither
    ``snr_at`` nor ``field_angle_deg`` was given (``field_angle_deg`` 0), ranges for arrays."""
    from .sensor import snr_at_text

    level = f"{_range_text(snr_db)} dB"
    angles = np.asarray(field_angle_deg, dtype=float)
    if angles.size == 1 or np.all(angles == angles.flat[0]):
        angle = float(angles.flat[0])
        default = snr_at is None and angle == 0.0
        return f"{level} at {snr_at_text(snr_at, angle, default)}"
    if snr_at == "corner":
        return f"{level} at corner ({_range_text(angles, '.2f')} deg)"
    return f"{level} at field angles {_range_text(angles)} deg"


#: The MTF factors whose shares of the loss at f50 evaluate gives, in the core's order.
SHARE_NAMES = ("diffraction", "pixel", "motion", "jitter", "alignment", "aberration", "denoise",
               "lens", "demosaic")
#: The shares of the loss at f50, one output each (``outputs=`` names them; docs/limits.md).
SHARE_OUTPUTS = tuple(f"share_{name}" for name in SHARE_NAMES)
#: The outputs computed only when ``outputs=`` names them.
SENSITIVITY_OUTPUTS = SHARE_OUTPUTS + ("elasticities",)
#: The fields a call with ``modes=`` adds (:mod:`epc_fast.modes`).
MODE_OUTPUTS = ("mode",)
#: The shares of the loss at f50_across_cyc_per_mm, one output each.
SHARE_ACROSS_OUTPUTS = tuple(f"share_{name}_across" for name in SHARE_NAMES)
#: The outputs across the motion (:mod:`epc_fast.axes`): the system MTF without the motion
#: blur, solved by a second pass of the backend.
ACROSS_OUTPUTS = ("f50_across_cyc_per_mm",) + SHARE_ACROSS_OUTPUTS
#: The outputs of a call's exposure limits (:mod:`epc_fast.exposure_limits`): the frames a
#: burst takes.
LIMIT_OUTPUTS = ("frames_used",)
#: Each default output's dtype, in Result's field order.
OUTPUT_DTYPES = {f.name: np.dtype(np.uint8 if f.name in ("status", "cause") else np.float64)
                 for f in fields(Result)
                 if f.name not in SENSITIVITY_OUTPUTS + MODE_OUTPUTS + ACROSS_OUTPUTS
                 + LIMIT_OUTPUTS}
#: Every output's dtype (the elasticities: float64 rows), in Result's field order.
ALL_OUTPUT_DTYPES = {name: np.dtype(np.uint8 if name in ("status", "cause") else np.float64)
                     for name in (f.name for f in fields(Result)) if name not in MODE_OUTPUTS}
#: The outputs that hold one float a point.
_FLOAT_OUTPUTS = frozenset(name for name, dtype in ALL_OUTPUT_DTYPES.items()
                           if dtype == np.float64 and name != "elasticities")
#: Every output's dtype by its name inside: the Result fields', and each single elasticity's.
DTYPES = {**ALL_OUTPUT_DTYPES, **dict.fromkeys(elasticity_outputs.ROWS, np.dtype(np.float64))}


def scalar_fields(fields: dict) -> dict:
    """A call on scalars' fields (name -> 0-d value) as evaluate gives them: Status, Cause,
    floats (each float output and each elasticity); None and the other fields as they are."""
    out = {}
    for name, value in fields.items():
        if value is None:
            out[name] = None
        elif name == "status":
            out[name] = Status(int(value))
        elif name == "cause":
            out[name] = Cause(int(value))
        elif name == "elasticities":
            out[name] = {key: float(v) for key, v in value.items()}
        elif name in _FLOAT_OUTPUTS:
            out[name] = float(value)
        else:
            out[name] = value
    return out


def names_any(outputs, names) -> bool:
    """Whether ``outputs=`` (None, a name or an iterable of names) names one of ``names`` (a
    set); False for what is not iterable, which :func:`selected_outputs` names."""
    if outputs is None:
        return False
    listed = (outputs,) if isinstance(outputs, str) else outputs
    try:
        return any(isinstance(name, str) and name in names for name in listed)
    except TypeError:
        return False


def selected_outputs(outputs, is_pixel_count=False) -> tuple:
    """The outputs ``outputs=`` asks for, in Result's order (then the single elasticities',
    by their names in elasticity_outputs.ROWS); the default ones for None."""
    if outputs is None:
        return tuple(OUTPUT_DTYPES)
    if isinstance(outputs, str):
        outputs = (outputs,)
    try:
        names = list(outputs)
    except TypeError:
        raise TypeError(f"outputs must be a field name or an iterable of them, got "
                        f"{short(outputs)}") from None
    others = [name for name in names if name not in ALL_OUTPUT_DTYPES]
    rows = [elasticity_outputs.row_of(name, is_pixel_count) for name in others]
    unknown = [name for name, row in zip(others, rows) if row is None]
    if unknown or not names:
        what = f"unknown field(s) {unknown}" if unknown else "none"
        raise ValueError(f"outputs must name at least one of {', '.join(ALL_OUTPUT_DTYPES)}, "
                         f"or elasticity_ and a parameter's name; got {what}")
    chosen = set(names)
    if others and elasticity_outputs.ALL in chosen:
        raise ValueError(f"outputs names 'elasticities', every elasticity, and also {others}")
    selected = tuple(name for name in ALL_OUTPUT_DTYPES if name in chosen)
    return selected + elasticity_outputs.rows_in(rows) if rows else selected


def out_arrays(out, shape, selected, is_pixel_count=False, core=False) -> dict:
    """The caller's ``out=`` arrays by output name (a single elasticity's as in
    elasticity_outputs.ROWS), each checked, or an error naming it. Two arrays that share memory
    are an error too: for ``core`` the core's (register_evaluate.cpp, which names them as the
    caller did), except for elasticities, whose names only this module knows."""
    if isinstance(out, Result):
        out = result_arrays(out, is_pixel_count)
    if type(out) is not dict and not isinstance(out, Mapping):
        raise TypeError(f"out must be a Result or a mapping of its field names to arrays, "
                        f"got {short(out)}")
    shown = elasticity_outputs.output_names(is_pixel_count)
    known = {shown.get(name, name): name for name in selected}
    if elasticity_outputs.ALL in selected and elasticity_outputs.ALL not in out:
        # every elasticity, one array per row (a Result's, as out=)
        known.update({shown[row]: row for row in elasticity_outputs.ROWS})
        del known[elasticity_outputs.ALL]
    if out.keys() != known.keys():
        unknown = sorted(set(out) - set(known), key=str)
        missing = [name for name in known if name not in out]
        raise ValueError(f"out must have exactly the fields {', '.join(known)}; "
                         f"missing: {missing}, unknown: {unknown}")
    for name, inside in known.items():
        dtype = DTYPES[inside]
        array = out[name]
        if not isinstance(array, np.ndarray):
            raise TypeError(f"out[{name!r}] must be a NumPy array, got {short(array)}")
        if array.dtype != dtype:
            raise TypeError(f"out[{name!r}] has dtype {array.dtype.str}, expected {dtype.str} "
                            f"({dtype.name}, native byte order)")
        expected = output_shape(inside, shape)
        if array.shape != expected:
            what = ("(one row per parameter of ELASTICITY_PARAMETERS, then the broadcast shape)"
                    if inside == elasticity_outputs.ALL else "the broadcast shape")
            raise ValueError(f"out[{name!r}] has shape {array.shape}, expected {what} "
                             f"{expected}")
        flags = array.flags
        if not flags.c_contiguous:
            raise ValueError(f"out[{name!r}] must be C-contiguous")
        if not flags.writeable:
            raise ValueError(f"out[{name!r}] is read-only")
    if not core or not _ELASTICITY_NAMES.isdisjoint(known.values()):
        names = list(known)
        for i, a in enumerate(names):
            for b in names[i + 1:]:
                if np.may_share_memory(out[a], out[b]):
                    raise ValueError(f"out[{a!r}] and out[{b!r}] share memory")
    return {inside: out[name] for name, inside in known.items()}


#: The outputs that hold elasticities (every one, or one each).
_ELASTICITY_NAMES = frozenset((elasticity_outputs.ALL,) + elasticity_outputs.ROWS)


def result_arrays(result: Result, is_pixel_count: bool) -> dict:
    """A Result's arrays by output name, its elasticities one output each."""
    arrays = {k: v for k, v in result.as_dict().items() if v is not None and k != "elasticities"}
    arrays.update({elasticity_outputs.output_of_key(key): array
                   for key, array in (result.elasticities or {}).items()})
    return arrays


def output_shape(name, shape) -> tuple:
    """The shape of output ``name`` for the broadcast ``shape``."""
    return (len(ELASTICITY_PARAMETERS),) + tuple(shape) if name == "elasticities" else shape


def output_bytes(name) -> int:
    """Bytes output ``name`` takes per point."""
    rows = len(ELASTICITY_PARAMETERS) if name == "elasticities" else 1
    return rows * DTYPES[name].itemsize


def result_of(out, shape, is_pixel_count: bool) -> Result:
    """A Result of the flat arrays in ``out`` (the elasticities one row each, by their names in
    elasticity_outputs.ROWS); a field ``out`` lacks is None."""
    def value(name, v):
        if v is None:
            return None
        if shape != ():
            return v if v.shape == shape else v.reshape(shape)
        return (Status(int(v[0])) if name == "status" else
                Cause(int(v[0])) if name == "cause" else float(v[0]))
    if elasticity_outputs.ALL in out:
        elasticities = elasticity_outputs.every_by_key(out[elasticity_outputs.ALL], shape,
                                                       is_pixel_count)
    else:
        rows = {row: value(row, out[row]) for row in elasticity_outputs.rows_in(out)}
        elasticities = elasticity_outputs.by_key(rows, is_pixel_count) if rows else None
    fields = {name: value(name, v) for name, v in out.items() if name in _RESULT_ARRAYS}
    fields["elasticities"] = elasticities
    return new_result(fields)


#: The Result fields that hold one output's array (all but the elasticities and the mode).
_RESULT_ARRAYS = frozenset(ALL_OUTPUT_DTYPES) - {"elasticities"}
#: Every Result field None.
_NO_FIELDS = dict.fromkeys(f.name for f in fields(Result))


def new_result(values: dict) -> Result:
    """The Result of ``values`` (field name -> value; the fields it lacks None), made as the
    dataclass's __init__ would make it, without its per-field frozen __setattr__ (a call's
    fixed cost)."""
    if not _NO_FIELDS.keys() >= values.keys():  # a lookup per value, not per field
        unknown = values.keys() - _NO_FIELDS.keys()
        raise TypeError(f"Result has no field(s) {sorted(unknown)}")
    result = object.__new__(Result)
    state = _NO_FIELDS.copy()  # a copy of a dict of the same keys: one block copied
    state.update(values)
    object.__setattr__(result, "__dict__", state)
    return result
