"""Coulomb friction by the fixed point on its slip bound: the fallback of the semismooth Newton
method where its node states cycle, one node at a time too (docs/method.md, *When the
iteration cycles*).

Coulomb's problem is a fixed point of Tresca's: with the slip bound ``s = F Λ_n`` given, the
problem is the classical Tresca problem (a convex minimisation, bound on every node), whose
solution gives a new ``Λ_n``. The map ``s ↦ F Λ_n(s)`` is a contraction for small ``F``
(Nečas, Jarušek and Haslinger [1]_; Haslinger, Hlaváček, Nečas [2]_), so the iteration

    s_{k+1} = s_k + ω (F Λ_n(s_k) − s_k),   ω = 1, halved while the step grows (to 1/16),

converges where the coupled semismooth Newton method, which linearises ``s = F Λ_n`` inside
its systems, may cycle between node states (a large constant ``c``, a curved contact zone
of two bodies with small forces at its ends). Each inner Tresca problem is solved by the
same active set method (:func:`~.newton._iterate`) on one :class:`~.friction.system.
CoupledSystem` whose slip bounds change between the outer iterations
(:meth:`~.friction.system.CoupledSystem.rebound`): with the node states unchanged the new
bound only changes the load, and the solve reuses the LU. When the inner states repeat from
one outer iteration to the next, the coupled iteration is tried again from them; from the
states of the solution it converges in one solve (quadratic convergence restored). The
fixed point stops when the Coulomb KKT residuals (:func:`~.friction.kkt.friction_kkt`) meet
the tolerance.

References
----------
.. [1] J. Nečas, J. Jarušek, J. Haslinger, On the solution of the variational inequality to
   the Signorini problem with small friction, Boll. Un. Mat. Ital. B 17 (1980) 796-811.
.. [2] J. Haslinger, I. Hlaváček, J. Nečas, Numerical methods for unilateral problems in
   solid mechanics, Handbook of Numerical Analysis IV (1996) 313-485, Sec. 3.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import replace

import numpy as np

from ..errors import FrictionConvergenceError
from .kkt import FrictionProblem, friction_kkt
from .laws import LawGroups
from .result import INACTIVE, STICK, FrictionStep
from .system import CoupledSystem

__all__ = ["GivenBound", "solve_by_fixed_point"]

logger = logging.getLogger(__name__)

#: The smallest damping factor ω of the bound's update.
MIN_DAMPING = 1.0 / 16.0

States = tuple[np.ndarray, np.ndarray, np.ndarray]


class GivenBound:
    """The law of the inner problems: the slip bound is the node's weight, on every node
    (classical Tresca with a bound per node, force units)."""

    symmetric = True
    everywhere = True

    def nodal_weight(self, integrate, size: int) -> np.ndarray:  # not asked: no mesh here
        raise NotImplementedError("GivenBound takes its weights as bounds per node")

    def slip_bound(self, weight, normal_force, in_contact) -> np.ndarray:
        return np.asarray(weight, dtype=np.float64)

    def bound_derivative(self, weight, in_contact) -> np.ndarray:
        return np.zeros(np.shape(weight))


def solve_by_fixed_point(
    system: CoupledSystem,
    failed: FrictionConvergenceError,
    rules: tuple[tuple[float, float], tuple[float, float]],
    options,
    iterate: Callable,
) -> tuple[np.ndarray, States, list[FrictionStep], float]:
    """Finish the frictional problem of ``system`` after its coupled iteration ``failed``.

    Parameters
    ----------
    system : CoupledSystem
        The coupled systems of the problem (their LU solver is used for the inner ones too).
    failed : FrictionConvergenceError
        The cycling of the coupled iteration: its last iterate and states are the start.
    rules : ((c, d), (c, d))
        The constants of the update rule of the coupled iteration and of the inner ones.
    options : FrictionOptions
        ``max_iter`` bounds the outer iterations and each inner one; ``kkt_tol`` stops.
    iterate : callable
        The active set loop, ``iterate(system, states, rule, max_iter) -> (x, states,
        history)``, raising :class:`FrictionConvergenceError`.

    Returns
    -------
    x : (n,) float array
    states : the node states of ``x`` (active, stick, direction)
    history : list of FrictionStep
        The failed iteration's steps, then the inner and the retried coupled ones.
    time_assembly : float
        Seconds the inner systems spent forming the systems.

    Raises
    ------
    FrictionConvergenceError
        If the fixed point does not meet ``kkt_tol`` in ``max_iter`` outer iterations, or an
        inner iteration fails; the message says what to do.
    """
    p = system.problem
    rule, inner_rule = rules
    history = list(failed.history)
    x = failed.x
    states = _decoded(failed.state, failed.direction)
    s = p.slip_bound(_normal_force(p, x, states[0]), states[0])
    groups = LawGroups((GivenBound(),), np.where(p.friction.can_rub, 0, -1), s)
    inner = CoupledSystem(replace(p, friction=groups), system.solver)
    omega, last_step, tried, settled = 1.0, np.inf, set(), None
    for outer in range(1, options.max_iter + 1):
        inner.rebound(s)
        try:
            x, inner_states, steps = iterate(inner, states, inner_rule, options.max_iter)
        except FrictionConvergenceError as err:
            history += _renumbered(err.history, history)
            message = f"the inner Tresca iteration of fixed point {outer} failed"
            raise _advice(message, history) from err
        history += _renumbered(steps, history)
        states = _for_law(p, inner_states)
        lam_n = _normal_force(p, x, states[0])
        target = p.slip_bound(lam_n, states[0])
        kkt = friction_kkt(p, x, states[0])
        step = float(np.abs(target - s).max(initial=0.0))
        logger.debug(
            "friction fixed point %d: bound step %.3e, omega %g, KKT %.2e", outer, step, omega,
            kkt.max,
        )  # fmt: skip
        if kkt.max <= options.kkt_tol:
            logger.info("friction: the fixed point on the slip bound converged in %d", outer)
            return x, states, history, inner.time_assembly
        key = _key(states)
        if key == settled and key not in tried:  # the states repeat: Newton from them
            tried.add(key)
            try:
                x, states, steps = iterate(system, states, rule, options.max_iter)
            except FrictionConvergenceError as err:
                history += _renumbered(err.history, history)
            else:
                history += _renumbered(steps, history)
                logger.info("friction: the coupled iteration converged after %d", outer)
                return x, states, history, inner.time_assembly
        settled = key
        if step > last_step:
            omega = max(omega / 2, MIN_DAMPING)
        last_step = step
        s = s + omega * (target - s)
    raise _advice(
        f"the fixed point on the Coulomb slip bound did not reach the KKT tolerance "
        f"{options.kkt_tol:.0e} in max_iter = {options.max_iter} outer iterations (last "
        f"residual {kkt.max:.2e})",
        history,
    )


def _decoded(state: np.ndarray, direction: np.ndarray) -> States:
    return state != INACTIVE, state == STICK, direction.astype(np.float64)


def _normal_force(p: FrictionProblem, x: np.ndarray, active: np.ndarray) -> np.ndarray:
    """``Λ_n = F_n − (K x)_n`` in contact, 0 elsewhere."""
    r = p.qp.F - p.qp.matvec(x)
    return np.where(active, r[p.normal], 0.0)


def _for_law(p: FrictionProblem, states: States) -> States:
    """The inner states as states of ``p``'s laws: out of contact, no friction force where
    the law acts only in contact (the inner bound acts everywhere)."""
    active, stick, direction = states
    off = ~active & ~p.friction.everywhere
    return active, stick & ~off, np.where(off | stick, 0.0, direction)


def _key(states: States) -> bytes:
    active, stick, direction = states
    return active.tobytes() + stick.tobytes() + direction.astype(np.int8).tobytes()


def _renumbered(steps: list[FrictionStep], before: list[FrictionStep]) -> list[FrictionStep]:
    """``steps`` numbered on after those of ``before`` (one count of solves per call)."""
    return [replace(step, iteration=len(before) + k + 1) for k, step in enumerate(steps)]


def _advice(message: str, history: list[FrictionStep]) -> FrictionConvergenceError:
    return FrictionConvergenceError(
        f"the frictional active set iteration cycles, and {message}. Apply the load in more "
        "steps (a load path: docs/method.md, *Load paths*), refine where the contact zone "
        "ends, or check that the friction coefficient is small (the Coulomb problem may have "
        "no unique solution for large F)",
        history,
        "cycling",
    )
