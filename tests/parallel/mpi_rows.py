"""Each rank's rows of the assembled system under ``mpiexec``: the serial system's, bit for bit.

Run as ``mpiexec -n N python tests/parallel/mpi_rows.py``: every rank assembles the serial
system and its own rows (``assemble(..., ranks=world_ranks())``) of a few problems, and checks
with the MPI collectives that its rows are the serial ones, that every row is on one rank,
and that the products and diagonals summed over the ranks are the serial ones. Exits with
status 1 and a message on the first difference; rank 0 prints ``rows: N ranks same``.
:mod:`test_rows` runs it.
"""

from __future__ import annotations

import sys

import numpy as np

from signorini.algebra.ranks import world_ranks
from signorini.contact.system import assemble
from signorini.examples.paper import example_6_2
from signorini.examples.two_bodies import two_cylinders
from signorini.mesh.refine import refine_uniform


def check(name: str, problem, mesh, ranks) -> str | None:
    """The first difference of this rank's rows from the serial system's, or None."""
    serial = assemble(problem, mesh)
    mine = assemble(problem, mesh, ranks=ranks)
    own = mine.partition.owned_dofs
    K, Kr = serial.K, mine.K
    kept = np.repeat(own, np.diff(K.indptr))
    if not np.array_equal(np.diff(Kr.indptr), np.where(own, np.diff(K.indptr), 0)):
        return f"{name}: rank {ranks.rank} stores other rows than its own"
    if not (np.array_equal(Kr.indices, K.indices[kept]) and np.array_equal(Kr.data, K.data[kept])):
        return f"{name}: rank {ranks.rank}'s rows differ from the serial ones"
    if not (ranks.sum(own.astype(np.int64)) == 1).all():
        return f"{name}: a row is on no rank or on two"
    x = np.cos(0.37 * np.arange(K.shape[0]))
    if not np.array_equal(ranks.sum(Kr @ x), K @ x):
        return f"{name}: the product summed over the ranks is not the serial one"
    if not np.array_equal(ranks.sum(Kr.diagonal()), K.diagonal()):
        return f"{name}: the diagonal summed over the ranks is not the serial one"
    if not np.array_equal(mine.F, serial.F):
        return f"{name}: F differs"
    return None


def main() -> int:
    ranks = world_ranks()
    cases = {
        "example-6.2": (example_6_2(), 1),
        "two-cylinders": (two_cylinders(), 0),
    }
    for name, (problem, refinements) in cases.items():
        mesh = problem.mesh
        for _ in range(refinements):
            mesh = refine_uniform(mesh).mesh
        fault = check(name, problem, mesh, ranks)
        if ranks.max(float(fault is not None)) > 0.0:
            print(fault or f"{name}: another rank differs", file=sys.stderr, flush=True)
            return 1
    if ranks.rank == 0:
        print(f"rows: {ranks.size} ranks same", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
