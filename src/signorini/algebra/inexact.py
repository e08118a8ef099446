"""The inexact active set stopping rule, for iterative solvers (docs/parallel.md, *Inexact
active set iterations*; docs/method.md, *Solver*).

A direct solver solves every system of an active set iteration to round-off, and the
iteration stops when the active set repeats (:func:`~.pdas.solve_pdas`,
:func:`~.newton.solve_friction`). An iterative solver (:attr:`~.solvers.SPDSolver.rtol` not
None, e.g. :mod:`.petsc_gamg`) solves each system to its relative residual ``rtol`` only.
Then, in the spirit of the inexact strategy of Hüeber, Mair and Wohlmuth [1]_:

1. the iteration runs with solves to ``rtol`` until the active set (the states) repeats;
2. the system of that set is solved again to :data:`CONFIRM_RTOL`, and the active set rule
   applied to that solution; every later solve of the call is as tight;
3. the iteration stops when the set repeats after a tight solve. Its iterate is the
   solution of the final set's system to :data:`CONFIRM_RTOL`, and its KKT residuals
   (:mod:`.kkt`, :mod:`.friction.kkt`) are reported as they are; on Example 6.2 and the
   two-body tests they stay below :data:`KKT_RTOL` (tests/parallel/test_gamg.py).

A loose solve's residual is checked against the solver's own tolerance
(:func:`check_iterative`), not by the direct solves' :func:`~.active_system.refine` (whose
iterative refinement would only repeat the iterative solve), and low-rank updates, which
trust a solve to round-off, are not used.

References
----------
.. [1] S. Hüeber, M. Mair, B. I. Wohlmuth, A priori error estimates and an inexact
   primal-dual active set strategy for linear and quadratic finite elements applied to
   multibody contact problems, Appl. Numer. Math. 54 (2005) 555-576.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from .backends.solvers import SPDSolver
from .errors import SingularSystemError

__all__ = ["CONFIRM_RTOL", "KKT_RTOL", "RESIDUAL_SLACK", "InexactRule", "check_iterative"]

#: Relative residual ``‖b − A x‖₂ / ‖b‖₂`` of the solves that confirm the final active set.
CONFIRM_RTOL = 1e-14

#: The stated bound of the KKT residuals of an inexact solve's final iterate (measured on
#: Example 6.2 to 3·10⁵ unknowns, its Tresca variant and two bodies: below 1e-10).
KKT_RTOL = 1e-9

#: How far the true residual of an iterative solve may exceed its tolerance before it is
#: refused: the solver's residual is its recursively updated one, which drifts from the true
#: ``b − A x`` by round-off.
RESIDUAL_SLACK = 10.0


class InexactRule:
    """The phases of the inexact stopping rule for one call of an active set method.

    For a direct solver (``solver.rtol is None``) :meth:`stop` is True whenever the set
    repeats: the exact path is unchanged. For an iterative one, the first repeat switches
    the solver to :data:`CONFIRM_RTOL` (its ``rtol`` is restored by :meth:`close`) and only a
    repeat after that stops.

    Parameters
    ----------
    solver : SPDSolver
    """

    def __init__(self, solver: SPDSolver) -> None:
        self.solver = solver
        self.loose = getattr(solver, "rtol", None)
        self.tight = self.loose is None

    def stop(self) -> bool:
        """Called when the active set repeats: whether the iteration stops (True), or must
        confirm the set by a tight solve first (False; the solver is now tight)."""
        if self.tight:
            return True
        self.tighten()
        return False

    def tighten(self) -> None:
        """Make the solver's later solves tight (:data:`CONFIRM_RTOL`), e.g. for a
        fallback method that stops on its own test."""
        if self.loose is not None:
            self.solver.rtol = min(CONFIRM_RTOL, self.loose)
        self.tight = True

    def close(self) -> None:
        """Give the solver back its own tolerance."""
        if self.loose is not None:
            self.solver.rtol = self.loose

    def __enter__(self) -> InexactRule:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def check_iterative(
    residual: Callable[[np.ndarray], np.ndarray],
    b: np.ndarray,
    x: np.ndarray,
    solver: SPDSolver,
    norm_A: Callable[[], float],
) -> np.ndarray:
    """``x`` if its true residual meets the solver's tolerance, ``‖b − A x‖₂ ≤``
    :data:`RESIDUAL_SLACK` ``max(rtol ‖b‖₂, eps ‖A‖∞ ‖x‖₂)`` (the second term: the round-off
    of ``A x``); a :class:`~.errors.SingularSystemError` otherwise.

    Parameters
    ----------
    residual : callable (n,) -> (n,)
        ``x ↦ b − A x``.
    b, x : (n,) float arrays
    solver : SPDSolver
        An iterative solver (``rtol`` set).
    norm_A : callable () -> float
        ``‖A‖∞`` (an upper bound will do).
    """
    r = np.linalg.norm(residual(x))
    size = max(float(np.linalg.norm(b)), 1e-300)
    floor = float(np.finfo(np.float64).eps) * norm_A() * float(np.linalg.norm(x))
    if not r <= RESIDUAL_SLACK * max(solver.rtol * size, floor):  # also NaN
        raise SingularSystemError(
            f"the iterative solve's relative residual ‖b − A x‖ / ‖b‖ = {r / size:.1e} exceeds "
            f"its tolerance {solver.rtol:.0e} (backend {solver.backend})",
            backend=solver.backend,
            residual=float(r / size),
        )
    return x
