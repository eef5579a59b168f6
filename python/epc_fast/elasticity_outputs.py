"""The names of evaluate's elasticity outputs.

``outputs=`` asks for every elasticity at once (``"elasticities"``: one array of a row per
parameter of :data:`ELASTICITY_PARAMETERS`) or for some of them, one output each:
``"elasticity_f_number"``, ``"elasticity_read_noise_e"`` ... The size's is named as the call
gives the size: ``"elasticity_sensor_area_mm2"`` (an area, width and height, or diagonal) or
``"elasticity_pixel_count"``. Either way :attr:`Result.elasticities` is a dict by the
parameters' names. Inside, and in the core, each parameter's row goes by its name in
:data:`ROWS`, the size's as ``"elasticity_size"``.
"""

from __future__ import annotations

from .params import PARAMETER_NAMES

#: The parameters an elasticity is given for, in the core's order: every model parameter, with
#: ``"size"`` for the sensor's size (``Result.elasticities`` names it ``pixel_count`` or
#: ``sensor_area_mm2``, as the caller gave it).
ELASTICITY_PARAMETERS = PARAMETER_NAMES

#: The output that holds every elasticity.
ALL = "elasticities"
#: Each parameter's elasticity as one output, inside and in the core, in the order of
#: ELASTICITY_PARAMETERS.
ROWS = tuple(f"elasticity_{name}" for name in ELASTICITY_PARAMETERS)
_PREFIX = "elasticity_"
_SIZE_KEYS = {False: "sensor_area_mm2", True: "pixel_count"}


def key(parameter: str, is_pixel_count: bool) -> str:
    """A parameter's key in Result.elasticities: its name, the size's as the call gave it."""
    return _SIZE_KEYS[is_pixel_count] if parameter == "size" else parameter


def output_names(is_pixel_count: bool) -> dict:
    """Each row's name for ``outputs=`` and ``out=`` (output_name), by row."""
    return _OUTPUT_NAMES[is_pixel_count]


def output_of_key(parameter_key: str) -> str:
    """The output that holds the elasticity of Result.elasticities' ``parameter_key``."""
    return _PREFIX + parameter_key


def output_name(row: str, is_pixel_count: bool) -> str:
    """The name ``outputs=`` and ``out=`` know the row (a name in ROWS) by."""
    return output_of_key(key(row[len(_PREFIX):], is_pixel_count))


def row_of(name, is_pixel_count: bool) -> str | None:
    """The row (a name in ROWS) that the output ``name`` asks for; None if it names no
    elasticity. A ValueError for the size's elasticity under the other way of giving the size."""
    if not isinstance(name, str) or not name.startswith(_PREFIX):
        return None
    parameter = name[len(_PREFIX):]
    if parameter in _SIZE_KEYS.values():
        if parameter != _SIZE_KEYS[is_pixel_count]:
            raise ValueError(
                f"outputs names {name!r}, but this call gives the sensor "
                f"{'as a pixel count' if is_pixel_count else 'by its area or lengths'}: its "
                f"size's elasticity is {output_name('elasticity_size', is_pixel_count)!r}")
        parameter = "size"
    elif parameter == "size":
        return None
    return _PREFIX + parameter if parameter in ELASTICITY_PARAMETERS else None


def rows_in(names) -> tuple:
    """The rows that ``names`` (outputs inside: ALL, rows and others) hold, in ROWS' order."""
    wanted = set(names)
    if ALL in wanted:
        return ROWS
    return tuple(row for row in ROWS if row in wanted) if not _ROW_SET.isdisjoint(wanted) else ()


def by_key(rows: dict, is_pixel_count: bool) -> dict:
    """``rows`` (row name to value) as Result.elasticities: by the parameters' keys, in ROWS'
    order."""
    keys = _KEYS[is_pixel_count]
    return {keys[row]: rows[row] for row in ROWS if row in rows}


def every_by_key(every, shape, is_pixel_count: bool, arrays: bool = False) -> dict:
    """The array of every elasticity (a row per parameter, flat or not) as
    Result.elasticities: each row of the broadcast ``shape``; floats for scalar input, unless
    ``arrays`` (0-d views of the rows then, as for ``out=``)."""
    every = every.reshape((len(ROWS),) + tuple(shape))
    keys = _KEYS[is_pixel_count].values()
    if shape == ():
        return dict(zip(keys, [every[j, ...] for j in range(len(ROWS))] if arrays
                        else every.tolist()))
    return dict(zip(keys, every))


_ROW_SET = frozenset(ROWS)
_OUTPUT_NAMES = {flag: {row: output_name(row, flag) for row in ROWS} for flag in (False, True)}
_KEYS = {flag: {row: key(row[len(_PREFIX):], flag) for row in ROWS} for flag in (False, True)}
