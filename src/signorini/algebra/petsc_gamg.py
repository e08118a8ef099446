"""CG preconditioned by PETSc's GAMG as a solver backend (the ``"petsc-gamg"`` backend).

An iterative solver for the symmetric positive definite systems of the active set methods
(the frictionless and Tresca systems): PETSc's conjugate gradients (``KSPCG``) with the
smoothed-aggregation algebraic multigrid ``PCGAMG``, on ``PETSC_COMM_WORLD`` (serial or under
``mpiexec``, the rows split as by the ``"petsc"`` backend, :func:`~.petsc.row_block`). It
needs the optional extra ``signorini[mpi]`` and is imported only when asked for.

**The near-nullspace.** Smoothed aggregation builds its coarse spaces from the modes the
matrix nearly annihilates; for elasticity these are the rigid motions of each body, two
translations and a rotation in 2D. The systems are written in node frames at the contact and
roller nodes and, with two bodies, in the basis of the relative displacement
(docs/method.md, *Two bodies*), so the motions must be written in those unknowns too: the
contact layer computes them (:func:`signorini.contact.rigid_modes.system_rigid_modes`) and
hands them over as :attr:`~.solvers.SolverRequest.rigid_modes`. Without them GAMG falls back
to the constant vectors of each of the two components. The matrix has block size 2 (a node's
two DOFs aggregate together).

**The eliminated DOFs.** The active set methods impose the Dirichlet and active DOFs by
zeroing their rows and columns in place, the diagonal kept (:mod:`.elimination`): such a
row is decoupled, ``d_i x_i = b_i``. PETSc's graph of the matrix drops the zeroed entries, so
the DOF is its own aggregate-less point; the near-nullspace vectors are zeroed there (the
tentative prolongator then has a zero row for it, and the smoothers solve its diagonal
equation). Measured in ``benchmarks/gamg.py``: the same iteration counts as on the free DOFs'
block alone.

**Inexact solves.** A solve stops at ``‖b − A x‖₂ ≤ rtol ‖b‖₂`` (the true residual:
``KSP_NORM_UNPRECONDITIONED``), or where the residual reaches the round-off of the product,
``eps ‖A‖∞ ‖x‖₂`` (``x`` the previous solution). A solve of the matrix and right-hand side
of the last solve (the confirming solve of :mod:`.inexact`) starts from that solve's
solution; every other from zero. The active set methods read
:attr:`GamgSolver.rtol` and follow the inexact stopping rule of :mod:`.inexact`
(docs/parallel.md, *Inexact active set iterations*). A solve that does not reach its
tolerance in :attr:`GamgSolver.max_it` iterations, or meets an indefinite matrix, raises
:class:`~.solvers.SingularSystemError`.

**Non-symmetric systems** (Coulomb friction) are not for CG: the factory returns the
``"petsc"`` backend's MUMPS LU for them (:class:`~.petsc.PetscLUSolver`), exact to round-off.

PETSc options with the prefix ``signorini_gamg_`` (``-signorini_gamg_pc_gamg_threshold
0.02``, ``-signorini_gamg_ksp_monitor``) reach the KSP and GAMG.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import scipy.sparse as sp

from .petsc import PetscLUSolver, petsc_module, row_block
from .solvers import FactorizationError, SingularSystemError, SolverRequest, SPDSolver
from .sparse import abs_matvec

__all__ = ["GamgSolver", "RTOL", "petsc_gamg_solver"]

#: Relative residual ``‖b − A x‖₂ / ‖b‖₂`` of the solves of an active set iteration. The
#: final active set is confirmed by a solve to :data:`~.inexact.CONFIRM_RTOL` (:mod:`.inexact`).
RTOL = 1e-8

#: Largest number of CG iterations of one solve (measured: 30 to 60 on Example 6.2 up to
#: 3·10⁵ unknowns, docs/parallel.md).
MAX_IT = 1000

EPS = float(np.finfo(np.float64).eps)

#: Prefix of the PETSc options database entries that reach this backend's KSP and PC.
OPTIONS_PREFIX = "signorini_gamg_"


class GamgSolver(SPDSolver):
    """CG + GAMG with the rigid-body near-nullspace, for SPD matrices with a fixed pattern.

    :meth:`factorize` sets GAMG up (its aggregation, prolongators and coarse matrices: the
    analogue of a factorization; done again only when the values change), :meth:`solve`
    runs CG to :attr:`rtol`. The PETSc matrix is kept per pattern: a new active set only
    rewrites its values.

    Parameters
    ----------
    A : scipy sparse matrix, shape (n, n), optional
        Set up right away if given; every process passes the same matrix.
    check_symmetry : bool
        As in :class:`~.solvers.SPDSolver`.
    ordering : (n,) int array, optional
        Accepted for the interface and checked; not used.
    near_nullspace : callable () -> (n, k) float array, optional
        The rigid motions in the system's unknowns (:attr:`SolverRequest.rigid_modes`),
        called at each analysis. Default: GAMG's own (constant vectors).
    rtol : float
        The relative residual of a solve; :data:`RTOL`.
    max_it : int
        Largest number of CG iterations per solve; :data:`MAX_IT`.

    Attributes
    ----------
    iterations : list of int
        CG iterations of every solve (one entry per right-hand side), in order.
    comm_size : int
        Processes of ``PETSC_COMM_WORLD``.

    Raises
    ------
    BackendUnavailableError
        If petsc4py is missing (:func:`~.petsc.petsc_module`).
    ValueError
        If ``rtol`` is not in (0, 1) or ``max_it`` not a positive integer.
    """

    backend = "petsc-gamg"
    reuses_analysis = True

    def __init__(
        self,
        A: sp.spmatrix | None = None,
        *,
        check_symmetry: bool = True,
        ordering: np.ndarray | None = None,
        near_nullspace: Callable[[], np.ndarray] | None = None,
        rtol: float = RTOL,
        max_it: int = MAX_IT,
    ) -> None:
        if not (isinstance(rtol, (int, float)) and 0 < rtol < 1):
            raise ValueError(f"rtol must be a number in (0, 1), got {rtol!r}")
        if isinstance(max_it, bool) or not isinstance(max_it, (int, np.integer)) or max_it < 1:
            raise ValueError(f"max_it must be a positive integer, got {max_it!r}")
        self._PETSc = petsc_module()
        comm = self._PETSc.COMM_WORLD
        self.comm_size = comm.getSize()
        self._rank = comm.getRank()
        self.near_nullspace = near_nullspace
        self.rtol = float(rtol)
        self.max_it = int(max_it)
        self.iterations: list[int] = []
        self._mat = self._ksp = self._x = self._b = self._scatter = self._all = None
        self._modes: np.ndarray | None = None
        self._keep: np.ndarray | None = None
        self._data: np.ndarray | None = None
        self._norm = self._x_norm = 0.0
        self._last: tuple[np.ndarray, np.ndarray] | None = None  # the last solve's b and x
        super().__init__(A, check_symmetry=check_symmetry, ordering=ordering)

    def _analyze(self, A: sp.csr_matrix, rows: np.ndarray) -> None:
        PETSc = self._PETSc
        self._release()
        n = A.shape[0]
        # whole nodes (2 × 2 blocks) on every process
        block = _even_block if n % 2 == 0 else row_block
        lo, hi = self._rows = block(n, self._rank, self.comm_size)
        first, last = A.indptr[lo], A.indptr[hi]
        int_type = PETSc.IntType
        self._csr = (
            (A.indptr[lo : hi + 1] - first).astype(int_type),
            A.indices[first:last].astype(int_type),
        )
        self._slice = (first, last)
        mat = PETSc.Mat().createAIJ(
            size=((hi - lo, n), (hi - lo, n)),
            bsize=2 if n % 2 == 0 else 1,
            csr=(*self._csr, np.zeros(last - first)),
            comm=PETSc.COMM_WORLD,
        )
        mat.assemble()
        mat.setOption(PETSc.Mat.Option.NEW_NONZERO_LOCATION_ERR, True)
        mat.setOption(PETSc.Mat.Option.SPD, True)
        ksp = PETSc.KSP().create(comm=PETSc.COMM_WORLD)
        ksp.setOptionsPrefix(OPTIONS_PREFIX)
        ksp.setType(PETSc.KSP.Type.CG)
        ksp.setNormType(PETSc.KSP.NormType.UNPRECONDITIONED)
        ksp.getPC().setType(PETSc.PC.Type.GAMG)
        ksp.setErrorIfNotConverged(False)
        ksp.setFromOptions()
        self._mat, self._ksp = mat, ksp
        self._x, self._b = mat.createVecs()
        self._scatter, self._all = PETSc.Scatter.toAll(self._x)
        # ‖A‖∞ ≤ ‖K‖∞ for every eliminated matrix of the pattern: the round-off floor's
        self._norm = float(abs_matvec(A, np.ones(n)).max(initial=0.0))
        self._modes = None
        if self.near_nullspace is not None:
            modes = np.asarray(self.near_nullspace(), dtype=np.float64)
            if modes.ndim != 2 or modes.shape[0] != n or not np.isfinite(modes).all():
                raise ValueError(
                    f"near_nullspace must give a finite ({n}, k) array, got shape {modes.shape}"
                )
            self._modes = modes
        self._keep = None

    def _factorize(self, A: sp.csr_matrix, keep: np.ndarray | None) -> None:
        PETSc = self._PETSc
        if self._keep is not None and keep is not None and np.array_equal(keep, self._keep):
            if A.data is self._data:
                return  # the same matrix: GAMG's set-up stands
        first, last = self._slice
        data = A.data[first:last] if keep is None else A.data[first:last] * keep[first:last]
        self._mat.setValuesCSR(*self._csr, np.ascontiguousarray(data, dtype=np.float64))
        self._mat.assemble()
        if self._modes is not None:
            self._set_near_nullspace(A, keep)
        self._ksp.setOperators(self._mat)
        try:
            self._ksp.setUp()
        except PETSc.Error as err:
            raise FactorizationError(
                f"GAMG could not be set up for the matrix (PETSc error {err.ierr})",
                backend=self.backend,
                code=int(err.ierr),
            ) from err
        self._keep = None if keep is None else keep.copy()
        self._data = A.data
        self._last = None  # a new matrix: no solution to start from

    def _set_near_nullspace(self, A: sp.csr_matrix, keep: np.ndarray | None) -> None:
        """The rigid motions, zero on the eliminated DOFs (rows that keep only their
        diagonal), orthonormalized, as the matrix's near-nullspace."""
        PETSc = self._PETSc
        modes = self._modes
        if keep is not None:
            kept = np.diff(np.concatenate([[0], np.cumsum(keep)])[A.indptr])
            modes = np.where((kept <= 1)[:, None], 0.0, modes)
        q, r = np.linalg.qr(modes)
        q = q[:, np.abs(np.diag(r)) > 1e-12 * max(np.abs(np.diag(r)).max(initial=0.0), 1e-300)]
        lo, hi = self._rows
        vectors = []
        for k in range(q.shape[1]):  # the rigid motions: six at most
            v = self._mat.createVecLeft()
            v.setArray(np.ascontiguousarray(q[lo:hi, k]))
            vectors.append(v)
        space = PETSc.NullSpace().create(vectors=vectors, comm=PETSc.COMM_WORLD)
        self._mat.setNearNullSpace(space)
        space.destroy()
        for v in vectors:
            v.destroy()

    def _solve(self, b: np.ndarray) -> np.ndarray:
        lo, hi = self._rows
        columns = b.reshape(b.shape[0], -1)
        x = np.empty_like(columns)
        # the round-off floor: a residual at eps ‖A‖∞ ‖x‖₂ (x the last solution) is as
        # small as the product A x can tell
        atol = EPS * self._norm * self._x_norm
        self._ksp.setTolerances(rtol=self.rtol, atol=atol, max_it=self.max_it)
        for j in range(columns.shape[1]):  # a handful of right-hand sides
            self._b.setArray(np.ascontiguousarray(columns[lo:hi, j]))
            # the same system again (a confirming solve, .inexact): from its last solution
            again = self._last is not None and np.array_equal(columns[:, j], self._last[0])
            if again:
                self._x.setArray(np.ascontiguousarray(self._last[1][lo:hi]))
            else:
                self._x.set(0.0)
            self._ksp.setInitialGuessNonzero(again)
            self._ksp.solve(self._b, self._x)
            reason = int(self._ksp.getConvergedReason())
            its = int(self._ksp.getIterationNumber())
            self.iterations.append(its)
            if reason < 0:
                relative = self._ksp.getResidualNorm() / max(self._b.norm(), 1e-300)
                raise SingularSystemError(
                    f"CG + GAMG did not reach the relative residual {self.rtol:.0e} "
                    f"(KSP converged reason {reason} after {its} iterations, relative "
                    f"residual {relative:.1e}): the matrix is singular, indefinite or too "
                    "ill-conditioned for this preconditioner (the 'petsc' backend's MUMPS "
                    "solves such systems directly)",
                    backend=self.backend,
                    residual=float(relative),
                )
            self._scatter.scatter(self._x, self._all)
            x[:, j] = self._all.getArray()
            self._x_norm = float(np.linalg.norm(x[:, j]))
            self._last = (columns[:, j].copy(), x[:, j].copy())
        return x.reshape(b.shape)

    def _release(self) -> None:
        for obj in (self._ksp, self._mat, self._x, self._b, self._scatter, self._all):
            if obj is not None:
                obj.destroy()
        self._mat = self._ksp = self._x = self._b = self._scatter = self._all = None
        self._keep = self._last = None

    def close(self) -> None:
        self._release()
        super().close()


def _even_block(n: int, rank: int, size: int) -> tuple[int, int]:
    """:func:`~.petsc.row_block` of the ``n // 2`` nodes, in DOFs: every process owns whole
    2 × 2 node blocks (PETSc's block size 2)."""
    lo, hi = row_block(n // 2, rank, size)
    return 2 * lo, 2 * hi


def petsc_gamg_solver(request: SolverRequest) -> SPDSolver:
    """The ``"petsc-gamg"`` backend's solver factory (:class:`~.solvers.SolverFactory`):
    :class:`GamgSolver` with the request's rigid motions as near-nullspace for a symmetric
    request; MUMPS LU (:class:`~.petsc.PetscLUSolver`, exact) for a non-symmetric one, which
    CG cannot solve. The request's ordering is not computed.

    Raises
    ------
    BackendUnavailableError
        If petsc4py is missing, naming the extra that brings it.
    """
    if request.symmetric:
        return GamgSolver(
            check_symmetry=request.check_symmetry,
            near_nullspace=getattr(request, "rigid_modes", None),
        )
    return PetscLUSolver()
