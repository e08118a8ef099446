"""CG preconditioned by PETSc's GAMG as a solver backend (the ``"petsc-gamg"`` backend).

An iterative solver for the symmetric positive definite systems of the active set methods
(the frictionless and Tresca systems): PETSc's conjugate gradients (``KSPCG``) with the
smoothed-aggregation algebraic multigrid ``PCGAMG``, on ``PETSC_COMM_WORLD`` (serial or under
``mpiexec``). It needs the optional extra ``signorini[mpi]`` and is imported only when asked
for.

**The rows.** As the ``"petsc"`` backend (:mod:`.petsc_rows`), a process passes either the
whole matrix (the same on every process: PETSc's rows are split in contiguous blocks of whole
nodes) or its own rows of a matrix split by rows over the processes (the other rows empty:
PETSc's numbering then puts each process's rows together, in increasing order within it).
The factory's ``ranks`` (:func:`~.ranks.solver_ranks`) tells the contact layer to build the
latter. Right-hand sides, solutions and the near-nullspace vectors are replicated arrays in
the caller's numbering, renumbered to PETSc's and back.

**The near-nullspace.** Smoothed aggregation builds its coarse spaces from the modes the
matrix nearly annihilates; for elasticity these are the rigid motions of each body, two
translations and a rotation in 2D, three translations and three rotations in 3D. The
systems are written in node frames at the contact and roller nodes, with two bodies in the
basis of the relative displacement (docs/method.md, *Two bodies*) and on 3D contact faces in
the transformed face basis (docs/method.md, *Three dimensions: contact on faces*), so the
motions must be written in those unknowns too: the contact layer computes them
(:func:`signorini.contact.rigid_modes.system_rigid_modes`) and hands them over as
:attr:`~.solvers.SolverRequest.rigid_modes`. Without them GAMG falls back to the constant
vectors of each component. The matrix has block size ``d`` (the request's
:attr:`~.solvers.SolverRequest.dimension`: a node's ``d`` DOFs aggregate together) where every
process's rows are whole nodes: ``n`` a multiple of ``d``, and with a split matrix each
process's rows runs ``d i, …, d i + d − 1`` (all DOFs of a node on one rank, as
:func:`signorini.contact.partition.partition` makes them); else block size 1.

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
:class:`~.errors.SingularSystemError`.

**Non-symmetric systems** (Coulomb friction) are not for CG: the factory returns the
``"petsc"`` backend's MUMPS LU for them (:class:`~.petsc.PetscLUSolver`), exact to round-off.

PETSc options with the prefix ``signorini_gamg_`` (``-signorini_gamg_pc_gamg_threshold
0.02``, ``-signorini_gamg_ksp_monitor``) reach the KSP and GAMG.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import scipy.sparse as sp

from ..errors import SingularSystemError
from ..ranks import world_ranks
from ..sparse import abs_matvec
from .petsc import PetscLUSolver
from .petsc_rows import PetscRows, row_block
from .solvers import SolverRequest, SPDSolver

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


class GamgSolver(PetscRows):
    """CG + GAMG with the rigid-body near-nullspace, for SPD matrices with a fixed pattern.

    :meth:`factorize` sets GAMG up (its aggregation, prolongators and coarse matrices: the
    analogue of a factorization; done again only when the values change), :meth:`solve`
    runs CG to :attr:`rtol`. The PETSc matrix is kept per pattern: a new active set only
    rewrites its values.

    Parameters
    ----------
    A : scipy sparse matrix, shape (n, n), optional
        Set up right away if given; whole on every process, or split by rows over them.
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
    block_size : int
        DOFs per node (interleaved): 2 in 2D, 3 in 3D.

    Attributes
    ----------
    iterations : list of int
        CG iterations of every solve (one entry per right-hand side), in order.
    comm_size : int
        Processes of ``PETSC_COMM_WORLD``.
    split : bool
        Whether the last analysed matrix was split by rows over the processes.
    matrix_block_size : int
        The block size PETSc read the last analysed matrix in (:attr:`block_size` where
        every process's rows are whole nodes, else 1; 0 before an analysis).
    near_nullspace_size : int
        The vectors of the last near-nullspace GAMG was set up with (0: GAMG's default).

    Raises
    ------
    BackendUnavailableError
        If petsc4py is missing (:func:`~.petsc.petsc_module`).
    ValueError
        If ``rtol`` is not in (0, 1), or ``max_it`` or ``block_size`` not a positive integer.
    """

    backend = "petsc-gamg"
    reuses_analysis = True
    takes_guess = True

    def __init__(
        self,
        A: sp.spmatrix | None = None,
        *,
        check_symmetry: bool = True,
        ordering: np.ndarray | None = None,
        near_nullspace: Callable[[], np.ndarray] | None = None,
        rtol: float = RTOL,
        max_it: int = MAX_IT,
        block_size: int = 2,
    ) -> None:
        if not (isinstance(rtol, (int, float)) and 0 < rtol < 1):
            raise ValueError(f"rtol must be a number in (0, 1), got {rtol!r}")
        for name, value in (("max_it", max_it), ("block_size", block_size)):
            if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
                raise ValueError(f"{name} must be a positive integer, got {value!r}")
        self.block_size = int(block_size)
        self.near_nullspace = near_nullspace
        self.rtol = float(rtol)
        self.max_it = int(max_it)
        self.iterations: list[int] = []
        self.matrix_block_size = self.near_nullspace_size = 0
        self._mat = self._ksp = self._x = self._b = self._scatter = self._all = None
        self._modes: np.ndarray | None = None
        self._keep: np.ndarray | None = None
        self._data: np.ndarray | None = None
        self._norm = self._x_norm = 0.0
        self._last: tuple[np.ndarray, np.ndarray] | None = None  # the last solve's b and x
        self._guess: np.ndarray | None = None  # the next solve's first iterate (start_from)
        super().__init__(A, check_symmetry=check_symmetry, ordering=ordering)

    def _whole_rows(self, n: int) -> tuple[int, int]:
        """A whole matrix's rows of this process: :func:`~.petsc_rows.row_block` of the
        ``n // d`` nodes, in DOFs, for ``n`` a multiple of ``d`` = :attr:`block_size` (whole
        ``d × d`` node blocks, PETSc's block size ``d``)."""
        d = self.block_size
        if n % d:
            return row_block(n, self._rank, self.comm_size)
        lo, hi = row_block(n // d, self._rank, self.comm_size)
        return d * lo, d * hi

    def _row_ordering(self) -> None:
        """None: the rows stay in increasing order within each process (whole nodes; the
        ordering is not used)."""
        return None

    def _analyze(self, A: sp.csr_matrix, rows: np.ndarray) -> None:
        PETSc = self._PETSc
        self._release()
        n = A.shape[0]
        own = self._rows(A)
        m = own.size
        # whole nodes (d × d blocks) on every process
        d = self.block_size
        nodes = m % d == 0 and (self._order is None or _whole_nodes(own, d))
        self.matrix_block_size = d if n % d == 0 and self._everywhere(nodes) else 1
        mat = PETSc.Mat().createAIJ(
            size=((m, n), (m, n)),
            bsize=self.matrix_block_size,
            csr=(*self._csr, np.zeros(self._csr[1].size)),
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
        self._norm = self._ranks.max(float(abs_matvec(A, np.ones(n)).max(initial=0.0)))
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
        same = self._keep is not None and keep is not None and A.data is self._data
        if self._everywhere(same and np.array_equal(keep, self._keep)):
            return  # the same matrix: GAMG's set-up stands
        self._write_values(A, keep)
        if self._modes is not None:
            self._set_near_nullspace(A, keep)
        self._set_up("GAMG could not be set up for the matrix (PETSc error {ierr})")
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
            eliminated = kept <= 1
            if self.split:  # this rank's rows are read here, the others on theirs
                eliminated = np.zeros(A.shape[0], dtype=bool)
                eliminated[self._ranks.gather(self._own[kept[self._own] <= 1])] = True
            modes = np.where(eliminated[:, None], 0.0, modes)
        q, r = np.linalg.qr(modes)
        q = q[:, np.abs(np.diag(r)) > 1e-12 * max(np.abs(np.diag(r)).max(initial=0.0), 1e-300)]
        local = self._local_entries(q)  # this rank's rows, in PETSc's order
        vectors = []
        for k in range(q.shape[1]):  # the rigid motions: six at most
            v = self._mat.createVecLeft()
            v.setArray(np.ascontiguousarray(local[:, k]))
            vectors.append(v)
        self.near_nullspace_size = len(vectors)
        space = PETSc.NullSpace().create(vectors=vectors, comm=PETSc.COMM_WORLD)
        self._mat.setNearNullSpace(space)
        space.destroy()
        for v in vectors:
            v.destroy()

    def near_nullspace_vectors(self) -> np.ndarray:
        """The near-nullspace GAMG was last set up with, gathered on every process in the
        caller's numbering: ``(n, k)``, orthonormal columns (``(n, 0)`` without one).
        Collective."""
        if not self._factorized:
            raise RuntimeError("near_nullspace_vectors() called before a successful factorize()")
        space = self._mat.getNearNullSpace()
        vectors = space.getVecs() if space is not None else []
        out = np.empty((self.n, len(vectors)))
        for k, v in enumerate(vectors):
            self._scatter.scatter(v, self._all)
            self._caller_order(self._all.getArray(), out[:, k])
        return out

    def _solve(self, b: np.ndarray) -> np.ndarray:
        columns = b.reshape(b.shape[0], -1)
        x = np.empty_like(columns)
        guess, self._guess = self._guess, None
        guess = guess if self._everywhere(guess is not None and columns.shape[1] == 1) else None
        # the round-off floor: a residual at eps ‖A‖∞ ‖x‖₂ (x the last solution) is as
        # small as the product A x can tell
        atol = EPS * self._norm * self._x_norm
        self._ksp.setTolerances(rtol=self.rtol, atol=atol, max_it=self.max_it)
        for j in range(columns.shape[1]):  # a handful of right-hand sides
            self._b.setArray(self._local_entries(columns[:, j]))
            # the same system again (a confirming solve, .inexact): from its last solution
            last = self._last
            again = self._everywhere(last is not None and np.array_equal(columns[:, j], last[0]))
            if guess is not None:
                self._x.setArray(self._local_entries(guess))
            elif again:
                self._x.setArray(self._local_entries(last[1]))
            else:
                self._x.set(0.0)
            self._ksp.setInitialGuessNonzero(guess is not None or again)
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
            self._caller_order(self._all.getArray(), x[:, j])
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


def _whole_nodes(own: np.ndarray, d: int) -> bool:
    """Whether the rows ``own`` (in order, ``own.size`` a multiple of ``d``) are whole nodes:
    runs ``d i, d i + 1, …, d i + d − 1``."""
    runs = own.reshape(-1, d)
    return bool((runs[:, 0] % d == 0).all() and (runs == runs[:, :1] + np.arange(d)).all())


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
            block_size=request.dimension,
        )
    return PetscLUSolver()


#: The ranks the backend's matrices are split over (:func:`~.ranks.solver_ranks`): on several,
#: the contact layer hands each rank its own rows.
petsc_gamg_solver.ranks = world_ranks  # type: ignore[attr-defined]
