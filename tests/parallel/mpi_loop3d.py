"""The 3D adaptive loop on several ranks, each rank estimating its own cells.

Run under ``mpiexec -n N python tests/parallel/mpi_loop3d.py LEVELS SOLVER OUT.npz``: every
rank runs the adaptive loop of :data:`PROBLEM` on the backend ``SOLVER`` (``petsc-gamg``: each
rank assembles its rows; the loop's estimator integrates the rank's own cells and faces and sums
the integrals over the ranks, :mod:`signorini.estimator.owned`). Rank 0 writes per level the
mesh, the active set, the marked cells, η and u (:func:`level_record`), and per level and rank
the number of cells the rank's estimator integrated. :mod:`test_loop3d` compares them with the
serial loop.
"""

from __future__ import annotations

import sys

import numpy as np

import signorini.loop as loop
from signorini.algebra import solver_factory
from signorini.algebra.ranks import solver_ranks
from signorini.estimator.residual import estimate
from signorini.examples import hertz_3d
from signorini.loop import adaptive


def problem():
    """Hertz in 3D on a coarse contact mesh: a few levels in seconds."""
    return hertz_3d(h_contact=0.2)


def level_record(levels) -> dict[str, np.ndarray]:
    """Per level (object arrays, one entry a level): ``cells`` (the tetrahedra), ``active``
    (the contact set), ``marked`` (empty on the last level), ``u``; and ``eta`` ``(levels,)``."""
    rows = list(levels)

    def stack(values):
        out = np.empty(len(values), dtype=object)
        out[:] = values
        return out

    return {
        "cells": stack([lv.result.mesh.cells for lv in rows]),
        "active": stack([np.asarray(lv.result.active) for lv in rows]),
        "marked": stack([np.zeros(0, int) if lv.marked is None else lv.marked for lv in rows]),
        "u": stack([lv.result.u for lv in rows]),
        "eta": np.array([lv.estimate.eta for lv in rows]),
    }


def main(n_levels: int, solver: str, out: str) -> None:
    owned = []  # the cells each call of the loop's estimate integrated on this rank

    def recording(result, *args, **kwargs):
        part = kwargs.get("partition")
        owned.append(-1 if part is None else int(part.owned_cells.sum()))
        return estimate(result, *args, **kwargs)

    loop.estimate = recording  # the loop's own estimate, seen from outside
    factory = solver_factory(solver)
    ranks = solver_ranks(factory)
    run = adaptive(problem(), max_levels=n_levels, max_ndof=10**7, solver=factory)
    numbers = level_record(run)
    table = ranks.gather(np.array(owned, dtype=float)[None])  # (ranks, levels)
    if ranks.rank == 0:
        np.savez(out, size=ranks.size, owned=table, **numbers)


if __name__ == "__main__":
    main(int(sys.argv[1]), sys.argv[2], sys.argv[3])
