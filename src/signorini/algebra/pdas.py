"""Primal-dual active set (PDAS) method for the bound-constrained QP of :mod:`.qp`.

The problem is ``min 1/2 x^T K x - F^T x`` subject to ``x_c <= g`` and ``x_d = x_D``, with
``K`` symmetric, positive definite on the non-Dirichlet DOFs; its multiplier is the residual of
the constrained rows, ``Λ = F_c - (K x)_c`` (the nodal contact force of the paper, eqs. (3.5),
(3.9), (3.17)) and its KKT conditions are those of :mod:`.kkt`.

The method of Hüeber, Mair and Wohlmuth [1]_ (docs/method.md, *Solver*) iterates on the active
set ``A_k = { i : Λ_i + c (x_i - g_i) > 0 }``: on ``A_k`` it imposes ``x_i = g_i``, off it
``Λ_i = 0``, and it stops when the active set repeats. Every iteration solves one linear
system with Dirichlet and active DOFs eliminated symmetrically *in place*
(:class:`~.active_system.ActiveSetSystem`), so all systems share one sparsity pattern and
the direct solver's symbolic analysis is done once per call (or once for many calls when the
caller keeps the solver).

For an M-matrix ``K`` the method converges monotonically; for a general SPD matrix (P2
elements are not M-matrices) it converges locally superlinearly [2]_ but may cycle. Cycling
and the iteration bound are detected and reported by :class:`~.errors.PDASConvergenceError`,
unless ``fallback=True``, which finishes with the primal active set method of :mod:`.primal`.

References
----------
.. [1] S. Hüeber, M. Mair, B. I. Wohlmuth, A priori error estimates and an inexact primal-dual
   active set strategy for linear and quadratic finite elements applied to multibody contact
   problems, Appl. Numer. Math. 54 (2005) 555-576.
.. [2] M. Hintermüller, K. Ito, K. Kunisch, The primal-dual active set strategy as a semismooth
   Newton method, SIAM J. Optim. 13 (2003) 865-888.
"""

from __future__ import annotations

import logging
import time
import warnings
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from .active_system import ActiveSetSystem
from .backends.selection import make_solver
from .backends.solvers import SolverFactory, SPDSolver, solver_usage
from .errors import IllConditionedWarning, PDASConvergenceError
from .inexact import InexactRule
from .kkt import ill_conditioned_message, qp_residuals
from .primal import primal_active_set
from .qp import BoundQP, check_qp, check_vector
from .ranks import SERIAL, Ranks
from .result import PDASResult, PDASStep
from .sparse import abs_matvec

__all__ = ["KKT_WARN", "PDASOptions", "rule_active_set", "solve_pdas"]

logger = logging.getLogger(__name__)

# Relative size of the band ``|Λ + c (x - g)| <= _ACTIVE_RTOL * scale`` in which a constraint
# keeps its state when the active set is updated: a degenerate constraint (Λ = 0 and x = g,
# "just touching") has both Λ and x - g at round-off, whose sign must not decide. The round-off
# of x grows with the condition number of K (measured: |x_c - g| / |g| = 2e-12 at 33k unknowns),
# so the band is far above eps and far below any decision that matters. An inactive
# constraint's band is on c (x - g), relative to max(max |F|, c max |x|) (a displacement band);
# an active one's is on Λ, relative to the forces max(max |F|, Σ Λ⁺) and never below the
# round-off of Λ itself, _FORCE_ROUNDOFF max (|K| |x|)_c: not c max |x|, which grows with the
# stiffness (ν → 1/2, a sliver cell) and kept tensile forces of 5 % of the total active.
_ACTIVE_RTOL = 1e-9
_FORCE_ROUNDOFF = 1e3 * float(np.finfo(np.float64).eps)


#: A solution whose largest relative KKT residual exceeds this gets an
#: :class:`~.errors.IllConditionedWarning`: its forces have fewer than six digits (the
#: residuals are honest, docs/method.md, *Solver*; measured: 1e-6 at ν = 0.499999999, 1e-7
#: with a sliver cell of aspect ratio 1e9).
KKT_WARN = 1e-6


