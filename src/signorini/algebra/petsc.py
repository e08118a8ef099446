"""PETSc with MUMPS as a solver backend, serial or under ``mpiexec`` (the ``"petsc"`` backend).

The optional extra ``signorini[mpi]`` brings PETSc, petsc4py, MPICH and MUMPS as binary wheels
(docs/parallel.md, *Install*); any other petsc4py whose PETSc has MUMPS serves as well (a
source or Debian build). Nothing here is imported unless the backend is asked for: the
default install stays PETSc-free.

The matrix is a PETSc AIJ matrix on ``PETSC_COMM_WORLD`` (``seqaij`` on one process,
``mpiaij`` on several) with the rows split in contiguous blocks as PETSc splits them
(:func:`row_block`); every process passes the same scipy matrix and hands PETSc its own rows
only. The solve is ``KSPPREONLY`` with a MUMPS factorization: Cholesky with the matrix flagged
symmetric positive definite (MUMPS ``SYM = 1``) for a symmetric request, LU otherwise
(Coulomb's non-symmetric systems). One PETSc matrix, its :class:`KSP` and its factor are kept
per pattern: a refactorization only rewrites the values (:meth:`Mat.setValuesCSR` into the
existing nonzero structure), so PETSc keeps MUMPS's symbolic analysis, as PARDISO's phase 11
is kept (:mod:`.solvers`). The solution is gathered on every process
(:meth:`Scatter.toAll`): the loop above the solver stays replicated (docs/parallel.md).

Each LU solve does :data:`REFINEMENT_STEPS` steps of iterative refinement inside MUMPS. A failed
Cholesky factorization (negative pivots counted by MUMPS, ``INFOG(12)``) names the first
non-positive diagonal entry as its equation, where there is one.

MUMPS orders by METIS nested dissection (``ICNTL(7) = 5``) where PETSc has METIS, else by its
own choice; the contact layer's ordering (:attr:`SolverRequest.ordering`) is not computed for
it.
"""

from __future__ import annotations

from functools import cache
from typing import Any

import numpy as np
import scipy.sparse as sp

from .solvers import BackendUnavailableError, FactorizationError, SolverRequest, SPDSolver

__all__ = [
    "PetscLUSolver",
    "PetscSolver",
    "petsc_library",
    "petsc_module",
    "petsc_solver",
    "row_block",
]

#: Steps of iterative refinement MUMPS does in each LU solve (``ICNTL(10) = -2``): without
#: them an LU solve of a non-symmetric system left a relative residual of 1.7e-12, with them
#: below 1e-12 as PARDISO (tests/algebra/test_lu_solvers.py). The Cholesky solves go without:
#: refinement made MUMPS keep the matrix and took 1.6 x the refactorization and 6 x the solve
#: at 132 000 unknowns, for no gain on the symmetric positive definite systems.
REFINEMENT_STEPS = 2

#: How to install the backend, ending the message of a missing petsc4py.
INSTALL_HINT = (
    "install the extra: pip install 'signorini[mpi]' (binary PETSc + MUMPS + MPICH wheels, "
    "Python >= 3.12), or use a petsc4py built with MUMPS (docs/parallel.md, Install)"
)


@cache
def petsc_module() -> Any:
    """``petsc4py.PETSc``, imported once; :class:`BackendUnavailableError` naming the extra
    when petsc4py is missing or its PETSc has no MUMPS."""
    try:
        # The binary wheel's package loads its MPI library before petsc4py (it must come
        # first); other installs of petsc4py do not have it.
        import dolfinx_solver  # noqa: F401
    except ImportError:
        pass
    try:
        from petsc4py import PETSc
    except ImportError as err:
        raise BackendUnavailableError(
            f"the petsc backend needs petsc4py, which is not importable ({err}): {INSTALL_HINT}"
        ) from err
    if not PETSc.Sys.hasExternalPackage("mumps"):
        version = ".".join(map(str, PETSc.Sys.getVersion()))
        raise BackendUnavailableError(
            f"the petsc backend needs MUMPS, and this PETSc ({version}) was built without it: "
            f"{INSTALL_HINT}"
        )
    return PETSc


def petsc_library() -> str:
    """``"PETSc 3.25.5 + MUMPS (2 ranks)"``: the versions and ``PETSC_COMM_WORLD``'s size,
    for a run's manifest; what is missing when the backend is not usable."""
    try:
        PETSc = petsc_module()
    except BackendUnavailableError as err:
        return f"PETSc (not usable: {err})"
    version = ".".join(map(str, PETSc.Sys.getVersion()))
    size = PETSc.COMM_WORLD.getSize()
    return f"PETSc {version} + MUMPS ({size} rank{'s' if size > 1 else ''})"


def row_block(n: int, rank: int, size: int) -> tuple[int, int]:
    """The rows ``[start, end)`` that process ``rank`` of ``size`` owns in an ``n``-row
    matrix: contiguous blocks, the first ``n % size`` one row longer (PETSc's
    ``PetscSplitOwnership``)."""
    base, extra = divmod(n, size)
    start = rank * base + min(rank, extra)
    return start, start + base + (rank < extra)


