"""docs/architecture.md tells the truth about the package's files: every path it writes
exists, and its module list names every module of the package (in its folder)."""

from __future__ import annotations

import re
from pathlib import Path

import signorini

PACKAGE = Path(signorini.__file__).parent
ROOT = Path(__file__).parents[1]
DOC = ROOT / "docs" / "architecture.md"

#: an entry of the module list: its name (``x.py`` or ``folder/``) at the line's start
_ENTRY = re.compile(r"^( *)([a-z_0-9]+(?:\.py|/))")
#: a module's name in a line, not part of a path (``a/b.py`` is a path)
_NAME = re.compile(r"(?<![/\w])([a-z_0-9]+\.py)\b")
#: a path of a Python file: ``folder/.../name.py``
_PATH = re.compile(r"(?<![\w/])((?:[a-z_0-9]+/)+[a-z_0-9]+\.py)\b")


def module_list(text: str) -> str:
    """The module list: the code block that starts with ``src/signorini/``."""
    return text.split("```\nsrc/signorini/\n", 1)[1].split("```", 1)[0]


def listed_modules(block: str) -> set[str]:
    """The modules the list names, as paths relative to the package: an entry ``name/``
    opens a folder for the lines indented below it, and every ``name.py`` on a line (the
    entry or its description) is a module of the folder the line is in."""
    stack: list[tuple[int, str]] = []
    found = set()
    for line in block.splitlines():
        entry = _ENTRY.match(line)
        if entry and len(entry.group(1)) < 20:  # a description's lines are indented further
            indent = len(entry.group(1))
            while stack and stack[-1][0] >= indent:
                stack.pop()
            if entry.group(2).endswith("/"):
                stack.append((indent, entry.group(2)[:-1]))
        folder = [name for _, name in stack]
        found.update("/".join([*folder, name]) for name in _NAME.findall(line))
    return found


def written_paths(text: str) -> set[str]:
    """Every ``folder/name.py`` the document writes."""
    return set(_PATH.findall(text))


def exists(path: str) -> bool:
    """A path of the package (from ``src/signorini/``, from ``signorini/`` or from a layer),
    or of the repository (``tests/...``, ``examples/...``)."""
    bare = path.removeprefix("src/").removeprefix("signorini/")
    return (PACKAGE / bare).is_file() or (ROOT / path).is_file()


def test_every_path_the_architecture_writes_exists():
    missing = sorted(p for p in written_paths(DOC.read_text()) if not exists(p))
    assert not missing, f"docs/architecture.md names files that do not exist: {missing}"


def test_the_module_list_names_exactly_the_modules_of_the_package():
    listed = listed_modules(module_list(DOC.read_text()))
    modules = {str(p.relative_to(PACKAGE)) for p in PACKAGE.rglob("*.py")}
    absent = sorted(m for m in modules - listed if not m.endswith("__init__.py"))
    assert not absent, f"modules docs/architecture.md does not list: {absent}"
    gone = sorted(listed - modules)
    assert not gone, f"docs/architecture.md lists modules that do not exist: {gone}"


def test_the_reader_of_the_module_list_can_fail():
    block = (
        "  mesh/                 the mesh\n"
        "    mesh.py             Mesh (with topology.py)\n"
        "  algebra/              solvers\n"
        "    backends/           the SPD solvers\n"
        "      mkl.py            MKL; by algebra/ranks.py\n"
        "    qp.py               the QP\n"
        "  version.py            the version\n"
    )
    assert listed_modules(block) == {
        "mesh/mesh.py",
        "mesh/topology.py",
        "algebra/backends/mkl.py",
        "algebra/qp.py",
        "version.py",
    }
    assert written_paths("`algebra/friction.py` and src/signorini/mesh/mesh.py") == {
        "algebra/friction.py",
        "src/signorini/mesh/mesh.py",
    }
    assert not exists("algebra/friction.py") and not exists("algebra/laws.py")
    assert exists("src/signorini/mesh/mesh.py") and exists("tests/test_layers.py")
