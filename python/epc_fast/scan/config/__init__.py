"""Scan configurations in TOML (``epc-fast scan CONFIG``): :mod:`~epc_fast.scan.config.parse`
reads the space, the point count, the seed and the reductions (the format is in its docstring);
:mod:`~epc_fast.scan.config.reductions` the ``[reductions]`` tables,
:mod:`~epc_fast.scan.config.indices` the ``[sobol]`` table and
:mod:`~epc_fast.scan.config.files` the files a config reads;
:mod:`~epc_fast.scan.config.extras` checks the optional dependencies a run needs. Its names are importable from here
(``from epc_fast.scan.config import load_config``).
"""

from __future__ import annotations

from .parse import (DEFAULT_CONFIG, ScanConfig, default_config, load_config, parse_config,
                    parse_space, toml_document)

__all__ = ["ScanConfig", "load_config", "parse_config", "default_config", "DEFAULT_CONFIG",
           "toml_document", "parse_space"]
