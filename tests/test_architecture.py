"""The import graph of the package runs one way (DESIGN.md, Layout).

cli -> study -> verification -> (dynamics, closedform, similarity, risk) -> structures -> motions
-> constants. The test reads every module's imports (top level and inside functions) with
``ast`` and checks that no package imports a package of a higher layer, and that the
package-level graph has no cycle. Inside ``study/`` the subpackages follow the flow of a study
the same way: spec -> designs -> running -> analysis -> report. No function of the package has
over 80 lines of code, and the kernels' package ``dynamics/`` keeps its files under 700 lines.
"""

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "rockstudy"

# Lower number = lower layer. A module may import only from its own package or lower layers.
LAYER = {
    "constants": 0,
    "_validate": 0,
    "_roots": 0,  # the one Newton-bisection root finder, shared from motions up to closedform
    "_warnings": 0,
    "warnings": 0,
    "_numba_cache": 0,  # numba's cache saves made safe between processes
    "data": 0,
    "motions": 1,
    "structures": 2,
    "dynamics": 3,
    "closedform": 3,
    "similarity": 3,
    "risk": 3,  # hazard curves and annual rates: numpy/scipy over motions' IM names
    "verification": 4,
    "figures": 5,
    "demo": 5,
    "study": 5,
    "cli": 6,
    "__init__": 6,
}
# Physics packages of one layer must not import each other (no sideways loops).
SIDEWAYS_FORBIDDEN = {"dynamics", "closedform", "similarity", "risk"}


def _package_of(path: Path) -> str:
    rel = path.relative_to(PACKAGE)
    return rel.parts[0].removesuffix(".py")


def _imported_packages(path: Path) -> set[str]:
    tree = ast.parse(path.read_text())
    rel = path.relative_to(PACKAGE)
    depth = len(rel.parts) - 1  # 0 for rockstudy/x.py, 1 for rockstudy/pkg/x.py
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            if node.level == 0:
                mod = node.module or ""
                if mod.startswith("rockstudy."):
                    out.add(mod.split(".")[1])
                continue
            up = node.level - 1  # levels above the module's own package
            if up > depth:
                continue
            if up == depth:  # relative to rockstudy/
                if node.module:
                    out.add(node.module.split(".")[0])
                else:  # `from . import name`: a submodule, or a name of rockstudy/__init__
                    out.update(a.name if a.name in LAYER else "__init__" for a in node.names)
            else:  # inside the module's own package
                out.add(rel.parts[0])
        elif isinstance(node, ast.Import):
            for a in node.names:
                if a.name.startswith("rockstudy."):
                    out.add(a.name.split(".")[1])
    return out


def _graph():
    graph: dict[str, set[str]] = {}
    for path in PACKAGE.rglob("*.py"):
        pkg = _package_of(path)
        graph.setdefault(pkg, set()).update(_imported_packages(path) - {pkg})
    return graph


def test_every_package_has_a_layer():
    assert set(_graph()) <= set(LAYER), set(_graph()) - set(LAYER)


def test_imports_run_downwards_only():
    bad = []
    for pkg, deps in _graph().items():
        for dep in deps:
            if LAYER[dep] > LAYER[pkg]:
                bad.append(f"{pkg} imports {dep}")
            elif dep in SIDEWAYS_FORBIDDEN and pkg in SIDEWAYS_FORBIDDEN and dep != pkg:
                bad.append(f"{pkg} imports {dep} sideways")
    assert not bad, bad


def _module_name(path: Path) -> str:
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _module_graph():
    """Module-level graph: each module to the rockstudy modules it imports (a name imported
    from a package resolves to its submodule when there is one, else to the package)."""
    paths = {_module_name(p): p for p in PACKAGE.rglob("*.py")}

    def existing(name):
        while name and name not in paths:
            name = name.rpartition(".")[0]
        return name

    graph = {}
    for mod, path in paths.items():
        package = mod if path.name == "__init__.py" else mod.rpartition(".")[0]
        deps = set()
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Import):
                deps |= {existing(a.name) for a in node.names if a.name.startswith("rockstudy.")}
            elif isinstance(node, ast.ImportFrom):
                if node.level:
                    base = package.split(".")[: len(package.split(".")) - node.level + 1]
                    target = ".".join(base + ([node.module] if node.module else []))
                elif (node.module or "").startswith("rockstudy"):
                    target = node.module
                else:
                    continue
                deps |= {existing(f"{target}.{a.name}") for a in node.names}
        graph[mod] = deps - {mod, ""}
    return graph


