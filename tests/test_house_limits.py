"""The house limits every module keeps (docs/architecture.md): no module over 450 lines, no
public function or method with 12 or more parameters (``self`` and ``cls`` not counted)."""

from __future__ import annotations

import ast
from pathlib import Path

import signorini

PACKAGE = Path(signorini.__file__).parent
MAX_LINES = 450
MAX_PARAMETERS = 11


def _modules() -> list[Path]:
    return sorted(PACKAGE.rglob("*.py"))


def test_modules_are_at_most_450_lines() -> None:
    long = {
        str(p.relative_to(PACKAGE)): n
        for p in _modules()
        if (n := len(p.read_text(encoding="utf-8").splitlines())) > MAX_LINES
    }
    assert not long, f"modules over {MAX_LINES} lines: {long}"


def _parameters(node: ast.FunctionDef | ast.AsyncFunctionDef) -> int:
    a = node.args
    names = [x.arg for x in a.posonlyargs + a.args + a.kwonlyargs]
    return len([n for n in names if n not in ("self", "cls")])


def test_public_functions_take_fewer_than_12_parameters() -> None:
    wide = []
    for path in _modules():
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for node in ast.walk(tree):
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
                if not node.name.startswith("_") and _parameters(node) > MAX_PARAMETERS:
                    wide.append(f"{path.relative_to(PACKAGE)}:{node.lineno} {node.name}")
    assert not wide, f"public functions with 12 or more parameters: {wide}"


def test_the_limits_see_a_long_module_and_a_wide_function(tmp_path: Path) -> None:
    """The checks above can fail: a 451-line text and a 12-parameter function are caught."""
    source = "def f(" + ", ".join(f"a{i}" for i in range(12)) + "):\n    pass\n"
    node = ast.parse(source).body[0]
    assert isinstance(node, ast.FunctionDef) and _parameters(node) == 12
    method = ast.parse("def g(self, a, b):\n    pass\n").body[0]
    assert isinstance(method, ast.FunctionDef) and _parameters(method) == 2
    assert len(("x = 1\n" * (MAX_LINES + 1)).splitlines()) > MAX_LINES
