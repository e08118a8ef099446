"""The linear system of one active set, solved by refactorization or a low-rank update.

Each active set iteration (docs/method.md, *Solver*) solves the QP's equality problem with the
Dirichlet DOFs and the active constrained DOFs fixed, eliminated symmetrically in place
(:mod:`.elimination`), so all systems share ``K``'s pattern and the solver's symbolic analysis.
When only a few DOFs change (the free boundary moving by a node), the previous factorization is
reused with a bordered system of the changed DOFs.
"""

from __future__ import annotations

import logging
import time
import warnings
from collections.abc import Callable

import numpy as np

from .backends.solvers import SPDSolver
from .elimination import SymmetricEliminator
from .errors import SINGULAR_CAUSES, FactorizationError, IllConditionedWarning, SingularSystemError
from .inexact import check_iterative
from .qp import BoundQP
from .sparse import abs_matvec

__all__ = [
    "ActiveSetSystem",
    "BACKWARD_RTOL",
    "FORWARD_RTOL",
    "FORWARD_WARN",
    "SOLVE_RTOL",
    "UPDATE_RTOL",
    "check_residual",
    "forward_error",
    "refine",
    "update_accepted",
]

logger = logging.getLogger(__name__)

#: Largest relative residual ``max |b - A x| / max |b|`` of a direct solve accepted as it is.
#: A backward stable solve of an SPD system has a residual of about eps times its condition
#: number (measured: below 1e-13 on Example 6.2 up to 1.2M unknowns); a floating part of the
#: body gives 1e-3 and more. Above it the solve is refined (:func:`refine`) and judged by its
#: backward and forward errors instead.
SOLVE_RTOL = 1e-6

#: Largest normwise backward error ``max |b - A x| / (‖A‖∞ max |x| + max |b|)`` (LAPACK's
#: measure) of a refined solve: a few hundred eps, what a backward stable solve of any SPD
#: system reaches, bending-dominated or not (measured: 2e-16 on cantilevers up to L/h = 3000).
BACKWARD_RTOL = 1e-13

#: Estimated relative forward error of a refined solve above which the matrix is reported
#: singular, and above which a warning says how many digits the solution may have lost
#: (:func:`forward_error`; measured on cantilevers: 10 times the actual error).
FORWARD_RTOL = 0.1
FORWARD_WARN = 1e-2

#: Steps of iterative refinement tried on a solve whose residual fails :data:`SOLVE_RTOL`.
REFINE_STEPS = 3

#: Largest residual of a low-rank updated solve, relative to ``max(max |b|, max |diag A| max |x|)``;
#: above it the system is refactorized.
UPDATE_RTOL = 1e-12


def update_accepted(residual: float, b: np.ndarray, diagonal: np.ndarray, x: np.ndarray) -> bool:
    """Whether a low-rank updated solve ``x`` of ``A x = b`` is accepted: its residual
    ``max |b − A x|`` (NaN fails) at most :data:`UPDATE_RTOL` times the size of both sides,
    ``max(max |b|, max |diag A| max |x|)`` (``diagonal``: that of the matrix factorized)."""
    scale = max(np.abs(b).max(), np.abs(diagonal).max() * np.abs(x).max(), 1e-300)
    return bool(residual <= UPDATE_RTOL * scale)


def check_residual(residual: np.ndarray | float, b: np.ndarray, backend: str) -> None:
    """Raise :class:`SingularSystemError` unless ``max|residual| / max|b| ≤ SOLVE_RTOL``
    (a NaN fails too): a direct solve whose answer does not satisfy its system."""
    relative = _relative(residual, b)
    if not relative <= SOLVE_RTOL:  # also NaN
        raise _singular(
            f"the relative residual max|b - A x| / max|b| = {relative:.1e}",
            backend,
            relative,
            f"bound {SOLVE_RTOL:.0e}",
        )