class PetscSolver(SPDSolver):
    """Sparse Cholesky (or LU) by MUMPS through PETSc, the analysis kept per pattern.

    Parameters
    ----------
    A : scipy sparse matrix, shape (n, n), optional
        Factorized right away if given; every process passes the same matrix.
    check_symmetry : bool
        As in :class:`~.solvers.SPDSolver`.
    ordering : (n,) int array, optional
        Accepted for the interface and checked; MUMPS orders by itself.

    Attributes
    ----------
    factorization : str
        ``"cholesky"`` or ``"lu"``.
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
        self._PETSc = petsc_module()
        comm = self._PETSc.COMM_WORLD
        self.comm_size = comm.getSize()
        self._rank = comm.getRank()
        self._mat = self._ksp = self._x = self._b = self._scatter = self._all = None
        super().__init__(A, check_symmetry=check_symmetry, ordering=ordering)

    def _local(self, A: sp.csr_matrix, data: np.ndarray) -> tuple[np.ndarray, ...]:
        """This process's rows of ``A`` (with values ``data``) as local CSR arrays."""
        lo, hi = self._rows
        first, last = A.indptr[lo], A.indptr[hi]
        int_type = self._PETSc.IntType
        indptr = (A.indptr[lo : hi + 1] - first).astype(int_type)
        return (
            indptr,
            A.indices[first:last].astype(int_type),
            np.ascontiguousarray(data[first:last], dtype=np.float64),
        )

    def _analyze(self, A: sp.csr_matrix, rows: np.ndarray) -> None:
        PETSc = self._PETSc
        self._release()
        n = A.shape[0]
        self._rows = row_block(n, self._rank, self.comm_size)
        m = self._rows[1] - self._rows[0]
        indptr, indices, values = self._local(A, np.zeros(A.nnz))
        self._csr = (indptr, indices)
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
        ksp.setOperators(mat)
        pc.setFactorSetUpSolverType()
        factor = pc.getFactorMatrix()
        if PETSc.Sys.hasExternalPackage("metis"):
            factor.setMumpsIcntl(7, 5)  # METIS nested dissection for the analysis
        if self.factorization == "lu":
            factor.setMumpsIcntl(10, -REFINEMENT_STEPS)
        self._mat, self._ksp = mat, ksp
        self._x, self._b = mat.createVecs()
        self._scatter, self._all = PETSc.Scatter.toAll(self._x)

    def _factorize(self, A: sp.csr_matrix, keep: np.ndarray | None) -> None:
        PETSc = self._PETSc
        data = A.data if keep is None else A.data * keep
        indptr, indices = self._csr
        _, _, values = self._local(A, data)
        self._mat.setValuesCSR(indptr, indices, values)
        self._mat.assemble()
        self._ksp.setOperators(self._mat)
        pc = self._ksp.getPC()
        try:
            self._ksp.setUp()
        except PETSc.Error as err:
            raise FactorizationError(
                f"MUMPS could not factorize the matrix (PETSc error {err.ierr}): it is singular",
                backend=self.backend,
                code=int(err.ierr),
            ) from err
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
                equation = _nonpositive_diagonal(A, data)
                where = "" if equation is None else f"; diagonal entry {equation} is not positive"
                raise FactorizationError(
                    f"the matrix is not positive definite: MUMPS met {negative} negative "
                    f"pivot(s){where}",
                    backend=self.backend,
                    equation=equation,
                )

    def _solve(self, b: np.ndarray) -> np.ndarray:
        lo, hi = self._rows
        columns = b.reshape(b.shape[0], -1)
        x = np.empty_like(columns)
        for j in range(columns.shape[1]):  # a handful of right-hand sides
            self._b.setArray(columns[lo:hi, j])
            self._ksp.solve(self._b, self._x)
            reason = int(self._ksp.getConvergedReason())
            if reason < 0:
                raise FactorizationError(
                    f"the MUMPS solve failed (KSP converged reason {reason})",
                    backend=self.backend,
                )
            self._scatter.scatter(self._x, self._all)
            x[:, j] = self._all.getArray()
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


def _nonpositive_diagonal(A: sp.csr_matrix, data: np.ndarray) -> int | None:
    """The first row whose diagonal entry (of ``A`` with the values ``data``) is not
    positive, or None: where a Cholesky factorization that reached it would stop (MUMPS
    counts negative pivots but does not say where)."""
    diagonal = sp.csr_matrix((data, A.indices, A.indptr), shape=A.shape).diagonal()
    bad = np.flatnonzero(diagonal <= 0)
    return int(bad[0]) if bad.size else None


def petsc_solver(request: SolverRequest) -> PetscSolver:
    """The PETSc backend's solver factory (:class:`~.solvers.SolverFactory`):
    :class:`PetscSolver` (MUMPS Cholesky) for a symmetric request, :class:`PetscLUSolver`
    otherwise. The request's ordering is not computed (MUMPS orders by itself).

    Raises
    ------
    BackendUnavailableError
        If petsc4py or MUMPS is missing, naming the extra that brings them.
    """
    if request.symmetric:
        return PetscSolver(check_symmetry=request.check_symmetry)
    return PetscLUSolver()


def _world_ranks():
    from .ranks import world_ranks

    return world_ranks()


#: The ranks the backend's matrices are split over (:func:`~.ranks.solver_ranks`).
petsc_solver.ranks = _world_ranks  # type: ignore[attr-defined]
