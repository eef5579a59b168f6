"""Scan configurations in TOML (``epc-fast scan CONFIG``): :mod:`~epc_fast.scan.config.parse`
reads the space, the point count, the seed and the reductions (the format is in its docstring);
:mod:`~epc_fast.scan.config.reductions` the ``[reductions]`` tables,
:mod:`~epc_fast.scan.config.indices` the ``[sobol]`` table,
:mod:`~epc_fast.scan.config.samples` an empirical distribution's sample file,
:mod:`~epc_fast.scan.config.bounds` the bounds on every size a config controls and
:mod:`~epc_fast.scan.config.needs` the optional dependencies a scan needs. Its names are
importable from here (``from epc_fast.scan.config import load_config``).
"""

from __future__ import annotations

from .parse import (DEFAULT_CONFIG, ScanConfig, default_config, load_config, parse_config,
                    parse_space)

__all__ = ["ScanConfig", "load_config", "parse_config", "default_config", "DEFAULT_CONFIG",
           "parse_space"]
