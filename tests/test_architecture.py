"""The package's shape (docs/architecture.md): layers without cycles, small modules and
functions, nothing loose at the top, and the command line that answers without the stack.

The layer order itself is import-linter's contract in pyproject.toml (``make lint``); these
tests hold what it does not: no cycle between any two modules (type-checking imports
included), no module over 500 lines and no function over 80 (docstrings aside).
"""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import grimp
import pytest
from conftest import ROOT

PACKAGE = ROOT / "uvms_pin"
#: What the package's top level holds: the layers, and four small modules every layer uses.
TOP_LEVEL = {
    "__init__.py",
    "_lazy.py",
    "_moved.py",
    "checks.py",
    "errors.py",
    "apps",
    "control",
    "flow",
    "hydro",
    "model",
    "ocp",
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


def test_no_import_cycle_between_any_two_modules():
    graph = grimp.build_graph("uvms_pin", exclude_type_checking_imports=False)
    modules = sorted(graph.modules)
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


def test_the_command_line_answers_without_loading_the_stack():
    code = (
        "import sys\n"
        "from uvms_pin.apps.cli.main import build_parser\n"
        "build_parser().format_help()\n"
        "heavy = sorted({m.split('.')[0] for m in sys.modules} & {'pinocchio', 'scipy', "
        "'matplotlib', 'meshcat', 'pandas', 'dask'})\n"
        "print(','.join(heavy))\n"
    )
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "", f"--help loads {result.stdout.strip()}"
