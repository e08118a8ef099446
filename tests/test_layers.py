"""The package's layers import only what their row of the table allows (docs/architecture.md).

Every module of ``signorini`` is read as text; each import of the package (relative, or
absolute ``signorini.x``) must name the module's own layer, a layer of its row of
:data:`ALLOWED`, or a module of its row of :data:`DOORS`. The package itself (a bare
``import signorini``, or a name taken from it) counts as its top layer ``__init__``, which
no module below may import.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

import signorini

PACKAGE = Path(signorini.__file__).parent

_GROUND = frozenset({"mesh", "algebra"})
_CONTACT = _GROUND | {"fem", "problem", "contact"}

#: Each layer (a subpackage or a top-level module of ``signorini``) and the layers it may
#: import besides itself. ``mesh`` and ``algebra`` are the ground: a triangulation, and
#: sparse linear algebra that knows nothing of meshes. ``problem`` may import ``algebra``
#: for the friction-law protocol its laws implement. The leaves ``output`` and ``plots`` take
#: arrays and plain records: of the package only ``mesh`` (a mesh read back from a file, pure
#: geometry helpers) and, for ``plots``, the history files ``output`` reads; the command line
#: is the only module that joins them to the numerics. ``version`` holds the package's
#: version for the package and its leaves.
ALLOWED: dict[str, frozenset[str]] = {
    "mesh": frozenset(),
    "algebra": frozenset(),
    "fem": frozenset({"mesh"}),
    "problem": frozenset({"mesh", "fem", "algebra"}),
    "contact": _CONTACT - {"contact"},
    "estimator": _CONTACT,
    "loop": _CONTACT | {"estimator"},
    "examples": _CONTACT | {"estimator", "loop"},
    "output": frozenset({"mesh", "version"}),
    "plots": frozenset({"mesh", "output"}),
    "runtime": frozenset(),
    "version": frozenset(),
    "cli": _CONTACT | {"estimator", "loop", "examples", "output", "plots", "runtime", "version"},
    "__init__": _CONTACT | {"estimator", "loop", "examples", "output", "version"},
}

#: Single modules a layer may import beyond its row of :data:`ALLOWED`: plain data that
#: imports nothing of the package (checked below). The figures read the estimator's term
#: names, from which their legends and styles are derived.
DOORS: dict[str, frozenset[str]] = {
    "plots": frozenset({"estimator.names"}),
}


#: The rooms of ``algebra`` and the rooms each may import besides itself: ``errors`` (the
#: module ``algebra/errors.py``, every error and warning) is the bottom; ``core`` (the
#: top-level modules of ``algebra/``: CSR helpers, ranks, the QP and its KKT residuals, the
#: active set iterations) imports only the errors; the SPD solvers of ``backends/`` build on
#: the core's CSR helpers and ranks; the frictional solver of ``friction/`` on the core's QP,
#: KKT and active systems. ``__init__`` (``algebra/__init__.py``) is the subpackage's door
#: and re-exports every room.
ROOMS: dict[str, frozenset[str]] = {
    "errors": frozenset(),
    "core": frozenset({"errors"}),
    "backends": frozenset({"errors", "core"}),
    "friction": frozenset({"errors", "core"}),
    "__init__": frozenset({"errors", "core", "backends", "friction"}),
}

#: Single modules of another room that a room of ``algebra`` may import, each with its
#: reason. The core's door to the backends is the solver interface and its selection: the
#: active set iterations factor SPD systems through the interface ``SPDSolver`` and pick the
#: backend by name (``make_solver``), and the ranks' collectives find petsc4py where the
#: PETSc backends find it (one import of petsc4py, asked for only under MPI). The frictional
#: solver factors its systems through the same door. No backend imports the frictional
#: solver.
ROOM_DOORS: dict[str, dict[str, str]] = {
    "core": {
        "backends.solvers": "SPDSolver, SolverFactory: the interface the iterations factor with",
        "backends.selection": "make_solver: a backend chosen by name (PDAS's solver=)",
        "backends.petsc_import": "petsc_module: the ranks' communicator under MPI",
    },
    "friction": {
        "backends.solvers": "SPDSolver, SolverFactory: the interface Newton's systems factor with",
        "backends.selection": "make_solver: a backend chosen by name (solve_friction's solver=)",
    },
}


def room_of(name: str) -> str:
    """The room of ``algebra`` of a module given by its dotted name under ``algebra``
    (``algebra.backends.mkl`` -> ``backends``, ``algebra.errors`` -> ``errors``,
    ``algebra.pdas`` -> ``core``, ``algebra`` -> ``__init__``)."""
    parts = name.split(".")[1:]
    if not parts or parts == ["__init__"]:
        return "__init__"
    if parts[0] in ("backends", "friction", "errors"):
        return parts[0]
    return "core"


def forbidden_room_imports(root: Path = PACKAGE) -> list[str]:
    """Every import between the rooms of ``algebra`` under ``root`` that :data:`ROOMS` and
    :data:`ROOM_DOORS` do not allow."""
    found = []
    for path in sorted((root / "algebra").rglob("*.py")):
        dotted = ".".join(path.relative_to(root).with_suffix("").parts)
        own = room_of(dotted)
        doors = ROOM_DOORS.get(own, {})
        for name in sorted(imported_modules(path, root)):
            if name.split(".")[0] != "algebra":
                continue
            room = room_of(name)
            door = any(name == "algebra." + d for d in doors)
            if room != own and room not in ROOMS[own] and not door:
                found.append(f"{path.relative_to(root)} ({own}) imports {name} ({room})")
    return found


def layer_of(path: Path, root: Path = PACKAGE) -> str:
    return path.relative_to(root).parts[0].removesuffix(".py")


def _resolved(parts: list[str], root: Path) -> str:
    """The dotted name of the longest module or package of ``parts`` under ``root``."""
    while parts and not (
        (root.joinpath(*parts)).is_dir() or root.joinpath(*parts).with_suffix(".py").is_file()
    ):
        parts = parts[:-1]
    return ".".join(parts)


def imported_modules(path: Path, root: Path = PACKAGE) -> set[str]:
    """The modules and subpackages of the package (dotted, relative to it: ``mesh.mesh``,
    ``estimator``) that ``path`` imports, whether relatively, as ``signorini.x`` or as
    ``from signorini import x``; ``from .pkg import name`` counts as ``pkg.name`` when
    ``name`` is a module of ``pkg``. The package itself, imported bare (``import signorini``)
    or as the source of a name (``from signorini import Mesh``, ``from .. import x`` up to the
    top), is ``__init__``."""
    package = path.relative_to(root).with_suffix("").parts[:-1]
    if path.name == "__init__.py":
        package = path.relative_to(root).parts[:-1]
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            for alias in node.names:
                first, *rest = alias.name.split(".")
                if first == root.name:
                    found.add(_resolved(rest, root) or "__init__")
            continue
        if not isinstance(node, ast.ImportFrom):
            continue
        if node.level > 0:
            base = list(package[: len(package) - (node.level - 1)])
        elif node.module and node.module.split(".")[0] == root.name:
            base = []
        else:
            continue
        module = node.module.split(".") if node.module else []
        if node.level == 0:
            module = module[1:]
        target = base + module
        for alias in node.names:
            name = _resolved([*target, alias.name], root)
            found.add(name or _resolved(target, root) or "__init__")
    return {name for name in found if name}


def imported_layers(path: Path, root: Path = PACKAGE) -> set[str]:
    """Top-level subpackages or modules of the package that ``path`` imports."""
    return {name.split(".")[0] for name in imported_modules(path, root)}


def forbidden_imports(root: Path = PACKAGE) -> list[str]:
    """Every import of a module under ``root`` that its layer's rows do not allow."""
    found = []
    for path in sorted(root.rglob("*.py")):
        own = layer_of(path, root)
        if own not in ALLOWED:
            found.append(f"{path.relative_to(root)} is in no layer of ALLOWED")
            continue
        for name in sorted(imported_modules(path, root)):
            layer = name.split(".")[0]
            door = any(name == d or name.startswith(d + ".") for d in DOORS.get(own, ()))
            if layer != own and layer not in ALLOWED[own] and not door:
                found.append(f"{path.relative_to(root)} imports {name}")
    return found


