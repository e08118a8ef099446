"""Choice of the SPD solver backend: :func:`make_solver` and :func:`available_backends`.

``"pardiso"``
    MKL PARDISO (:mod:`.pardiso`): sparse Cholesky with the symbolic analysis done once per
    pattern.
``"scipy"``
    SuperLU (:mod:`.superlu`), always there, with no reuse of the analysis.
``"auto"``
    PARDISO when it loads and solves a small test system; otherwise SuperLU, and a
    :class:`SolverFallbackWarning` says why (once per reason and process). The solver's
    :attr:`~.solvers.SPDSolver.backend` (the ``backend`` column of the history) tells which
    one was taken. Asking for ``"pardiso"`` where it cannot load raises
    :class:`~.solvers.BackendUnavailableError` with the reason.
"""

from __future__ import annotations

import warnings
from functools import cache

import scipy.sparse as sp

from .pardiso import PardisoLUSolver, PardisoSolver, pardiso_problem
from .solvers import BackendUnavailableError, SPDSolver
from .superlu import SuperLULUSolver, SuperLUSolver

__all__ = [
    "BACKENDS",
    "SolverFallbackWarning",
    "available_backends",
    "make_lu_solver",
    "make_solver",
]

#: Names accepted by :func:`make_solver` besides ``"auto"``.
BACKENDS: tuple[str, ...] = ("pardiso", "scipy")


class SolverFallbackWarning(RuntimeWarning):
    """``backend="auto"`` could not load PARDISO and uses SuperLU (much slower at 10⁵+
    unknowns)."""


@cache
def _warn_fallback(reason: str) -> None:
    """Warn once per process (and reason) that ``"auto"`` falls back to SuperLU."""
    warnings.warn(
        f"the fast sparse solver (MKL PARDISO) is not usable, falling back to SuperLU: {reason}",
        SolverFallbackWarning,
        stacklevel=4,  # the caller of make_solver (or make_lu_solver)
    )


def available_backends() -> tuple[str, ...]:
    """Backends that work on this machine, best first (``"scipy"`` is always there)."""
    return ("pardiso", "scipy") if pardiso_problem() is None else ("scipy",)


def _takes_pardiso(backend: str) -> bool:
    """Whether ``backend`` means PARDISO here: ``"pardiso"`` (raising when it cannot be
    used), ``"auto"`` when it loads and works (else a warning once); never ``"scipy"``."""
    valid = ("auto", *BACKENDS)
    if backend not in valid:
        raise ValueError(f"unknown backend {backend!r}; valid backends are {', '.join(valid)}")
    if backend == "scipy":
        return False
    problem = pardiso_problem()
    if problem is None:
        return True
    if backend == "pardiso":
        raise BackendUnavailableError(f"the pardiso backend is not usable here: {problem}")
    _warn_fallback(problem)
    return False


def make_solver(
    backend: str = "auto", A: sp.spmatrix | None = None, **options: object
) -> SPDSolver:
    """Create an SPD solver.

    Parameters
    ----------
    backend : {"auto", "pardiso", "scipy"}
        ``"auto"`` takes PARDISO when it loads and works, SuperLU otherwise (with a
        :class:`SolverFallbackWarning`).
    A : scipy sparse matrix, shape (n, n), optional
        Factorized right away if given.
    **options
        Passed to the solver class (e.g. ``check_symmetry=False``).

    Returns
    -------
    SPDSolver
        Its :attr:`~SPDSolver.backend` names the backend taken.

    Raises
    ------
    ValueError
        For an unknown backend name.
    BackendUnavailableError
        If ``"pardiso"`` is asked for and cannot be used (a :class:`RuntimeError`).
    """
    if _takes_pardiso(backend):
        return PardisoSolver(A, **options)
    return SuperLUSolver(A, **options)


def make_lu_solver(backend: str = "auto", A: sp.spmatrix | None = None) -> SPDSolver:
    """Create a sparse LU solver for general (non-symmetric) matrices, with the interface of
    :class:`~.solvers.SPDSolver` (no symmetry check).

    Parameters
    ----------
    backend : {"auto", "pardiso", "scipy"}
        ``"pardiso"``: :class:`~.pardiso.PardisoLUSolver` (analysis reused per pattern);
        ``"scipy"``: :class:`~.superlu.SuperLULUSolver`; ``"auto"`` as in
        :func:`make_solver`.
    A : scipy sparse matrix, shape (n, n), optional
        Factorized right away if given.

    Returns
    -------
    SPDSolver

    Raises
    ------
    ValueError
        For an unknown backend name.
    BackendUnavailableError
        If ``"pardiso"`` is asked for and cannot be used.
    """
    if _takes_pardiso(backend):
        return PardisoLUSolver(A)
    return SuperLULUSolver(A)
