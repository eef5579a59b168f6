"""epc_fast.call_options: evaluate's options checked, and kept by value for the next call."""

import numpy as np
import pytest

from epc_fast.call_options import CallOptions, options_of

DEFAULTS = ("core", "status", "halley", 1e-14, "closed_form", 1e-15, "float64")


def test_the_same_options_give_the_same_checked_object():
    first = options_of(*DEFAULTS, ("f50_cyc_per_mm", "epc"))
    assert isinstance(first, CallOptions) and first.selected == ("f50_cyc_per_mm", "epc")
    assert options_of(*DEFAULTS, ("f50_cyc_per_mm", "epc")) is first
    # a value of another type that compares equal is kept apart, with the same checked values
    other = options_of(*DEFAULTS[:3], np.float64(1e-14), *DEFAULTS[4:], ("f50_cyc_per_mm", "epc"))
    assert other == first and other is not first


def test_unhashable_outputs_and_tables_are_checked_every_call():
    listed = options_of(*DEFAULTS, ["epc"])
    assert listed.selected == ("epc",) and options_of(*DEFAULTS, ["epc"]) is not listed
    tables = (object(),)
    with_tables = options_of(*DEFAULTS, None, lens_tables=tables)
    assert with_tables.lens_tables is tables and with_tables.lens_count == 1


@pytest.mark.parametrize("change, error, match", [
    (dict(f50_rtol=float("nan")), ValueError, r"f50_rtol must be in \[0, 1\), got nan"),
    (dict(f50_rtol="x"), TypeError, "f50_rtol must be a number"),
    (dict(f50_solver="secant"), ValueError, "f50_solver must be one of"),
    (dict(outputs=3), TypeError, "outputs must be a field name"),
    (dict(outputs=["epc", "nope"]), ValueError, r"unknown field\(s\) \['nope'\]")])
def test_a_bad_option_is_an_error_naming_it_on_every_call(change, error, match):
    args = dict(zip(("backend", "invalid", "f50_solver", "f50_rtol", "t_mpe_solver",
                     "t_mpe_rtol", "precision"), DEFAULTS), outputs=None) | change
    for _ in range(2):  # an error is not kept
        with pytest.raises(error, match=match):
            options_of(**args)
