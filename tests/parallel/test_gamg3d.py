"""CG + GAMG in 3D (``"petsc-gamg"``: block size 3, the six rigid motions in the solver's
variables as near-nullspace): in this process and under ``mpiexec -n 1, 2, 3``, with each rank
assembling its own rows, elasticity-3d and a small hertz-3d give the serial direct answer.

Compared with the reference backend (PARDISO where it loads, else SuperLU) in this process:
the same active set and PDAS iterations plus the one confirming solve, the displacements and
contact forces within :data:`U_RTOL` of their largest entry (the solves' tolerance; measured
below 2e-13), KKT residuals below :data:`~signorini.algebra.inexact.KKT_RTOL`. Skipped where
petsc4py or mpiexec is missing, except under ``SIGNORINI_REQUIRE_PETSC=1`` (CI's MPI stage).
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from signorini.algebra import make_solver, solve_pdas
from signorini.algebra.inexact import KKT_RTOL

from .gamg3d import PROBLEMS, run
from .test_mpi import PROBLEM, REFERENCE, mpiexec

SCRIPT = Path(__file__).with_name("gamg3d.py")

pytestmark = pytest.mark.skipif(PROBLEM is not None, reason=f"PETSc runs: {PROBLEM}")

#: The stated tolerance of the displacements and forces (relative to their largest entry).
U_RTOL = 1e-8


@pytest.fixture(scope="module")
def serial():
    """The reference backend's solutions, computed once."""
    return {name: run(name, REFERENCE) for name in PROBLEMS}


def compare(got: dict, reference: dict) -> None:
    """The comparison of the module docstring."""
    np.testing.assert_array_equal(got["active"], reference["active"])
    assert np.abs(got["u"] - reference["u"]).max() <= U_RTOL * np.abs(reference["u"]).max()
    if reference["force"].size:
        scale = np.abs(reference["force"]).max()
        assert np.abs(got["force"] - reference["force"]).max() <= U_RTOL * scale
    assert float(got["kkt"]) <= KKT_RTOL
    assert int(got["iterations"]) == int(reference["iterations"]) + 1
    assert 5 <= got["cg"].min() and got["cg"].max() <= 60, got["cg"]
    # PETSc read the matrix in 3 × 3 node blocks with the six rigid motions
    assert got["block"].size and (got["block"] == 3).all() and (got["modes"] == 6).all()


@pytest.mark.parametrize("name", PROBLEMS)
def test_one_rank_gives_the_direct_answer(serial, name):
    got = run(name, "petsc-gamg")
    compare(got, serial[name])
    assert not got["split"].any()


@pytest.mark.slow
@pytest.mark.parametrize("size", [1, 2, 3])
@pytest.mark.parametrize("name", PROBLEMS)
def test_ranks_that_assemble_their_own_rows_give_the_direct_answer(serial, tmp_path, name, size):
    if mpiexec() is None:
        pytest.skip("no mpiexec")
    out = tmp_path / "solution.npz"
    command = [*mpiexec(), "-n", str(size), sys.executable, str(SCRIPT), name, str(out)]
    done = subprocess.run(command, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]
    got = dict(np.load(out))
    assert int(got["size"]) == size
    compare(got, serial[name])
    if size > 1:
        assert got["split"].all()  # each rank handed PETSc the rows it assembled
    else:  # one process assembles every row: the matrix is whole, as in process
        assert got["split"].size and not got["split"].any()


def test_the_rigid_motions_in_the_solver_variables_cut_the_iterations():
    """hertz-3d solved from its active set: fewer CG iterations with the six rigid motions
    (in node frames and the transformed face basis) than with GAMG's default near-nullspace
    (the constant vector of each component); the same active set."""
    from signorini.algebra.backends.petsc_gamg import petsc_gamg_solver
    from signorini.contact import assemble, solve
    from signorini.contact.rigid_modes import system_rigid_modes

    problem = PROBLEMS["hertz-3d"]()
    reference = solve(problem)
    a = assemble(problem, problem.mesh)
    counts = {}
    for label, modes in (("rigid", lambda: system_rigid_modes(a)), ("default", None)):
        with make_solver(
            petsc_gamg_solver, rigid_modes=modes, check_symmetry=False, dimension=3
        ) as solver:
            result = solve_pdas(
                a.K, a.F, a.contact.constrained_dofs, a.contact.gap, a.dirichlet,
                a.dirichlet_values, active0=reference.active, solver=solver,
            )  # fmt: skip
            counts[label] = solver.iterations
        assert result.kkt.max <= KKT_RTOL and np.array_equal(result.active, reference.active)
    assert len(counts["rigid"]) == len(counts["default"]) == 2
    assert (np.array(counts["rigid"]) < 0.8 * np.array(counts["default"])).all(), counts


def test_the_petsc_backend_takes_gamg_for_large_symmetric_3d_systems():
    """``"petsc"`` chooses by size as ``"auto"`` does: CG + GAMG (block size 3) for a
    symmetric 3D request of GAMG_FROM_3D unknowns or more, MUMPS below it, in 2D and for LU."""
    from signorini.algebra import SolverRequest
    from signorini.algebra.backends.petsc import (
        GAMG_FROM_3D,
        PetscLUSolver,
        PetscSolver,
        petsc_solver,
    )
    from signorini.algebra.backends.petsc_gamg import GamgSolver

    cases = [
        (SolverRequest(dimension=3, size=GAMG_FROM_3D), GamgSolver),
        (SolverRequest(dimension=3, size=GAMG_FROM_3D - 1), PetscSolver),
        (SolverRequest(dimension=2, size=10 * GAMG_FROM_3D), PetscSolver),
        (SolverRequest(dimension=3, size=GAMG_FROM_3D, symmetric=False), PetscLUSolver),
    ]
    for request, kind in cases:
        solver = petsc_solver(request)
        assert type(solver) is kind, (request, type(solver))
        if kind is GamgSolver:
            assert solver.block_size == 3 and solver.rtol == 1e-8
        solver.close()