def test_every_module_imports_only_what_its_layer_allows():
    assert len(list(PACKAGE.rglob("*.py"))) > 40
    found = forbidden_imports()
    assert not found, "imports the layer table does not allow: " + "; ".join(found)


def test_the_table_names_every_layer_it_allows():
    for own, allowed in ALLOWED.items():
        assert own not in allowed, own
        assert allowed <= set(ALLOWED), f"{own} may import {sorted(allowed - set(ALLOWED))}"
    assert not ALLOWED["mesh"] and not ALLOWED["algebra"]


def test_a_door_imports_nothing_of_the_package():
    for doors in DOORS.values():
        for door in doors:
            path = PACKAGE.joinpath(*door.split(".")).with_suffix(".py")
            assert imported_modules(path) == set(), door


def test_the_errors_of_the_linear_algebra_are_its_bottom():
    """``algebra.errors`` imports nothing of the package, so every module of ``algebra`` (the
    backends, the active set core, the friction room) imports it at its top."""
    assert imported_modules(PACKAGE / "algebra" / "errors.py") == set()
    ranks = imported_modules(PACKAGE / "algebra" / "ranks.py")
    assert ranks == {"algebra.backends.petsc_import", "algebra.errors"}


def test_the_rooms_of_the_linear_algebra_import_only_what_their_row_allows():
    found = forbidden_room_imports()
    assert not found, "imports the rooms' table does not allow: " + "; ".join(found)


