"""``K`` split by rows over 2 and 3 ranks (each rank its own nodes' rows, the others empty):
PDAS, its bordered updates, its warm start and its primal fallback, Tresca and Coulomb
friction and a two-body problem give the serial answer.

Each run is :mod:`mpi_split_solve` in a child ``mpiexec``; the reference is the same problem with
the whole ``K`` on a serial backend (SuperLU), solved in the same processes. Only the
factorization differs (MUMPS on the ranks against SuperLU), so the iterates agree to
round-off and every discrete decision (active sets, states, iteration and update counts)
exactly.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from .test_mpi import mpiexec, pytestmark  # noqa: F401  (skips where MPI is missing)

SCRIPT = Path(__file__).with_name("mpi_split_solve.py")
PDAS = ["example-6.2", "example-6.2 refactorized", "example-6.2 warm", "example-6.2 ordered",
        "example-6.2 primal fallback", "two-cylinders"]  # fmt: skip
FRICTION = ["example-6.2-coulomb", "example-6.2-tresca"]


@pytest.fixture(scope="module", params=[2, 3])
def runs(request, tmp_path_factory):
    out = tmp_path_factory.mktemp(f"rows{request.param}") / "rows.npz"
    command = [*mpiexec(), "-n", str(request.param), sys.executable, str(SCRIPT), str(out)]
    done = subprocess.run(command, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]
    got = dict(np.load(out))
    assert int(got["size"]) == request.param
    return got


def case(runs: dict, name: str) -> dict[str, np.ndarray]:
    prefix = name + "/"
    return {key[len(prefix) :]: value for key, value in runs.items() if key.startswith(prefix)}


@pytest.mark.parametrize("name", PDAS + FRICTION)
def test_the_split_matrix_gives_the_serial_answer(runs, name):
    got = case(runs, name)
    size = int(runs["size"])
    n = got["serial_x"].size
    owned = got["owned_rows"]
    # every rank holds a share of the rows, together each row once
    assert owned.size == size and owned.sum() == n and (owned > 0).all()
    np.testing.assert_array_equal(got["split_active"], got["serial_active"])
    np.testing.assert_array_equal(got["split_counts"], got["serial_counts"])
    x, xs = got["split_x"], got["serial_x"]
    assert np.abs(x - xs).max() <= 1e-11 * np.abs(xs).max()
    m, ms = got["split_multiplier"], got["serial_multiplier"]
    assert np.abs(m - ms).max() <= 1e-11 * np.abs(ms).max()
    assert got["split_kkt"].max() <= 1e-12 and got["serial_kkt"].max() <= 1e-12


def test_the_cases_take_the_paths_they_are_named_for(runs):
    counts = {name: case(runs, name)["serial_counts"] for name in PDAS + FRICTION}
    # (iterations, bordered updates, factorizations, steps) for PDAS
    assert counts["example-6.2"][1] > 0  # solves by a bordered update of the factor
    assert counts["example-6.2 refactorized"][1] == 0
    assert counts["example-6.2 warm"][0] < counts["example-6.2"][0]
    assert str(case(runs, "example-6.2 primal fallback")["split_method"]) == "primal-active-set"
    assert case(runs, "two-cylinders")["serial_active"].sum() >= 3
    # (iterations, factorizations, symmetric) for friction: Coulomb LU, Tresca Cholesky
    assert counts["example-6.2-coulomb"][2] == 0 and counts["example-6.2-tresca"][2] == 1
    assert counts["example-6.2-tresca"][1] < counts["example-6.2-tresca"][0]  # an update


def test_a_whole_matrix_passed_as_split_and_a_skew_one_are_refused(runs):
    whole, skew = runs["refusals/messages"]
    assert "K must hold each row on exactly one of the" in whole
    assert "A is not symmetric" in skew
