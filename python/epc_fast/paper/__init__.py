"""The paper's quantitative statements held against the model
(:mod:`~epc_fast.paper.claims`) and checked on simulated captures
(:mod:`~epc_fast.paper.simulated`), and their tables as CSV and Markdown
(:mod:`~epc_fast.paper.table`); ``epc-fast paper`` writes them with the figures, the values
on simulated captures with ``--simulate``.
"""

from __future__ import annotations

from .claims import (CLAIMS, FIGURES, KINDS, PAPER_LUX_RANGE, RAYLEIGH_FACTOR, VGA_PIXELS,
                         Figure, Statement, statements)
from .table import CSV_COLUMNS, markdown_table, simulated_markdown_table, write_csv

__all__ = ["Statement", "Figure", "FIGURES", "CLAIMS", "PAPER_LUX_RANGE", "KINDS", "VGA_PIXELS",
           "RAYLEIGH_FACTOR", "statements", "CSV_COLUMNS", "write_csv", "markdown_table",
           "simulated_markdown_table"]
