"""Solve a 3D problem on the ``"petsc-gamg"`` backend and save its numbers.

Run under ``mpiexec -n N python tests/parallel/gamg3d.py PROBLEM OUT.npz``: every rank
assembles its own rows of the system (``solve`` takes the ranks from the backend) and CG +
GAMG solves it with block size 3 and the six rigid motions, in the solver's variables, as its
near-nullspace; rank 0 writes :func:`run`'s numbers. :mod:`test_gamg3d` compares them with
the serial run of a direct backend.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))  # gamg_levels, when run as a script

from gamg_levels import recording  # noqa: E402

from signorini.algebra import solver_factory  # noqa: E402
from signorini.contact.solution import solve  # noqa: E402
from signorini.examples import elasticity_3d, hertz_3d  # noqa: E402

PROBLEMS = {
    "elasticity-3d": lambda: elasticity_3d(3),
    "hertz-3d": lambda: hertz_3d(h_contact=0.2),
}


def run(problem: str, solver: str) -> dict[str, np.ndarray]:
    """The solution of ``problem`` on the backend ``solver``: ``u``, ``active``, ``force``
    (the contact force), ``kkt`` and ``iterations`` (PDAS), ``cg`` (the CG iterations of every
    solve), and for the CG + GAMG solvers that factorized: ``split`` (the matrix split by rows
    over the ranks), ``block`` (PETSc's block size) and ``modes`` (near-nullspace vectors)."""
    factory, made = recording(solver_factory(solver))
    result = solve(PROBLEMS[problem](), solver=factory)
    gamg = [s for s in made if s.backend == "petsc-gamg" and s.n_analyses]
    return {
        "u": result.u,
        "active": result.active,
        "force": result.contact_force,
        "kkt": np.array(result.report.kkt.max),
        "iterations": np.array(result.report.iterations),
        "cg": np.array([k for s in made for k in getattr(s, "iterations", [])], dtype=int),
        "split": np.array([s.split for s in gamg], dtype=bool),
        "block": np.array([s.matrix_block_size for s in gamg], dtype=int),
        "modes": np.array([s.near_nullspace_size for s in gamg], dtype=int),
    }


if __name__ == "__main__":
    name, out = sys.argv[1], sys.argv[2]
    numbers = run(name, "petsc-gamg")
    from signorini.algebra.backends.petsc import petsc_module

    comm = petsc_module().COMM_WORLD
    if comm.getRank() == 0:
        np.savez(out, size=comm.getSize(), **numbers)
