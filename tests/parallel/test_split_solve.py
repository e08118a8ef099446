"""``K`` split by rows over 2 ranks (each rank its own nodes' rows, the others empty):
PDAS, its bordered updates, its warm start and its primal fallback, Tresca and Coulomb
friction and a two-body problem give the serial answer.

Each run is :mod:`mpi_split_solve` in a child ``mpiexec``; the reference is the same problem with
the whole ``K`` on a serial backend (SuperLU), solved in the same processes. Only the
factorization differs (MUMPS on the ranks against SuperLU), so the iterates agree to
round-off and every discrete decision (active sets, states, iteration and update counts)
exactly.

The cases named ``… gamg`` solve on CG + GAMG (``"petsc-gamg"``, the inexact active set rule,
the rigid motions as near-nullspace), with ``K`` split and with the whole ``K`` on every rank:
both give SuperLU's answer within the rule's stated tolerances.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from signorini.algebra.inexact import KKT_RTOL

from .test_mpi import mpiexec, pytestmark  # noqa: F401  (skips where MPI is missing)

SCRIPT = Path(__file__).with_name("mpi_split_solve.py")
PDAS = ["example-6.2", "example-6.2 refactorized", "example-6.2 warm", "example-6.2 ordered",
        "example-6.2 primal fallback", "two-cylinders"]  # fmt: skip
FRICTION = ["example-6.2-coulomb", "example-6.2-tresca"]
GAMG = ["example-6.2 gamg", "two-cylinders gamg", "example-6.2-tresca gamg"]


# Two ranks here; three ranks split K in test_mpi.py's whole adaptive runs (Example 6.2 and
# Coulomb) and in test_rows.py's assembly
@pytest.fixture(scope="module", params=[2])
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


def test_mumps_orders_by_amd_unless_petsc_options_say_otherwise(runs):
    """On several ranks too, MUMPS's Cholesky orders by AMD (``INFOG(7) = 0``; faster than
    METIS on two ranks, docs/parallel.md), and by METIS (5) where PETSc's options database
    says ``-mat_mumps_icntl_7 5``."""
    assert runs["mumps_orderings"].tolist() == [0, 5]


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


@pytest.mark.parametrize("name", GAMG)
def test_the_split_matrix_on_cg_gamg_gives_the_serial_answer(runs, name):
    """Split and whole on CG + GAMG against SuperLU: the same active sets (states), one more
    iteration (the confirming solve), x and the multipliers within 1e-8 relative, the KKT
    residuals below KKT_RTOL (measured on 2 and 3 ranks: within 3.2e-13, below 2.7e-13)."""
    got = case(runs, name)
    size = int(runs["size"])
    owned = got["owned_rows"]
    assert owned.size == size and owned.sum() == got["serial_x"].size and (owned > 0).all()
    assert bool(got["split_split"]) and not bool(got["whole_split"])
    for path in ("split", "whole"):
        np.testing.assert_array_equal(got[f"{path}_active"], got["serial_active"])
        np.testing.assert_array_equal(got[f"{path}_counts"], got["serial_counts"] + 1)
        x, xs = got[f"{path}_x"], got["serial_x"]
        assert np.abs(x - xs).max() <= 1e-8 * np.abs(xs).max()
        m, ms = got[f"{path}_multiplier"], got["serial_multiplier"]
        assert np.abs(m - ms).max() <= 1e-8 * np.abs(ms).max()
        assert got[f"{path}_kkt"].max() <= KKT_RTOL
        # one CG solve per iteration, each well inside the backend's bound
        cg = got[f"{path}_cg"]
        assert cg.size == got[f"{path}_counts"][0] and 10 <= cg.min() and cg.max() <= 60, cg


@pytest.mark.parametrize("name", GAMG)
def test_the_near_nullspace_follows_the_rows(runs, name):
    """GAMG's near-nullspace of the last set-up, gathered back into the system's numbering:
    the split run's is the whole run's (the same orthonormalized rigid motions, renumbered
    with the rows and back), orthonormal, three vectors a body, and on the DOFs it does not
    vanish on, in the span of the rigid motions there."""
    got = case(runs, name)
    q, modes = got["split_modes"], got["rigid_modes"]
    np.testing.assert_array_equal(q, got["whole_modes"])
    assert q.shape[1] == modes.shape[1] == (6 if name.startswith("two") else 3)
    assert np.abs(q.T @ q - np.eye(q.shape[1])).max() <= 1e-12
    live = np.abs(q).max(axis=1) > 1e-10 * np.abs(q).max()  # zero, to the QR's round-off
    assert 0 < np.count_nonzero(~live) < q.shape[0] // 10  # the eliminated DOFs only
    coefficients = np.linalg.lstsq(modes[live], q[live], rcond=None)[0]
    assert np.abs(modes[live] @ coefficients - q[live]).max() <= 1e-12