def _find_cycle(graph):
    state: dict[str, int] = {}

    def visit(node, stack):
        state[node] = 1
        for dep in sorted(graph.get(node, ())):
            if state.get(dep) == 1:
                raise AssertionError(" -> ".join([*stack, node, dep]))
            if dep not in state:
                visit(dep, [*stack, node])
        state[node] = 2

    for node in sorted(graph):
        if node not in state:
            visit(node, [])


def test_no_cycle_between_modules():
    """Not only the packages: no module imports, through any chain, a module that imports it
    (so no import works only because an ``__init__`` leaves a module out)."""
    graph = _module_graph()
    assert "rockstudy.dynamics.batch" in graph["rockstudy.verification.validity"]
    _find_cycle(graph)


def test_no_cycle():
    _find_cycle(_graph())


def test_the_cycle_finder_finds_cycles():
    _find_cycle({"a": {"b"}, "b": {"c"}, "c": set()})
    with pytest.raises(AssertionError, match="a -> b -> c -> a"):
        _find_cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}})


# The subpackages of study/ in the order of a study's flow (issue 25 section 1): the study file,
# its designs, running them, analysing the cube, reporting it. Lower number = earlier; a module
# of study/ may import only from its own subpackage or from earlier ones.
STUDY_LAYER = {
    "spec": 0,  # the study file: schema, distributions, feasibility, IDA options
    "designs": 1,  # sampled designs, record designs (Python API), a study's record rows
    "running": 2,  # runner (dask), evaluate (one chunk), store (zarr cube), kernel warm-up
    "analysis": 3,  # Sobol', fragility, collapse, record fragility and similarity
    "report": 4,  # the HTML pages
    "__init__": 5,  # rockstudy.study itself: the public names
}


def _study_part(module: str) -> str:
    """The subpackage of study/ that holds ``module`` (``__init__`` for rockstudy.study)."""
    parts = module.split(".")
    return parts[2] if len(parts) > 2 else "__init__"


def _study_graph():
    """Each subpackage of study/ to the subpackages of study/ its modules import."""
    graph: dict[str, set[str]] = {}
    for mod, deps in _module_graph().items():
        if mod == "rockstudy.study" or mod.startswith("rockstudy.study."):
            inside = {_study_part(d) for d in deps if d.startswith("rockstudy.study.")}
            graph.setdefault(_study_part(mod), set()).update(inside - {_study_part(mod)})
    return graph


def _against_the_flow(graph, layer) -> list[str]:
    return sorted(
        f"{a} imports {b}" for a, deps in graph.items() for b in deps if layer[b] > layer[a]
    )


def test_every_study_subpackage_has_a_layer():
    graph = _study_graph()
    assert {"spec", "designs", "running", "analysis", "report"} <= set(graph)
    assert set(graph) <= set(STUDY_LAYER), set(graph) - set(STUDY_LAYER)


def test_study_imports_follow_the_flow():
    graph = _study_graph()
    assert "designs" in graph["running"] and "running" in graph["report"]  # the graph is read
    assert not _against_the_flow(graph, STUDY_LAYER), _against_the_flow(graph, STUDY_LAYER)
    _find_cycle(graph)


def test_the_flow_check_finds_an_import_against_it():
    graph = {"spec": {"designs"}, "designs": {"spec"}, "report": {"spec"}}
    assert _against_the_flow(graph, STUDY_LAYER) == ["spec imports designs"]


