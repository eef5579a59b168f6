"""Coverage-guided fuzzing of epc_fast.evaluate and of the core's entry point, with atheris.

    python fuzz/fuzz_evaluate.py -max_total_time=60          # libFuzzer options after the name

.ci/fuzz.sh runs it for a bounded time against the sanitizer build (EPC_FAST_CORE_DIR, as in
tests/conftest.py). Each input is decoded (atheris.FuzzedDataProvider) into one of two calls:

- the public API: every model parameter omitted, a scalar or an array (empty, broadcasting, or
  not), its values arbitrary doubles (NaN, infinities, subnormals, huge) or the values next to
  a domain's ends, sometimes not numbers at all; any backend, T_MPE and f50 solver, precision,
  tolerance, thread count, invalid= policy, size keyword, spectrum, outputs= selection and
  out= arrays;
- _core.evaluate directly, with columns, domains, spectrum, n, options (solvers, precision,
  threads, chunk size), out= arrays of any size and new outputs (allocate=) by any names.

What must hold: nothing crashes or trips a sanitizer; the only exceptions are TypeError,
ValueError (invalid="raise", bad arguments) and MemoryError; every status and cause is a known
code; OK points have finite outputs, INVALID points NaN outputs and no cause, UNREACHABLE
points T_MPE = +inf and a cause, BLUR_UNBOUNDED points an infinite blur and f50 = EPC = 0; and
the core and the reference agree on every status and cause.
"""

import inspect
import math
import os
import sys

import atheris
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests"))
from helpers.core_override import load_core_override  # noqa: E402

load_core_override()  # EPC_FAST_CORE_DIR's core, loaded before epc_fast loads its own

import epc_fast  # noqa: E402
from epc_fast import Status, _core, api, outputs, params  # noqa: E402


def instrument_package(package, skip=()):
    """Coverage instrumentation for every function and method of `package`'s loaded modules.

    (atheris.instrument_imports misses modules that an editable install's import hook loads,
    so the functions are patched in place once imported.)
    """
    for name, module in list(sys.modules.items()):
        if name != package and not name.startswith(package + ".") or name in skip:
            continue
        for obj in list(vars(module).values()):
            members = [obj] + (list(vars(obj).values()) if inspect.isclass(obj) else [])
            for member in members:
                if inspect.isfunction(member) and member.__module__ == name:
                    atheris.instrument_func(member)


# Not the reference: its whole-array code has no branches worth steering towards, and tracing
# the comparisons of its bisection (thousands per call) only costs time and memory.
instrument_package("epc_fast", skip={"epc_fast.reference"})

KEYWORDS = [p.name for p in params.PARAMETERS if p.name != "size"]
EXPECTED_ERRORS = (TypeError, ValueError, MemoryError)
FLOAT_FIELDS = ("electron_rate_e_per_s", "electrons", "t_mpe_s", "blur_mm", "f50_cyc_per_mm",
                "epc")
#: The elasticities one output each, the size's by both of its names (one of them the call's).
SINGLE_ELASTICITIES = [f"elasticity_{name}" for name in params.PARAMETER_NAMES if name != "size"]
SINGLE_ELASTICITIES += ["elasticity_sensor_area_mm2", "elasticity_pixel_count"]
#: The outputs the core itself knows: the defaults, the shares, every elasticity in one array
#: and one per elasticity (the core refuses the first with any of the others).
CORE_OUTPUTS = list(api.OUTPUT_DTYPES) + list(api.SHARE_OUTPUTS) + ["elasticities"] + [
    f"elasticity_{name}" for name in params.PARAMETER_NAMES]


def _edges():
    """Doubles at and next to every domain end, and the usual suspects."""
    values = {0.0, -0.0, 5e-324, -5e-324, 2.2250738585072014e-308, 1.0, -1.0, 0.5,
              1.7976931348623157e308, -1.7976931348623157e308, math.inf, -math.inf, math.nan}
    for p in params.PARAMETERS:
        for end in (p.lo, p.hi):
            if math.isfinite(end):
                values.update({end, float(np.nextafter(end, math.inf)),
                               float(np.nextafter(end, -math.inf))})
    return sorted(values, key=repr)


