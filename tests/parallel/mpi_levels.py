"""Run an example's adaptive loop on the ``"petsc"`` backend and save every level's numbers.

Run under ``mpiexec -n N python tests/parallel/mpi_levels.py PROBLEM LEVELS OUT.npz``: every
rank runs the (replicated) loop, the linear systems are solved by MUMPS on all ranks, and
rank 0 writes :func:`level_numbers` of each level. :mod:`test_mpi` compares them with the
serial run of another backend.
"""

from __future__ import annotations

import sys

import numpy as np

from signorini.algebra import solver_factory
from signorini.examples import example_6_2, example_6_2_coulomb, example_6_2_tresca
from signorini.loop import Level, adaptive

PROBLEMS = {
    "example-6.2": example_6_2,
    "example-6.2-coulomb": example_6_2_coulomb,
    "example-6.2-tresca": example_6_2_tresca,
}


def level_numbers(levels: list[Level]) -> dict[str, np.ndarray]:
    """Ndof, η and its eight terms, the active sets and the marked cells of each level, and
    the displacements of the last one, as flat arrays (``*_sizes`` split the ragged ones)."""
    active = [np.flatnonzero(level.result.active) for level in levels]
    marked = [np.flatnonzero(level.marked) for level in levels if level.marked is not None]
    return {
        "ndof": np.array([level.record.ndof for level in levels]),
        "eta": np.array([level.record.eta for level in levels]),
        "eta_terms": np.array([level.estimate.eta_terms for level in levels]),
        "active": np.concatenate(active),
        "active_sizes": np.array([a.size for a in active]),
        "marked": np.concatenate(marked) if marked else np.zeros(0, dtype=int),
        "marked_sizes": np.array([m.size for m in marked]),
        "u": levels[-1].result.u,
        "backend": np.array([level.record.backend for level in levels]),
    }


def run(problem: str, levels: int, solver: str) -> dict[str, np.ndarray]:
    """The numbers of ``levels`` adaptive levels of ``problem`` (a key of PROBLEMS)."""
    factory = solver_factory(solver)
    run = adaptive(PROBLEMS[problem](), max_levels=levels, max_ndof=10**7, solver=factory)
    return level_numbers(list(run))


if __name__ == "__main__":
    name, n_levels, out = sys.argv[1], int(sys.argv[2]), sys.argv[3]
    numbers = run(name, n_levels, "petsc")
    from signorini.algebra.backends.petsc import petsc_module

    comm = petsc_module().COMM_WORLD
    if comm.getRank() == 0:
        np.savez(out, size=comm.getSize(), **numbers)
