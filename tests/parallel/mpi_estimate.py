"""The estimator of an adaptive run on several ranks against the serial estimator of the same
solutions.

Run under ``mpiexec -n N python tests/parallel/mpi_estimate.py PROBLEM LEVELS OUT.npz``: every
rank runs the loop on the ``"petsc"`` backend, whose estimator integrates that rank's cells
only and sums the integrals over the ranks (:mod:`signorini.estimator.owned`). On every level
each rank also estimates the same solution serially (every cell on this rank) and marks by it;
rank 0 writes, per level and rank, the largest difference of the indicators relative to the
largest indicator of their term, whether the marked cells are the same, and the number of
cells the rank integrated. :mod:`test_estimator_ranks` reads them.
"""

from __future__ import annotations

import sys

import numpy as np
from mpi_levels import PROBLEMS  # beside this script

import signorini.loop as loop
from signorini.algebra import solver_factory
from signorini.algebra.ranks import solver_ranks
from signorini.estimator import mark_doerfler
from signorini.estimator.residual import estimate
from signorini.loop import AdaptiveOptions, adaptive

THETA = AdaptiveOptions().theta  # the loop's marking


def relative_difference(a: np.ndarray, b: np.ndarray) -> float:
    """``max |a − b|`` over each row, relative to the row's ``max |b|`` (0 for a zero row)."""
    scale = np.abs(b).max(axis=1)
    diff = np.abs(a - b).max(axis=1)
    return float(np.max(np.where(scale > 0, diff / np.where(scale > 0, scale, 1.0), diff)))


def main(name: str, n_levels: int, out: str) -> None:
    owned = []  # the cells each call of the loop's estimate integrated on this rank

    def recording(result, *args, **kwargs):
        part = kwargs.get("partition")
        owned.append(-1 if part is None else int(part.owned_cells.sum()))
        return estimate(result, *args, **kwargs)

    loop.estimate = recording  # the loop's own estimate, seen from outside
    factory = solver_factory("petsc")
    ranks = solver_ranks(factory)
    rows = []
    for level in adaptive(PROBLEMS[name](), max_levels=n_levels, max_ndof=10**7, solver=factory):
        serial = estimate(level.result)  # no ranks: every cell here
        same_marks = True
        if level.marked is not None:
            same_marks = bool(np.array_equal(level.marked, mark_doerfler(serial.eta2, THETA)))
        rows.append(
            (
                relative_difference(level.estimate.eta2_cell, serial.eta2_cell),
                relative_difference(level.estimate.eta2_node, serial.eta2_node),
                abs(level.estimate.eta - serial.eta) / serial.eta,
                float(same_marks),
                level.result.mesh.n_cells,
                owned[-1],
            )
        )
    table = ranks.gather(np.array(rows)[None])  # (ranks, levels, 6)
    if ranks.rank == 0:
        np.savez(out, size=ranks.size, table=table)


if __name__ == "__main__":
    main(sys.argv[1], int(sys.argv[2]), sys.argv[3])