EDGES = _edges()
NOT_NUMBERS = ["1.0", None, 1 + 2j, object(), [1.0, "x"], b"\x00", True]


def _value(fdp, shape):
    kind = fdp.ConsumeIntInRange(0, 9)
    if kind <= 2:
        return fdp.ConsumeFloat()
    if kind <= 4:
        return EDGES[fdp.ConsumeIntInRange(0, len(EDGES) - 1)]
    if kind <= 7:
        size = int(np.prod(shape))
        values = [fdp.ConsumeFloat() if fdp.ConsumeBool() else
                  EDGES[fdp.ConsumeIntInRange(0, len(EDGES) - 1)] for _ in range(size)]
        return np.array(values, dtype=np.float64).reshape(shape)
    if kind == 8:  # an unrelated shape: broadcasts or not
        return np.full(fdp.ConsumeIntInRange(0, 4), fdp.ConsumeFloat())
    return NOT_NUMBERS[fdp.ConsumeIntInRange(0, len(NOT_NUMBERS) - 1)]


def _public_call(fdp):
    shape = [(), (0,), (fdp.ConsumeIntInRange(1, 70),), (2, 3), (3, 1)][
        fdp.ConsumeIntInRange(0, 4)]
    kwargs = {}
    for name in KEYWORDS:
        if fdp.ConsumeIntInRange(0, 2) > 0:
            kwargs[name] = _value(fdp, shape)
    for name in ("illuminance_lux", "pixel_pitch_um", "f_number", "focal_length_mm"):
        kwargs.setdefault(name, 1.0)
    kwargs["pixel_count" if fdp.ConsumeBool() else "sensor_area_mm2"] = _value(fdp, shape)
    backend = "core" if fdp.ConsumeBool() else "reference"
    options = dict(
        t_mpe_solver=["closed_form", "brent", "newton"][fdp.ConsumeIntInRange(0, 2)],
        f50_rtol=[1e-14, 0.0, fdp.ConsumeFloat()][fdp.ConsumeIntInRange(0, 2)],
        threads=[None, 1, 2, 3, 0, -1, 10**4, 1.5][fdp.ConsumeIntInRange(0, 7)],
        invalid="raise" if fdp.ConsumeIntInRange(0, 4) == 0 else "status",
        f50_solver=["halley", "newton", "brent", "bisection"][fdp.ConsumeIntInRange(0, 3)],
        precision=["float64", "float32"][fdp.ConsumeIntInRange(0, 1)])
    selected = tuple(api.OUTPUT_DTYPES)
    if fdp.ConsumeIntInRange(0, 3) == 0:
        names = list(api.ALL_OUTPUT_DTYPES)
        if fdp.ConsumeBool():  # some elasticities one by one (either size's name), not all
            names = [n for n in names if n != "elasticities"] + SINGLE_ELASTICITIES
        selected = tuple(name for name in names if fdp.ConsumeBool()) or ("epc",)
        options["outputs"] = selected
    if fdp.ConsumeIntInRange(0, 5) == 0:
        n = fdp.ConsumeIntInRange(0, 6)
        kwargs["spectrum"] = (np.array([fdp.ConsumeFloat() for _ in range(n)]),
                              np.array([fdp.ConsumeFloat() for _ in range(n)]))
    if fdp.ConsumeIntInRange(0, 5) == 0:
        out_shape = shape if fdp.ConsumeIntInRange(0, 3) else (fdp.ConsumeIntInRange(0, 5),)
        options["out"] = {name: np.zeros(outputs.output_shape(name, out_shape),
                                         dtype=api.ALL_OUTPUT_DTYPES.get(name, np.float64))
                          for name in selected}
    try:
        result = epc_fast.evaluate(**kwargs, backend=backend, **options)
    except EXPECTED_ERRORS:
        return
    _check(result)
    if options["invalid"] == "status" and options["t_mpe_solver"] != "newton":
        other = "reference" if backend == "core" else "core"
        options.pop("out", None)
        try:
            twin = epc_fast.evaluate(**kwargs, backend=other, **options)
        except EXPECTED_ERRORS:
            return  # e.g. a thread count only the core reads
        for name in ("status", "cause"):
            if getattr(result, name) is not None:
                assert np.array_equal(np.asarray(getattr(result, name)),
                                      np.asarray(getattr(twin, name))), (name, kwargs, options)


