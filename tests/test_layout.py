"""The house's rooms hold: the package's and the core's layout, as docs/internals.md maps it.

Architecture guards, read from the source tree: subsystems are subpackages (no module-name
prefix stands for one), files stay small, no module imports itself round a circle, importing
epc_fast loads neither the scan nor the optimiser, the import paths users have keep working,
and tests share code only through tests/helpers/ (no test module imports another, no test
file edits sys.path).
"""

import ast
import importlib
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
from helpers.layout import shared_prefixes

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "python" / "epc_fast"
INTERNALS = ROOT / "docs" / "internals.md"

#: Longest Python module of the package, and binding file of the core, in lines.
MAX_PY_LINES = 500
MAX_CPP_LINES = 400


def _modules() -> dict:
    """{dotted name: path} of every module of the package's source tree."""
    modules = {}
    for path in PACKAGE.rglob("*.py"):
        parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        modules[".".join(parts)] = path
    return modules


def _imports(name: str, path: Path, modules: dict) -> set:
    """The package's modules that module ``name`` imports anywhere in its text (at the top or
    inside a function): ``from .x import y`` counts y when it is a module, else x."""
    found = set()
    package = name.split(".") if path.name == "__init__.py" else name.split(".")[:-1]
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package[:len(package) - (node.level - 1)]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            for alias in node.names:
                sub = f"{target}.{alias.name}"
                found.add(sub if sub in modules else target)
        elif isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
    return {m for m in found if m in modules and m != name}


def _circles(graph: dict) -> list:
    """The strongly connected components of more than one module (Tarjan)."""
    index, low, stack, on_stack, circles = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                circles.append(sorted(component))

    for v in graph:
        if v not in index:
            visit(v)
    return circles


def test_no_module_of_the_package_imports_itself_round_a_circle():
    modules = _modules()
    graph = {name: _imports(name, path, modules) for name, path in modules.items()}
    assert _circles(graph) == []


def test_the_circle_check_finds_a_circle():
    # the check itself: a -> b -> c -> a is one circle, d alone none
    assert _circles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]


#: The modules outside scan/ that may import the scan's inner modules (``epc_fast.scan.x``),
#: {module or subpackage: (the inner modules' prefixes it may import, why)}. Every module may
#: use the scan's public names (``from epc_fast import scan``; ``scan.run``), as users do.
SCAN_INSIDERS = {
    "epc_fast.commands.scan": (("epc_fast.scan.",), "the scan command"),
    "epc_fast.commands.sobol": (("epc_fast.scan.",), "the Sobol' indices of a scan config's "
                                "space and its [sobol] table: part of the scan"),
    "epc_fast.optimize": (("epc_fast.scan.config", "epc_fast.scan.sampling.",
                           "epc_fast.scan.running.readout_modes",
                           "epc_fast.scan.running.core_plan"),
                          "the optimiser scans: its scene and designs are a scan config's space "
                          "(the scan's parser), drawn by the scan's sampling, evaluated per "
                          "readout group and seeded as a scan's points are"),
    "epc_fast.simulate.config": (("epc_fast.scan.config",), "a review's designs are a scan "
                                 "config's [design] and [evaluate] tables (the scan's parser)"),
}


def _scan_intrusions(modules: dict, insiders: dict) -> list:
    """"importer -> inner module" of every import of an inner module of epc_fast.scan from
    outside it that ``insiders`` does not allow."""
    found = []
    for name, path in modules.items():
        if name == "epc_fast.scan" or name.startswith("epc_fast.scan."):
            continue
        allowed = [prefixes for owner, (prefixes, _) in insiders.items()
                   if name == owner or name.startswith(owner + ".")]
        found += [f"{name} -> {m}" for m in sorted(_imports(name, path, modules))
                  if m.startswith("epc_fast.scan.")
                  and not any(m.startswith(p) for prefixes in allowed for p in prefixes)]
    return found


def test_no_subsystem_imports_the_scans_inner_modules_but_the_scan_command():
    assert _scan_intrusions(_modules(), SCAN_INSIDERS) == []