@dataclass(frozen=True)
class PDASOptions:
    """How :func:`solve_pdas` iterates.

    Attributes
    ----------
    max_iter : int
        Bound on PDAS iterations (linear solves).
    c : float, optional
        The positive constant of the active set rule; default the mean diagonal of ``K`` over
        the constrained DOFs (docs/method.md, *Solver*).
    fallback : bool
        If PDAS cycles or reaches ``max_iter``, finish with a primal active set method instead
        of raising.
    max_update : int
        When the active set changes by at most this many DOFs, solve with the existing
        factorization and a bordered system of the changed DOFs, checked by its residual,
        instead of refactorizing (0 disables). It costs one solve with k + 1 right-hand sides
        for k changed DOFs.

    Raises
    ------
    ValueError
        Naming the attribute: ``max_iter`` below 1, ``max_update`` below 0, ``c`` not
        positive and finite.
    """

    max_iter: int = 50
    c: float | None = None
    fallback: bool = False
    max_update: int = 4

    def __post_init__(self) -> None:
        _check_count(self.max_iter, "max_iter", minimum=1)
        _check_count(self.max_update, "max_update", minimum=0)
        if self.c is not None and not (np.isfinite(float(self.c)) and float(self.c) > 0):
            raise ValueError(f"c must be positive and finite, got {float(self.c)}")


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
    options: PDASOptions | None = None,
    solver: SPDSolver | SolverFactory | None = None,
    ranks: Ranks = SERIAL,
) -> PDASResult:
    r"""Solve ``min 1/2 x^T K x - F^T x`` subject to ``x_c <= g`` and ``x_d = x_D`` by PDAS.

    Parameters
    ----------
    K : scipy sparse matrix, shape (n, n)
        Symmetric; positive definite on the non-Dirichlet DOFs. Its pattern must contain the
        diagonal. Rotate contact DOFs into normal frames first
        (:func:`signorini.contact.node_frames.rotate_frames`) so each constraint bounds one DOF.
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
        Warm start: an iterative solver (``takes_guess``) starts its first solve from it;
        without ``active0`` the active set rule at it (:func:`rule_active_set`) is the first set.
    active0 : (m,) bool array, optional
        Initial active set (e.g. the previous adaptive level's). Takes precedence over ``x0``.
        Default (neither given): the empty set, so the first iterate is the unconstrained
        solution and the second active set is the set of DOFs where it violates the bound.
        Starting from the exact active set costs one linear solve.
    options : PDASOptions, optional
        ``max_iter``, ``c``, ``fallback``, ``max_update``; default :class:`PDASOptions`\ ().
    solver : SPDSolver or SolverFactory, optional
        An :class:`SPDSolver` is used and kept (not closed; its symbolic analysis is reused
        when ``K`` has the pattern it was analysed for). A factory
        (:class:`~.solvers.SolverFactory`, default :func:`~.selection.auto_solver`) makes one
        for this call, released afterwards.
    ranks : Ranks
        The processes that split ``K`` by rows (:attr:`~.qp.BoundQP.ranks`; docs/parallel.md):
        on each rank ``K`` holds that rank's rows, the others empty, and every other argument
        is the same on every rank; the result is the same on every rank. Default one
        process and a whole ``K``.

    Returns
    -------
    PDASResult

    Raises
    ------
    ValueError
        For malformed input, naming the argument.
    PDASConvergenceError
        If the active set cycles or ``max_iter`` is reached and ``options.fallback`` is False.
    signorini.algebra.backends.solvers.FactorizationError
        If ``K`` restricted to the free DOFs is not positive definite.

    Notes
    -----
    This function checks the input and collects the result; the method itself is in the named
    steps below it (:func:`_initial_active_set`, :func:`_iterate`, :func:`_after_failure`).
    """
    t_start = time.perf_counter()
    qp = check_qp(K, F, constrained, gap, dirichlet, dirichlet_values, ranks=ranks)
    options = PDASOptions() if options is None else options
    if not isinstance(options, PDASOptions):
        raise ValueError(f"options must be a PDASOptions, got {type(options).__name__}")
    c_scale = _rule_constant(qp, options.c)
    x0 = None if x0 is None else check_vector(x0, qp.n, "x0")  # before any work
    active = _initial_active_set(qp, c_scale, x0, active0)
    own_solver = not isinstance(solver, SPDSolver)
    if own_solver:
        solver = make_solver(solver)

    before = solver_usage(solver)
    its_before = len(getattr(solver, "iterations", ()))  # an iterative solver's counts
    try:
        system = ActiveSetSystem(qp, solver, max_update=options.max_update)
        system.guess = x0
        history: list[PDASStep] = []
        with InexactRule(solver) as rule:  # an iterative solver's stopping rule (.inexact)
            x, multiplier, active, failure = _iterate(
                system, active, c_scale, options.max_iter, history, rule
            )
            method = "pdas"
            if failure is not None:
                rule.tighten()
                x, multiplier, active = _after_failure(
                    system, x, active, failure, options.fallback, history
                )
                method = "primal-active-set"
    finally:
        used = {key: value - before[key] for key, value in solver_usage(solver).items()}
        backend_name = solver.backend
        linear_iterations = tuple(int(k) for k in getattr(solver, "iterations", ())[its_before:])
        if own_solver:
            solver.close()

    kkt = qp_residuals(qp, x)
    if not kkt.max <= KKT_WARN:
        warnings.warn(
            ill_conditioned_message(kkt, KKT_WARN, _FORCE_ROUNDOFF),
            IllConditionedWarning,
            stacklevel=2,
        )
    times = {key: used[key] for key in ("analysis", "factorization", "solve")}
    times["elimination"] = system.time_elimination
    times["total"] = time.perf_counter() - t_start
    logger.info(
        "%s finished after %d solves (|A| = %d of %d), KKT residual %.2e",
        method,
        len(history),
        int(active.sum()),
        active.size,
        kkt.max,
    )
    return PDASResult(
        x=x,
        multiplier=multiplier,
        active=active,
        iterations=len(history),
        n_solves=used["n_solves"],
        n_factorizations=used["n_factorizations"],
        n_analyses=used["n_analyses"],
        history=history,
        kkt=kkt,
        backend=backend_name,
        method=method,
        c_scale=c_scale,
        times=times,
        n_updates=system.n_updates,
        linear_iterations=linear_iterations,
    )


