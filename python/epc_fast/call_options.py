"""evaluate's options (backend, solvers and tolerances, precision, invalid points, binning
readout, outputs), checked: each a :class:`CallOptions`, kept by value for the next call that
gives the same."""

from __future__ import annotations

import functools
from dataclasses import dataclass

from ._validation import choice, tolerance
from .outputs import selected_outputs
from .params import READOUT_CODES

__all__ = ["BACKENDS", "T_MPE_SOLVERS", "F50_SOLVERS", "PRECISIONS", "INVALID_POLICIES",
           "BINNING_READOUTS", "CallOptions", "options_of"]

BACKENDS = ("core", "reference")
T_MPE_SOLVERS = ("closed_form", "brent")
F50_SOLVERS = ("halley", "newton", "brent", "bisection")
#: The floating-point types f50 can be solved in (``precision=``).
PRECISIONS = ("float64", "float32")
INVALID_POLICIES = ("status", "raise")
#: How a binned pixel's k x k pixels are read (``binning_readout=``, a per-point column):
#: k^2 reads, or one.
BINNING_READOUTS = tuple(READOUT_CODES)


@dataclass(frozen=True)
class CallOptions:
    """The checked options of one call."""

    backend: str
    invalid: str
    f50_solver: str
    f50_rtol: float
    t_mpe_solver: str
    t_mpe_rtol: float
    precision: str
    selected: tuple
    #: the checked lens_mtf tables (a tuple of MtfTable), None without lens_mtf
    lens_tables: tuple | None = None
    #: a colour sensor's demosaicker's table (epc_fast.cfa), None for the monochrome sensor
    demosaic_table: object = None

    @property
    def lens_count(self) -> int:
        """The number of lens tables, 1 without them (lens = 0 alone is valid then)."""
        return 1 if self.lens_tables is None else len(self.lens_tables)

    @functools.cached_property
    def computed(self) -> tuple:
        """The outputs to compute: those selected, and the status ``invalid="raise"`` reads."""
        extra = ("status",) if self.invalid == "raise" and "status" not in self.selected else ()
        return self.selected + extra


def options_of(backend, invalid, f50_solver, f50_rtol, t_mpe_solver, t_mpe_rtol, precision,
               outputs, is_pixel_count=False, lens_tables=None,
               demosaic_table=None) -> CallOptions:
    """The checked options of a call (errors name the argument); those without tables, and
    with a hashable ``outputs``, are kept for the next call that gives the same."""
    args = (backend, invalid, f50_solver, f50_rtol, t_mpe_solver, t_mpe_rtol, precision,
            outputs, is_pixel_count)
    if lens_tables is None and demosaic_table is None:
        try:
            return _kept_options(*args)
        except TypeError:  # an unhashable argument (outputs as a list), or a bad one
            pass
    return _checked_options(*args, lens_tables, demosaic_table)


@functools.lru_cache(maxsize=256, typed=True)
def _kept_options(*args) -> CallOptions:
    return _checked_options(*args)


def _checked_options(backend, invalid, f50_solver, f50_rtol, t_mpe_solver, t_mpe_rtol,
                     precision, outputs, is_pixel_count=False, lens_tables=None,
                     demosaic_table=None) -> CallOptions:
    choice("backend", backend, BACKENDS)
    choice("invalid", invalid, INVALID_POLICIES)
    choice("t_mpe_solver", t_mpe_solver, T_MPE_SOLVERS)
    choice("f50_solver", f50_solver, F50_SOLVERS)
    choice("precision", precision, PRECISIONS)
    return CallOptions(backend, invalid, f50_solver, tolerance("f50_rtol", f50_rtol),
                       t_mpe_solver, tolerance("t_mpe_rtol", t_mpe_rtol), precision,
                       selected_outputs(outputs, is_pixel_count), lens_tables, demosaic_table)

