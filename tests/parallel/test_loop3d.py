"""The 3D adaptive loop under ``mpiexec -n 1, 2, 3`` on ``petsc-gamg`` (each rank assembles its
rows and estimates its own cells and faces, :mod:`signorini.estimator.owned`) against the
serial loop of the default direct backend: per level the same meshes, active sets and marked
cells, η and u to the CG solve's tolerance. Each run is :mod:`mpi_loop3d` in a child
``mpiexec``; skipped where petsc4py or mpiexec is missing, except under
``SIGNORINI_REQUIRE_PETSC=1`` (CI's MPI stage).
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from .mpi_loop3d import level_record, problem
from .test_mpi import PROBLEM, mpiexec

SCRIPT = Path(__file__).with_name("mpi_loop3d.py")
LEVELS = 4
#: η and u relative to the serial run: CG + GAMG stops at a relative residual of 1e-8
#: (``petsc_gamg.RTOL``); the error of u is that times the condition number's share, and
#: η's a like share of it (measured: at most 1e-13 on these levels)
TOLERANCE = 1e-5

pytestmark = [
    pytest.mark.skipif(PROBLEM is not None, reason=f"MPI runs: {PROBLEM}"),
    pytest.mark.slow,
]


@pytest.fixture(scope="module")
def serial():
    from signorini.loop import adaptive

    return level_record(adaptive(problem(), max_levels=LEVELS, max_ndof=10**7))


@pytest.mark.parametrize("size", [1, 2, 3])
def test_the_3d_loop_on_ranks_gives_the_serial_levels(serial, tmp_path, size):
    out = tmp_path / "levels.npz"
    command = [*mpiexec(), "-n", str(size), sys.executable, str(SCRIPT), str(LEVELS)]
    done = subprocess.run(
        [*command, "petsc-gamg", str(out)], capture_output=True, text=True, timeout=600
    )
    assert done.returncode == 0, done.stderr[-3000:]
    got = np.load(out, allow_pickle=True)
    assert int(got["size"]) == size and len(got["eta"]) == LEVELS
    worst = 0.0
    for level in range(LEVELS):
        for name in ("cells", "active", "marked"):
            np.testing.assert_array_equal(got[name][level], serial[name][level], err_msg=name)
        u, reference = got["u"][level], serial["u"][level]
        worst = max(worst, np.abs(u - reference).max() / np.abs(reference).max())
    eta = np.abs(got["eta"] - serial["eta"]) / serial["eta"]
    print(f"hertz-3d on {size} ranks: u to {worst:.1e}, eta to {eta.max():.1e} of serial")
    assert worst <= TOLERANCE
    np.testing.assert_allclose(got["eta"], serial["eta"], rtol=TOLERANCE, atol=0)
    owned = got["owned"]  # (ranks, levels): the cells each rank's estimator integrated
    n_cells = [len(c) for c in serial["cells"]]
    if size == 1:
        assert (owned == -1).all()  # one process: the serial path, every cell
    else:
        assert (owned > 0).all() and (owned < np.array(n_cells)).all()
        np.testing.assert_array_equal(owned.sum(axis=0), n_cells)