def rule_active_set(
    K: sp.spmatrix,
    F: np.ndarray,
    constrained: np.ndarray,
    gap: np.ndarray | float,
    x0: np.ndarray,
    dirichlet: np.ndarray | None = None,
    *,
    ranks: Ranks = SERIAL,
) -> np.ndarray:
    """``(m,) bool``: the active set rule of :func:`solve_pdas` at ``x0``,
    ``{ Λ0 + c (x0_c − g) > 0 }`` with ``Λ0 = F_c − (K x0)_c`` and ``c`` the default
    constant (the mean diagonal of ``K`` over ``constrained``): the active set the first
    PDAS step from ``x0`` would take, its ``x0`` argument's (docs/method.md, *Three
    dimensions: warm starts by the active set rule*). The arguments are those of
    :func:`solve_pdas`; a ValueError names a malformed one."""
    qp = check_qp(K, F, constrained, gap, dirichlet, ranks=ranks)
    return _initial_active_set(qp, _rule_constant(qp, None), x0, None)


# ----------------------------------------------------------------------------------------------
# The steps of solve_pdas
# ----------------------------------------------------------------------------------------------


def _check_count(value: object, name: str, minimum: int) -> None:
    """Reject anything but an integer ``>= minimum`` (bools included)."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < minimum:
        kind = "a positive" if minimum == 1 else "a non-negative"
        raise ValueError(f"{name} must be {kind} integer, got {value!r}")


def _rule_constant(qp: BoundQP, c: float | None) -> float:
    """The constant ``c`` of the active set rule: given, or the mean diagonal of ``K`` over
    the constrained DOFs (docs/method.md, *Solver*)."""
    if c is None:
        m = qp.constrained.size
        c_scale = float(qp.diagonal()[qp.constrained].mean()) if m else 1.0
    else:
        c_scale = float(c)
    if not np.isfinite(c_scale) or c_scale <= 0:
        raise ValueError(f"c must be positive and finite, got {c_scale}")
    return c_scale


def _initial_active_set(qp: BoundQP, c_scale: float, x0: object, active0: object) -> np.ndarray:
    """(m,) bool: ``active0`` (checked), else the active set rule at ``x0``, else empty."""
    m = qp.constrained.size
    if active0 is not None:
        active = np.asarray(active0)
        if active.dtype != np.bool_ or active.shape != (m,):
            raise ValueError(f"active0 must be a boolean array of shape ({m},)")
        return active.copy()
    if x0 is not None:
        x_start = check_vector(x0, qp.n, "x0")
        c = qp.constrained
        multiplier0 = qp.F[c] - qp.ranks.sum(qp.K[c] @ x_start) if m else np.zeros(0)
        return multiplier0 + c_scale * (x_start[c] - qp.gap) > 0
    return np.zeros(m, dtype=bool)


def _iterate(
    system: ActiveSetSystem,
    active: np.ndarray,
    c_scale: float,
    max_iter: int,
    history: list[PDASStep],
    rule: InexactRule,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, tuple[str, str] | None]:
    """The PDAS loop from ``active``, appending one step per solve to ``history``; with an
    iterative solver a repeated active set is confirmed by a tight solve first (``rule``,
    :mod:`.inexact`).

    Returns
    -------
    x : (n,) float array
        The last iterate.
    multiplier : (m,) float array
        Its multiplier, zero off the active set.
    active : (m,) bool array
        The active set of ``x`` (converged), or the one to use next (``max_iter`` reached).
    failure : (reason, message) or None
        ``reason`` is ``"cycling"`` or ``"max_iter"``; None when the active set repeated.
    """
    qp = system.qp
    c, g = qp.constrained, qp.gap
    force = np.abs(qp.F).max(initial=0.0)
    seen = {active.tobytes(): 1}  # active set -> iteration that used it
    previous = active.copy()
    for it in range(1, max_iter + 1):
        x, multiplier = system.solve(active)
        multiplier = np.where(active, multiplier, 0.0)
        history.append(PDASStep.between(it, "pdas", previous, active))
        logger.debug("PDAS %s", history[-1])
        value = multiplier + c_scale * (x[c] - g)
        bands = _bands(system, active, multiplier, force, c_scale, x)
        new_active = _update_active_set(active, value, bands)
        if np.array_equal(new_active, active):
            if rule.stop():
                return x, multiplier, active, None
            seen, previous = {active.tobytes(): it + 1}, active  # solve it again, tightly
            continue
        key = new_active.tobytes()
        if key in seen and not rule.tight:  # a cycle of loose solves: go on with tight ones
            rule.tighten()
            seen = {}
        if key in seen:
            message = (
                f"PDAS cycles: the active set computed in iteration {it} "
                f"is the one iteration {seen[key]} used"
            )
            return x, multiplier, active, ("cycling", message)
        seen[key] = it + 1
        previous, active = active, new_active
    message = f"PDAS did not converge in max_iter = {max_iter} iterations"
    return x, multiplier, active, ("max_iter", message)


def _bands(
    system: ActiveSetSystem,
    active: np.ndarray,
    multiplier: np.ndarray,
    force: float,
    c_scale: float,
    x: np.ndarray,
) -> np.ndarray:
    """The round-off band of each constraint for :func:`_update_active_set` (docs/method.md,
    *Solver*): on an inactive one ``_ACTIVE_RTOL max(max |F|, c max |x|)`` (on ``c (x - g)``,
    a displacement band), on an active one ``max(_ACTIVE_RTOL max(max |F|, Σ Λ⁺),
    _FORCE_ROUNDOFF max (|K| |x|)_c)`` (on Λ: relative to the forces, at least Λ's round-off).

    Returns
    -------
    (m,) float array
    """
    inactive_band = _ACTIVE_RTOL * max(force, c_scale * np.abs(x).max(initial=0.0))
    if not active.any():
        return np.full(active.size, inactive_band)
    contact = float(np.maximum(multiplier, 0.0).sum())
    round_off = system.ranks.max(float(abs_matvec(system.K_c, x).max(initial=0.0)))
    active_band = max(_ACTIVE_RTOL * max(force, contact), _FORCE_ROUNDOFF * round_off)
    return np.where(active, active_band, inactive_band)


def _update_active_set(active: np.ndarray, value: np.ndarray, bands: np.ndarray) -> np.ndarray:
    """The active set rule ``Λ + c (x - g) > 0`` with a round-off band (docs/method.md,
    *Solver*).

    A constraint whose ``|Λ + c (x - g)|`` is at most its band (:func:`_bands`) keeps its
    state in ``active``: there both Λ and ``x - g`` are round-off, either state satisfies the
    KKT conditions to round-off, and deciding by their sign makes PDAS cycle on degenerate
    complementarity.

    Parameters
    ----------
    active : (m,) bool array
        The active set of the last solve.
    value : (m,) float array
        ``Λ + c (x_c - g)`` of the last solve (Λ on the active set, ``c (x_c - g)`` off it).
    bands : (m,) float array

    Returns
    -------
    (m,) bool array
    """
    return np.where(np.abs(value) <= bands, active, value > 0)


def _after_failure(
    system: ActiveSetSystem,
    x: np.ndarray,
    active: np.ndarray,
    failure: tuple[str, str],
    fallback: bool,
    history: list[PDASStep],
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Raise :class:`PDASConvergenceError`, or (``fallback``) finish with the primal active
    set method from ``x``; returns its ``x``, multiplier and active set."""
    reason, message = failure
    if not fallback:
        raise PDASConvergenceError(
            message + " (to finish with a primal active set method instead, pass fallback=True to "
            "solve() or adaptive(), or --fallback to signorini run)",
            history,
            reason,
            x=x,
            active=active,
        )
    logger.warning("%s; finishing with the primal active set method", message)
    qp = system.qp
    force = max(np.abs(qp.F).max(initial=0.0), np.abs(qp.matvec(x)).max(initial=0.0), 1e-300)
    return primal_active_set(system, x, force, 10 * active.size + 50, history)