def test_physics_never_imports_the_study_backends():
    heavy = ("dask", "distributed", "SALib", "zarr", "netCDF4", "h5netcdf")
    bad = []
    for sub in ("motions", "structures", "dynamics", "closedform", "similarity.py", "risk"):
        for path in (PACKAGE / sub).rglob("*.py") if not sub.endswith(".py") else [PACKAGE / sub]:
            for node in ast.walk(ast.parse(path.read_text())):
                names = []
                if isinstance(node, ast.Import):
                    names = [a.name for a in node.names]
                elif isinstance(node, ast.ImportFrom) and node.level == 0:
                    names = [node.module or ""]
                bad += [f"{path.name}: {n}" for n in names if n.split(".")[0] in heavy]
    assert not bad, bad


# Size limits (issue 25 §4): short functions everywhere, and the kernels' files of one job.
MAX_FUNCTION_LINES = 80
MAX_MODULE_LINES = 700


def _docstring_lines(node) -> set[int]:
    """Line numbers of the docstrings of ``node`` and of the functions and classes inside it."""
    lines = set()
    for n in ast.walk(node):
        body = getattr(n, "body", None)
        if (
            isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef))
            and body
            and isinstance(body[0], ast.Expr)
            and isinstance(body[0].value, ast.Constant)
            and isinstance(body[0].value.value, str)
        ):
            lines |= set(range(body[0].lineno, body[0].end_lineno + 1))
    return lines


def code_lines(source: str) -> dict[str, int]:
    """Lines of code of every function in ``source`` (nested functions count in their
    enclosing one too): from ``def`` to its end, without docstrings, blank lines or comment
    lines. Keyed by the name, with its line number."""
    text = source.split("\n")
    out = {}
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            doc = _docstring_lines(node)
            out[f"{node.name}:{node.lineno}"] = sum(
                1
                for i in range(node.lineno, node.end_lineno + 1)
                if i not in doc and text[i - 1].strip() and not text[i - 1].strip().startswith("#")
            )
    return out


def test_code_lines_counts_code_only():
    source = (
        'def f(x):\n    """Doc.\n\n    More.\n    """\n\n    # a comment\n    y = x\n    return y\n'
    )
    assert code_lines(source) == {"f:1": 3}
    nested = "def f():\n    def g():\n        return 1\n\n    return g\n"
    assert code_lines(nested) == {"f:1": 4, "g:2": 2}


def test_functions_are_short():
    """Every function of the package, not only the kernels."""
    paths = sorted(PACKAGE.rglob("*.py"))
    assert PACKAGE / "study" / "designs" / "sampling.py" in paths
    long = {
        f"{path.relative_to(PACKAGE)}:{name}": n
        for path in paths
        for name, n in code_lines(path.read_text()).items()
        if n > MAX_FUNCTION_LINES
    }
    assert not long, f"functions over {MAX_FUNCTION_LINES} lines of code: {long}"


def test_dynamics_modules_are_short():
    long = {
        path.name: n
        for path in sorted((PACKAGE / "dynamics").glob("*.py"))
        if (n := len(path.read_text().splitlines())) > MAX_MODULE_LINES
    }
    assert not long, f"modules over {MAX_MODULE_LINES} lines: {long}"


def _public(path: Path) -> bool:
    """Whether users may import names from ``path``: no part of its path below the package
    starts with an underscore (``__init__.py`` aside)."""
    parts = path.relative_to(PACKAGE).parts
    return not any(p.startswith("_") and p != "__init__.py" for p in parts)


#: The modules users import names from: every module of the package, its subpackages and
#: theirs (rockstudy.risk.curves, rockstudy.similarity, ...), but the private ones.
PUBLIC_MODULES = sorted(p for p in PACKAGE.rglob("*.py") if _public(p))


def _declared_all(path: Path):
    """The names of ``__all__`` assigned at the top of a module, or None."""
    for node in ast.parse(path.read_text()).body:
        targets = getattr(node, "targets", None) or [getattr(node, "target", None)]
        if any(isinstance(t, ast.Name) and t.id == "__all__" for t in targets if t):
            return ast.literal_eval(node.value)
    return None


