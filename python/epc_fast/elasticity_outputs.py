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

from .reference_sensitivity import ELASTICITY_PARAMETERS

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
    return tuple(row for row in ROWS if ALL in wanted or row in wanted)


def by_key(rows: dict, is_pixel_count: bool) -> dict:
    """``rows`` (row name to value) as Result.elasticities: by the parameters' keys, in ROWS'
    order."""
    return {key(row[len(_PREFIX):], is_pixel_count): rows[row] for row in ROWS if row in rows}