def test_the_scan_import_check_finds_an_intrusion():
    modules = {name: path for name, path in _modules().items()
               if name.startswith("epc_fast.scan.sampling") or name in (
                   "epc_fast.optimize.checks", "epc_fast.plotting.common")}
    assert _scan_intrusions(modules, {}) == ["epc_fast.optimize.checks -> "
                                             "epc_fast.scan.sampling.space"]
    assert _scan_intrusions(modules, SCAN_INSIDERS) == []


#: A statement that edits the module search path: sys.path.insert/append/extend, an item or
#: slice of it assigned, or sys.path itself assigned or extended (in code or in a code string).
SYS_PATH_EDIT = re.compile(r"\bsys\s*\.\s*path\s*"
                           r"(\.\s*(insert|append|extend)\s*\(|\[[^\]]*\]\s*=|\+?=[^=])")


def _test_module_imports(source: str) -> list:
    """The imports in ``source`` that reach a test module (a dotted part named test_*), as
    written (``test_x``, ``.test_x``, ``tests.test_x``, ``pkg.test_x`` for ``from pkg import
    test_x``); helpers.* and conftest are the shared pieces tests may import."""
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            names = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = "." * node.level + (node.module or "")
            sep = "" if base.endswith(".") else "."
            names = [base] if _names_a_test(base) else [f"{base}{sep}{alias.name}"
                                                        for alias in node.names]
        else:
            continue
        found += [name for name in names if _names_a_test(name)]
    return sorted(set(found))


def _names_a_test(dotted: str) -> bool:
    return any(part.startswith("test_") for part in dotted.split("."))


@pytest.mark.parametrize("path", sorted((ROOT / "tests").rglob("*.py")),
                         ids=lambda p: str(p.relative_to(ROOT / "tests")))
def test_no_test_file_imports_a_test_module_or_edits_sys_path(path):
    # what tests share lives in tests/helpers/ (pyproject.toml puts tests/ on sys.path; a child
    # process gets it through PYTHONPATH, helpers.child_env)
    source = path.read_text()
    assert _test_module_imports(source) == []
    assert not SYS_PATH_EDIT.search(source)


def test_the_test_import_check_finds_an_import_of_a_test_module():
    planted = ("import os, tests.test_api\nfrom test_core_vs_reference import x\n"
               "from .test_golden import y\nfrom . import test_cfa\nfrom tests import test_modes\n"
               "import helpers.designs\nfrom helpers.mp_model import mp_model\nimport conftest\n"
               "import pytest\nfrom epc_fast import testing_tools\n")
    assert _test_module_imports(planted) == [".test_cfa", ".test_golden", "test_core_vs_reference",
                                             "tests.test_api", "tests.test_modes"]
    path = "sys" + ".path"  # spelt apart, so that this file holds no edit of its own
    for edit in (".insert(0, 'tests')", ".append(root)", ".extend([a])", "[:0] = [a]",
                 " = ['x']", " += ['x']"):
        assert SYS_PATH_EDIT.search(f"import sys\n{path}{edit}\n"), edit
        assert SYS_PATH_EDIT.search(f"code = \"import sys; {path}{edit}\"\n"), edit
    for reading in ("print(sys" ".path)", "x = sys" ".path[0]", "if sys" ".path == []: pass",
                    "# pyproject.toml puts tests/ on sys" ".path"):
        assert not SYS_PATH_EDIT.search(reading), reading


@pytest.mark.parametrize("folder", sorted({p.parent for p in PACKAGE.rglob("__init__.py")}),
                         ids=lambda p: str(p.relative_to(PACKAGE.parent)))
def test_no_module_name_prefix_stands_for_a_subsystem(folder):
    # a subsystem is a subpackage (optimize/, scan/config/, ...), not modules that share a
    # name's first word side by side
    names = [p.stem for p in folder.glob("*.py")] + [p.name for p in folder.iterdir()
                                                     if (p / "__init__.py").exists()]
    assert shared_prefixes(names) == {}


def test_the_prefix_check_finds_a_subsystem():
    assert shared_prefixes(["optimize", "optimize_config", "api", "_core_x86"]) == {"optimize": 2}
    assert shared_prefixes(["plot_text", "plot_layout", "limits_plot"]) == {"plot": 2}
    assert shared_prefixes(["elasticity_outputs", "api"]) == {}


