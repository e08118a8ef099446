"""``mpiexec -n N signorini run PROBLEM --backend petsc``: one run, its files written once.

Every rank runs the same adaptive loop (mesh, estimator, marking and refinement replicated;
docs/parallel.md) and the linear systems are solved by MUMPS on all of them together. Rank 0
is the run the command line describes: it owns the output folder and writes the levels, the
figures and the uniform comparison. The other ranks *follow* (:func:`follow`): they run the
same loops, the uniform comparison's too, with no output, so that each solve has all ranks.
"""

from __future__ import annotations

import argparse
import os
import sys
from dataclasses import replace

from ..algebra.backends.selection import solver_name
from ..loop import AdaptiveOptions, adaptive
from .problems import RunProblem
from .settings import RunSettings

__all__ = ["end_ranks", "follow", "launched_ranks"]

#: Environment variables in which MPI launchers give the number of processes they started
#: (MPICH's Hydra, Open MPI, PMIx).
SIZE_VARIABLES = ("PMI_SIZE", "OMPI_COMM_WORLD_SIZE", "PMIX_SIZE")


def launched_ranks() -> int:
    """How many processes the MPI launcher started (1 outside ``mpiexec``), read from its
    environment without loading MPI."""
    for name in SIZE_VARIABLES:
        value = os.environ.get(name, "")
        if value.isdigit():
            return int(value)
    return 1


def follow(args: argparse.Namespace, settings: RunSettings, job: RunProblem) -> bool:
    """On a rank other than 0 of a several-rank ``petsc`` or ``petsc-gamg`` run: run the loops
    rank 0 runs, without output, and return True; False everywhere else (the caller runs as
    usual).

    Raises
    ------
    ValueError
        For ``--resume`` on several ranks (a resumed run's state is read by one process).
    """
    if solver_name(settings.options.solver) not in ("petsc", "petsc-gamg"):
        return False
    from ..algebra.backends.petsc import petsc_module

    comm = petsc_module().COMM_WORLD
    if comm.getSize() == 1:
        return False
    if args.resume is not None:
        raise ValueError("--resume runs on one process: continue the run without mpiexec")
    if comm.getRank() == 0:
        return False
    options = settings.options
    loop = {"metrics": job.metrics, "path": job.path}
    for _ in adaptive(job.problem, options, **loop):
        pass
    if settings.compare_uniform and not options.uniform:  # as cli.figures.compare_uniform
        uniform = replace(options, uniform=True, tol=AdaptiveOptions.tol)
        for _ in adaptive(job.problem, uniform, **loop):
            pass
    return True


def end_ranks(code: int) -> int:
    """``code``, or, for an error on a rank of a several-rank ``petsc`` run, the end of this
    process without MPI's finalization, on which the launcher ends the other ranks: a rank
    that stopped alone (rank 0 refusing its output folder, Ctrl-C) would leave them waiting
    in a collective solve, and itself in ``MPI_Finalize``."""
    if code == 0 or "petsc4py.PETSc" not in sys.modules:
        return code
    comm = sys.modules["petsc4py.PETSc"].COMM_WORLD
    if comm.getSize() > 1:
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(code)
    return code
