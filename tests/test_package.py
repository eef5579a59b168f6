"""Architecture guards: what importing the package pulls in, and the shape of its public API."""

import dataclasses
import inspect
import subprocess
import sys

import pytest

import epc_fast
from epc_fast import params, reference


def test_importing_epc_fast_does_not_import_optional_dependencies():
    code = ("import sys, epc_fast; epc_fast.evaluate(1000.0, 1.4, 2.8, 5.6, sensor_area_mm2=15.0);"
            "bad = [m for m in ('colour', 'matplotlib', 'tqdm', 'dask', 'pyarrow', 'scipy')"
            " if m in sys.modules]; print(bad); sys.exit(1 if bad else 0)")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=60)
    assert proc.returncode == 0, proc.stdout + proc.stderr


def test_evaluate_has_the_documented_signature():
    sig = inspect.signature(epc_fast.evaluate)
    names = list(sig.parameters)
    assert names[:4] == ["illuminance_lux", "pixel_pitch_um", "f_number", "focal_length_mm"]
    expected_defaults = {
        "pixel_count": None, "sensor_area_mm2": None, "reflectance": 0.4,
        "lens_transmittance": 1.0, "field_angle_deg": 0.0, "fill_factor": 1.0,
        "electrons_per_lux_s_m2": None, "read_noise_e": 0.0, "dark_current_e_per_s": 0.0,
        "prnu": 0.0, "full_well_e": float("inf"), "snr_db": 30.0, "shake_deg_per_s": 4.39,
        "stabilization": 1.0, "jitter_um": 0.0, "wavelength_nm": 550.0, "mtf_threshold": 0.5,
        "threads": None, "backend": "core",
    }
    for name, default in expected_defaults.items():
        assert sig.parameters[name].default == default, name
        assert sig.parameters[name].kind is inspect.Parameter.KEYWORD_ONLY, name


def test_parameter_table_defaults_match_the_signature():
    sig = inspect.signature(epc_fast.evaluate)
    for p in params.PARAMETERS:
        if p.name in params.CFA_PARAMETERS:  # None: 1 (the table's) or the Bayer CFA's
            assert sig.parameters[p.name].default is None and p.default == 1.0, p.name
        elif p.name == "binning_readout":  # its name in the signature, its code in the table
            default = sig.parameters[p.name].default
            assert params.READOUT_CODES[default] == p.default == 0.0
        elif p.default is not None:
            assert sig.parameters[p.name].default == p.default, p.name


def test_status_codes_are_the_documented_names():
    assert [s.name for s in epc_fast.Status] == ["OK", "INVALID", "UNREACHABLE",
                                                 "BLUR_UNBOUNDED", "BEYOND_TABLE",
                                                 "EXPOSURE_LIMIT"]
    assert [c.name for c in epc_fast.Cause] == ["NONE", "NO_LIGHT", "PRNU", "FULL_WELL"]


def test_core_formulas_carry_the_reference_names():
    from epc_fast import _core

    for name in ("sinc", "mtf_diffraction", "signal_electrons"):
        assert hasattr(_core.testing, name) and hasattr(reference, name), name


#: The newest terms' formulas (the wavefront error, denoising, a lens table, a colour sensor's
#: demosaicker): each defined under this name in a header of the core and in the reference.
TERM_FORMULAS = ("mtf_aberration", "aberration_log_factor", "noise_gain_denoise",
                 "denoise_log_factor", "noise_gain_log_slope", "mtf_lens", "lens_log_factor",
                 "mtf_demosaic", "demosaic_log_factor", "diffraction_log_slope_numerator")


@pytest.mark.parametrize("name", TERM_FORMULAS)
def test_each_terms_formulas_carry_the_same_name_in_the_core_and_the_reference(name):
    import re
    from pathlib import Path

    headers = Path(__file__).resolve().parents[1] / "cpp" / "include" / "epc_fast"
    # a definition: the name after a return type, then its parameters
    returns = r"(?:void|bool|double|T|\w+Factor|\w+Slopes<T>)"
    defined = re.compile(rf"^[\w:<>, ]*\b{returns} {name}\(", re.M)
    assert any(defined.search(h.read_text()) for h in headers.rglob("*.h")), name
    modules = (reference.model, reference.mtf, reference.optics, reference.lens, reference.cfa,
               reference.sensitivity)
    assert any(callable(getattr(m, name, None)) for m in modules), name


def test_the_core_stub_lists_every_public_function_of_the_core():
    import ast
    from pathlib import Path

    from epc_fast import _core

    stub = Path(epc_fast.__file__).with_name("_core.pyi")
    tree = ast.parse(stub.read_text())
    stubbed = {node.name for node in tree.body if isinstance(node, ast.FunctionDef)}
    public = {name for name in dir(_core) if not name.startswith("_")
              and callable(getattr(_core, name))}
    assert stubbed == public


def test_the_core_stub_lists_every_function_of_the_testing_submodule():
    import ast
    from pathlib import Path

    from epc_fast import _core

    stub = Path(epc_fast.__file__).with_name("_core.pyi")
    tree = ast.parse(stub.read_text())
    testing = next(node for node in tree.body
                   if isinstance(node, ast.ClassDef) and node.name == "_Testing")
    stubbed = {node.name for node in testing.body if isinstance(node, ast.FunctionDef)}
    public = {name for name in dir(_core.testing) if not name.startswith("_")
              and callable(getattr(_core.testing, name))}
    assert stubbed == public


def test_the_loaded_build_is_public():
    from epc_fast import _core

    info = epc_fast.build_info()
    assert info.isa == _core.isa and info.isa in info.built_levels
    assert info.isa in info.cpu_levels and "x86-64" in info.cpu_levels
    assert info.cpu_levels == tuple(level for level in ("x86-64", "x86-64-v2", "x86-64-v3",
                                                        "x86-64-v4")
                                    if level == "x86-64" or _core.cpu_levels()[level])
    assert info.openmp is _core.openmp_enabled()
    assert info.default_threads == _core.checked_default_threads()
    assert info.version == epc_fast.__version__
    assert dataclasses.is_dataclass(info)
    with pytest.raises(dataclasses.FrozenInstanceError):
        info.isa = "generic"
    assert str(info) == (f"epc_fast {info.version}, core {info.isa} (built: "
                         f"{', '.join(info.built_levels)}; CPU: "
                         f"{', '.join(info.cpu_levels)}), OpenMP "
                         f"{'on' if info.openmp else 'off'}, {info.default_threads} threads "
                         "by default")


def test_the_package_refers_to_sections_of_docs_model_md_that_exist():
    import re
    from pathlib import Path

    from helpers.scripts import ROOT

    package = ROOT / "python" / "epc_fast"  # the source tree's, whichever copy is imported
    model = (ROOT / "docs" / "model.md").read_text()
    headings = set(re.findall(r"^#+ (.+)$", model, flags=re.M))
    texts = {path.relative_to(package): path.read_text() for path in package.rglob("*.py")}
    texts["help(Design)"] = epc_fast.Design.__doc__
    stale = [name for name, text in texts.items() if "MODEL.md" in text]
    assert stale == []
    cited = {section for text in texts.values()
             for section in re.findall(r'docs/model\.md, "([^"]+)"', " ".join(text.split()))}
    assert "EPC" in cited and cited <= headings