@pytest.mark.parametrize("path", PUBLIC_MODULES, ids=lambda p: str(p.relative_to(PACKAGE)))
def test_every_public_module_declares_its_names(path):
    """Each public module says what it exports (``__all__``), so that ``np``, ``math`` or ``Path``
    imported inside it are not public names; every name it lists exists."""
    import importlib

    names = _declared_all(path)
    assert names is not None, f"{path.relative_to(PACKAGE)} has no __all__"
    dotted = ".".join(("rockstudy",) + path.relative_to(PACKAGE).with_suffix("").parts)
    module = importlib.import_module(dotted.removesuffix(".__init__"))
    missing = [n for n in names if not hasattr(module, n)]
    assert not missing, f"{dotted} lists names it does not have: {missing}"


def test_every_module_of_a_public_package_is_checked():
    names = {str(p.relative_to(PACKAGE)) for p in PUBLIC_MODULES}
    assert {
        "similarity.py",
        "risk/curves.py",
        "risk/readers.py",
        "study/spec/design_kinds.py",
    } <= names
    assert not {"_validate.py", "dynamics/_linear.py", "study/report/_page.py"} & names


def test_the_public_module_check_sees_a_module_without_all(tmp_path):
    path = tmp_path / "m.py"
    path.write_text("import numpy as np\n\nX = 1\n")
    assert _declared_all(path) is None
    path.write_text("__all__ = ['X']\nX = 1\n")
    assert _declared_all(path) == ["X"]


#: Allocators whose first argument is a shape.
_ALLOCATORS = {"empty", "zeros", "ones", "full"}
#: The packages that compute, return or store the batch outputs.
_OUTPUT_PACKAGES = ("dynamics", "study/running")


def _outcome_names(function) -> set:
    """Names assigned in ``function`` from a call to a scene kernel (``*scene``)."""
    return {
        t.id
        for node in ast.walk(function)
        if isinstance(node, ast.Assign) and isinstance(node.value, ast.Call)
        for func in [node.value.func]
        if getattr(func, "attr", getattr(func, "id", "")).endswith("scene")
        for t in node.targets
        if isinstance(t, ast.Name)
    }


def _is_int(node, values=None) -> bool:
    return (
        isinstance(node, ast.Constant)
        and type(node.value) is int
        and (values is None or node.value in values)
    )


def _width_literals(source: str, width: int) -> list:
    """Lines of ``source`` that write the batch kernels' row width as a literal: an array
    allocated with a shape holding ``width`` (``np.empty((n, 8))``), or the outcome of a scene
    kernel (a name assigned from a call to ``*scene`` in the same function) read by a literal
    index (``r[3]``)."""
    tree = ast.parse(source)
    lines = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Call) and getattr(node.func, "attr", None) in _ALLOCATORS:
            shape = node.args[0] if node.args else None
            if isinstance(shape, ast.Tuple) and any(_is_int(e, {width}) for e in shape.elts):
                lines.append(node.lineno)
    for function in ast.walk(tree):
        if isinstance(function, (ast.FunctionDef, ast.AsyncFunctionDef)):
            outcomes = _outcome_names(function)
            lines += [
                node.lineno
                for node in ast.walk(function)
                if isinstance(node, ast.Subscript)
                and isinstance(node.value, ast.Name)
                and node.value.id in outcomes
                and _is_int(node.slice)
            ]
    return sorted(set(lines))


def _row_width() -> int:
    """The width of the batch kernels' row: one field per kernel output of the table."""
    from rockstudy.dynamics import outputs

    return len(outputs.KERNEL_ROW.names)


def test_no_batch_width_literal():
    """The batch outputs are declared once (rockstudy.dynamics.outputs): no module that computes
    or stores them allocates their array with the width as a literal, nor reads a scene
    kernel's outcome by position."""
    paths = sorted(p for pkg in _OUTPUT_PACKAGES for p in (PACKAGE / pkg).rglob("*.py"))
    assert PACKAGE / "dynamics" / "batch.py" in paths
    found = {
        str(path.relative_to(PACKAGE)): lines
        for path in paths
        if (lines := _width_literals(path.read_text(), _row_width()))
    }
    assert not found, f"the batch width {_row_width()} written as a literal at: {found}"