def refine(
    solve: Callable[[np.ndarray], np.ndarray],
    residual: Callable[[np.ndarray], np.ndarray],
    b: np.ndarray,
    x: np.ndarray,
    norm_A: Callable[[], float],
    backend: str,
) -> np.ndarray:
    """The solution of ``A x = b`` from a first solve ``x`` whose residual may be large only
    because ``A x`` is large, or a :class:`SingularSystemError` (docs/method.md, *Solver*,
    "Residual check").

    A solve whose relative residual ``max |r| / max |b|`` is at most :data:`SOLVE_RTOL` is
    returned as it is (no cost beyond its residual, already computed). Otherwise (bending:
    ``max |A| |x|`` far above ``max |b|``, or a singular matrix) up to :data:`REFINE_STEPS`
    steps of iterative refinement with the existing factorization, ``x ← x + A⁻¹ (b − A x)``
    (stopping when the relative residual meets :data:`SOLVE_RTOL`), then two measures
    decide: the normwise backward error ``max |r| / (‖A‖∞ max |x| + max |b|)`` must be at
    most :data:`BACKWARD_RTOL`, and the estimated forward error (:func:`forward_error`, one
    more solve) at most :data:`FORWARD_RTOL`; above :data:`FORWARD_WARN` an
    :class:`IllConditionedWarning` says how far the solution may be off. A singular matrix (a
    floating body) factorizes with a round-off pivot: its solution is backward stable too,
    but its estimated forward error is far above 1.

    Parameters
    ----------
    solve : callable (n,) -> (n,)
        The factorized matrix's solve.
    residual : callable (n,) -> (n,)
        ``x ↦ b − A x``.
    b, x : (n,) float arrays
        The right-hand side and the first solution (not modified).
    norm_A : callable () -> float
        ``‖A‖∞``, the largest row sum of ``|A|`` (an upper bound will do); called only when
        the solve is refined.
    backend : str

    Returns
    -------
    (n,) float array

    Raises
    ------
    SingularSystemError
        Naming the backward and the estimated forward error.
    """
    r = residual(x)
    if _relative(r, b) <= SOLVE_RTOL:
        return x
    x = x.copy()
    for _ in range(REFINE_STEPS):
        x += solve(r)
        r = residual(x)
        if _relative(r, b) <= SOLVE_RTOL:
            break
    norm = norm_A()
    backward = _max(r) / max(norm * _max(x) + _max(b), 1e-300)
    forward = forward_error(solve, x, norm)
    logger.info(
        "refined solve: residual %.1e of max|b|, backward error %.1e, forward error %.1e",
        _relative(r, b),
        backward,
        forward,
    )
    if not (backward <= BACKWARD_RTOL and forward <= FORWARD_RTOL):  # also NaN
        raise _singular(
            "the normwise backward error max|b - A x| / (‖A‖ max|x| + max|b|) = "
            f"{backward:.1e} and an estimated relative error of {forward:.1e} after iterative "
            "refinement",
            backend,
            _relative(r, b),
            f"bounds {BACKWARD_RTOL:.0e} and {FORWARD_RTOL:.0e}",
        )
    if forward > FORWARD_WARN:
        warnings.warn(
            f"the linear system is ill-conditioned: its solution may be off by up to "
            f"{forward:.1e} relative (estimated from the round-off of its matrix; backend "
            f"{backend}). {SINGULAR_CAUSES}",
            IllConditionedWarning,
            stacklevel=2,
        )
    return x


def forward_error(solve: Callable[[np.ndarray], np.ndarray], x: np.ndarray, norm_A: float) -> float:
    """Estimated relative error ``max |δx| / max |x|`` of a solution ``x`` of ``A x = b``
    caused by the round-off of ``A`` itself (docs/method.md, *Solver*, "Residual check").

    ``δx = A⁻¹ (eps ‖A‖∞ max |x| sign(x))``: the response to a perturbation of the size of
    ``A``'s round-off, aligned with ``x`` — where ``A`` is ill-conditioned, ``x`` lies along
    its softest modes, which the round-off of the assembled matrix excites coherently (a
    random sign pattern underestimated the actual error of cantilevers by 10 to 100). One
    solve. Measured on P2 cantilevers of length/thickness 700 to 3000: 10 to 15 times the
    actual error of the tip deflection.

    Parameters
    ----------
    solve : callable (n,) -> (n,)
    x : (n,) float array
    norm_A : float
        ``‖A‖∞``.

    Returns
    -------
    float
        NaN if the solve is not finite.
    """
    size = _max(x)
    if not size > 0:
        return 0.0 if size == 0 else float("nan")
    eps = float(np.finfo(np.float64).eps)
    return _max(solve(eps * norm_A * size * np.sign(x))) / size


def _max(v: np.ndarray) -> float:
    v = np.abs(v)
    return float(v.max(initial=0.0)) if np.isfinite(v).all() else float("nan")


def _relative(residual: np.ndarray | float, b: np.ndarray) -> float:
    return _max(np.asarray(residual)) / max(_max(b), 1e-300)


def _singular(what: str, backend: str, residual: float, bound: str) -> SingularSystemError:
    return SingularSystemError(
        f"the linear system is singular or too ill-conditioned: its solution has {what} "
        f"(backend {backend}, {bound}). {SINGULAR_CAUSES}",
        backend=backend,
        residual=residual,
    )


