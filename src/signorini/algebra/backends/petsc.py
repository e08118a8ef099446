"""PETSc with MUMPS as a solver backend, serial or under ``mpiexec`` (the ``"petsc"`` backend).

The optional extra ``signorini[mpi]`` brings PETSc, petsc4py, MPICH and MUMPS as binary wheels
(docs/parallel.md, *Install*); any other petsc4py whose PETSc has MUMPS serves as well (a
source or Debian build). Nothing here is imported unless the backend is asked for: the
default install stays PETSc-free.

The matrix is a PETSc AIJ matrix on ``PETSC_COMM_WORLD`` (``seqaij`` on one process,
``mpiaij`` on several), and each process hands PETSc its own rows only. The scipy matrix each
process passes is either

- *whole*, the same on every process (a user's script): PETSc's rows are split in contiguous
  blocks as PETSc splits them (:func:`row_block`);
- or *split by rows* (:mod:`.ranks`; what ``assemble`` builds on a rank of several): each
  process's matrix holds its own rows, the other rows empty, and the matrix is the sum of
  the processes' copies. PETSc needs each process's rows contiguous, so its numbering is a
  permutation of the unknowns (computed once per pattern): process 0's rows first, then
  process 1's, … (:attr:`PetscSolver.split`).

The backend tells them apart by counting the non-empty rows over the processes (at each new
pattern, collectively): ``n`` on every process is whole, ``n`` in total is split, anything
else is refused (:class:`~.petsc_rows.PetscRows`, shared with :mod:`.petsc_gamg`).
Right-hand sides and solutions are replicated vectors in the caller's numbering: each
process sets the entries of its own rows, and the solution is gathered on every process
(:meth:`Scatter.toAll`) and mapped back: the loop above the solver stays replicated
(docs/parallel.md).

The solve is ``KSPPREONLY`` with a MUMPS factorization: Cholesky with the matrix flagged
symmetric positive definite (MUMPS ``SYM = 1``) for a symmetric request, LU otherwise
(Coulomb's non-symmetric systems). One PETSc matrix, its :class:`KSP` and its factor are kept
per pattern: a refactorization only rewrites the values (:meth:`Mat.setValuesCSR` into the
existing nonzero structure), so PETSc keeps MUMPS's symbolic analysis, as PARDISO's phase 11
is kept (:mod:`.solvers`). With an ordering (:attr:`~.solvers.SPDSolver.ordering`) PETSc's
numbering follows it (within each process's rows, when split), and an LU on one process
hands it to MUMPS (``ICNTL(7) = 1``): PETSc passes its natural ordering to MUMPS's LU as
``PERM_IN``, but ignores any ordering for MUMPS's Cholesky.

Each LU solve does :data:`REFINEMENT_STEPS` steps of iterative refinement inside MUMPS. A failed
Cholesky factorization (negative pivots counted by MUMPS, ``INFOG(12)``) names the first
non-positive diagonal entry as its equation, where there is one.

MUMPS's Cholesky orders by AMD (``ICNTL(7) = 0``: its analysis is MUMPS's own at every new
pattern, and METIS's took six times as long), unless PETSc's options database sets
``-mat_mumps_icntl_7``; the contact layer's ordering (:attr:`SolverRequest.ordering`, METIS on
the vertex graph) is computed for an LU on one process only (:func:`petsc_solver`).
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager

import numpy as np
import scipy.sparse as sp

from ..errors import BackendUnavailableError, FactorizationError
from ..ranks import world_ranks
from ..sparse import in_node_blocks
from .mkl import mkl_threads_local
from .petsc_import import _MUMPS_BLAS, petsc_library, petsc_module
from .petsc_rows import PetscRows, row_block
from .solvers import SolverRequest

__all__ = [
    "GAMG_FROM_3D",
    "MUMPS_ORDERING",
    "PetscLUSolver",
    "PetscSolver",
    "petsc_library",
    "petsc_module",
    "petsc_solver",
    "row_block",
]

#: Steps of iterative refinement MUMPS does in each LU solve (``ICNTL(10) = -2``): without
#: them an LU solve of a non-symmetric system left a relative residual of 1.7e-12, with them
#: below 1e-12 as PARDISO (tests/algebra/backends/test_lu_solvers.py). The Cholesky solves go
#: without: refinement made MUMPS keep the matrix and took 1.6 x the refactorization and 6 x
#: the solve at 132 000 unknowns, for no gain on the symmetric positive definite systems.
REFINEMENT_STEPS = 2

#: MUMPS's ordering for its Cholesky's analysis (``ICNTL(7)``), which PETSc does not hand an
#: ordering: AMD, unless PETSc's options database sets ``-mat_mumps_icntl_7``. A new pattern
#: comes at every level, and MUMPS orders it itself. At 10⁶ unknowns METIS's ordering took
#: 4.4 s of MUMPS's 4.5 s analysis, AMD's 0.7 s, for a factor 10 % larger and a factorization
#: 0.3 s slower; the adaptive loop to 10⁶ unknowns took 35–44 s with AMD against 75 s with
#: METIS on one rank, 43 s against 55 s on two (docs/parallel.md, *MUMPS's ordering*).
MUMPS_ORDERING = 0

#: From this many unknowns on, the backend solves a symmetric 3D system by CG + GAMG instead
#: of MUMPS's Cholesky: measured on the 3D cantilever, GAMG 0.86 s and 52 MB against MUMPS's
#: 1.06 s and 157 MB at 1.5·10⁴ unknowns, 4.7 s and 162 MB against 9.6 s and 724 MB at
#: 4.7·10⁴ (docs/parallel.md, *Three dimensions on PETSc*).
GAMG_FROM_3D = 20_000


@contextmanager
def _one_mkl_thread() -> Iterator[None]:
    """MKL on one thread in the calling thread while MUMPS runs, where MUMPS calls MKL's BLAS:
    ranks sharing a machine do not oversubscribe its cores, and a second thread did not make
    MUMPS's factorization faster (docs/parallel.md, *MUMPS's BLAS*). Thread-local, so PARDISO's
    threads elsewhere keep MKL's setting."""
    if not _MUMPS_BLAS["mkl"]:
        yield
        return
    previous = mkl_threads_local(1)
    try:
        yield
    finally:
        mkl_threads_local(previous)


