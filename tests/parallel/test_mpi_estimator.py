"""The estimator under ``mpiexec -n 2`` and ``-n 3``: on several ranks each rank integrates its own
cells and edges (:mod:`signorini.estimator.owned`), and every rank's estimate is the serial
estimate of the same solution.

Each run is :mod:`mpi_estimate` in a child ``mpiexec``: the adaptive loop on the ``"petsc"``
backend, which on every level also estimates its solution serially on each rank. Compared per
level and rank: the indicators per cell and per node and η to 1e-13 relative (measured: equal
bit for bit), the same marked cells, and the cells each rank integrated (the partition's, which
cover the mesh once). The whole runs against
the serial PARDISO runs are :mod:`test_mpi`'s.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from .test_mpi import PROBLEM, mpiexec

SCRIPT = Path(__file__).with_name("mpi_estimate.py")

pytestmark = [
    pytest.mark.skipif(PROBLEM is not None, reason=f"MPI runs: {PROBLEM}"),
    pytest.mark.slow,
]


@pytest.mark.parametrize(
    "name,levels,ranks",
    # -n 1 takes the serial path and -n 2 on Example 6.2 is in test_mpi.py's comparison of
    # whole runs; here the most ranks (-n 3) and friction
    [("example-6.2", 16, 3), ("example-6.2-coulomb", 10, 2)],
)
def test_every_ranks_estimate_is_the_serial_one(tmp_path, name, levels, ranks):
    out = tmp_path / "estimate.npz"
    command = [*mpiexec(), "-n", str(ranks), sys.executable, str(SCRIPT), name, str(levels)]
    done = subprocess.run([*command, str(out)], capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]
    got = np.load(out)
    table = got["table"]  # (ranks, levels, 6)
    assert int(got["size"]) == ranks and table.shape == (ranks, levels, 6)
    cell, node, eta, same_marks, n_cells, owned = np.moveaxis(table, -1, 0)
    worst = max(cell.max(), node.max(), eta.max())
    print(f"{name} on {ranks} ranks: largest relative difference to serial {worst:.1e}")
    assert worst <= 1e-13
    assert same_marks.all()
    assert (owned > 0).all()
    np.testing.assert_array_equal(owned.sum(axis=0), n_cells[0])
