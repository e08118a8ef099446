"""The ``"petsc"`` backend under ``mpiexec -n 1, 2, 3``: the same adaptive runs as serially.

Each run is :mod:`mpi_levels` in a child ``mpiexec`` (3 ranks oversubscribe a 2-core machine:
MPICH's ranks then share the cores, which only costs time). Compared level by level with the
serial run of the reference backend (PARDISO where it loads, else SuperLU): the same Ndof,
active sets and marked cells on every level, η and its terms and the final displacements to
round-off. Skipped where petsc4py or mpiexec is missing, except under
``SIGNORINI_REQUIRE_PETSC=1`` (CI's MPI stage), where that is a failure.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from signorini.algebra import BackendUnavailableError, available_backends
from signorini.algebra.backends.petsc import petsc_module

from .mpi_levels import run

SCRIPT = Path(__file__).with_name("mpi_levels.py")
REFERENCE = "pardiso" if "pardiso" in available_backends() else "scipy"


def mpiexec() -> list[str] | None:
    """The launcher beside this Python (the MPICH wheel's) or on PATH, with the flags Open MPI
    needs to run as root and oversubscribed; None where there is none."""
    here = Path(sys.executable).parent / "mpiexec"
    found = str(here) if here.exists() else shutil.which("mpiexec")
    if found is None:
        return None
    version = subprocess.run([found, "--version"], capture_output=True, text=True).stdout
    if "Open MPI" in version or "OpenRTE" in version:
        return [found, "--allow-run-as-root", "--oversubscribe"]
    return [found]


def problem() -> str | None:
    try:
        petsc_module()
    except BackendUnavailableError as err:
        return str(err)
    return None if mpiexec() is not None else "no mpiexec found"


PROBLEM = problem()
if PROBLEM is not None and os.environ.get("SIGNORINI_REQUIRE_PETSC") == "1":
    raise RuntimeError(f"SIGNORINI_REQUIRE_PETSC=1 but the MPI tests cannot run: {PROBLEM}")
pytestmark = [
    pytest.mark.skipif(PROBLEM is not None, reason=f"MPI runs: {PROBLEM}"),
    pytest.mark.slow,
]


def split(flat: np.ndarray, sizes: np.ndarray) -> list[np.ndarray]:
    return np.split(flat, np.cumsum(sizes)[:-1])


@pytest.fixture(scope="module")
def serial():
    """The reference backend's serial runs, computed once."""
    return {}


RUNS = {
    "example-6.2": (20, [144, 152, 160, 180]),
    "example-6.2-coulomb": (20, [144, 152]),
    "example-6.2-tresca": (20, [144]),
}


@pytest.mark.parametrize(
    "name,ranks",
    [(name, ranks) for name in RUNS for ranks in (1, 2, 3) if name != "example-6.2-tresca"]
    + [("example-6.2-tresca", 2)],  # Tresca's symmetric path on one rank count (time)
)
def test_every_level_is_the_serial_one(serial, tmp_path, name, ranks):
    levels, first_ndofs = RUNS[name]
    if name not in serial:
        serial[name] = run(name, levels, REFERENCE)
    reference = serial[name]
    out = tmp_path / "levels.npz"
    command = [*mpiexec(), "-n", str(ranks), sys.executable, str(SCRIPT), name, str(levels)]
    done = subprocess.run([*command, str(out)], capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]
    got = dict(np.load(out))
    assert int(got["size"]) == ranks and set(got["backend"]) == {"petsc"}
    assert set(reference["backend"]) == {REFERENCE}
    assert got["ndof"].size == levels and list(got["ndof"][: len(first_ndofs)]) == first_ndofs
    np.testing.assert_array_equal(got["ndof"], reference["ndof"])
    for key in ("active", "marked"):
        for a, b in zip(
            split(got[key], got[f"{key}_sizes"]),
            split(reference[key], reference[f"{key}_sizes"]),
            strict=True,
        ):
            np.testing.assert_array_equal(a, b)
    np.testing.assert_allclose(got["eta"], reference["eta"], rtol=1e-11)
    scale = reference["eta"][:, None]
    assert (np.abs(got["eta_terms"] - reference["eta_terms"]) <= 1e-10 * scale).all()
    assert np.abs(got["u"] - reference["u"]).max() <= 1e-11 * np.abs(reference["u"]).max()


def history(folder: Path) -> dict[str, np.ndarray]:
    table = np.genfromtxt(folder / "history.csv", delimiter=",", names=True, dtype=None)
    return {name: table[name] for name in table.dtype.names}


def test_the_command_line_on_two_ranks_writes_the_serial_run_once(tmp_path):
    from signorini.cli import main

    args = ["run", "example-6.2", "--max-levels", "6", "--no-figures", "--quiet"]
    assert main([*args, "--backend", REFERENCE, "--out", str(tmp_path / "serial")]) == 0
    command = [*mpiexec(), "-n", "2", sys.executable, "-m", "signorini.cli", *args]
    out = tmp_path / "two"
    done = subprocess.run(
        [*command, "--backend", "petsc", "--out", str(out)],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 0, done.stderr[-3000:]
    assert "2 ranks" in (out / "signorini-run.json").read_text()
    assert sorted(p.name for p in out.glob("level_*.vtu")) == [f"level_00{k}.vtu" for k in range(6)]
    got, reference = history(out), history(tmp_path / "serial")
    assert set(got["backend"].astype(str)) == {"petsc"}
    np.testing.assert_array_equal(got["ndof"], reference["ndof"])
    np.testing.assert_array_equal(got["n_active"], reference["n_active"])
    np.testing.assert_allclose(got["eta"], reference["eta"], rtol=1e-11)
    # a refusal on rank 0 (the folder is taken) ends the job at once, with its message
    again = subprocess.run(
        [*command, "--backend", "petsc", "--out", str(out)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert again.returncode == 2 and "is not empty" in again.stderr