class ActiveSetSystem:
    """The fixed-pattern linear systems of one call: eliminate, factorize, solve.

    When the fixed set differs from the factorized one in at most ``max_update`` DOFs, the
    new system is solved with the existing factorization and a bordered system of the k
    changed DOFs (one solve with k + 1 right-hand sides) instead of a new factorization; the
    result is checked by its residual and the system refactorized if the check fails.

    With ``qp.ranks`` of several processes ``K`` holds this rank's rows (:mod:`.ranks`): the
    products with ``K`` and its rows are summed over the ranks, the diagonal read where it is
    stored, ``‖K‖∞`` maximised over them; the answers are those of the whole matrix.

    Parameters
    ----------
    qp : BoundQP
    solver : SPDSolver
        Factorizes the eliminated matrices; its first factorization here checks the pattern
        of ``K`` (and analyses it if new), the later ones only refactorize.
    max_update : int
        Largest change of the fixed set solved by a low-rank update (0: never).

    Attributes
    ----------
    diagonal : (n,) float array
        The diagonal of ``K`` (on every rank).
    time_elimination : float
        Seconds spent forming right-hand sides.
    n_updates : int
        Solves done by a low-rank update instead of a factorization.
    guess : (n,) float array or None
        Where an iterative solver's next solve starts (its
        :meth:`~.backends.solvers.SPDSolver.start_from`, the fixed DOFs at their values): the
        caller's warm start, then each solve's solution.
    """

    def __init__(self, qp: BoundQP, solver: SPDSolver, max_update: int = 0) -> None:
        self.qp = qp
        K, F, c = qp.K, qp.F, qp.constrained
        self.K, self.F, self.c, self.g = K, F, c, qp.gap
        self.K_c = K[c]  # rows of the constrained DOFs, for the multiplier
        self.ranks = qp.ranks  # every product with K is summed over them (:mod:`.ranks`)
        self.solver = solver
        self.eliminator = SymmetricEliminator(K, qp.ranks)
        # read once (an empty K, refused by the solver, has no positions to read)
        self.diagonal = self.eliminator.diagonal(K) if K.nnz else np.zeros(K.shape[0])
        self.fixed = np.zeros(K.shape[0], dtype=bool)
        self.fixed[qp.dirichlet] = True
        self.values = np.zeros(K.shape[0])
        self.values[qp.dirichlet] = qp.dirichlet_values
        self.time_elimination = 0.0
        self.max_update = max_update
        self.factored: np.ndarray | None = None  # fixed mask of the current factorization
        self.n_updates = 0
        self._norm_K: float | None = None
        self.guess: np.ndarray | None = None

    def solve(
        self, active: np.ndarray, load: np.ndarray | None = None
    ) -> tuple[np.ndarray, np.ndarray]:
        """Minimizer with ``x_c = g`` on ``active`` and the residual of the constrained rows.

        Parameters
        ----------
        active : (m,) bool array
            Constrained DOFs held at their bound.
        load : (n,) float array, optional
            A load to use instead of ``qp.F`` for this solve (same matrix).

        Returns
        -------
        x : (n,) float array
        multiplier : (m,) float array
            ``F_c - (K x)_c`` on every constrained DOF (not masked by ``active``).
        """
        c = self.c
        F = self.F if load is None else load
        self.fixed[c] = active
        self.values[c] = np.where(active, self.g, 0.0)
        t0 = time.perf_counter()
        b = self.eliminator.rhs(self.K, F, self.fixed, self.values, self.diagonal)
        self.time_elimination += time.perf_counter() - t0
        x = None
        exact = self.solver.rtol is None  # else no update: it trusts solves to round-off
        if self.factored is not None and self.max_update > 0 and exact:
            changed = np.flatnonzero(self.fixed != self.factored)
            if 0 < changed.size <= self.max_update:
                x = self._solve_updated(F, b, changed)
        if x is None:
            keep = self.eliminator.keep_mask(self.fixed)
            # the solver factorizes K with the eliminated entries dropped: no copy of K
            try:
                if self.factored is None:
                    self.solver.factorize(self.K, keep=keep)
                else:
                    self.solver.refactorize(keep)
            except SingularSystemError:
                raise
            except FactorizationError as err:
                raise FactorizationError(
                    "the stiffness matrix with the Dirichlet and active DOFs eliminated is not "
                    f"positive definite in floating point: {err}. {SINGULAR_CAUSES}",
                    backend=err.backend,
                    code=err.code,
                    equation=err.equation,
                ) from err
            self.factored = self.fixed.copy()
            if not exact and self.guess is not None and self.solver.takes_guess:
                self.solver.start_from(np.where(self.fixed, self.values, self.guess))
            x = self.solver.solve(b)
            if not exact:  # an iterative solve: checked against its tolerance (.inexact)
                x = check_iterative(
                    lambda y: self._residual_vector(b, y), b, x, self.solver, self._norm
                )
            else:
                x = refine(
                    self.solver.solve,
                    lambda y: self._residual_vector(b, y),
                    b,
                    x,
                    self._norm,
                    self.solver.backend,
                )
        x[self.fixed] = self.values[self.fixed]
        self.guess = x
        return x, F[c] - self.ranks.sum(self.K_c @ x)

    def _solve_updated(
        self, F: np.ndarray, b: np.ndarray, changed: np.ndarray
    ) -> np.ndarray | None:
        """Solve with the current factor and a bordered system for the changed DOFs, or None
        if unreliable (docs/method.md, *Solver*, "Low-rank updates").

        With ``f`` the free DOFs of the factorization, ``R`` the DOFs freed since, ``D`` those
        fixed since and ``B = [K_fR, P_D]``, the new solution is ``x_f = z − W y`` with
        ``z = K_ff⁻¹ g``, ``W = K_ff⁻¹ B`` (one solve with ``|R| + |D| + 1`` right-hand
        sides) and ``y = (x_R, λ_D)`` from the Schur complement ``(C − Bᵀ W) y = (h, v_D) −
        Bᵀ z``, ``C = diag(K_RR, 0)``; ``g``, ``h`` are the load minus the columns of the DOFs
        fixed in both, on ``f`` and on ``R``.
        """
        fixed0, fixed1, values, K = self.factored, self.fixed, self.values, self.K
        total = self.ranks.sum  # of the products with rows of K: each row is on one rank
        released = changed[fixed0[changed]]
        added = changed[fixed1[changed]]
        r, k = released.size, changed.size
        t = F - total(K @ np.where(fixed0 & fixed1, values, 0.0))
        rows_R = K[released]  # rows R = columns R (K is symmetric)
        K_Rf = rows_R.multiply(~fixed0[None, :]).tocsr()  # only the columns free in the factor
        rhs = np.zeros((K.shape[0], k + 1), order="F")
        rhs[:, 0] = np.where(fixed0, 0.0, t)
        rhs[:, 1 : r + 1] = total(K_Rf.T.toarray())
        rhs[added, np.arange(r + 1, k + 1)] = 1.0
        Z = self.solver.solve(rhs)  # K_ff⁻¹ [g, B] in one call (zero on the fixed DOFs)
        z, W = Z[:, 0], Z[:, 1:]
        schur = -np.vstack([total(K_Rf @ W), W[added]])
        schur[:r, :r] += total(rows_R[:, released].toarray())
        load = np.concatenate([t[released], values[added]])
        try:
            y = np.linalg.solve(schur, load - np.concatenate([total(K_Rf @ z), z[added]]))
        except np.linalg.LinAlgError:
            return None
        x = z - W @ y
        x[released] = y[:r]
        x[fixed1] = values[fixed1]
        if not update_accepted(self.residual(b, x), b, self.diagonal, x):
            return None
        self.n_updates += 1
        return x

    def residual(self, b: np.ndarray, x: np.ndarray) -> float:
        """``max |b - A x|`` for the eliminated matrix ``A`` of the current fixed set.

        The one residual check of every solve (one product with ``K``): the free rows of
        ``A x`` are ``K`` applied to ``x`` with its fixed entries zeroed, the fixed rows are
        the diagonal times ``x``.

        Parameters
        ----------
        b, x : (n,) float arrays

        Returns
        -------
        float
            NaN if ``x`` is not finite.
        """
        return _max(self._residual_vector(b, x))

    def _residual_vector(self, b: np.ndarray, x: np.ndarray) -> np.ndarray:
        """``b - A x`` (:meth:`residual`)."""
        r = self.qp.matvec(np.where(self.fixed, 0.0, x))
        r[self.fixed] = self.diagonal[self.fixed] * x[self.fixed]
        return b - r

    def _norm(self) -> float:
        """``‖K‖∞``: an upper bound of ``‖A‖∞`` for every eliminated matrix (whose rows are
        rows of ``K`` with entries dropped); computed once, when a solve is refined."""
        if self._norm_K is None:
            rows = abs_matvec(self.K, np.ones(self.K.shape[0]))  # this rank's rows
            self._norm_K = self.ranks.max(float(rows.max(initial=0.0)))
        return self._norm_K
