"""CG preconditioned by pyamg's smoothed aggregation, in the default install (``"amg"``).

The iterative path that needs nothing beyond pip's wheels: conjugate gradients with one
V-cycle of pyamg's smoothed-aggregation AMG (Vaněk, Mandel, Brezina [1]_) per iteration,
for the symmetric positive definite systems of the active set methods: asked for
(``--backend amg``, ``solver="amg"``) or taken by ``"auto"`` for symmetric 3D systems from
:data:`~.selection.AMG_FROM_3D` unknowns (docs/method.md, *Three dimensions: the linear
solver (measured)* and *Three dimensions: solving elasticity*, give the rule by size and
the measurements behind this module's defaults).

**The near-nullspace.** Smoothed aggregation builds its coarse spaces from the modes the
matrix nearly annihilates; for elasticity the rigid motions (2D: three per body, 3D: six),
handed over as an ``(n, k)`` array or as the request's
:attr:`~.solvers.SolverRequest.rigid_modes` (a callable, called at each analysis). Without
them the constant vector of each DOF of a node block (the translations) is taken: in 3D
twice the CG iterations (measured). The matrix is read in ``block_size × block_size`` node
blocks (interleaved DOFs: 2 in 2D, 3 in 3D), so a node's DOFs aggregate together.

**The eliminated DOFs.** The active set methods impose the Dirichlet and active DOFs by
zeroing their rows and columns, the diagonal kept (:mod:`.elimination`, the ``keep`` mask of
:meth:`~.solvers.SPDSolver.factorize`): such a row is decoupled, ``d_i x_i = b_i``. The
modes are zeroed there (as in :mod:`.petsc_gamg`), and the hierarchy is built on the
eliminated matrix. With ``reuse`` a new ``keep`` of the same matrix (the next active set)
keeps the hierarchy of an earlier one, as the preconditioner
``r ↦ P M⁻¹ P r + D⁻¹ (I − P) r`` (P the projection on the current free DOFs, M⁻¹ the
old V-cycle): symmetric positive definite, so CG converges, in more iterations the more the
sets differ (about one more per changed DOF, measured). So the hierarchy is kept only while
the free DOFs differ from those it was built on in at most :data:`REUSE_CHANGED` DOFs, and
rebuilt when a solve takes more than :data:`REBUILD` times the iterations of the first solve
after its set-up; the old hierarchy is released before a new one is built (one in memory at
a time). The ``"amg"`` factory asks for ``reuse``.

**Inexact solves.** A solve stops at ``‖b − A x‖₂ ≤ rtol ‖b‖₂`` (the true residual, checked
at the end; CG restarts from its iterate if the recursive residual drifted), or at the
round-off of the product, ``eps ‖A‖∞ ‖x‖₂``. CG starts from the iterate handed to
:meth:`AmgSolver.start_from` (the active set methods hand over the previous step's solution,
and the first step the prolongated solution of the previous level: docs/method.md, *Three
dimensions: warm-started CG*), else, for the right-hand side of the last solve (the
confirming solve of :mod:`.inexact`), from that solve's solution, else from zero. A solve
that does not get there in :attr:`AmgSolver.max_it` iterations, or meets ``pᵀ A p ≤ 0``,
raises :class:`~.errors.SingularSystemError`.

**Non-symmetric systems** (Coulomb friction) are not for CG: the factory returns SuperLU's
LU (:func:`~.superlu.superlu_solver`) for them.

References
----------
.. [1] P. Vaněk, J. Mandel, M. Brezina, Algebraic multigrid by smoothed aggregation for
   second and fourth order elliptic problems, Computing 56 (1996) 179-196.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import scipy.sparse as sp

from ..errors import BackendUnavailableError, SingularSystemError
from ..sparse import abs_matvec
from .solvers import SolverRequest, SPDSolver
from .superlu import superlu_solver

__all__ = ["REBUILD", "REUSE_CHANGED", "RTOL", "AmgSolver", "amg_solver"]

#: Relative residual ``‖b − A x‖₂ / ‖b‖₂`` of a solve (the active set iterations'; the
#: confirming solve's is :data:`~.inexact.CONFIRM_RTOL`).
RTOL = 1e-8

#: Largest number of CG iterations of one solve (measured 28–80 on the 3D cube, uniform and
#: graded, ν ≤ 0.45, docs/method.md).
MAX_IT = 1000

#: A reused hierarchy is rebuilt when a solve takes more than this many times the iterations
#: of the first solve after its set-up.
REBUILD = 1.5

#: A reused hierarchy is kept for a new ``keep`` whose free DOFs differ from the hierarchy's
#: in at most this many DOFs (each changed DOF adds about one CG iteration; a set-up costs
#: 15–25: docs/method.md, *Three dimensions: warm-started CG*).
REUSE_CHANGED = 8

#: Restarts of CG from its iterate when the true residual misses the tolerance.
RESTARTS = 3

EPS = float(np.finfo(np.float64).eps)

Modes = np.ndarray | Callable[[], np.ndarray]


def _pyamg():  # noqa: ANN202 (a module)
    """pyamg, imported when a solver is made; :class:`BackendUnavailableError` if missing."""
    try:
        import pyamg
    except ImportError as error:  # pragma: no cover - a default dependency
        raise BackendUnavailableError(
            f"the 'amg' backend needs pyamg (a default dependency: pip install pyamg): {error}"
        ) from None
    return pyamg


class AmgSolver(SPDSolver):
    """CG + smoothed-aggregation AMG (pyamg) with a near-nullspace, for SPD matrices.

    :meth:`factorize` builds the AMG hierarchy (the analogue of a factorization; kept for the
    same matrix and ``keep``, and with ``reuse`` for a new ``keep``), :meth:`solve` runs CG
    to :attr:`rtol`.

    Parameters
    ----------
    A : scipy sparse matrix, shape (n, n), optional
        Set up right away if given.
    check_symmetry : bool
        As in :class:`~.solvers.SPDSolver`.
    ordering : (n,) int array, optional
        Accepted for the interface and checked; not used.
    near_nullspace : (n, k) float array or callable () -> (n, k) array, optional
        The rigid motions in the system's unknowns; checked at each analysis. Default: the
        ``block_size`` translations.
    block_size : int
        DOFs per node (interleaved), 2 by default; 1 where ``n`` is not a multiple.
    rtol : float
        The relative residual of a solve, in (0, 1); :data:`RTOL`.
    max_it : int
        Largest number of CG iterations per solve; :data:`MAX_IT`.
    reuse : bool
        Keep the hierarchy across new ``keep`` masks of the same matrix (module docstring).

    Attributes
    ----------
    iterations : list of int
        CG iterations of every solve (one entry per right-hand side), in order.
    n_setups : int
        AMG hierarchies built.
    operator_complexity : float
        Σ nnz of the levels' matrices over nnz of the finest, of the last hierarchy.

    Raises
    ------
    ValueError
        For an ``rtol``, ``max_it`` or ``block_size`` out of range.
    """

    backend = "amg"
    reuses_analysis = True
    takes_guess = True

    def __init__(
        self,
        A: sp.spmatrix | None = None,
        *,
        check_symmetry: bool = True,
        ordering: np.ndarray | None = None,
        near_nullspace: Modes | None = None,
        block_size: int = 2,
        rtol: float = RTOL,
        max_it: int = MAX_IT,
        reuse: bool = False,
    ) -> None:
        if not (isinstance(rtol, (int, float)) and 0 < rtol < 1):
            raise ValueError(f"rtol must be a number in (0, 1), got {rtol!r}")
        for name, value in (("max_it", max_it), ("block_size", block_size)):
            if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
                raise ValueError(f"{name} must be a positive integer, got {value!r}")
        self._pyamg = _pyamg()
        self.near_nullspace = near_nullspace
        self.block_size = int(block_size)
        self.rtol = float(rtol)
        self.max_it = int(max_it)
        self.reuse = bool(reuse)
        self.iterations: list[int] = []
        self.n_setups = 0
        self.operator_complexity = np.nan
        self._modes: np.ndarray | None = None
        self._cycle: Callable[[np.ndarray], np.ndarray] | None = None
        self._hierarchy_free: np.ndarray | None = None  # free DOFs the hierarchy was built on
        self._first_its = 0  # CG iterations of the first solve after the last set-up
        self._free: np.ndarray | None = None
        self._inverse_diagonal = np.zeros(0)
        self._system: sp.csr_matrix | None = None
        self._keep: np.ndarray | None = None
        self._data: np.ndarray | None = None
        self._norm = self._x_norm = 0.0
        self._last: tuple[np.ndarray, np.ndarray] | None = None
        self._guess: np.ndarray | None = None  # the next solve's initial iterate
        super().__init__(A, check_symmetry=check_symmetry, ordering=ordering)

    def _analyze(self, A: sp.csr_matrix, rows: np.ndarray) -> None:
        n = A.shape[0]
        self._norm = float(abs_matvec(A, np.ones(n)).max(initial=0.0))
        modes = self.near_nullspace
        if callable(modes):
            modes = modes()
        if modes is not None:
            modes = np.asarray(modes, dtype=np.float64)
            if modes.ndim != 2 or modes.shape[0] != n or modes.shape[1] == 0:
                raise ValueError(
                    f"near_nullspace must be an ({n}, k) array with k >= 1, got shape {modes.shape}"
                )
            if not np.isfinite(modes).all():
                raise ValueError("near_nullspace has non-finite (NaN or inf) entries")
        self._modes = modes
        self._keep = self._data = self._cycle = self._hierarchy_free = None
        self._last = None

    def _factorize(self, A: sp.csr_matrix, keep: np.ndarray | None) -> None:
        same_values = A.data is self._data
        if same_values and _same_mask(keep, self._keep):
            return  # the same matrix: the hierarchy stands
        system = A if keep is None else sp.csr_matrix((A.data * keep, A.indices, A.indptr), A.shape)
        counted = np.arange(A.nnz + 1) if keep is None else np.concatenate([[0], np.cumsum(keep)])
        kept = np.diff(counted[A.indptr])
        free = kept > 1  # an eliminated row keeps only its diagonal
        diagonal = system.diagonal()
        if (diagonal <= 0).any() or not np.isfinite(diagonal).all():
            raise SingularSystemError(
                "the matrix has a non-positive diagonal entry: not positive definite",
                backend=self.backend,
            )
        self._system, self._free = system, free
        self._inverse_diagonal = np.where(free, 0.0, 1 / diagonal)
        if not (self.reuse and same_values and self._close_to_hierarchy(free)):
            self._set_up(system, free)
        self._keep = None if keep is None else keep.copy()
        self._data = A.data
        self._last = None

    def _close_to_hierarchy(self, free: np.ndarray) -> bool:
        """Whether the hierarchy was built on free DOFs that differ from ``free`` in at most
        :data:`REUSE_CHANGED` DOFs."""
        if self._cycle is None:
            return False
        return int(np.count_nonzero(free != self._hierarchy_free)) <= REUSE_CHANGED

    def _set_up(self, system: sp.csr_matrix, free: np.ndarray) -> None:
        """Build the hierarchy of ``system`` (its free DOFs ``free``)."""
        pyamg = self._pyamg
        n = system.shape[0]
        size = self.block_size if n % self.block_size == 0 else 1
        self._cycle = None  # the old hierarchy released before the new one is built
        B = None if self._modes is None else np.where(free[:, None], self._modes, 0.0)
        matrix = system.tobsr(blocksize=(size, size)) if size > 1 else system
        try:
            ml = pyamg.smoothed_aggregation_solver(matrix, B=B)
        except (ValueError, np.linalg.LinAlgError) as error:
            raise SingularSystemError(
                f"smoothed aggregation could not be set up for the matrix: {error}",
                backend=self.backend,
            ) from None
        self._cycle = ml.aspreconditioner(cycle="V")
        self._hierarchy_free = free
        self.operator_complexity = float(ml.operator_complexity())
        self.n_setups += 1
        self._first_its = 0

    def _precondition(self, r: np.ndarray) -> np.ndarray:
        """One V-cycle on the free DOFs, the diagonal on the eliminated ones."""
        if self._hierarchy_free is self._free:
            return self._cycle(r)
        free = self._free
        return np.where(free, self._cycle(np.where(free, r, 0.0)), 0.0) + self._inverse_diagonal * r

    def _solve(self, b: np.ndarray) -> np.ndarray:
        columns = b.reshape(b.shape[0], -1)
        x = np.empty_like(columns)
        guess, self._guess = self._guess, None
        for j in range(columns.shape[1]):  # a handful of right-hand sides
            if guess is not None and columns.shape[1] == 1:
                start = guess
            else:  # the last right-hand side again: from its solution
                last = self._last
                again = last is not None and np.array_equal(columns[:, j], last[0])
                start = last[1].copy() if again else None
            x[:, j] = self._cg(columns[:, j], start)
            self._x_norm = float(np.linalg.norm(x[:, j]))
            self._last = (columns[:, j].copy(), x[:, j].copy())
        return x.reshape(b.shape)

    def _cg(self, b: np.ndarray, x: np.ndarray | None) -> np.ndarray:
        """CG from ``x`` (None: zero) to the true residual :attr:`rtol` ‖b‖₂."""
        A = self._system
        norm_b = float(np.linalg.norm(b))
        # the round-off floor: a residual at eps ‖A‖∞ ‖x‖₂ is as small as A x can tell
        goal = max(self.rtol * norm_b, EPS * self._norm * self._x_norm)
        x = np.zeros_like(b) if x is None else x
        its = 0
        for _ in range(RESTARTS + 1):  # CG, restarted on the true residual
            r = b - A @ x
            if np.linalg.norm(r) <= goal:
                break
            z = self._precondition(r)
            p, rz = z.copy(), r @ z
            while its < self.max_it:  # CG iterations
                q = A @ p
                curvature = p @ q
                if curvature <= 0:
                    self._fail(its, np.linalg.norm(r) / max(norm_b, 1e-300), "pᵀAp ≤ 0")
                alpha = rz / curvature
                x += alpha * p
                r -= alpha * q
                its += 1
                if np.linalg.norm(r) <= goal:
                    break
                z = self._precondition(r)
                rz, rz_old = r @ z, rz
                p *= rz / rz_old
                p += z
        relative = float(np.linalg.norm(b - A @ x)) / max(norm_b, 1e-300)
        self.iterations.append(its)
        if relative * norm_b > goal * (1 + 1e-8):
            self._fail(its, relative, "no convergence")
        self._check_reuse(its)
        return x

    def _check_reuse(self, its: int) -> None:
        """Rebuild a reused hierarchy whose solves have grown past :data:`REBUILD` times."""
        if self._first_its == 0:
            self._first_its = max(its, 1)
        elif self._hierarchy_free is not self._free and its > REBUILD * self._first_its:
            self._set_up(self._system, self._free)

    def _fail(self, its: int, relative: float, why: str) -> None:
        raise SingularSystemError(
            f"CG + AMG did not reach the relative residual {self.rtol:.0e} ({why} after "
            f"{its} iterations, relative residual {relative:.1e}): the matrix is singular, "
            "indefinite or too ill-conditioned for this preconditioner (a direct backend, "
            "'pardiso' or 'scipy', solves such systems)",
            backend=self.backend,
            residual=float(relative),
        )

    def close(self) -> None:
        self._cycle = self._system = self._keep = self._data = self._last = self._guess = None
        self._hierarchy_free = self._free = None
        super().close()


def _same_mask(keep: np.ndarray | None, old: np.ndarray | None) -> bool:
    """Whether two ``keep`` masks (None: all kept) are the same."""
    if keep is None or old is None:
        return keep is None and old is None
    return np.array_equal(keep, old)


def amg_solver(request: SolverRequest) -> SPDSolver:
    """The ``"amg"`` backend's solver factory (:class:`~.solvers.SolverFactory`):
    :class:`AmgSolver` with the request's rigid modes for a symmetric request, SuperLU's LU
    (exact) for a non-symmetric one. The request's ordering is not computed."""
    if request.symmetric:
        return AmgSolver(
            check_symmetry=request.check_symmetry,
            near_nullspace=request.rigid_modes,
            block_size=request.dimension,
            reuse=True,
        )
    return superlu_solver(request)
