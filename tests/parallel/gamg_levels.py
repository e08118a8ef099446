"""Run an example's adaptive loop on a backend and save every level's numbers, with the KKT
residuals of each level and the CG iterations of every solve.

Run under ``mpiexec -n N python tests/parallel/gamg_levels.py PROBLEM LEVELS OUT.npz``: every
rank runs the (replicated) loop on the ``"petsc-gamg"`` backend, and rank 0 writes
:func:`run`'s numbers. :mod:`test_gamg` compares them with the serial run of a direct backend.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))  # mpi_levels, when run as a script

from mpi_levels import level_numbers  # noqa: E402

from signorini.algebra import solver_factory  # noqa: E402
from signorini.examples import (  # noqa: E402
    example_6_2,
    example_6_2_coulomb,
    example_6_2_tresca,
    two_cylinders,
)
from signorini.loop import adaptive  # noqa: E402

PROBLEMS = {
    "example-6.2": example_6_2,
    "example-6.2-tresca": example_6_2_tresca,
    "example-6.2-coulomb": example_6_2_coulomb,
    "two-cylinders": two_cylinders,
}


def run(problem: str, levels: int, solver: str) -> dict[str, np.ndarray]:
    """:func:`mpi_levels.level_numbers` of ``levels`` adaptive levels of ``problem`` on the
    backend ``solver``, with ``kkt`` (the largest relative KKT residual of each level),
    ``iterations`` (the active set iterations of each level) and ``cg`` (the CG iterations
    of every solve of an iterative backend, in order), and ``split`` (for every CG + GAMG
    solver that factorized, whether its matrix was split by rows over the ranks)."""
    factory, made = recording(solver_factory(solver))
    run = list(adaptive(PROBLEMS[problem](), max_levels=levels, max_ndof=10**7, solver=factory))
    numbers = level_numbers(run)
    numbers["kkt"] = np.array([level.result.report.kkt.max for level in run])
    numbers["iterations"] = np.array([level.result.report.iterations for level in run])
    numbers["cg"] = np.array([k for s in made for k in getattr(s, "iterations", [])], dtype=int)
    gamg = [s for s in made if s.backend == "petsc-gamg" and s.n_analyses]
    numbers["split"] = np.array([s.split for s in gamg], dtype=bool)
    return numbers


def recording(factory):
    """``factory`` and the list of every solver it makes; with the factory's ranks (the ranks
    it splits matrices over, :func:`~signorini.algebra.ranks.solver_ranks`)."""
    made = []

    def make(request):
        solver = factory(request)
        made.append(solver)
        return solver

    if hasattr(factory, "ranks"):
        make.ranks = factory.ranks
    return make, made


if __name__ == "__main__":
    name, n_levels, out = sys.argv[1], int(sys.argv[2]), sys.argv[3]
    numbers = run(name, n_levels, "petsc-gamg")
    from signorini.algebra.backends.petsc import petsc_module

    comm = petsc_module().COMM_WORLD
    if comm.getRank() == 0:
        np.savez(out, size=comm.getSize(), **numbers)
