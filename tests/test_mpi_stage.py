"""The MPI stage: the ``"petsc"`` backend's tests (``tests/algebra/backends/test_petsc.py``) and the
invariance runs under ``mpiexec -n 1, 2, 3`` (``tests/parallel``), run by the Python that has
the ``[mpi]`` extra (PETSc, MUMPS and MPICH wheels need Python >= 3.12; docs/parallel.md).

``SIGNORINI_MPI_PYTHON`` names that Python; ``.ci/run`` makes it (a venv of the machine's
Python 3.12 or 3.13 with ``.[fast,test,mpi]``) and sets it, so the README's test command runs
the stage in CI, where a missing petsc4py or mpiexec is a failure
(``SIGNORINI_REQUIRE_PETSC=1`` in the child). Without it the stage is skipped, saying how to
run it.
"""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).parents[1]
MPI_PYTHON = os.environ.get("SIGNORINI_MPI_PYTHON")
#: A file of ``tests/parallel`` that plays the ranks in one process and needs neither PETSc
#: nor MPI: the serial stage runs it, the MPI stage need not run it again.
SERIAL_ONLY = "tests/parallel/test_estimator_ranks.py"
#: One BLAS thread per process: up to three ranks share the machine's cores (oversubscribed
#: on two), and their BLAS threads would compete for them (the stage took 62 s with them,
#: 55 s without).
ONE_THREAD = dict.fromkeys(("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"), "1")


@pytest.mark.slow
@pytest.mark.skipif(
    not MPI_PYTHON,
    reason="SIGNORINI_MPI_PYTHON is not set: make a Python >= 3.12 venv with "
    "pip install -e '.[fast,test,mpi]' and name its python there (docs/parallel.md)",
)
def test_the_petsc_backend_and_the_mpi_runs_pass():
    env = {**os.environ, "SIGNORINI_REQUIRE_PETSC": "1", "MPLBACKEND": "Agg", **ONE_THREAD}
    done = subprocess.run(
        [MPI_PYTHON, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-m", "", "tests/parallel",
         "tests/algebra/backends/test_petsc.py", f"--ignore={SERIAL_ONLY}"],
        cwd=ROOT, env=env, capture_output=True, text=True, timeout=1200,
    )  # fmt: skip
    summary = done.stdout.strip().splitlines()[-1] if done.stdout.strip() else ""
    print(f"MPI stage ({MPI_PYTHON}): {summary}")
    assert done.returncode == 0, done.stdout[-6000:] + done.stderr[-3000:]
    assert "passed" in summary and "skipped" not in summary and "failed" not in summary
