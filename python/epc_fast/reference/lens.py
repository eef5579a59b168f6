"""The NumPy reference of a lens's tabulated MTF (docs/model.md, "Tabulated MTFs" and "System
MTF"; issue #40): the table a point's ``lens`` index picks, its monotone interpolant L(f) in
place of the aberration-free diffraction factor D(f), and where f50's bracket ends on it.

A call gives its tables (``lens_mtf``) to every point: point i uses table ``lens[i]``. Each
table is an :class:`epc_fast.mtf_table.MtfTable`, interpolated by
:func:`epc_fast.mtf_table.mtf_tabulated`, the per-segment cubic both backends evaluate.
"""

from __future__ import annotations

import numpy as np

from ..mtf_table import mtf_tabulated

__all__ = ["lens_choice", "mtf_lens", "lens_bracket", "lens_log_factor"]


def lens_choice(lens, tables) -> np.ndarray:
    """int: each point's table index, ``lens`` clipped to 0 .. len(tables) - 1 (a point whose
    index is outside is INVALID, and computes on a stand-in until it is masked)."""
    index = np.nan_to_num(np.asarray(lens, dtype=np.float64), nan=0.0)
    return np.clip(index, 0, len(tables) - 1).astype(np.intp)


def _tabulated(f_cyc_per_mm, lens, tables):
    """(L, L', L'') at f from each point's table (the shapes of f and lens broadcast)."""
    f = np.asarray(f_cyc_per_mm, dtype=np.float64)
    choice = lens_choice(lens, tables)
    shape = np.broadcast_shapes(f.shape, choice.shape)
    values = [np.zeros(shape) for _ in range(3)]
    for i, table in enumerate(tables):
        picked = choice == i
        for out, v in zip(values, mtf_tabulated(f, table)):
            np.copyto(out, np.broadcast_to(v, shape), where=np.broadcast_to(picked, shape))
    return tuple(values)


def mtf_lens(f_cyc_per_mm, lens, tables):
    """1: L(f), the interpolated MTF of the table each point's ``lens`` index picks, held at
    the table's last value past its last frequency (where f50 never is: :func:`lens_bracket`).
    It includes diffraction and the lens's aberrations: it replaces D(f) and the wavefront
    error's ATF."""
    return _tabulated(f_cyc_per_mm, lens, tables)[0]


def lens_bracket(lens, tables) -> np.ndarray:
    """cycles/mm: where each point's table ends for f50's bracket, the smaller of its last
    frequency and its first frequency with MTF 0 (the monotone interpolant is 0 from that knot
    on, and above 0 before it)."""
    ends = [table.frequencies[np.flatnonzero(table.values == 0.0)[0]]
            if np.any(table.values == 0.0) else table.last_frequency for table in tables]
    return np.asarray(ends, dtype=np.float64)[lens_choice(lens, tables)]


def lens_log_factor(f_cyc_per_mm, lens, tables, diffraction_value):
    """1: (ln(L / D), f d ln L / df) at f: the lens table's factor against the aberration-free
    diffraction D (``diffraction_value``, D(f) summed over the spectrum), whose log is
    share_lens's numerator, and the log-slope of L in f, which replaces diffraction's in f50's
    slope (the table's L does not depend on the f-number or the wavelength)."""
    f = np.asarray(f_cyc_per_mm, dtype=np.float64)
    value, slope, _ = _tabulated(f, lens, tables)
    return np.log(value) - np.log(diffraction_value), f * slope / value
