"""The paper's statements through each backend, computed once for the tests of this folder."""

from __future__ import annotations

import pytest

from epc_fast.paper import statements


@pytest.fixture(scope="package", params=("core", "reference"))
def table(request):
    """{id: statement} of every claim, through one backend (once per backend: the reference's
    takes seconds), for the statements' tests and the table's."""
    return {s.id: s for s in statements(backend=request.param)}
