"""The processes that share one run's linear algebra (docs/parallel.md, *What is distributed*).

A run on several MPI ranks keeps its loop replicated (every rank holds the mesh, the
solution and every vector) and splits the stiffness matrix by rows: rank r holds the rows of
the DOFs it owns, the other rows of its copy are empty, and the matrix is the sum of the
ranks' copies. A product with a replicated vector is therefore each rank's product summed
over the ranks (:meth:`Ranks.sum`); as every row lives on one rank only, that sum adds zeros
to one rank's exact value and equals the serial product bit for bit.

:data:`SERIAL` is the one process of a serial run: its :meth:`~Ranks.sum` returns its argument
itself, so the serial path does no copy and no extra work. :func:`world_ranks` is
``PETSC_COMM_WORLD``, through mpi4py (which the extra ``signorini[mpi]`` brings).
"""

from __future__ import annotations

from functools import cache
from typing import Any

import numpy as np

from .backends.petsc_import import petsc_module
from .errors import BackendUnavailableError

__all__ = ["SERIAL", "Ranks", "solver_ranks", "stored_values", "world_ranks"]


class Ranks:
    """One process's view of the ranks of a run: its rank, their number, the collectives.

    The base class is a single process; :func:`world_ranks` gives the MPI one.

    Attributes
    ----------
    rank : int
        This process, ``0 … size − 1``.
    size : int
        The number of processes.
    """

    rank: int = 0
    size: int = 1

    @property
    def distributed(self) -> bool:
        """Whether more than one process shares the run."""
        return self.size > 1

    def sum(self, a: np.ndarray) -> np.ndarray:
        """The elementwise sum of ``a`` over the ranks, on every rank (``a`` itself here)."""
        return a

    def gather(self, a: np.ndarray) -> np.ndarray:
        """The ranks' arrays ``a`` joined along their first axis in rank order, on every rank
        (``a`` itself here)."""
        return a

    def max(self, value: float) -> float:
        """The largest ``value`` over the ranks, on every rank."""
        return value


#: The one process of a serial run.
SERIAL = Ranks()


class MPIRanks(Ranks):
    """The ranks of an MPI communicator (an ``mpi4py`` ``Comm``)."""

    def __init__(self, comm: Any) -> None:
        self._comm = comm
        self.rank = comm.Get_rank()
        self.size = comm.Get_size()

    def sum(self, a: np.ndarray) -> np.ndarray:
        if self.size == 1:
            return a
        from mpi4py import MPI

        out = np.ascontiguousarray(a).copy()
        self._comm.Allreduce(MPI.IN_PLACE, out, op=MPI.SUM)
        return out

    def gather(self, a: np.ndarray) -> np.ndarray:
        if self.size == 1:
            return a
        a = np.ascontiguousarray(a)
        row = int(np.prod(a.shape[1:], dtype=np.int64))
        counts = np.array(self._comm.allgather(a.shape[0] * row), dtype=np.int64)
        out = np.empty((int(counts.sum()) // max(row, 1),) + a.shape[1:], dtype=a.dtype)
        self._comm.Allgatherv(a, [out, counts])
        return out

    def max(self, value: float) -> float:
        if self.size == 1:
            return value
        from mpi4py import MPI

        return float(self._comm.allreduce(float(value), op=MPI.MAX))


@cache
def world_ranks() -> Ranks:
    """The ranks of ``PETSC_COMM_WORLD`` (all the processes ``mpiexec`` started).

    Raises
    ------
    BackendUnavailableError
        If petsc4py or mpi4py is missing, naming the extra that brings them.
    """
    PETSc = petsc_module()
    try:
        comm = PETSc.COMM_WORLD.tompi4py()
    except Exception as err:  # mpi4py missing, or built for another MPI
        raise BackendUnavailableError(
            f"several ranks need mpi4py with PETSc's MPI ({err}): pip install 'signorini[mpi]'"
        ) from err
    return MPIRanks(comm)


def stored_values(data: np.ndarray, positions: np.ndarray, ranks: Ranks) -> np.ndarray:
    """Entries of a matrix split by rows over ``ranks``, on every rank: ``data[positions]``
    with the positions ``-1`` (rows stored on another rank) read as 0, summed over the ranks.

    Each row lives on one rank, so the sum is that rank's value exactly. With one process,
    where every position is stored, it is ``data[positions]`` (no extra pass).

    Parameters
    ----------
    data : (nnz,) float array
        The matrix's stored values (``A.data``).
    positions : (k,) int array
        Positions in ``data`` (e.g. of diagonal entries), ``-1`` where this rank stores none.

    Returns
    -------
    (k,) float array
    """
    if not ranks.distributed:
        return data[positions]
    return ranks.sum(np.where(positions >= 0, data[positions], 0.0))


def solver_ranks(solver: object) -> Ranks:
    """The ranks over which ``solver`` (a factory or a solver) splits its matrices: what its
    ``ranks`` attribute (a zero-argument callable) returns, :data:`SERIAL` without one."""
    ranks = getattr(solver, "ranks", None)
    return SERIAL if ranks is None else ranks()
