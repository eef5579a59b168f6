"""Optionally run the tests against another build of the compiled core.

``EPC_FAST_CORE_DIR=<dir>`` makes every ``epc_fast._core_*`` extension module found in <dir>
(e.g. the sanitizer build of .ci/sanitize.sh) the one the package loads, whatever is installed,
editable or not. Such a build holds the baseline module only, so the x86-64 level is forced.
conftest.py calls :func:`load_core_override` before any test imports epc_fast; so do the
subprocesses of the tests and fuzz/fuzz_evaluate.py, which start from a fresh interpreter.
"""

import importlib.util
import os
import sys
from pathlib import Path


def load_core_override():
    """Registers the modules of $EPC_FAST_CORE_DIR before epc_fast imports its core.

    Returns the module names loaded (empty without the variable).
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
