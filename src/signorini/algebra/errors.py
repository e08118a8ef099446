"""The errors and warnings of the linear algebra: of a factorization or a solve, of a backend
that cannot be loaded, of an active set iteration that does not converge.

The bottom of :mod:`signorini.algebra`: it imports nothing of the package, so that every
module above (the backends, the active set core, the friction room) raises them without a
cycle. The steps an iteration's error carries (:class:`~.result.PDASStep`,
:class:`~.friction.result.FrictionStep`) are only formatted here, by their ``str``.
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "SINGULAR_CAUSES",
    "BackendUnavailableError",
    "ConvergenceError",
    "FactorizationError",
    "FrictionConvergenceError",
    "IllConditionedWarning",
    "PDASConvergenceError",
    "SingularSystemError",
    "SolverFallbackWarning",
    "with_history",
]


class FactorizationError(np.linalg.LinAlgError):
    """The matrix could not be factorized as symmetric positive definite.

    A subclass of :class:`numpy.linalg.LinAlgError` (itself a :class:`ValueError`).

    Attributes
    ----------
    backend : str
        The backend that failed.
    code : int or None
        The backend's error code (PARDISO's ``error``), if any.
    equation : int or None
        0-based index of the equation where a non-positive pivot was met, if known.
    """

    def __init__(
        self,
        message: str,
        *,
        backend: str = "",
        code: int | None = None,
        equation: int | None = None,
    ) -> None:
        super().__init__(message)
        self.backend = backend
        self.code = code
        self.equation = equation


#: What usually makes a stiffness matrix singular in floating point; ends the messages of
#: :class:`SingularSystemError` and of a failed factorization in an active set solve.
SINGULAR_CAUSES = (
    "Usually a part of the body is not held: it has no Dirichlet condition and can move "
    "rigidly. A body so slender that its stiffness matrix is singular in double precision "
    "does the same (measured with P2 on cantilevers of length/thickness L/h: within 1 % of "
    "beam theory up to L/h = 1000, 1 % off at 1500, refused from 2000). So does a contrast "
    "of stiffness between regions of about 1e12 or more, or a region close to incompressible "
    "beside others, with every part held: ContactProblem warns about those, naming the "
    "regions and the ratio of their moduli."
)


class SingularSystemError(FactorizationError):
    """A solve whose residual shows the matrix is singular or too ill-conditioned.

    Raised whatever the backend, when the relative residual ``max |b - A x| / max |b|`` of a
    solve exceeds its bound: a factorization that went through with a near-zero pivot gives
    a garbage solution that only its residual reveals.

    Attributes
    ----------
    residual : float
        The relative residual of the failed solve.
    """

    def __init__(self, message: str, *, backend: str = "", residual: float = np.nan) -> None:
        super().__init__(message, backend=backend)
        self.residual = residual


class IllConditionedWarning(RuntimeWarning):
    """A linear system was solved, but so ill-conditioned that its solution may have lost
    digits; the message gives the estimated relative error."""


class BackendUnavailableError(RuntimeError):
    """A solver backend that was asked for cannot be loaded here; the message says why."""


class SolverFallbackWarning(RuntimeWarning):
    """The ``"auto"`` backend could not load PARDISO and uses SuperLU (much slower at 10⁵+
    unknowns)."""


def with_history(message: str, history: list) -> str:
    """An error message followed by the last 20 steps of an iteration's history."""
    lines = "\n".join(str(step) for step in history[-20:])
    skipped = f"\n  ({len(history) - 20} earlier steps not shown)" if len(history) > 20 else ""
    return f"{message}\niteration history:{skipped}\n{lines}"


class ConvergenceError(RuntimeError):
    """An active set iteration (PDAS or the frictional semismooth Newton method) cycled, hit
    its bound, or stopped at a point whose KKT residuals are too large.

    Attributes
    ----------
    history : list
        The steps of the iteration.
    reason : str
        ``"cycling"``, ``"max_iter"`` or ``"kkt"``.
    x : numpy array or None
        The last iterate.
    """

    def __init__(self, message: str, history: list, reason: str, x: np.ndarray | None) -> None:
        super().__init__(with_history(message, history))
        self.history = history
        self.reason = reason
        self.x = x


class PDASConvergenceError(ConvergenceError):
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
        history: list,
        reason: str,
        x: np.ndarray | None = None,
        active: np.ndarray | None = None,
    ) -> None:
        super().__init__(message, history, reason, x)
        self.active = active


class FrictionConvergenceError(ConvergenceError):
    """The frictional active set iteration cycled, hit its bound, or stopped at a point whose
    KKT residuals are too large.

    Attributes
    ----------
    history : list of FrictionStep
    reason : str
        ``"cycling"``, ``"max_iter"`` or ``"kkt"``.
    x, state, direction : numpy arrays
        The last iterate and the states used for it.
    """

    def __init__(
        self,
        message: str,
        history: list,
        reason: str,
        x: np.ndarray | None = None,
        state: np.ndarray | None = None,
        direction: np.ndarray | None = None,
    ) -> None:
        super().__init__(message, history, reason, x)
        self.state = state
        self.direction = direction