@pytest.mark.parametrize("path", sorted(PACKAGE.rglob("*.py")), ids=lambda p: str(p.relative_to(PACKAGE)))
def test_no_python_module_is_over_500_lines(path):
    assert len(path.read_text().splitlines()) <= MAX_PY_LINES


@pytest.mark.parametrize("path", sorted((ROOT / "cpp" / "src").glob("*.cpp")), ids=lambda p: p.name)
def test_no_binding_file_is_over_400_lines(path):
    assert len(path.read_text().splitlines()) <= MAX_CPP_LINES


def test_importing_epc_fast_loads_neither_the_scan_nor_the_optimiser_nor_the_simulator():
    code = ("import sys, epc_fast\n"
            "loaded = sorted(m for m in sys.modules if m.split('.')[:2] in "
            "(['epc_fast', 'scan'], ['epc_fast', 'optimize'], ['epc_fast', 'reference'], "
            "['epc_fast', 'simulate']))\n"
            "assert not loaded, loaded\n"
            "assert epc_fast.scan.Space and epc_fast.optimize.maximize\n"
            "assert epc_fast.simulate.capture\n"
            "assert 'epc_fast.scan' in sys.modules and 'epc_fast.optimize' in sys.modules\n"
            "assert 'epc_fast.simulate' in sys.modules\n")
    env = dict(os.environ)
    proc = subprocess.run([sys.executable, "-c", "import conftest\n" + code],
                          cwd=Path(__file__).parent, env=env, capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr


def test_the_package_lists_scan_and_optimize_alike():
    import epc_fast

    assert {"scan", "optimize", "simulate"} <= set(epc_fast.__all__) <= set(dir(epc_fast))
    with pytest.raises(AttributeError, match="no attribute 'nothing'"):
        epc_fast.nothing  # noqa: B018


#: Import paths users write today, each "module:name".
PUBLIC_PATHS = [
    "epc_fast:evaluate", "epc_fast:Result", "epc_fast:Design", "epc_fast:lux_for_epc",
    "epc_fast:crossover_lux", "epc_fast:Spectrum", "epc_fast:Status", "epc_fast:Cause",
    "epc_fast:output_cache", "epc_fast:scan", "epc_fast:optimize",
    "epc_fast.api:evaluate", "epc_fast.api:Result", "epc_fast.api:ELASTICITY_PARAMETERS",
    "epc_fast.api:SHARE_OUTPUTS", "epc_fast.api:OUTPUT_DTYPES", "epc_fast.api:MAX_THREADS",
    "epc_fast.optimize:maximize", "epc_fast.optimize:Problem", "epc_fast.optimize:Mean",
    "epc_fast.optimize:Quantile", "epc_fast.optimize:ProbabilityAtLeast",
    "epc_fast.optimize:Optimum", "epc_fast.optimize:Estimate", "epc_fast.optimize:Curve",
    "epc_fast.optimize.objectives:order_statistics", "epc_fast.optimize.config:load_optimize_config",
    "epc_fast.plotting:plot_epc_over_illuminance", "epc_fast.plotting:plot_limits_over_illuminance",
    "epc_fast.plotting:save_figure",
    "epc_fast.tradeoff:measure", "epc_fast.tradeoff:default_settings",
    "epc_fast.tradeoff:pareto_front", "epc_fast.tradeoff:plot_tradeoff",
    "epc_fast.tradeoff:markdown_columns", "epc_fast.tradeoff:csv_columns",
    "epc_fast.paper:statements", "epc_fast.paper:FIGURES", "epc_fast.paper:write_csv",
    "epc_fast.paper:markdown_table", "epc_fast.paper:simulated_markdown_table",
    "epc_fast:simulate", "epc_fast.simulate:capture", "epc_fast.simulate:slanted_edge",
    "epc_fast.simulate:flat", "epc_fast.simulate:image", "epc_fast.simulate:esfr",
    "epc_fast.simulate:snr", "epc_fast.simulate.agreement:agreement",
    "epc_fast.reference:mtf_diffraction", "epc_fast.reference:evaluate_points",
    "epc_fast.reference.sensitivity:sensitivity_points",
    "epc_fast.scan:run", "epc_fast.scan:Space", "epc_fast.scan:LogUniform",
    "epc_fast.presets:HIGH_TIER", "epc_fast.spectra:diffraction_spectrum",
    "epc_fast.inverse:lux_for_epc", "epc_fast.memory:output_cache",
    "epc_fast.params:PARAMETERS", "epc_fast.sensor:sensor_shape",
]


@pytest.mark.parametrize("path", PUBLIC_PATHS)
def test_a_public_import_path_keeps_working(path):
    module, name = path.split(":")
    assert getattr(importlib.import_module(module), name) is not None


def test_every_all_entry_names_something():
    missing = []
    for name in _modules():
        if name.rsplit(".", 1)[-1].startswith("_core_") or name.endswith("__main__"):
            continue
        module = importlib.import_module(name)
        missing += [f"{name}.{entry}" for entry in getattr(module, "__all__", ())
                    if not hasattr(module, entry)]
    assert missing == []


def test_the_map_in_docs_internals_names_every_header_and_binding_file():
    # a header by its path under cpp/include/epc_fast/ (its folder: f50/stage.h)
    text = INTERNALS.read_text()
    headers = ROOT / "cpp" / "include" / "epc_fast"
    files = [f.relative_to(headers).as_posix() for f in sorted(headers.rglob("*.h"))]
    files += [f.name for f in sorted(ROOT.glob("cpp/src/*"))]
    unnamed = [f for f in files if not re.search(rf"`(?:[\w/]+/)?{re.escape(f)}`", text)]
    assert unnamed == []


def test_the_map_in_docs_internals_names_every_room_of_the_package():
    text = INTERNALS.read_text()
    rooms = [p.name for p in PACKAGE.iterdir() if p.is_dir() and (p / "__init__.py").exists()]
    rooms += [p.name for p in PACKAGE.glob("*.py") if p.stem != "__init__"]
    unnamed = [room for room in sorted(rooms) if f"`{room}" not in text]
    assert unnamed == []


def test_the_map_in_docs_internals_names_every_module_of_the_package():
    # a module by its name in backticks (`noise`, `noise.py`) or its path from the package
    text = INTERNALS.read_text()
    unnamed = [str(path.relative_to(PACKAGE)) for path in sorted(PACKAGE.rglob("*.py"))
               if path.stem != "__init__" and not path.stem.startswith("_core_")
               and not re.search(rf"`(?:[\w/]+/)?{re.escape(path.stem)}(?:\.py)?`", text)]
    assert unnamed == []


def _stale_files(text: str, files) -> list:
    """The files ``text`` names in backticks (``x.py``, ``scan/pass.h``) that none of
    ``files`` (paths from the repository's root) is or ends with."""
    named = set(re.findall(r"`([\w./-]+\.(?:py|pyi|h|cpp|md|toml|csv|json))`", text))
    return sorted(n for n in named if not any(f == n or f.endswith("/" + n) for f in files))


def test_every_file_the_map_in_docs_internals_names_exists():
    files = [str(p.relative_to(ROOT)) for p in ROOT.rglob("*")
             if p.is_file() and ".git" not in p.parts and "build" not in p.parts]
    assert _stale_files(INTERNALS.read_text(), files) == []


def test_the_stale_file_check_finds_a_file_that_is_gone():
    files = ["cpp/include/epc_fast/scan/pass.h", "python/epc_fast/api.py"]
    assert _stale_files("`scan/pass.h`, `api.py` and `sensitivity.h`", files) == \
        ["sensitivity.h"]


def test_every_test_file_the_ci_scripts_and_docs_name_exists():
    # the sanitizer's run names test files one by one: a moved test would leave it failing
    texts = [p for p in (ROOT / ".ci").iterdir() if p.is_file()]
    texts += [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
    missing = [f"{p.name}: {name}" for p in texts
               for name in re.findall(r"\b(tests/[\w/]+\.py)", p.read_text())
               if not (ROOT / name).exists()]
    assert missing == []


def test_no_name_a_subpackage_exports_hides_one_of_its_modules():
    # `from .measurements import measure` in tradeoff/__init__ is fine; a module named measure
    # would be hidden behind the function, and epc_fast.tradeoff.measure would not be it
    import pkgutil
    import types

    hidden = []
    for name, path in _modules().items():
        if path.name != "__init__.py":
            continue
        package = importlib.import_module(name)
        for sub in pkgutil.iter_modules(package.__path__):
            value = getattr(package, sub.name, None)
            if value is not None and not isinstance(value, types.ModuleType):
                hidden.append(f"{name}.{sub.name}")
    assert hidden == []


def _is_private(name: str) -> bool:
    return name.startswith("_") and not name.startswith("__")


def _private_names(tree) -> set:
    """The private names (one leading underscore) a module's text defines or binds anywhere:
    functions, classes, variables, imports' aliases and attributes it assigns (``self._x``)."""
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            names.add(node.name)
        elif isinstance(node, ast.Name) and isinstance(node.ctx, ast.Store):
            names.add(node.id)
        elif isinstance(node, ast.Attribute) and isinstance(node.ctx, ast.Store):
            names.add(node.attr)
        elif isinstance(node, ast.alias):
            names.add(node.asname or node.name.split(".")[0])
    return {name for name in names if _is_private(name)}


def _private_uses(texts: dict, packages: set) -> list:
    """Where a module of ``texts`` ({dotted name: source}; ``packages``: the names that are
    packages) uses a private name another module defines: ``from .x import _y``, ``x._y`` for
    an imported module x of the package, and ``obj._y`` where only other modules define _y.
    Private modules (``from . import _limits``) are the package's own and may be imported."""
    trees = {name: ast.parse(text) for name, text in texts.items()}
    defined = {name: _private_names(tree) for name, tree in trees.items()}
    found = []
    for name, tree in trees.items():
        package = name.split(".") if name in packages else name.split(".")[:-1]
        aliases = {}  # local name -> module of the package
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom):
                base = (".".join(package[:len(package) - (node.level - 1)]
                                 + ([node.module] if node.module else []))
                        if node.level else node.module or "")
                for alias in node.names:
                    sub = f"{base}.{alias.name}"
                    if sub in texts:
                        aliases[alias.asname or alias.name] = sub
                    elif base in texts and _is_private(alias.name):
                        found.append(f"{name}: from {base} import {alias.name}")
            elif isinstance(node, ast.Import):
                for alias in node.names:
                    if alias.name in texts and alias.asname:
                        aliases[alias.asname] = alias.name
        others = set().union(*(d for m, d in defined.items() if m != name))
        for node in ast.walk(tree):
            if not (isinstance(node, ast.Attribute) and _is_private(node.attr)):
                continue
            owner = node.value.id if isinstance(node.value, ast.Name) else None
            if owner in aliases:
                if f"{aliases[owner]}.{node.attr}" not in texts:
                    found.append(f"{name}: {aliases[owner]}.{node.attr}")
            elif (owner not in ("self", "cls") and node.attr not in defined[name]
                  and node.attr in others):
                found.append(f"{name}: .{node.attr} of another module")
    return sorted(set(found))


def test_no_module_of_the_package_uses_another_modules_private_names():
    modules = _modules()
    texts = {name: path.read_text() for name, path in modules.items()}
    packages = {name for name, path in modules.items() if path.name == "__init__.py"}
    assert _private_uses(texts, packages) == []


def test_the_private_name_check_finds_a_private_use():
    texts = {
        "pkg": "",
        "pkg._internal": "def public():\n    pass\n",
        "pkg.a": ("def _hidden():\n    pass\n\nclass Bins:\n    def __init__(self):\n"
                  "        self._bins = 1\n"),
        "pkg.b": ("from .a import _hidden\nfrom . import a\n\na._hidden()\n\n"
                  "def first(histogram):\n    return histogram._bins\n"),
        "pkg.c": ("from . import _internal\nfrom .a import Bins\n\n_internal.public()\n\n"
                  "class Own:\n    def __init__(self):\n        self._own = 1\n\n"
                  "    def same(self, other):\n        return other._own, self._bins\n"),
    }
    # b reaches into a three ways; c imports a private module and uses its own and its
    # instances' private names, which is fine
    assert _private_uses(texts, {"pkg"}) == [
        "pkg.b: ._bins of another module", "pkg.b: from pkg.a import _hidden",
        "pkg.b: pkg.a._hidden"]