class PetscSolver(PetscRows):
    """Sparse Cholesky (or LU) by MUMPS through PETSc, the analysis kept per pattern.

    Parameters
    ----------
    A : scipy sparse matrix, shape (n, n), optional
        Factorized right away if given; every process passes the same matrix.
    check_symmetry : bool
        As in :class:`~.solvers.SPDSolver`.
    ordering : (n,) int array, optional
        PETSc's numbering follows it (within each process's rows of a split matrix); an LU
        on one process hands it to MUMPS, a Cholesky orders by AMD regardless.

    Attributes
    ----------
    factorization : str
        ``"cholesky"`` or ``"lu"``.
    split : bool
        Whether the last analysed matrix was split by rows over the processes (else whole
        on every process).
    comm_size : int
        Processes of ``PETSC_COMM_WORLD`` sharing the matrix's rows.

    Raises
    ------
    BackendUnavailableError
        If petsc4py or MUMPS is missing (:func:`petsc_module`).
    """

    backend = "petsc"
    reuses_analysis = True
    factorization = "cholesky"

    def __init__(
        self,
        A: sp.spmatrix | None = None,
        *,
        check_symmetry: bool = True,
        ordering: np.ndarray | None = None,
    ) -> None:
        self._ksp = self._x = self._b = self._scatter = self._all = None
        self.block_size = 1  # 2: MUMPS's last analysis compressed 2 x 2 blocks (ICNTL(15))
        super().__init__(A, check_symmetry=check_symmetry, ordering=ordering)

    def _analyze(self, A: sp.csr_matrix, rows: np.ndarray) -> None:
        PETSc = self._PETSc
        self._release()
        n = A.shape[0]
        own = self._rows(A)
        m = own.size
        indptr, indices = self._csr
        # every rank's rows in 2 x 2 node blocks: MUMPS's Cholesky analyses the node graph
        in_blocks = self._ranks.max(0.0 if in_node_blocks(indptr, indices) else 1.0) == 0.0
        values = np.zeros(indices.size)
        mat = PETSc.Mat().createAIJ(
            size=((m, n), (m, n)), csr=(indptr, indices, values), comm=PETSc.COMM_WORLD
        )
        mat.assemble()
        mat.setOption(PETSc.Mat.Option.NEW_NONZERO_LOCATION_ERR, True)
        if self.factorization == "cholesky":
            mat.setOption(PETSc.Mat.Option.SPD, True)
        ksp = PETSc.KSP().create(comm=PETSc.COMM_WORLD)
        ksp.setType(PETSc.KSP.Type.PREONLY)
        ksp.setErrorIfNotConverged(False)
        pc = ksp.getPC()
        pc.setType(self.factorization)
        pc.setFactorSolverType("mumps")
        # PETSc's numbering follows the ordering; PETSc hands its natural ordering to MUMPS
        # as PERM_IN (ICNTL(7) = 1) for an LU on one process (it ignores it for Cholesky)
        natural = self.factorization == "lu" and self._perm is not None and self.comm_size == 1
        if natural:
            pc.setFactorOrdering("natural")
        ksp.setOperators(mat)
        pc.setFactorSetUpSolverType()
        factor = pc.getFactorMatrix()
        # the user's -mat_mumps_icntl_7, if any, else AMD (MUMPS_ORDERING)
        if not natural and not PETSc.Options().hasName("mat_mumps_icntl_7"):
            factor.setMumpsIcntl(7, MUMPS_ORDERING)
        if self.factorization == "lu":
            factor.setMumpsIcntl(10, -REFINEMENT_STEPS)
        elif in_blocks:  # the graph compressed to 2 x 2 blocks (docs/method.md, *Block Cholesky*)
            factor.setMumpsIcntl(15, -2)
        self.block_size = 2 if self.factorization == "cholesky" and in_blocks else 1
        self._mat, self._ksp = mat, ksp
        self._x, self._b = mat.createVecs()
        self._scatter, self._all = PETSc.Scatter.toAll(self._x)

    def _factorize(self, A: sp.csr_matrix, keep: np.ndarray | None) -> None:
        self._write_values(A, keep)
        failure = "MUMPS could not factorize the matrix (PETSc error {ierr}): it is singular"
        with _one_mkl_thread():
            self._set_up(failure)
        pc = self._ksp.getPC()
        factor = pc.getFactorMatrix()
        status = int(factor.getMumpsInfog(1))
        failed = getattr(pc, "getFailedReason", lambda: 0)()  # petsc4py >= 3.19
        if status < 0 or int(failed) != 0:
            raise FactorizationError(
                f"MUMPS could not factorize the matrix (INFOG(1) = {status}): it is singular",
                backend=self.backend,
                code=status,
            )
        if self.factorization == "cholesky":
            negative = int(factor.getMumpsInfog(12))
            if negative:
                equation = self._nonpositive_diagonal(A, keep)
                where = "" if equation is None else f"; diagonal entry {equation} is not positive"
                raise FactorizationError(
                    f"the matrix is not positive definite: MUMPS met {negative} negative "
                    f"pivot(s){where}",
                    backend=self.backend,
                    equation=equation,
                )

    def _nonpositive_diagonal(self, A: sp.csr_matrix, keep: np.ndarray | None) -> int | None:
        """The first row whose diagonal entry (of ``A`` with the entries off ``keep``
        zeroed) is not positive, or None: where a Cholesky factorization that reached it
        would stop (MUMPS counts negative pivots but does not say where)."""
        data = A.data if keep is None else A.data * keep
        diagonal = sp.csr_matrix((data, A.indices, A.indptr), shape=A.shape).diagonal()
        if self.split:  # this rank's rows, then the first over the ranks
            bad = self._ranks.gather(self._own[diagonal[self._own] <= 0])
            return int(bad.min()) if bad.size else None
        bad = np.flatnonzero(diagonal <= 0)
        return int(bad[0]) if bad.size else None

    def _solve(self, b: np.ndarray) -> np.ndarray:
        columns = b.reshape(b.shape[0], -1)
        x = np.empty_like(columns)
        for j in range(columns.shape[1]):  # a handful of right-hand sides
            self._b.setArray(self._local_entries(columns[:, j]))  # in PETSc's order
            with _one_mkl_thread():
                self._ksp.solve(self._b, self._x)
            reason = int(self._ksp.getConvergedReason())
            if reason < 0:
                raise FactorizationError(
                    f"the MUMPS solve failed (KSP converged reason {reason})",
                    backend=self.backend,
                )
            self._scatter.scatter(self._x, self._all)
            self._caller_order(self._all.getArray(), x[:, j])
        return x.reshape(b.shape)

    def _release(self) -> None:
        for obj in (self._ksp, self._mat, self._x, self._b, self._scatter, self._all):
            if obj is not None:
                obj.destroy()
        self._mat = self._ksp = self._x = self._b = self._scatter = self._all = None

    def close(self) -> None:
        self._release()
        super().close()