def _check(result):
    """The invariants of the module's docstring, over the fields ``result`` has."""
    fields = {name: np.asarray(getattr(result, name)).reshape(-1)
              for name in api.OUTPUT_DTYPES if getattr(result, name) is not None}
    status, cause = fields.get("status"), fields.get("cause")
    if status is not None:
        assert np.all(status <= 3), status
    if cause is not None:
        assert np.all(cause <= 3), cause
    if status is None:
        return
    ok, invalid = status == Status.OK, status == Status.INVALID
    unreachable, unbounded = status == Status.UNREACHABLE, status == Status.BLUR_UNBOUNDED
    values = {name: fields[name].astype(np.float64) for name in FLOAT_FIELDS if name in fields}
    for name, v in values.items():
        assert np.all(np.isfinite(v[ok])), name
        assert np.all(np.isnan(v[invalid])), name
    if cause is not None:
        assert np.all(cause[ok | invalid | unbounded] == 0)
        assert np.all(cause[unreachable] != 0)
    if "t_mpe_s" in values:
        assert np.all(values["t_mpe_s"][unreachable] == math.inf)
    for name in ("blur_mm", "f50_cyc_per_mm", "epc"):
        if name in values:
            assert np.all(np.isnan(values[name][unreachable])), name
    if "blur_mm" in values:
        assert np.all(values["blur_mm"][unbounded] == math.inf)
    for name in ("f50_cyc_per_mm", "epc"):
        if name in values:
            assert np.all(values[name][unbounded] == 0.0), name
    _check_sensitivity(result, ok, unbounded)


#: The whole-number parameters (binning, frames, lens): they have no elasticity, NaN at every
#: point.
WHOLE_NUMBERS = {p.name for p in params.PARAMETERS if p.integer}


def _check_sensitivity(result, ok, unbounded):
    """OK points have shares in [0, 1] that sum to 1 and finite elasticities (but for the
    whole-number parameters, NaN everywhere); the others NaN, but where the blur is unbounded
    the shares 0, 0, 1, 0 (docs/limits.md)."""
    shares = {name: np.asarray(getattr(result, name), dtype=np.float64).reshape(-1)
              for name in api.SHARE_OUTPUTS if getattr(result, name) is not None}
    for name, v in shares.items():
        assert np.all((v[ok] >= 0.0) & (v[ok] <= 1.0)), name
        assert np.all(np.isnan(v[~ok & ~unbounded])), name
        assert np.all(v[unbounded] == (1.0 if name == "share_motion" else 0.0)), name
    if len(shares) == len(api.SHARE_OUTPUTS) and ok.any():
        assert np.allclose(sum(v[ok] for v in shares.values()), 1.0, rtol=0, atol=1e-14)
    for name, v in (result.elasticities or {}).items():
        v = np.asarray(v, dtype=np.float64).reshape(-1)
        if name in WHOLE_NUMBERS:
            assert np.all(np.isnan(v)), name
            continue
        assert np.all(np.isfinite(v[ok])), name
        assert np.all(np.isnan(v[~ok])), name


