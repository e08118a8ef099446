"""Primal-dual active set (PDAS) method for a bound-constrained quadratic program.

The discrete Signorini problem of docs/method.md, *Discrete problem* and *Solver*, once the contact
DOFs are rotated into
their normal frames (:mod:`signorini.frames`), is the algebraic problem

.. math::

    \\min_x \\tfrac12 x^T K x - F^T x
    \\quad\\text{subject to}\\quad x_c \\le g,\\quad x_d = x_D,

with ``K`` symmetric, positive definite on the non-Dirichlet DOFs, ``c`` the constrained
(normal) DOFs, ``g`` the gap and ``d`` the Dirichlet DOFs. Its multiplier is the residual of
the constrained rows, ``lam = F_c - (K x)_c``: the nodal contact force Lambda_z of the paper,
eqs. (3.5), (3.9) and (3.17). The KKT conditions are

.. math::

    x_c \\le g,\\qquad \\lambda \\ge 0,\\qquad \\lambda (x_c - g) = 0,\\qquad
    (F - K x)_i = 0 \\text{ on every other free DOF } i.

The method of Hüeber, Mair and Wohlmuth [1]_ iterates on the active set
``A_k = { i : lam_i + c_scale (x_i - g_i) > 0 }``: on ``A_k`` it imposes ``x_i = g_i``, off it
``lam_i = 0``, and it stops when the active set repeats. Every iteration solves one linear
system with Dirichlet and active DOFs eliminated symmetrically *in place*
(:class:`signorini.linsolve.SymmetricEliminator`), so all systems share one sparsity pattern and
the direct solver's symbolic analysis is done once per call (or once for many calls when the
caller keeps the solver).

For an M-matrix ``K`` the method converges monotonically; for a general SPD matrix (P2
elements are not M-matrices) it converges locally superlinearly but may cycle. Cycling and the
iteration bound are detected and reported by :class:`PDASConvergenceError`, unless
``fallback=True``, which finishes with a primal active set method (finite, monotone in the
objective, warm started from the last PDAS iterate) on the same factorization pattern.

References
----------
.. [1] S. Hüeber, M. Mair, B. I. Wohlmuth, A priori error estimates and an inexact primal-dual
   active set strategy for linear and quadratic finite elements applied to multibody contact
   problems, Appl. Numer. Math. 54 (2005) 555-576.
.. [2] M. Hintermüller, K. Ito, K. Kunisch, The primal-dual active set strategy as a semismooth
   Newton method, SIAM J. Optim. 13 (2003) 865-888.
.. [3] J. Nocedal, S. J. Wright, Numerical Optimization, 2nd ed., Springer 2006, section 16.5
   (primal active set method for convex QP).
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from .linsolve import SPDSolver, SymmetricEliminator, as_csr, make_solver

__all__ = [
    "KKTResiduals",
    "PDASConvergenceError",
    "PDASResult",
    "PDASStep",
    "kkt_residuals",
    "solve_pdas",
]

logger = logging.getLogger(__name__)

# Relative size below which ``lam + c (x - g)`` counts as zero when the active set is updated
# (keeps a degenerate constraint, lam = 0 and x = g, from flipping on round-off).
_ACTIVE_RTOL = 1e-13


@dataclass(frozen=True)
class PDASStep:
    """One linear solve of the active set iteration.

    Attributes
    ----------
    iteration : int
        1-based solve counter within the call.
    method : str
        ``"pdas"`` or ``"primal-active-set"`` (the fallback).
    n_active : int
        Size of the active (working) set used for this solve.
    n_added, n_removed : int
        Constraints added to / removed from the set of the previous solve.
    """

    iteration: int
    method: str
    n_active: int
    n_added: int
    n_removed: int

    def __str__(self) -> str:
        return (
            f"{self.iteration:3d} {self.method}: |A| = {self.n_active}, "
            f"+{self.n_added} -{self.n_removed}"
        )


@dataclass(frozen=True)
class KKTResiduals:
    """Relative KKT residuals of a point ``x`` (see :func:`kkt_residuals`).

    Attributes
    ----------
    primal : float
        ``max (x_c - g)^+ / disp_scale``.
    dual : float
        ``max (-lam)^+ / force_scale``.
    complementarity : float
        ``max |lam (x_c - g)| / (force_scale * disp_scale)``.
    stationarity : float
        ``max |F - K x|`` over the free unconstrained rows, over ``force_scale``.
    dirichlet : float
        ``max |x_d - x_D| / disp_scale``.
    force_scale : float
        ``max(max |F|, max (|K| |x|))`` (1 if both vanish): the size of the forces, which also
        bounds the round-off in ``F - K x``.
    disp_scale : float
        ``max(max |x|, max |g|, max |x_D|)`` (1 if all vanish).
    """

    primal: float
    dual: float
    complementarity: float
    stationarity: float
    dirichlet: float
    force_scale: float
    disp_scale: float

    @property
    def max(self) -> float:
        """The largest of the five relative residuals."""
        return max(self.primal, self.dual, self.complementarity, self.stationarity, self.dirichlet)


@dataclass
class PDASResult:
    """Solution of :func:`solve_pdas` and how it was obtained.

    Attributes
    ----------
    x : (n,) float array
        The minimizer (in the frame of ``K``).
    lam : (m,) float array
        Multiplier on the constrained DOFs, ``F_c - (K x)_c`` on the active set and 0 off it
        (paper's Lambda_z, eqs. (3.5), (3.9), (3.17)).
    active : (m,) bool array
        Final active set over the constrained DOFs.
    iterations : int
        Linear solves of the active set loop(s), PDAS and fallback together.
    n_solves, n_factorizations, n_analyses : int
        Work done by the linear solver during this call.
    history : list of PDASStep
    kkt : KKTResiduals
    backend : str
        Linear solver backend.
    method : str
        ``"pdas"``, or ``"primal-active-set"`` when the fallback finished the job.
    c_scale : float
        The constant ``c`` of the active set rule.
    times : dict of str to float
        Seconds: ``analysis``, ``factorization``, ``solve``, ``elimination``, ``total``.
    n_updates : int
        Iterations solved with the previous factorization and a low-rank correction.
    """

    x: np.ndarray
    lam: np.ndarray
    active: np.ndarray
    iterations: int
    n_solves: int
    n_factorizations: int
    n_analyses: int
    history: list[PDASStep]
    kkt: KKTResiduals
    backend: str
    method: str
    c_scale: float
    times: dict[str, float] = field(default_factory=dict)
    n_updates: int = 0


class PDASConvergenceError(RuntimeError):
    """The active set iteration cycled or hit its bound.

    Attributes
    ----------
    history : list of PDASStep
    reason : str
        ``"cycling"`` or ``"max_iter"``.
    x, active : numpy arrays
        The last iterate and its active set.
    """

    def __init__(
        self,
        message: str,
        history: list[PDASStep],
        reason: str,
        x: np.ndarray | None = None,
        active: np.ndarray | None = None,
    ) -> None:
        lines = "\n".join(str(step) for step in history[-20:])
        skipped = f"\n  ({len(history) - 20} earlier steps not shown)" if len(history) > 20 else ""
        super().__init__(f"{message}\niteration history:{skipped}\n{lines}")
        self.history = history
        self.reason = reason
        self.x = x
        self.active = active


# ----------------------------------------------------------------------------------------------
# Input checks
# ----------------------------------------------------------------------------------------------


def _index_array(idx: object, n: int, name: str) -> np.ndarray:
    """Distinct DOF indices from an int array or a length-n bool mask."""
    arr = np.asarray(idx)
    if arr.dtype == np.bool_:
        if arr.shape != (n,):
            raise ValueError(f"{name} as a boolean mask must have shape ({n},), got {arr.shape}")
        return np.flatnonzero(arr)
    if arr.ndim != 1:
        raise ValueError(f"{name} must be a 1D index array, got shape {arr.shape}")
    if arr.size and not np.issubdtype(arr.dtype, np.integer):
        raise ValueError(f"{name} must hold integer DOF indices, got dtype {arr.dtype}")
    arr = arr.astype(np.int64)
    if arr.size and (arr.min() < 0 or arr.max() >= n):
        raise ValueError(f"{name} has indices outside [0, {n}): [{arr.min()}, {arr.max()}]")
    if np.unique(arr).size != arr.size:
        raise ValueError(f"{name} has repeated indices")
    return arr


def _vector(v: object, n: int, name: str, *, allow_scalar: bool = False) -> np.ndarray:
    """A finite float64 vector of length n (a scalar is broadcast if allowed)."""
    try:
        arr = np.asarray(v, dtype=np.float64)
    except (TypeError, ValueError) as err:
        raise ValueError(f"{name} must be a real array: {err}") from None
    if arr.ndim == 0 and allow_scalar:
        arr = np.full(n, float(arr))
    if arr.shape != (n,):
        raise ValueError(f"{name} must have shape ({n},), got {arr.shape}")
    if not np.isfinite(arr).all():
        raise ValueError(f"{name} has non-finite (NaN or inf) entries")
    return arr


def _check_problem(
    K: object,
    F: object,
    constrained: object,
    gap: object,
    dirichlet: object,
    dirichlet_values: object,
) -> tuple[sp.csr_matrix, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Validate and normalise the problem data (see :func:`solve_pdas`)."""
    K = as_csr(K, "K")
    n = K.shape[0]
    F = _vector(F, n, "F")
    c = _index_array(constrained, n, "constrained")
    g = _vector(gap, c.size, "gap", allow_scalar=True)
    if dirichlet is None:
        d = np.zeros(0, dtype=np.int64)
    else:
        d = _index_array(dirichlet, n, "dirichlet")
    overlap = np.intersect1d(c, d)
    if overlap.size:
        raise ValueError(
            f"constrained and dirichlet overlap in {overlap.size} DOFs (first: {overlap[0]})"
        )
    if dirichlet_values is None:
        xd = np.zeros(d.size)
    else:
        vals = np.asarray(dirichlet_values, dtype=np.float64)
        if vals.shape == (n,) and d.size != n:
            vals = vals[d]
        xd = _vector(vals, d.size, "dirichlet_values", allow_scalar=True)
    return K, F, c, g, d, xd


# ----------------------------------------------------------------------------------------------
# KKT residuals
# ----------------------------------------------------------------------------------------------


def _kkt(
    K: sp.csr_matrix,
    F: np.ndarray,
    x: np.ndarray,
    c: np.ndarray,
    g: np.ndarray,
    d: np.ndarray,
    xd: np.ndarray,
) -> KKTResiduals:
    r = F - K @ x
    absK = sp.csr_matrix((np.abs(K.data), K.indices, K.indptr), shape=K.shape)
    force = max(np.abs(F).max(initial=0.0), (absK @ np.abs(x)).max(initial=0.0))
    disp = max(np.abs(x).max(initial=0.0), np.abs(g).max(initial=0.0), np.abs(xd).max(initial=0.0))
    force = force if force > 0 else 1.0
    disp = disp if disp > 0 else 1.0
    lam = r[c]
    slack = x[c] - g
    other = np.ones(x.size, dtype=bool)
    other[c] = False
    other[d] = False
    return KKTResiduals(
        primal=float(np.maximum(slack, 0.0).max(initial=0.0) / disp),
        dual=float(np.maximum(-lam, 0.0).max(initial=0.0) / force),
        complementarity=float(np.abs(lam * slack).max(initial=0.0) / (force * disp)),
        stationarity=float(np.abs(r[other]).max(initial=0.0) / force),
        dirichlet=float(np.abs(x[d] - xd).max(initial=0.0) / disp),
        force_scale=float(force),
        disp_scale=float(disp),
    )


def kkt_residuals(
    K: sp.spmatrix,
    F: np.ndarray,
    x: np.ndarray,
    constrained: np.ndarray,
    gap: np.ndarray | float,
    dirichlet: np.ndarray | None = None,
    dirichlet_values: np.ndarray | float | None = None,
) -> KKTResiduals:
    """Relative KKT residuals of ``x`` for ``min 1/2 x^T K x - F^T x``, ``x_c <= g``, ``x_d = x_D``.

    The multiplier is the residual of the constrained rows, ``lam = F_c - (K x)_c``
    (paper's (3.5)/(3.9)/(3.17)); see :class:`KKTResiduals` for the five measures and their
    scales.

    Parameters
    ----------
    K : scipy sparse matrix, shape (n, n)
    F : (n,) float array
    x : (n,) float array
    constrained : (m,) int array or (n,) bool mask
    gap : float or (m,) float array
    dirichlet : (n_d,) int array or (n,) bool mask, optional
    dirichlet_values : float, (n_d,) or (n,) float array, optional
        Default 0.

    Returns
    -------
    KKTResiduals
    """
    K, F, c, g, d, xd = _check_problem(K, F, constrained, gap, dirichlet, dirichlet_values)
    x = _vector(x, K.shape[0], "x")
    return _kkt(K, F, x, c, g, d, xd)


# ----------------------------------------------------------------------------------------------
# The solver
# ----------------------------------------------------------------------------------------------


class _System:
    """The fixed-pattern linear systems of one call: eliminate, factorize, solve.

    When the fixed set differs from the factorized one in at most ``max_update`` DOFs, the
    new system is solved with the existing factorization and a Woodbury correction of rank
    at most ``2 k`` (k changed DOFs) instead of a new factorization; the result is checked by
    its residual and the system refactorized if the check fails.
    """

    def __init__(
        self,
        K: sp.csr_matrix,
        F: np.ndarray,
        c: np.ndarray,
        g: np.ndarray,
        d: np.ndarray,
        xd: np.ndarray,
        solver: SPDSolver,
        max_update: int = 0,
    ) -> None:
        self.K, self.F, self.c, self.g = K, F, c, g
        self.K_c = K[c]  # rows of the constrained DOFs, for the multiplier
        self.solver = solver
        self.eliminator = SymmetricEliminator(K)
        self.fixed = np.zeros(K.shape[0], dtype=bool)
        self.fixed[d] = True
        self.values = np.zeros(K.shape[0])
        self.values[d] = xd
        self.time_elimination = 0.0
        self.max_update = max_update
        self.factored: np.ndarray | None = None  # fixed mask of the current factorization
        self.n_updates = 0

    def solve(self, active: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Minimizer with ``x_c = g`` on ``active``; returns ``x`` and ``F_c - (K x)_c``."""
        c = self.c
        self.fixed[c] = active
        self.values[c] = np.where(active, self.g, 0.0)
        t0 = time.perf_counter()
        b = self.eliminator.rhs(self.K, self.F, self.fixed, self.values)
        self.time_elimination += time.perf_counter() - t0
        x = None
        if self.factored is not None and self.max_update > 0:
            changed = np.flatnonzero(self.fixed != self.factored)
            if 0 < changed.size <= self.max_update:
                x = self._solve_updated(b, changed)
        if x is None:
            keep = self.eliminator.keep_mask(self.fixed)
            # the solver factorizes K with the eliminated entries dropped: no copy of K
            self.solver.factorize(self.K, keep=keep)
            self.factored = self.fixed.copy()
            x = self.solver.solve(b)
        x[self.fixed] = self.values[self.fixed]
        lam = self.F[c] - self.K_c @ x
        return x, lam

    def _columns(self, fixed: np.ndarray, cols: np.ndarray) -> sp.csc_matrix:
        """Columns ``cols`` of the matrix eliminated for ``fixed`` (symmetric: rows of K)."""
        rows = self.K[cols].tocoo()  # row r of K is column cols[r]
        j = cols[rows.row]
        ok = ~fixed[rows.col] & ~fixed[j]  # entries that survive the elimination
        data = np.where(ok, rows.data, 0.0)
        on_diag = rows.col == j
        data[on_diag] = rows.data[on_diag]
        return sp.csc_matrix((data, (rows.col, rows.row)), shape=(self.K.shape[0], cols.size))

    def _solve_updated(self, b: np.ndarray, changed: np.ndarray) -> np.ndarray | None:
        """Solve with the current factor and a Woodbury correction, or None if unreliable.

        With ``E = A_new − A_old`` supported on the rows and columns ``D = changed``,
        ``E = U Vᵀ`` for ``U = [P_D, E_{:,D}]``, ``V = [E_{:,D} − P_D E_DD, P_D]``.
        """
        n, k = self.K.shape[0], changed.size
        E = self._columns(self.fixed, changed) - self._columns(self.factored, changed)
        E = E.toarray()  # (n, k): k is small
        P = np.zeros((n, k))
        P[changed, np.arange(k)] = 1.0
        E_dd = E[changed]
        U = np.hstack([P, E])
        V = np.hstack([E - P @ E_dd, P])
        Z = self.solver.solve(np.column_stack([b, U]))  # A_old⁻¹ [b, U] in one call
        y, W = Z[:, 0], Z[:, 1:]
        capacitance = np.eye(2 * k) + V.T @ W
        try:
            x = y - W @ np.linalg.solve(capacitance, V.T @ y)
        except np.linalg.LinAlgError:
            return None
        # residual of the new eliminated system: free rows K x_free, fixed rows diag x
        diagonal = self.K.data[self.eliminator.diagonal_positions]
        z = np.where(self.fixed, 0.0, x)
        r = self.K @ z
        r[self.fixed] = diagonal[self.fixed] * x[self.fixed]
        r -= b
        scale = max(np.abs(b).max(), np.abs(diagonal).max() * np.abs(x).max(), 1e-300)
        if np.abs(r).max() > 1e-12 * scale:
            return None
        self.n_updates += 1
        return x


def _primal_active_set(
    system: _System,
    x: np.ndarray,
    force_scale: float,
    max_iter: int,
    history: list[PDASStep],
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Primal active set method for the bound-constrained QP, from a feasible-made start.

    ``x`` is projected onto ``x_c <= g``; the working set starts as the bounds that hold with
    equality. Each step solves the equality problem of the working set; a blocked step adds the
    blocking bounds, a full step with a negative multiplier drops the most negative one.
    The objective never increases, so (without degeneracy) no working set repeats.
    """
    c, g = system.c, system.g
    x = x.copy()
    xc = np.minimum(x[c], g)
    x[c] = xc
    work = xc >= g
    tol = 1e-12 * force_scale
    start = len(history)
    previous = work.copy()
    for _ in range(max_iter):
        x_star, lam = system.solve(work)
        history.append(
            PDASStep(
                iteration=len(history) + 1,
                method="primal-active-set",
                n_active=int(work.sum()),
                n_added=int((work & ~previous).sum()),
                n_removed=int((previous & ~work).sum()),
            )
        )
        previous = work.copy()
        step = x_star[c] - x[c]
        moving = ~work & (step > 0)
        alpha_i = np.full(c.size, np.inf)
        alpha_i[moving] = (g[moving] - x[c][moving]) / step[moving]
        alpha = float(alpha_i.min(initial=np.inf))
        if alpha < 1.0:
            x = x + alpha * (x_star - x)
            blocking = alpha_i <= alpha * (1 + 1e-12)
            x[c[blocking]] = g[blocking]
            work = work | blocking
            continue
        x = x_star
        lam = np.where(work, lam, 0.0)
        k = int(np.argmin(lam)) if c.size else 0
        if c.size == 0 or lam[k] >= -tol:
            return x, lam, work
        work = work.copy()
        work[k] = False
    raise PDASConvergenceError(
        f"the primal active set fallback did not finish in {max_iter} steps",
        history[start:],
        "max_iter",
        x=x,
        active=work,
    )


def solve_pdas(
    K: sp.spmatrix,
    F: np.ndarray,
    constrained: np.ndarray,
    gap: np.ndarray | float,
    dirichlet: np.ndarray | None = None,
    dirichlet_values: np.ndarray | float | None = None,
    *,
    x0: np.ndarray | None = None,
    active0: np.ndarray | None = None,
    c: float | None = None,
    max_iter: int = 50,
    solver: SPDSolver | None = None,
    backend: str = "auto",
    fallback: bool = False,
    max_update: int = 4,
) -> PDASResult:
    """Solve ``min 1/2 x^T K x - F^T x`` subject to ``x_c <= g`` and ``x_d = x_D`` by PDAS.

    Parameters
    ----------
    K : scipy sparse matrix, shape (n, n)
        Symmetric; positive definite on the non-Dirichlet DOFs. Its pattern must contain the
        diagonal. Rotate contact DOFs into normal frames first (:func:`signorini.frames.
        rotate_frames`) so each constraint bounds one DOF.
    F : (n,) float array
        Load vector.
    constrained : (m,) int array or (n,) bool mask
        Constrained DOFs ``c`` (normal components of contact nodes).
    gap : float or (m,) float array
        Upper bounds ``g`` (paper's psi at the contact nodes), in the order of ``constrained``.
    dirichlet : (n_d,) int array or (n,) bool mask, optional
        Fixed DOFs ``d``; must not meet ``constrained``.
    dirichlet_values : float, (n_d,) or (n,) float array, optional
        Values ``x_D`` on ``d`` (default 0).
    x0 : (n,) float array, optional
        Warm start: the initial active set is ``{ lam0 + c (x0_c - g) > 0 }`` with
        ``lam0 = F_c - (K x0)_c``. Ignored when ``active0`` is given.
    active0 : (m,) bool array, optional
        Initial active set (e.g. the previous adaptive level's). Takes precedence over ``x0``.
        Default (neither given): the empty set, so the first iterate is the unconstrained
        solution and the second active set is the set of DOFs where it violates the bound.
        Starting from the exact active set costs one linear solve.
    c : float, optional
        The positive constant of the active set rule; default the mean diagonal of ``K`` over
        the constrained DOFs (docs/method.md, *Solver*).
    max_iter : int
        Bound on PDAS iterations (linear solves).
    solver : SPDSolver, optional
        A solver to use and keep (its symbolic analysis is reused when ``K`` has the pattern
        it was analysed for). By default one is made with ``backend`` and released afterwards.
    backend : {"auto", "pardiso", "scipy"}
        Backend for the default solver (ignored when ``solver`` is given).
    fallback : bool
        If PDAS cycles or reaches ``max_iter``, finish with a primal active set method instead
        of raising.
    max_update : int
        When the active set changes by at most this many DOFs, solve with the existing
        factorization and a low-rank (Woodbury) correction, checked by its residual, instead
        of refactorizing (0 disables). A correction for k changed DOFs costs 2k + 1 solves.

    Returns
    -------
    PDASResult

    Raises
    ------
    ValueError
        For malformed input, naming the argument.
    PDASConvergenceError
        If the active set cycles or ``max_iter`` is reached and ``fallback`` is False.
    signorini.linsolve.FactorizationError
        If ``K`` restricted to the free DOFs is not positive definite.
    """
    t_start = time.perf_counter()
    K, F, cons, g, d, xd = _check_problem(K, F, constrained, gap, dirichlet, dirichlet_values)
    n, m = K.shape[0], cons.size
    if isinstance(max_iter, bool) or not isinstance(max_iter, (int, np.integer)) or max_iter < 1:
        raise ValueError(f"max_iter must be a positive integer, got {max_iter!r}")
    if (
        isinstance(max_update, bool)
        or not isinstance(max_update, (int, np.integer))
        or max_update < 0
    ):
        raise ValueError(f"max_update must be a non-negative integer, got {max_update!r}")
    if c is None:
        c_scale = float(K.diagonal()[cons].mean()) if m else 1.0
    else:
        c_scale = float(c)
    if not np.isfinite(c_scale) or c_scale <= 0:
        raise ValueError(f"c must be positive and finite, got {c_scale}")

    if active0 is not None:
        active = np.asarray(active0)
        if active.dtype != np.bool_ or active.shape != (m,):
            raise ValueError(f"active0 must be a boolean array of shape ({m},)")
        active = active.copy()
    elif x0 is not None:
        x_start = _vector(x0, n, "x0")
        lam0 = F[cons] - K[cons] @ x_start if m else np.zeros(0)
        active = lam0 + c_scale * (x_start[cons] - g) > 0
    else:
        active = np.zeros(m, dtype=bool)

    own_solver = solver is None
    if own_solver:
        solver = make_solver(backend)
    elif not isinstance(solver, SPDSolver):
        raise ValueError(f"solver must be an SPDSolver, got {type(solver).__name__}")
    counts0 = (solver.n_solves, solver.n_factorizations, solver.n_analyses)
    times0 = (solver.time_analysis, solver.time_factorization, solver.time_solve)

    try:
        system = _System(K, F, cons, g, d, xd, solver, max_update=max_update)
        scale = max(
            np.abs(F).max(initial=0.0),
            c_scale * np.abs(g).max(initial=0.0),
            c_scale * np.abs(xd).max(initial=0.0),
        )
        threshold = _ACTIVE_RTOL * scale
        history: list[PDASStep] = []
        seen = {active.tobytes(): 1}  # active set -> iteration that used it
        previous = active.copy()
        method = "pdas"
        failure = None
        for it in range(1, max_iter + 1):
            x, lam = system.solve(active)
            lam = np.where(active, lam, 0.0)
            history.append(
                PDASStep(
                    iteration=it,
                    method="pdas",
                    n_active=int(active.sum()),
                    n_added=int((active & ~previous).sum()),
                    n_removed=int((previous & ~active).sum()),
                )
            )
            logger.debug("PDAS %s", history[-1])
            new_active = lam + c_scale * (x[cons] - g) > threshold
            if np.array_equal(new_active, active):
                break
            key = new_active.tobytes()
            if key in seen:
                failure = (
                    "cycling",
                    f"PDAS cycles: the active set computed in iteration {it} "
                    f"is the one iteration {seen[key]} used",
                )
                break
            seen[key] = it + 1
            previous, active = active, new_active
        else:
            failure = ("max_iter", f"PDAS did not converge in max_iter = {max_iter} iterations")

        if failure is not None:
            reason, message = failure
            if not fallback:
                raise PDASConvergenceError(
                    message + " (pass fallback=True to finish with a primal active set method)",
                    history,
                    reason,
                    x=x,
                    active=active,
                )
            logger.warning("%s; finishing with the primal active set method", message)
            force = max(np.abs(F).max(initial=0.0), np.abs(K @ x).max(initial=0.0), 1e-300)
            x, lam, active = _primal_active_set(system, x, force, 10 * m + 50, history)
            method = "primal-active-set"
    finally:
        n_solves = solver.n_solves - counts0[0]
        n_factorizations = solver.n_factorizations - counts0[1]
        n_analyses = solver.n_analyses - counts0[2]
        times = {
            "analysis": solver.time_analysis - times0[0],
            "factorization": solver.time_factorization - times0[1],
            "solve": solver.time_solve - times0[2],
        }
        backend_name = solver.backend
        if own_solver:
            solver.close()

    times["elimination"] = system.time_elimination
    kkt = _kkt(K, F, x, cons, g, d, xd)
    times["total"] = time.perf_counter() - t_start
    logger.info(
        "%s finished after %d solves (|A| = %d of %d), KKT residual %.2e",
        method,
        len(history),
        int(active.sum()),
        m,
        kkt.max,
    )
    return PDASResult(
        x=x,
        lam=lam,
        active=active,
        iterations=len(history),
        n_solves=n_solves,
        n_factorizations=n_factorizations,
        n_analyses=n_analyses,
        history=history,
        kkt=kkt,
        backend=backend_name,
        method=method,
        c_scale=c_scale,
        times=times,
        n_updates=system.n_updates,
    )
