"""Global sensitivity over a space: Sobol' indices of EPC or log EPC
(:mod:`~epc_fast.scan.indices.estimate`), and their result as arrays and a table
(:mod:`~epc_fast.scan.indices.result`). Its names are importable from here.
"""

from __future__ import annotations

from .estimate import (MAX_BOOTSTRAP_VALUES, MAX_DESIGN_VALUES, MIN_POINTS, NOT_OK_POLICIES,
                       OUTPUTS, design_inputs, design_rows, random_parameters, sobol_indices,
                       unit_design)
from .result import SobolResult

__all__ = ["sobol_indices", "SobolResult", "random_parameters", "unit_design", "design_inputs",
           "design_rows", "OUTPUTS", "NOT_OK_POLICIES", "MIN_POINTS", "MAX_BOOTSTRAP_VALUES",
           "MAX_DESIGN_VALUES"]
