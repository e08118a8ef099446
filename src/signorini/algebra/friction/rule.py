"""The update rule of the frictional active set method (:mod:`.friction.newton`): the node states
of the next iteration from an iterate, and the records of an iteration.

The states are ``(active, stick, direction)``: ``(m,)`` bool, bool and float (±1 where a
node slips with a positive bound, 0 elsewhere).
"""

from __future__ import annotations

import numpy as np

from .kkt import FrictionProblem
from .result import INACTIVE, SLIP, STICK, FrictionStep

__all__ = [
    "States",
    "iteration_step",
    "multipliers",
    "node_state",
    "one_change",
    "states_key",
    "update_states",
]

#: Relative band in which a node keeps its state (as ``_ACTIVE_RTOL`` in :mod:`.pdas`): where
#: ``|Λ_n + c (x_n − g)|`` or ``| |Λ_t + c (x_t − x_ref)| − s |`` is at most this times
#: ``max(max |F|, c max |x|)``, both states satisfy the laws to round-off.
STATE_RTOL = 1e-9

States = tuple[np.ndarray, np.ndarray, np.ndarray]  # active, stick (m,) bool; direction (m,)


def update_states(
    p: FrictionProblem,
    rule: tuple[float, float],
    x: np.ndarray,
    lam_n: np.ndarray,
    lam_t: np.ndarray,
    states: States,
) -> States:
    """The update rule (module docstring) with a round-off band.

    A node keeps its state where the decision is round-off. Of the two terms of
    ``Λ_n + c (x_n − g)`` and of ``Λ_t + c (x_t − x_ref)``, one is imposed exactly by the last
    solve and the other is computed, so the band is that of the computed one:
    :data:`STATE_RTOL` ``max(max |F|, d max |x|)`` for a residual ``Λ`` (as in :mod:`.pdas`),
    ``c`` :data:`STATE_RTOL` ``max |x|`` for a displacement.

    Parameters
    ----------
    p : FrictionProblem
    rule : (c, d)
        The constant of the rule and the mean diagonal of ``K`` over the normal DOFs.
    x : (n,) float array
        The last iterate.
    lam_n, lam_t : (m,) float arrays
        Its multipliers (``lam_n`` zero off contact, ``lam_t`` its imposed value off stick).
    states : the states of the last solve

    Returns
    -------
    active, stick : (m,) bool arrays
    direction : (m,) float array
        ±1 where slipping with a positive bound, 0 elsewhere.
    """
    active, stick, direction = states
    c, d = rule
    scale_x = np.abs(x).max(initial=0.0)
    band_force = STATE_RTOL * max(np.abs(p.qp.F).max(initial=0.0), d * scale_x)
    band_disp = c * STATE_RTOL * scale_x
    value_n = lam_n + c * (x[p.normal] - p.gap)
    band_n = np.where(active, band_force, band_disp)
    new_active = np.where(np.abs(value_n) <= band_n, active, value_n > 0)
    s = p.slip_bound(value_n, new_active)
    acts = p.friction.everywhere | new_active
    y = lam_t + c * (x[p.tangent_2d] - p.reference)
    margin = np.abs(y) - s
    band_t = np.where(stick, band_force, band_disp)
    new_stick = np.where(np.abs(margin) <= band_t, stick, margin < 0) & acts
    slip = acts & ~new_stick & p.friction.can_rub
    new_direction = np.where(slip, np.where(np.abs(y) > band_t, np.sign(y), direction), 0.0)
    return new_active, new_stick, new_direction


def states_key(states: States) -> bytes:
    active, stick, direction = states
    return active.tobytes() + stick.tobytes() + direction.astype(np.int8).tobytes()


def node_state(active: np.ndarray, stick: np.ndarray, direction: np.ndarray) -> np.ndarray:
    """INACTIVE / STICK / SLIP per node, (m,) int8."""
    state = np.where(stick, STICK, SLIP).astype(np.int8)
    state[~active] = INACTIVE
    return state


def iteration_step(iteration: int, previous: States, states: States) -> FrictionStep:
    state = node_state(*states)
    changed = (state != node_state(*previous)) | (states[2] != previous[2])
    return FrictionStep(
        iteration=iteration,
        n_inactive=int((state == INACTIVE).sum()),
        n_stick=int((state == STICK).sum()),
        n_slip=int((state == SLIP).sum()),
        n_changed=int(changed.sum()),
    )


def multipliers(p: FrictionProblem, x: np.ndarray, states: States) -> tuple[np.ndarray, ...]:
    """``Λ_n`` (0 off contact) and ``Λ_t`` (its imposed value off stick), (m,) each."""
    active, stick, direction = states
    r = p.qp.F - p.qp.matvec(x)
    multiplier_n = np.where(active, r[p.normal], 0.0)
    imposed = direction * p.slip_bound(multiplier_n, active)
    return multiplier_n, np.where(stick, r[p.tangent_2d], imposed)


def one_change(states: States, new: States) -> States:
    """``states`` with the first node whose state or direction differs in ``new`` given
    its new ones, a slipping node whose direction reverses sticking first (the friction
    force goes from one bound of ``[−s, s]`` to the other through the inside): the
    least-index rule of Murty's principal pivoting method, which cannot cycle on a P-matrix
    complementarity problem (Murty [1]_), used by the iteration once its states have cycled
    (:func:`~.newton._iterate`). A fixed point of it is one of the rule.

    References
    ----------
    .. [1] K. G. Murty, Note on a Bard-type scheme for solving the complementarity problem,
       Opsearch 11 (1974) 123-130.
    """
    changed = (states[0] != new[0]) | (states[1] != new[1]) | (states[2] != new[2])
    first = np.flatnonzero(changed)[:1]
    active, stick, direction = (a.copy() for a in states)
    active[first], stick[first], direction[first] = new[0][first], new[1][first], new[2][first]
    # a slip that reverses passes through stick: the force moves from one bound to the other
    flip = (direction[first] == -states[2][first]) & (states[2][first] != 0)
    stick[first[flip]], direction[first[flip]] = True, 0.0
    return active, stick, direction
