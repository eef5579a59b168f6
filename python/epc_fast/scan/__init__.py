"""Design-space scans at scale: Monte Carlo and grids, reduced on the fly, locally or on Dask.

>>> from epc_fast.presets import HIGH_TIER
>>> from epc_fast import scan
>>> space = scan.Space(design=HIGH_TIER, illuminance_lux=scan.LogUniform(10, 1e5),
...                    shake_deg_per_s=scan.LogNormal(median=4.39, sigma=0.5))
>>> result = scan.run(space, points=200_000, seed=1, progress=False)
>>> int(result["summary"].points.sum())
200000

A space gives each parameter of :func:`epc_fast.evaluate` as a number, a :class:`Grid`, a
:class:`Choice` or a distribution, and optionally a ``design`` axis. :func:`run` evaluates it
chunk by chunk and keeps only the reductions: :class:`Summary`, :class:`Histogram`,
:class:`Quantiles`, :class:`FractionBelow` and :class:`TopK`, each per group (``by=``).
The same seed gives the same numbers for any chunk size, thread count or Dask cluster.
:func:`sobol_indices` apportions the variance of EPC (or log EPC) among the random parameters
(the ``sensitivity`` extra).
"""

from .reductions.best import TopK, TopKResult
from .sampling.distributions import (Choice, Empirical, Grid, LogNormal, LogUniform, Normal,
                                     Truncated, Uniform)
from .reductions.groups import Binned
from .reductions.histograms import Histogram, HistogramResult, Quantiles, QuantilesResult
from .running.runner import DEFAULT_CHUNK_POINTS, ScanResult, Timing, default_reductions, run
from .indices.estimate import sobol_indices
from .indices.result import SobolResult
from .sampling.space import BLOCK_POINTS, Space
from .reductions.summaries import FractionBelow, FractionBelowResult, Summary, SummaryResult

__all__ = [
    "Space", "Grid", "Choice", "Uniform", "LogUniform", "Normal", "LogNormal", "Truncated",
    "Empirical", "Binned", "Summary", "Histogram", "Quantiles", "FractionBelow", "TopK", "run",
    "default_reductions", "ScanResult", "Timing", "SummaryResult", "HistogramResult",
    "QuantilesResult", "FractionBelowResult", "TopKResult", "BLOCK_POINTS",
    "DEFAULT_CHUNK_POINTS", "sobol_indices", "SobolResult",
]