def _array(fdp, n):
    """An array the binding may or may not accept."""
    kind = fdp.ConsumeIntInRange(0, 6)
    size = [n, 1, 0, n + 1, max(n - 1, 0)][fdp.ConsumeIntInRange(0, 4)]
    values = [fdp.ConsumeFloat() for _ in range(min(size, 80))] + [1.0] * max(size - 80, 0)
    if kind <= 3:
        return np.array(values, dtype=np.float64)
    if kind == 4:
        return np.array(values, dtype=np.float32)
    if kind == 5:
        return np.array(values, dtype=np.float64).reshape(-1, 1)[::1]
    return values  # a list, not an ndarray


def _core_call(fdp):
    """Mostly a well-formed call, so that the kernel runs; now and then one flaw."""
    n = fdp.ConsumeIntInRange(-2, 70)
    flaw = fdp.ConsumeIntInRange(0, 17)  # 0-6: one flaw, else none

    def good_column():
        size = max(n, 0) if fdp.ConsumeIntInRange(0, 2) else 1
        return np.array([fdp.ConsumeFloat() if fdp.ConsumeBool() else
                         EDGES[fdp.ConsumeIntInRange(0, len(EDGES) - 1)]
                         for _ in range(min(size, 80))] + [1.0] * max(size - 80, 0))

    count = _core.n_params + (fdp.ConsumeIntInRange(-1, 1) if flaw == 0 else 0)
    columns = [good_column() for _ in range(count)]
    if flaw == 1 and columns:
        columns[fdp.ConsumeIntInRange(0, len(columns) - 1)] = _array(fdp, max(n, 0))
    domains = params.domain_table() if flaw != 2 else np.array(
        [[fdp.ConsumeFloat() for _ in range(5)] for _ in range(fdp.ConsumeIntInRange(0, 24))])
    k = fdp.ConsumeIntInRange(0, 4)
    wavelengths = np.array([fdp.ConsumeFloat() for _ in range(k)])
    weights = np.array([fdp.ConsumeFloat() for _ in range(k + (flaw == 3))])
    out = None
    if fdp.ConsumeBool():
        out = {name: np.zeros(max(n, 0) + (flaw == 5), dtype=dtype)
               for name, dtype in api.OUTPUT_DTYPES.items() if fdp.ConsumeBool()}
    allocate = None
    if fdp.ConsumeBool():
        allocate = [name for name in CORE_OUTPUTS
                    if name not in (out or {}) and fdp.ConsumeBool()]
        if flaw == 6:
            allocate.append(["f50", 3, *(out or {})][fdp.ConsumeIntInRange(0, len(out or {}) + 1)])
    try:
        result = _core.evaluate(
            columns, fdp.ConsumeBool(), domains, wavelengths, weights, n,
            ["halley", "newton", "brent", "bisection", ""][fdp.ConsumeIntInRange(0, 3 + (flaw == 4))],
            [1e-14, 0.0, fdp.ConsumeFloat()][fdp.ConsumeIntInRange(0, 2)],
            ["closed_form", "brent", ""][fdp.ConsumeIntInRange(0, 1 + (flaw == 4))],
            [1e-15, 0.0, fdp.ConsumeFloat()][fdp.ConsumeIntInRange(0, 2)],
            ["float64", "float32", "half"][fdp.ConsumeIntInRange(0, 1 + (flaw == 4))],
            fdp.ConsumeIntInRange(1 - (flaw == 4), 3), fdp.ConsumeIntInRange(1 - (flaw == 4), 100),
            out, allocate)
    except EXPECTED_ERRORS:
        return
    for name in ("status", "cause"):
        if name in result:
            assert np.all(result[name] <= 3), name


def test_one_input(data):
    fdp = atheris.FuzzedDataProvider(data)
    if fdp.ConsumeIntInRange(0, 3):
        _public_call(fdp)
    else:
        _core_call(fdp)


def main():
    np.seterr(all="ignore")
    atheris.Setup(sys.argv, test_one_input)
    atheris.Fuzz()


if __name__ == "__main__":
    main()
