"""Frictional contact by a primal-dual active set (semismooth Newton) method, in node frames.

The problem (:mod:`.friction.kkt`; docs/method.md, *Friction: the algebraic problem and its
solver*): at each frictional contact node a normal DOF ``x_n ≤ g`` with the Signorini
conditions, and a tangential DOF with the node's friction law (:mod:`.laws`; its slip bound
``s``, e.g. Tresca's given bound or Coulomb's ``F Λ_n`` in the static one-step form; laws may
differ from node to node), on the slip ``x_t − x_ref`` relative to a reference
tangential displacement (the previous load step's in a quasi-static path). ``Λ = F − K x``
on these rows are the nodal contact forces.

The method of Hüeber, Stadler and Wohlmuth [1]_ in its 2D form: every node is
:data:`~.friction.result.INACTIVE`, :data:`~.friction.result.STICK` or
:data:`~.friction.result.SLIP` (with a slip direction σ = ±1); one iteration solves the
linear system of these states (:mod:`.friction.system`) and updates them with the rule

- in contact where ``Λ_n + c (x_n − g) > 0``;
- among those (and out of contact where a law acts everywhere), stick where
  ``|Λ_t + c (x_t − x_ref)| < s``, with ``s`` the law's bound at ``Λ_n + c (x_n − g)``, else
  slip with ``σ = sign(Λ_t + c (x_t − x_ref))``,

the semismooth Newton step for the equations ``Λ_n = max(0, Λ_n + c (x_n − g))`` and
``Λ_t = P_[−s, s](Λ_t + c (x_t − x_ref))``, of which in 2D the slip branch ``Λ_t = σ s`` is
linear. It stops when the states repeat, and then checks the KKT residuals of both laws.
Once the states cycle, each iteration changes one node only (the least-index rule,
:func:`~.friction.rule.one_change`); where Coulomb's states cycle even so, the fixed point
on its slip bound finishes the solve (:mod:`.friction.fixed_point`; docs/method.md, *When
the iteration cycles*).
The constant ``c`` is :data:`C_FACTOR` times the mean diagonal of ``K`` over the normal DOFs,
not the diagonal itself as in :func:`~.pdas.solve_pdas`: it only decides whether a node
slipping against its force sticks (small ``c``) or flips its direction (large ``c``), and
flipping made the iteration cycle (docs/method.md, *Friction*).

When every law in play has a bound independent of ``Λ_n`` (Tresca) the systems are SPD;
otherwise they are solved by LU (:mod:`.friction.system`). A Tresca bound acts on every node
(``everywhere``), the classical Tresca problem: the minimisation of
``1/2 x^T K x − F^T x + Σ s |x_t − x_ref|`` subject to ``x_n ≤ g``; or only on nodes in
contact (``Λ_n > 0``, where the bound models a known contact pressure), which is
discontinuous where ``Λ_n`` vanishes and can make the iteration cycle at the edge of the
contact zone (docs/method.md, *Friction*).

References
----------
.. [1] S. Hüeber, G. Stadler, B. I. Wohlmuth, A primal-dual active set algorithm for
   three-dimensional contact problems with Coulomb friction, SIAM J. Sci. Comput. 30 (2008)
   572-596.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass

import numpy as np

from ..backends.selection import make_solver
from ..backends.solvers import SolverFactory, SPDSolver, solver_usage
from ..errors import FrictionConvergenceError
from ..inexact import InexactRule
from ..qp import check_vector
from .fixed_point import solve_by_fixed_point
from .kkt import FrictionProblem, friction_kkt
from .result import INACTIVE, SLIP, STICK, FrictionResult, FrictionStep
from .rule import (
    States,
    iteration_step,
    multipliers,
    node_state,
    one_change,
    states_key,
    update_states,
)
from .system import CoupledSystem, SymmetricSystem, friction_system

__all__ = ["INACTIVE", "SLIP", "STICK", "FrictionOptions", "solve_friction"]

logger = logging.getLogger(__name__)

#: The default constant ``c`` of the update rule, relative to the mean diagonal of ``K`` over
#: the normal DOFs (docs/method.md, *Friction*). Measured on the pressed block of the tests
#: (65-129 nodes, Tresca and Coulomb): 10⁻² to 10⁻⁸ give the same iterations; 1 cycles.
C_FACTOR = 1e-6


@dataclass(frozen=True)
class FrictionOptions:
    """How :func:`solve_friction` iterates.

    Attributes
    ----------
    max_iter : int
        Bound on iterations (linear solves).
    kkt_tol : float
        Largest relative KKT residual (:class:`~.friction.kkt.FrictionKKT`) accepted when the
        states repeat.
    c : float, optional
        The positive constant of the update rule; default :data:`C_FACTOR` times the mean
        diagonal of ``K`` over the normal DOFs (docs/method.md, *Friction*: with the mean
        diagonal itself, as in :func:`~.pdas.solve_pdas`, the slip directions flip and the
        iteration cycles).

    Raises
    ------
    ValueError
        Naming the attribute, for a ``max_iter`` below 1, a ``kkt_tol`` or ``c`` not positive.
    """

    max_iter: int = 50
    kkt_tol: float = 1e-8
    c: float | None = None

    def __post_init__(self) -> None:
        max_iter, kkt_tol = self.max_iter, self.kkt_tol
        if (
            isinstance(max_iter, bool)
            or not isinstance(max_iter, (int, np.integer))
            or max_iter < 1
        ):
            raise ValueError(f"max_iter must be a positive integer, got {max_iter!r}")
        if not isinstance(kkt_tol, (int, float)) or not kkt_tol > 0:
            raise ValueError(f"kkt_tol must be a positive number, got {kkt_tol!r}")
        if self.c is not None:
            try:
                value = float(self.c)
            except (TypeError, ValueError):
                raise ValueError(f"c must be a positive number, got {self.c!r}") from None
            if not np.isfinite(value) or value <= 0:
                raise ValueError(f"c must be positive and finite, got {value}")


def solve_friction(
    problem: FrictionProblem,
    *,
    state0: np.ndarray | None = None,
    direction0: np.ndarray | None = None,
    x0: np.ndarray | None = None,
    options: FrictionOptions | None = None,
    solver: SPDSolver | SolverFactory | None = None,
) -> FrictionResult:
    r"""Solve the frictional contact problem (laws per node) by semismooth Newton.

    Parameters
    ----------
    problem : FrictionProblem
        The checked data (:func:`~.friction.kkt.check_friction`): ``K``, ``F``, the normal
        and tangential DOFs, gaps, Dirichlet data, the laws per node and their weights, the
        reference of no slip.
    state0, direction0 : (m,) int arrays, optional
        Warm start: the states (:data:`INACTIVE`, :data:`STICK`, :data:`SLIP`) and slip
        directions (±1 where slipping, else 0) of a previous result. ``direction0`` is
        required where ``state0`` is SLIP at a node whose bound can be positive.
    x0 : (n,) float array, optional
        Warm start by the update rule at ``x0`` (ignored when ``state0`` is given). Default
        (neither): every node INACTIVE.
    options : FrictionOptions, optional
        ``max_iter``, ``kkt_tol``, ``c``; default :class:`FrictionOptions`\ ().
    solver : SPDSolver or SolverFactory, optional
        An :class:`SPDSolver` to use and keep (not closed): SPD when every law is symmetric,
        else LU. A factory (:class:`~.solvers.SolverFactory`, default
        :func:`~.selection.auto_solver`) makes the kind the laws need for this call.

    Returns
    -------
    FrictionResult

    Raises
    ------
    ValueError
        For malformed input, naming the argument.
    FrictionConvergenceError
        If the states cycle, ``max_iter`` is reached, or the KKT residuals exceed ``kkt_tol``
        when the states repeat; it carries the history.
    signorini.algebra.backends.solvers.FactorizationError
        If a system is singular.
    """
    t_start = time.perf_counter()
    method, inner_assembly = "semismooth-newton", 0.0
    if not isinstance(problem, FrictionProblem):
        raise ValueError(
            f"problem must be a FrictionProblem (from check_friction), got {type(problem).__name__}"
        )
    options = FrictionOptions() if options is None else options
    if not isinstance(options, FrictionOptions):
        raise ValueError(f"options must be a FrictionOptions, got {type(options).__name__}")
    rule = _rule_constants(problem, options.c)
    states = _initial_states(problem, rule, state0, direction0, x0)
    own_solver = not isinstance(solver, SPDSolver)
    if own_solver:
        solver = make_solver(solver, symmetric=problem.symmetric)
    before = solver_usage(solver)
    try:
        system = friction_system(problem, solver)
        with InexactRule(solver) as inexact:  # an iterative solver's stopping rule
            try:
                x, states, history = _iterate(system, states, rule, options.max_iter, inexact)
            except FrictionConvergenceError as failed:
                if failed.reason != "cycling" or system.symmetric:
                    raise
                # Coulomb's states cycle: the fixed point on its slip bound finishes
                x, states, history, inner_assembly = solve_by_fixed_point(
                    system, failed, (rule, _rule_constants(problem, None)), options,
                    lambda *args: _iterate(*args, inexact),
                )  # fmt: skip
                method = "fixed-point"
    finally:
        used = {key: value - before[key] for key, value in solver_usage(solver).items()}
        backend_name = solver.backend
        if own_solver:
            solver.close()
    active, stick, direction = states
    kkt = friction_kkt(problem, x, active)
    if not kkt.max <= options.kkt_tol:
        message = (
            f"the states repeat, but the KKT residual {kkt.max:.2e} exceeds {options.kkt_tol:.0e}"
        )
        direction = direction.astype(np.int8)
        raise FrictionConvergenceError(message, history, "kkt", x, node_state(*states), direction)
    multiplier_n, multiplier_t = multipliers(problem, x, states)
    times = {key: used[key] for key in ("analysis", "factorization", "solve")}
    times["assembly"] = system.time_assembly + inner_assembly
    times["total"] = time.perf_counter() - t_start
    state = node_state(active, stick, direction)
    logger.info(
        "friction (%s systems, %s): %d solves, stick %d, slip %d of %d nodes, KKT residual %.2e",
        "symmetric" if system.symmetric else "non-symmetric",
        method,
        len(history),
        int((state == STICK).sum()),
        int((state == SLIP).sum()),
        problem.m,
        kkt.max,
    )
    return FrictionResult(
        x=x,
        multiplier_n=multiplier_n,
        multiplier_t=multiplier_t,
        state=state,
        direction=direction.astype(np.int8),
        iterations=len(history),
        n_solves=len(history),
        history=history,
        kkt=kkt,
        backend=backend_name,
        symmetric=system.symmetric,
        method=method,
        c_scale=rule[0],
        n_factorizations=int(used["n_factorizations"]),
        n_analyses=int(used["n_analyses"]),
        times=times,
    )


# ----------------------------------------------------------------------------------------------
# The steps of solve_friction
# ----------------------------------------------------------------------------------------------


def _cycle_hint(p: FrictionProblem) -> str:
    """What to do where the iteration cycles one node at a time too."""
    law = p.friction
    in_contact = p.symmetric and bool((law.can_rub & ~law.everywhere).any())
    return (
        "A Tresca bound acting only in contact is discontinuous where the contact force "
        "vanishes: the classical law, Tresca(..., everywhere=True), is not; else apply the "
        "load in more steps"
        if in_contact
        else "Apply the load in more steps"
    ) + " (a load path: docs/method.md, *Load paths*)"


def _rule_constants(problem: FrictionProblem, c: float | None) -> tuple[float, float]:
    """``(c, d)``: the constant of the update rule (given, or :data:`C_FACTOR`
    ``d``) and the mean diagonal ``d`` of ``K`` over the normal DOFs (1 without nodes)."""
    diagonal = problem.qp.diagonal()[problem.normal]
    d = float(diagonal.mean()) if diagonal.size else 1.0
    return (C_FACTOR * d, d) if c is None else (float(c), d)


def _initial_states(
    problem: FrictionProblem,
    rule: tuple[float, float],
    state0: object,
    direction0: object,
    x0: object,
) -> States:
    """The states of the first solve: decoded from ``state0``/``direction0`` (checked), the
    update rule at ``x0``, or every node inactive."""
    m = problem.m
    law = problem.friction
    none = np.zeros(m, dtype=bool), np.zeros(m, dtype=bool), np.zeros(m)
    if state0 is None:
        if x0 is None:  # no contact; where a law acts everywhere, stick where it can rub
            return none[0], law.can_rub & law.everywhere, none[2]
        x = check_vector(x0, problem.qp.n, "x0")
        r = problem.qp.F - problem.qp.matvec(x)
        return update_states(problem, rule, x, r[problem.normal], r[problem.tangent_2d], none)
    state = np.asarray(state0)
    if state.shape != (m,) or not np.isin(state, (INACTIVE, STICK, SLIP)).all():
        raise ValueError(f"state0 must have shape ({m},) and hold INACTIVE, STICK or SLIP")
    forced = law.can_rub
    if direction0 is None:
        if (forced & (state == SLIP)).any():
            raise ValueError("direction0 is needed where state0 is SLIP")
        direction = np.zeros(m)
    else:
        direction = np.asarray(direction0)
        if direction.shape != (m,) or not np.isin(direction, (-1, 0, 1)).all():
            raise ValueError(f"direction0 must have shape ({m},) and hold -1, 0 or 1")
        direction = direction.astype(np.float64)
    active = state != INACTIVE
    stick = state == STICK
    # out of contact where a law acts everywhere: direction 0 means stuck (FrictionResult)
    stick |= law.everywhere & ~active & (direction == 0) & forced
    return active, stick, np.where(stick, 0.0, direction)


def _iterate(
    system: SymmetricSystem | CoupledSystem,
    states: States,
    rule: tuple[float, float],
    max_iter: int,
    inexact: InexactRule,
) -> tuple[np.ndarray, States, list[FrictionStep]]:
    """The active set loop from ``states``: the last iterate, its states and the history.
    With an iterative solver, repeated states are confirmed by a tight solve first
    (``inexact``, :mod:`.inexact`).

    Raises
    ------
    FrictionConvergenceError
        On cycling (also at ``max_iter`` one node at a time, after a cycle) or at
        ``max_iter``.
    """
    p = system.problem
    history: list[FrictionStep] = []
    seen = {states_key(states): 1}
    previous, single = states, False
    for it in range(1, max_iter + 1):
        x = system.solve(*states)
        history.append(iteration_step(it, previous, states))
        logger.debug("friction %s", history[-1])
        lam_n, lam_t = multipliers(p, x, states)
        new = update_states(p, rule, x, lam_n, lam_t, states)
        if single:
            new = one_change(states, new)
        key = states_key(new)
        if key == states_key(states):
            if inexact.stop():
                return x, states, history
            seen, previous = {key: it + 1}, states  # solve them again, tightly
            continue
        if key in seen and not inexact.tight:  # a cycle of loose solves: go on tightly
            inexact.tighten()
            seen = {}
        if key in seen and not single:  # a cycle: from here on one node at a time
            logger.info("friction: the states cycle at iteration %d; one node at a time", it)
            single, new = True, one_change(states, new)
            key, seen = states_key(new), {states_key(states): it}
        if key in seen:
            message = (
                f"the frictional active set iteration cycles: the states computed in iteration "
                f"{it} are the ones iteration {seen[key]} used, one node at a time too. "
                + _cycle_hint(p)
            )
            raise FrictionConvergenceError(
                message, history, "cycling", x, node_state(*states), states[2].astype(np.int8)
            )
        seen[key] = it + 1
        previous, states = states, new
    message = f"the frictional active set iteration did not converge in max_iter = {max_iter}"
    if single:  # each step changes one node: a larger bound may be all it needs
        message += " (its states cycled, and it went on one node at a time: raise max_iter)"
    raise FrictionConvergenceError(
        message, history, "cycling" if single else "max_iter", x, node_state(*states),
        states[2].astype(np.int8),
    )  # fmt: skip
