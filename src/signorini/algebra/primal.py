"""The primal active set method: the fallback when PDAS cycles or reaches its bound.

Finite and monotone in the objective (Nocedal and Wright [1]_, section 16.5), warm started
from the last PDAS iterate and solving its equality problems on the same fixed-pattern system
(:class:`~.active_system.ActiveSetSystem`), so it reuses the PDAS factorization pattern.

References
----------
.. [1] J. Nocedal, S. J. Wright, Numerical Optimization, 2nd ed., Springer 2006, section 16.5
   (primal active set method for convex QP).
"""

from __future__ import annotations

import numpy as np

from .active_system import ActiveSetSystem
from .errors import PDASConvergenceError
from .result import PDASStep

__all__ = ["primal_active_set"]


def primal_active_set(
    system: ActiveSetSystem,
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

    Parameters
    ----------
    system : ActiveSetSystem
    x : (n,) float array
        Start (the last PDAS iterate).
    force_scale : float
        Size of the forces: a multiplier above ``-1e-12 force_scale`` counts as non-negative.
    max_iter : int
        Bound on the number of solves.
    history : list of PDASStep
        Appended to, one step per solve.

    Returns
    -------
    x : (n,) float array
    multiplier : (m,) float array
        Zero off the working set.
    active : (m,) bool array
        The final working set.

    Raises
    ------
    PDASConvergenceError
        If ``max_iter`` solves do not finish.
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
        x_star, multiplier = system.solve(work)
        history.append(PDASStep.between(len(history) + 1, "primal-active-set", previous, work))
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
        multiplier = np.where(work, multiplier, 0.0)
        k = int(np.argmin(multiplier)) if c.size else 0
        if c.size == 0 or multiplier[k] >= -tol:
            return x, multiplier, work
        work = work.copy()
        work[k] = False
    raise PDASConvergenceError(
        f"the primal active set fallback did not finish in {max_iter} steps",
        history[start:],
        "max_iter",
        x=x,
        active=work,
    )
