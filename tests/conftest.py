"""pytest's set-up for the tests: the core override, assertion rewriting in the helpers, and
the report header.

``EPC_FAST_CORE_DIR=<dir>`` runs every test against the ``epc_fast._core_*`` modules in <dir>
(helpers/core_override.py), loaded here before any test module imports epc_fast. What the tests
share lives in the helpers package (tests/helpers/), never in a test module or here.
"""

import os

# The tests share the cores among pytest-xdist's workers (pyproject.toml): an OpenMP thread that
# waits sleeps instead of spinning on a core another worker needs (2m40s against 3m00s for
# the suite on 2 cores). Set before the core's OpenMP runtime starts, at its first import.
os.environ.setdefault("OMP_WAIT_POLICY", "passive")

import pytest  # noqa: E402

# A failing assert in a helper explains itself as one in a test does.
pytest.register_assert_rewrite("helpers")

from helpers.core_override import load_core_override  # noqa: E402

load_core_override()


@pytest.hookimpl(tryfirst=True)
def pytest_cmdline_main(config):
    """The tests on every core (pytest-xdist's ``-n auto``, work stealing) unless ``-n`` says
    otherwise: 2m40s for the suite on 2 cores instead of 4m50s. Here rather than in
    pyproject.toml's addopts, which bench/ shares: pytest-benchmark times nothing under xdist.
    Runs before xdist's own hook (a conftest's registers later, so it is called first)."""
    if hasattr(config, "workerinput"):  # an xdist worker (whose numprocesses xdist clears)
        return
    if getattr(config.option, "numprocesses", 0) is None and not config.getoption("usepdb"):
        config.option.numprocesses = "auto"
        if config.option.dist == "no":
            config.option.dist = "worksteal"


def pytest_report_header(config):
    directory = os.environ.get("EPC_FAST_CORE_DIR")
    return f"epc_fast core from EPC_FAST_CORE_DIR={directory}" if directory else None
