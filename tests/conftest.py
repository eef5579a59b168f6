"""Shared set-up: optionally run the tests against another build of the compiled core.

``EPC_FAST_CORE_DIR=<dir>`` makes every ``epc_fast._core_*`` extension module found in <dir>
(e.g. the sanitizer build of .ci/sanitize.sh) the one the package loads, whatever is installed,
editable or not. Such a build holds the baseline module only, so the x86-64 level is forced.
"""

import importlib.util
import os
import sys
from pathlib import Path


def load_core_override():
    """Registers the modules of $EPC_FAST_CORE_DIR before epc_fast imports its core.

    Returns the module names loaded (empty without the variable). Also run by the subprocesses
    of the tests, which start from a fresh interpreter.
    """
    directory = os.environ.get("EPC_FAST_CORE_DIR")
    if not directory:
        return []
    os.environ.setdefault("EPC_FAST_ISA", "x86-64")
    names = []
    for path in sorted(Path(directory).glob("_core_*.so")):
        name = "epc_fast." + path.name.split(".")[0]
        if name not in sys.modules:
            spec = importlib.util.spec_from_file_location(name, path)
            module = importlib.util.module_from_spec(spec)
            spec.loader.exec_module(module)
            sys.modules[name] = module
        names.append(name)
    if not names:
        raise RuntimeError(f"EPC_FAST_CORE_DIR={directory!r} holds no _core_*.so module")
    return names


load_core_override()

ROOT = Path(__file__).resolve().parents[1]


def load_script(relative_path):
    """A script of the repository (e.g. "bench/report.py"), not a package module, loaded as a
    module for the tests of its functions."""
    path = ROOT / relative_path
    spec = importlib.util.spec_from_file_location(path.stem, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def parameter_defaults():
    """{name: default} of every parameter of evaluate that has one (epc_fast.params), the one
    spelling of the defaults the tests build points from."""
    from epc_fast import params  # after load_core_override, as every import of the package

    return {p.name: p.default for p in params.PARAMETERS if p.default is not None}


def pytest_report_header(config):
    directory = os.environ.get("EPC_FAST_CORE_DIR")
    return f"epc_fast core from EPC_FAST_CORE_DIR={directory}" if directory else None
