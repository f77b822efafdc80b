"""The package's shape (docs/architecture.md): layers without cycles, small modules and
functions, nothing loose at the top, and the command line that answers without the stack.

The layer order itself is import-linter's contract in pyproject.toml (``make lint``); these
tests hold what it does not: no cycle between any two modules (type-checking imports
included; the package's own modules named in its ``lazy_exports`` tables counted as imports),
no module importing one of the package's own modules by a string (which neither tool
sees), no module over 500 lines and no function over 80 (docstrings aside).
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

import grimp
import pytest
from conftest import ROOT, heavy_packages_loaded_by

PACKAGE = ROOT / "uvms_pin"
#: What the package's top level holds: the layers, and four small modules every layer uses.
TOP_LEVEL = {
    "__init__.py",
    "_lazy.py",
    "checks.py",
    "errors.py",
    "apps",
    "control",
    "flow",
    "hydro",
    "model",
    "ocp",
    "perception",
    "physics",
    "results",
    "scenario",
    "sim",
}
MAX_MODULE_LINES = 500
MAX_FUNCTION_LINES = 80


def _modules() -> list[Path]:
    return sorted(PACKAGE.rglob("*.py"))


def _docstring_lines(node: ast.AST) -> int:
    body = getattr(node, "body", [])
    if body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant):
        if isinstance(body[0].value.value, str):
            return body[0].end_lineno - body[0].lineno + 1
    return 0


def _module_name(path: Path) -> str:
    parts = path.relative_to(ROOT).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _string_imports(tree: ast.AST) -> list[str]:
    """The calls of ``tree`` that import a module named by a string of the package's own
    (``import_module("uvms_pin...")``, an f-string or a concatenation, a relative name) or
    by any string through ``__import__``."""
    found = []
    for node in ast.walk(tree):
        if not (isinstance(node, ast.Call) and node.args):
            continue
        name = getattr(node.func, "attr", getattr(node.func, "id", None))
        if name not in ("import_module", "__import__"):
            continue
        first = node.args[0]
        literal = first.value if isinstance(first, ast.Constant) else None
        own = isinstance(literal, str) and literal.startswith(("uvms_pin", "."))
        built = isinstance(first, ast.JoinedStr | ast.BinOp)  # f"uvms_pin.{x}", "uvms_pin." + x
        if own or built or name == "__import__":
            found.append(f"line {node.lineno}: {ast.unparse(node)}")
    return found


def _lazy_imports(tree: ast.AST) -> dict[str, set[str]]:
    """What a ``lazy_exports(__name__, {module: names})`` table imports on first use: each
    module, with the names it gives."""
    return {
        key.value: {e.value for e in value.elts if isinstance(e, ast.Constant)}
        for node in ast.walk(tree)
        if isinstance(node, ast.Call) and getattr(node.func, "id", None) == "lazy_exports"
        for table in node.args[1:2]
        if isinstance(table, ast.Dict)
        for key, value in zip(table.keys, table.values, strict=True)
        if isinstance(key, ast.Constant) and isinstance(value, ast.Tuple)
    }


def _imported_names(line: str, package: str) -> set[str]:
    """The names ``from package import a, b as c`` takes (``{"*"}``, anything, for any other
    line, or one whose names go on over several lines)."""
    head = f"from {package} import "
    if not line.startswith(head) or line.rstrip().endswith(("(", "\\")):
        return {"*"}
    return {part.split(" as ")[0].strip(" ()") for part in line[len(head) :].split(",")}


def test_no_module_imports_one_of_the_package_by_a_string():
    """What import-linter and grimp read are import statements: a module the package imports
    by name at call time would hide a dependency (and a cycle) from both. Loading a user's
    ``package.module:Class`` (a variable, `uvms_pin.results.named`) and the lazy tables
    (`_lazy_imports`, counted in the cycle test) are what remains."""
    found = {
        _module_name(path): calls
        for path in _modules()
        if (calls := _string_imports(ast.parse(path.read_text())))
    }
    assert not found, f"imports by a string: {found}"


@pytest.mark.parametrize(
    "source",
    [
        'importlib.import_module("uvms_pin.scenario.load")',
        'import_module(f"uvms_pin.{layer}.load")',
        'importlib.import_module("." + name, "uvms_pin")',
        'importlib.import_module(".load", package="uvms_pin.scenario")',
        '__import__("uvms_pin.scenario.load")',
        "__import__(name)",
    ],
)
def test_an_import_by_a_string_is_found(source):
    assert _string_imports(ast.parse(source)) and not _string_imports(
        ast.parse("importlib.import_module(module_name)")  # a user's module, by a variable
    )


def test_no_import_cycle_between_any_two_modules():
    graph = grimp.build_graph("uvms_pin", exclude_type_checking_imports=False)
    modules = sorted(graph.modules)
    for path in _modules():  # the lazy tables import their modules too, on first use
        package, lazy = _module_name(path), _lazy_imports(ast.parse(path.read_text()))
        for imported in lazy:
            graph.add_import(importer=package, imported=imported)
        names = set().union(*lazy.values())
        for importer in list(graph.find_modules_that_directly_import(package)) if lazy else []:
            # `from uvms_pin import _core` (the compiled extension, which grimp does not see)
            # takes none of the lazy names: it runs none of the lazy imports
            details = graph.get_import_details(importer=importer, imported=package)
            taken = set().union(*(_imported_names(d["line_contents"], package) for d in details))
            if "*" not in taken and taken.isdisjoint(names):
                graph.remove_import(importer=importer, imported=package)
    # Tarjan's strongly connected components, iteratively
    index, low, on_stack, stack, cycles = {}, {}, set(), [], []
    counter = [0]

    def visit(root: str) -> None:
        work = [(root, iter(sorted(graph.find_modules_directly_imported_by(root))))]
        index[root] = low[root] = counter[0]
        counter[0] += 1
        stack.append(root)
        on_stack.add(root)
        while work:
            node, children = work[-1]
            child = next(children, None)
            if child is None:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[node])
                if low[node] == index[node]:
                    component = []
                    while True:
                        member = stack.pop()
                        on_stack.discard(member)
                        component.append(member)
                        if member == node:
                            break
                    if len(component) > 1:
                        cycles.append(sorted(component))
            elif child not in index:
                index[child] = low[child] = counter[0]
                counter[0] += 1
                stack.append(child)
                on_stack.add(child)
                work.append((child, iter(sorted(graph.find_modules_directly_imported_by(child)))))
            elif child in on_stack:
                low[node] = min(low[node], index[child])

    for module in modules:
        if module not in index:
            visit(module)
    assert not cycles, f"import cycles: {cycles}"


def test_the_top_level_holds_the_layers_only():
    found = {
        p.name
        for p in PACKAGE.iterdir()
        if p.suffix == ".py" or (p.is_dir() and any(p.rglob("*.py")))  # not a stale cache
    }
    assert found == TOP_LEVEL, f"unexpected: {found - TOP_LEVEL}, missing: {TOP_LEVEL - found}"


@pytest.mark.parametrize("path", _modules(), ids=lambda p: str(p.relative_to(PACKAGE)))
def test_modules_and_functions_are_small(path):
    source = path.read_text()
    tree = ast.parse(source)
    docstrings = sum(
        _docstring_lines(node)
        for node in ast.walk(tree)
        if isinstance(node, ast.Module | ast.ClassDef | ast.FunctionDef | ast.AsyncFunctionDef)
    )
    lines = len(source.splitlines()) - docstrings
    assert lines <= MAX_MODULE_LINES, f"{lines} lines besides docstrings"
    for node in ast.walk(tree):
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
            length = node.end_lineno - node.lineno + 1 - _docstring_lines(node)
            assert length <= MAX_FUNCTION_LINES, f"{node.name} (line {node.lineno}): {length}"


#: the classes that hold what moves in a run, and the most methods each may have
#: (properties counted, dunders not): what the system's logging took out of `System`
#: (`SystemLog`) kept it a stepper
SMALL_CLASSES = {"sim/plant.py": "Plant", "sim/system/system.py": "System"}
MAX_METHODS = 15


@pytest.mark.parametrize("path, name", SMALL_CLASSES.items())
def test_the_plant_and_the_system_have_few_methods(path, name):
    tree = ast.parse((PACKAGE / path).read_text())
    (cls,) = [n for n in tree.body if isinstance(n, ast.ClassDef) and n.name == name]
    methods = [
        n.name
        for n in cls.body
        if isinstance(n, ast.FunctionDef)
        and not (n.name.startswith("__") and n.name.endswith("__"))
    ]
    assert len(methods) <= MAX_METHODS, f"{name}: {len(methods)} methods: {methods}"


def test_the_command_line_answers_without_loading_the_stack():
    code = "from uvms_pin.apps.cli.main import build_parser\nbuild_parser().format_help()"
    heavy = {"pinocchio", "scipy", "matplotlib", "meshcat", "pandas", "dask"}
    assert heavy_packages_loaded_by(code, heavy) == []


def test_a_compiled_run_loads_no_scipy():
    """scipy's solvers (quad, solve_ivp, brentq, lapack, ndtri) are imported where they are
    used: a third of a second that every `uvms-pin run` would otherwise pay at start-up. A
    shipped scenario loads and runs (compiled, with its controller) without them."""
    code = (
        "import uvms_pin as up\n"
        "from uvms_pin.scenario import load_scenario\n"
        "from dataclasses import replace\n"
        "for name in ('passive_current', 'realistic_force_tracking'):\n"
        f"    scenario = load_scenario({str(ROOT)!r} + f'/scenarios/{{name}}.toml')\n"
        "    short = replace(scenario.settings, duration_s=0.2)\n"
        "    up.simulate(replace(scenario, settings=short), progress=False)\n"
    )
    assert heavy_packages_loaded_by(code, {"scipy"}) == []


#: The compiled seam: the only folders whose modules build the core's objects (and the
#: optimal-control problem's translation, which sits in the ocp layer above the physics)
SEAM = ("physics/compiled/", "sim/compiled/", "ocp/compiled.py")
CORE_OBJECT = re.compile(r"\bcore\.[A-Z]\w*\(")


def test_core_objects_are_built_only_in_the_compiled_seam():
    """A core object (``core.Plant(...)``, ``core.LoopSettings()``, ...) is built in
    `physics/compiled/`, `sim/compiled/` or `ocp/compiled.py` only, from its Python counterpart's public
    attributes; everywhere else holds what the seam built."""
    outside = [
        f"{path.relative_to(PACKAGE)}:{k + 1}"
        for path in _modules()
        if not str(path.relative_to(PACKAGE)).startswith(SEAM)
        for k, line in enumerate(path.read_text().splitlines())
        if CORE_OBJECT.search(line)
    ]
    assert outside == []


def test_the_seam_check_sees_a_core_object_built_elsewhere():
    assert CORE_OBJECT.search("        out = core.Plant(dynamics, 0)")
    assert CORE_OBJECT.search("settings = core.LoopSettings()")
    assert not CORE_OBJECT.search("core.run_sampled_chunk(plant, law)")
