"""Shared inputs for the benchmarks: the same random designs for every backend in a group."""

import pytest

from epc_fast.selfcheck import random_designs


@pytest.fixture(scope="session")
def designs_1e6():
    """10^6 phone-camera designs and scenes (epc_fast.selfcheck.random_designs)."""
    return random_designs(10**6, seed=12345)