def test_the_width_check_finds_a_literal():
    w = _row_width()
    assert _width_literals(f"import numpy as np\nout = np.empty((n, {w}))\n", w) == [2]
    assert _width_literals("def f(p):\n    r = trig_scene(p)\n    return r[3]\n", w) == [3]
    assert _width_literals("def f(p):\n    r = scene(p)\n    return r.steps\n", w) == []
    assert _width_literals("def f(p):\n    r = g(p)\n    return r[3]\n", w) == []
    assert _width_literals(f"out = np.empty((n, {w + 100}))\n", w) == []


# ------------------------------------------------------------- the test modules stand alone

TESTS = Path(__file__).resolve().parent
#: What a test module may import from the tests folder: its fixtures and its helpers.
SHARED_TEST_MODULES = {"conftest", "_helpers"}


def _test_modules_imported(source: str) -> set[str]:
    """The modules of the tests folder (but conftest and _helpers) that ``source`` imports,
    at top level or inside a function."""
    local = {p.stem for p in TESTS.glob("*.py")} - SHARED_TEST_MODULES
    names = set()
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            names |= {alias.name.split(".")[0] for alias in node.names}
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            names.add(node.module.split(".")[0])
    return names & local


def test_no_test_module_imports_another():
    """Shared fixtures live in conftest.py and shared helpers in _helpers.py: a test module
    that imports another runs that module's fixtures and tests' set-up in its own."""
    found = {
        path.name: sorted(_test_modules_imported(path.read_text()))
        for path in sorted(TESTS.glob("*.py"))
    }
    assert {name: mods for name, mods in found.items() if mods} == {}


def test_the_test_import_check_sees_imports_of_test_modules():
    source = "import os\nfrom _helpers import tree\ndef f():\n    import test_study\n"
    assert _test_modules_imported(source) == {"test_study"}
    assert _test_modules_imported("from test_risk import x\nimport conftest\n") == {"test_risk"}


# The design kinds (cloud, stripes, IDA) are told apart by their entries in one registry: no
# module but the registry selects behaviour by a kind's name.
DESIGN_REGISTRY = PACKAGE / "study" / "spec" / "design_kinds.py"


def kind_selections(source: str, names) -> list[int]:
    """Line numbers of ``source`` that select by a design kind's name: a comparison of one
    (``==``, ``!=``, ``in``, ``not in``, a kind's name alone or in a tuple, list or set) or a
    dict keyed by one."""

    def named(node) -> bool:
        if isinstance(node, ast.Constant):
            return node.value in names
        if isinstance(node, (ast.Tuple, ast.List, ast.Set)):
            return any(named(e) for e in node.elts)
        return False

    lines = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Compare) and any(named(n) for n in [node.left, *node.comparators]):
            lines.append(node.lineno)
        elif isinstance(node, ast.Dict) and any(k is not None and named(k) for k in node.keys):
            lines.append(node.lineno)
    return sorted(lines)


def test_no_module_but_the_registry_selects_by_a_design_kind_name():
    from rockstudy.study.spec.design_kinds import DESIGN_KINDS

    assert DESIGN_REGISTRY.exists()
    found = {
        str(path.relative_to(PACKAGE)): lines
        for path in sorted(PACKAGE.rglob("*.py"))
        if path != DESIGN_REGISTRY
        and (lines := kind_selections(path.read_text(), set(DESIGN_KINDS)))
    }
    assert not found, f"design kinds selected by name outside {DESIGN_REGISTRY.name}: {found}"


def test_the_kind_check_sees_each_way_of_selecting_by_name():
    names = {"ida", "stripes"}
    source = (
        'a = k == "ida"\nb = "stripes" != k\nc = k in ("ida", "x")\nd = {"ida": 1}[k]\n'
        'e = k not in ["stripes"]\nf = k == "cloudy"\ng = dict(design="ida")\n'
    )
    assert kind_selections(source, names) == [1, 2, 3, 4, 5]
