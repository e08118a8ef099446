"""The package's layers import only downwards (docs/architecture.md).

Every module of ``signorini`` is read as text; each relative import must name a layer that
comes earlier in ``LAYERS`` than the importing module's own layer (or the same layer).
"""

from __future__ import annotations

import ast
from pathlib import Path

import signorini

PACKAGE = Path(signorini.__file__).parent

#: lowest first; a module may import from its own layer and from the layers before it
LAYERS = (
    "mesh",
    "fem",
    "problem",
    "algebra",
    "contact",
    "estimator",
    "loop",
    "examples",
    "output",
    "plots",
    "runtime",
    "cli",
    "__init__",
)


def layer_of(path: Path) -> str:
    return path.relative_to(PACKAGE).parts[0].removesuffix(".py")


def imported_layers(path: Path) -> set[str]:
    """Top-level subpackages or modules of signorini that ``path`` imports."""
    module_parts = path.relative_to(PACKAGE).with_suffix("").parts
    package = module_parts[:-1]
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom) and node.level > 0:
            base = list(package[: len(package) - (node.level - 1)])
            target = base + (node.module.split(".") if node.module else [])
            names = target or [alias.name for alias in node.names]
            for name in [names[0]] if target else names:
                found.add(name)
        elif isinstance(node, ast.ImportFrom) and (node.module or "").startswith("signorini."):
            found.add(node.module.split(".")[1])
    return found


def test_every_module_imports_only_lower_layers():
    modules = sorted(PACKAGE.rglob("*.py"))
    assert len(modules) > 40
    rank = {name: k for k, name in enumerate(LAYERS)}
    upward = []
    for path in modules:
        own = layer_of(path)
        assert own in rank, f"{path} is in no layer of LAYERS"
        for name in imported_layers(path):
            assert name in rank, f"{path} imports {name!r}, which is in no layer"
            if rank[name] > rank[own]:
                upward.append(f"{path.relative_to(PACKAGE)} imports {name}")
    assert not upward, "imports that point upwards: " + "; ".join(upward)


def test_the_import_reader_sees_every_kind_of_relative_import():
    """``from ..x import``, ``from .x import`` at the top and ``from . import`` inside a layer."""
    solution = imported_layers(PACKAGE / "contact" / "solution.py")
    assert solution >= {"algebra", "contact", "fem", "mesh", "problem"}
    loop = PACKAGE / "loop" / "__init__.py"
    assert imported_layers(loop) >= {"contact", "estimator", "loop", "mesh", "problem"}
    assert imported_layers(PACKAGE / "mesh" / "refine.py") == {"mesh"}
