"""The repository's root, and its scripts (bench/, tools/: not package modules) loaded as
modules for the tests of their functions."""

import importlib.util
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def load_script(relative_path):
    """A script of the repository (e.g. "bench/report.py"), not a package module, loaded as a
    module for the tests of its functions."""
    path = ROOT / relative_path
    spec = importlib.util.spec_from_file_location(path.stem, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # as an import would: dataclasses look their module up
    spec.loader.exec_module(module)
    return module