def test_every_room_door_has_its_reason_and_exists():
    for own, doors in ROOM_DOORS.items():
        for door, reason in doors.items():
            assert reason, (own, door)
            path = PACKAGE.joinpath("algebra", *door.split(".")).with_suffix(".py")
            assert path.is_file(), door
            assert room_of("algebra." + door) not in ROOMS[own] | {own}, (own, door)
    assert ROOMS["errors"] == frozenset()
    assert "friction" not in ROOMS["backends"] and "friction" not in ROOMS["core"]


def test_the_import_reader_sees_every_kind_of_relative_import():
    """``from ..x import``, ``from .x import`` at the top and ``from . import`` inside a layer."""
    solution = imported_layers(PACKAGE / "contact" / "solution.py")
    assert solution >= {"algebra", "contact", "fem", "mesh", "problem"}
    loop = PACKAGE / "loop" / "__init__.py"
    assert imported_layers(loop) >= {"contact", "estimator", "loop", "mesh", "problem"}
    assert imported_layers(PACKAGE / "mesh" / "refine.py") == {"mesh"}
    assert "estimator.names" in imported_modules(PACKAGE / "plots" / "style.py")
    assert imported_modules(PACKAGE / "output" / "environment.py") == {"version"}


@pytest.fixture
def package(tmp_path):
    """A copy of the package's layout (empty modules) in which a test writes one module."""
    root = tmp_path / "signorini"
    for path in PACKAGE.rglob("*.py"):
        copy = root / path.relative_to(PACKAGE)
        copy.parent.mkdir(parents=True, exist_ok=True)
        copy.write_text("")
    return root


@pytest.mark.parametrize(
    "layer, source, reported",
    [
        ("algebra", "from ..mesh.mesh import Mesh\n", "algebra/probe.py imports mesh.mesh"),
        ("algebra", "from ..fem import p2\n", "algebra/probe.py imports fem.p2"),
        ("mesh", "import signorini.problem.obstacles\n", "imports problem.obstacles"),
        ("fem", "from signorini import contact\n", "fem/probe.py imports contact"),
        ("plots", "from ..loop import Level\n", "plots/probe.py imports loop"),
        (
            "plots",
            "from ..algebra.friction.result import STICK\n",
            "imports algebra.friction.result",
        ),
        ("plots", "from ..estimator.residual import Estimate\n", "imports estimator.residual"),
        ("output", "from ..contact.solution import ContactResult\n", "imports contact.solution"),
        ("problem", "def f():\n    from ..contact import solve\n", "imports contact"),
        ("output", "def f():\n    import signorini\n", "output/probe.py imports __init__"),
        ("mesh", "from signorini import __version__\n", "mesh/probe.py imports __init__"),
        ("fem", "from .. import Mesh\n", "fem/probe.py imports __init__"),
        ("cli", "import signorini as s\n", "cli/probe.py imports __init__"),
    ],
)
def test_a_forbidden_import_is_reported(package, layer, source, reported):
    assert forbidden_imports(package) == []
    (package / layer / "probe.py").write_text(source)
    found = forbidden_imports(package)
    assert len(found) == 1 and reported in found[0], found


@pytest.mark.parametrize(
    "room, source, reported",
    [
        ("errors.py", "from .sparse import csr\n", "algebra/errors.py (errors) imports algebra"),
        ("probe.py", "from .backends import pardiso\n", "imports algebra.backends.pardiso"),
        ("probe.py", "def f():\n    from .friction import kkt\n", "imports algebra.friction.kkt"),
        ("backends/probe.py", "from ..friction.laws import LawGroups\n", "(friction)"),
        ("friction/probe.py", "from ..backends.superlu import superlu_solver\n", "superlu"),
        ("backends/probe.py", "from .. import pdas\nimport signorini.algebra\n", "(__init__)"),
    ],
)
def test_a_forbidden_room_import_is_reported(package, room, source, reported):
    assert forbidden_room_imports(package) == []
    (package / "algebra" / room).write_text(source)
    found = forbidden_room_imports(package)
    assert len(found) == 1 and reported in found[0], found


def test_room_doors_and_allowed_rooms_are_not_reported(package):
    (package / "algebra" / "probe.py").write_text(
        "from .errors import ConvergenceError\nfrom .backends.solvers import SPDSolver\n"
    )
    (package / "algebra" / "friction" / "probe.py").write_text(
        "from ..backends.selection import make_solver\nfrom ..qp import BoundQP\n"
    )
    (package / "algebra" / "backends" / "probe.py").write_text("from ..sparse import csr\n")
    assert forbidden_room_imports(package) == []


def test_allowed_imports_and_doors_are_not_reported(package):
    (package / "plots" / "probe.py").write_text(
        "from ..estimator.names import TERMS\nfrom ..mesh.mesh import Mesh\nfrom . import style\n"
    )
    (package / "problem" / "probe.py").write_text("from ..algebra import sparse\n")
    (package / "cli.py").write_text("from .plots import run_figures\nimport signorini.loop\n")
    assert forbidden_imports(package) == []