class PetscLUSolver(PetscSolver):
    """LU factorization of a general sparse matrix by MUMPS through PETSc (Coulomb's
    non-symmetric systems); as :class:`PetscSolver`, the symmetry not checked.

    Parameters
    ----------
    A : scipy sparse matrix, optional
    ordering : (n,) int array, optional
    """

    factorization = "lu"

    def __init__(self, A: sp.spmatrix | None = None, *, ordering: np.ndarray | None = None) -> None:
        super().__init__(A, check_symmetry=False, ordering=ordering)


def petsc_solver(request: SolverRequest) -> PetscRows:
    """The PETSc backend's solver factory (:class:`~.solvers.SolverFactory`):
    :class:`PetscSolver` (MUMPS Cholesky, ordered by METIS on the matrix) for a symmetric
    request, :class:`PetscLUSolver` otherwise, given the request's ordering on one process
    (docs/parallel.md, *Measurements*: MUMPS's LU with it against its own METIS). A symmetric
    3D request of :data:`GAMG_FROM_3D` unknowns or more gets CG + GAMG instead
    (:func:`~.petsc_gamg.petsc_gamg_solver`): a direct factor of 3D elasticity grows like
    N^1.4 and does not fit at 10⁶ unknowns (docs/parallel.md, *Three dimensions on PETSc*).

    Raises
    ------
    BackendUnavailableError
        If petsc4py or MUMPS is missing, naming the extra that brings them.
    """
    if request.multigrid_from(GAMG_FROM_3D):
        from .petsc_gamg import petsc_gamg_solver  # (which builds on this module's LU)

        return petsc_gamg_solver(request)
    if request.symmetric:
        return PetscSolver(check_symmetry=request.check_symmetry)
    return PetscLUSolver(ordering=_lu_ordering(request))


def _lu_ordering(request: SolverRequest) -> np.ndarray | None:
    """The request's ordering where MUMPS can take it (an LU on one process), else None;
    None also where it cannot be computed here (the vertex graph's METIS needs MKL)."""
    if request.ordering is None or petsc_module().COMM_WORLD.getSize() > 1:
        return None
    try:
        return request.ordering()
    except BackendUnavailableError:
        return None


#: The ranks the backend's matrices are split over (:func:`~.ranks.solver_ranks`).
petsc_solver.ranks = world_ranks  # type: ignore[attr-defined]
