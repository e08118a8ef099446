"""The project's metadata says what the package does, and git ignores the local venvs."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    tomllib = pytest.importorskip("tomli")


def test_the_description_states_the_scope():
    # it said "the frictionless Signorini contact problem" after friction, two bodies and P1
    with open(ROOT / "pyproject.toml", "rb") as f:
        description = tomllib.load(f)["project"]["description"]
    assert "frictionless Signorini" not in description
    for word in ("P2", "P1", "2D", "two bodies", "Tresca", "Coulomb"):
        assert word in description, description


@pytest.mark.skipif(
    not (ROOT / ".git").exists() or shutil.which("git") is None, reason="not a git checkout"
)
@pytest.mark.parametrize("venv", [".venv", ".venv-mpi", ".venv312"])
def test_local_venvs_are_ignored(venv):
    result = subprocess.run(
        ["git", "check-ignore", "-q", f"{venv}/bin/python"], cwd=ROOT, check=False
    )
    assert result.returncode == 0, f"{venv}/ is not ignored by .gitignore"
