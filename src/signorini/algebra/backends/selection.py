"""The solver backends by name: the registry :data:`SOLVERS` and :func:`make_solver`.

A solver backend is a :class:`~.solvers.SolverFactory`: a callable that takes a
:class:`~.solvers.SolverRequest` and returns a new :class:`~.solvers.SPDSolver`. The
package's functions take the factory itself (``solve(problem, solver=superlu_solver)``);
names exist only here and at the command line (``--backend``), and a run folder records its
backend by name (:func:`solver_name`).

``"pardiso"``
    :func:`~.pardiso.pardiso_solver`: MKL PARDISO, sparse Cholesky or LU with the symbolic
    analysis done once per pattern; raises :class:`~.errors.BackendUnavailableError` with
    the reason where it cannot be used.
``"scipy"``
    :func:`~.superlu.superlu_solver`: SuperLU, always there, with no reuse of the analysis.
``"petsc"``
    :func:`~.petsc.petsc_solver`: MUMPS through PETSc (the optional extra ``signorini[mpi]``),
    serial or under ``mpiexec`` (docs/parallel.md); for a symmetric 3D system of
    :data:`~.petsc.GAMG_FROM_3D` unknowns or more CG + GAMG (``"petsc-gamg"``'s solver);
    raises :class:`~.errors.BackendUnavailableError` naming the extra where petsc4py is
    missing.
``"petsc-gamg"``
    :func:`~.petsc_gamg.petsc_gamg_solver`: CG preconditioned by PETSc's GAMG with the
    rigid-body near-nullspace (the extra ``signorini[mpi]``), an iterative solver with the
    inexact active set stopping rule of :mod:`.inexact`; MUMPS LU for non-symmetric systems.
``"amg"``
    :func:`~.amg.amg_solver`: CG preconditioned by pyamg's smoothed aggregation with the
    rigid-body near-nullspace, in the default install; iterative, with the inexact active
    set stopping rule of :mod:`.inexact`; SuperLU's LU for non-symmetric systems. ``"auto"``
    takes it for symmetric 3D systems from :data:`AMG_FROM_3D` unknowns (docs/method.md,
    *Three dimensions: solving elasticity*).
``"auto"``
    :func:`auto_solver`, the default everywhere: PARDISO when it loads and solves a small test
    system (``"amg"`` for a symmetric 3D system of :data:`AMG_FROM_3D` unknowns or more);
    otherwise SuperLU, and a :class:`SolverFallbackWarning` says why (once per reason
    and process). The solver's :attr:`~.solvers.SPDSolver.backend` (the ``backend`` column of
    the history) tells which one was taken.

A new backend is one module (an :class:`~.solvers.SPDSolver` subclass and its factory) and
one line of :data:`SOLVERS`.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from functools import cache

import numpy as np
import scipy
import scipy.sparse as sp

from ..errors import BackendUnavailableError, SolverFallbackWarning
from .amg import amg_solver
from .mkl import mkl_version
from .pardiso import pardiso_problem, pardiso_solver
from .petsc import petsc_library, petsc_solver
from .petsc_gamg import petsc_gamg_solver
from .solvers import SolverFactory, SolverRequest, SPDSolver
from .superlu import superlu_solver

__all__ = [
    "AMG_FROM_3D",
    "SOLVERS",
    "auto_solver",
    "available_backends",
    "make_solver",
    "solver_factory",
    "solver_library",
    "solver_name",
    "takes_ordering",
]


@cache
def _warn_fallback(reason: str) -> None:
    """Warn once per process (and reason) that ``"auto"`` falls back to SuperLU."""
    warnings.warn(
        f"the fast sparse solver (MKL PARDISO) is not usable, falling back to SuperLU: {reason}",
        SolverFallbackWarning,
        stacklevel=4,  # the caller of make_solver
    )


#: from this many unknowns on, ``"auto"`` takes ``"amg"`` for a symmetric 3D system
#: (measured: docs/method.md, *Three dimensions: solving elasticity*)
AMG_FROM_3D = 150_000


def auto_solver(request: SolverRequest) -> SPDSolver:
    """The default solver factory: PARDISO where it loads and works, else SuperLU with a
    :class:`SolverFallbackWarning` (once per process and reason); for a symmetric 3D system
    of :data:`AMG_FROM_3D` unknowns or more, ``"amg"`` (:func:`~.amg.amg_solver`)."""
    if request.multigrid_from(AMG_FROM_3D):
        return amg_solver(request)
    problem = pardiso_problem()
    if problem is None:
        return pardiso_solver(request)
    _warn_fallback(problem)
    return superlu_solver(request)


#: ``auto`` takes the ordering it is offered where it takes PARDISO (:func:`takes_ordering`)
auto_solver.takes_ordering = lambda: pardiso_problem() is None  # type: ignore[attr-defined]


def takes_ordering(solver: object) -> bool:
    """Whether the factory ``solver`` (``None``: :func:`auto_solver`) gives the solvers it
    makes the fill-reducing ordering it is offered (:attr:`~.solvers.SolverRequest.ordering`)
    for a symmetric system, so that the contact layer may compute it ahead
    (:class:`~signorini.contact.ordering.Ordering`): its attribute ``takes_ordering``, a bool
    or a function of nothing; False for a solver object (used as it is) and for a factory
    without the attribute (the ordering is then computed only if the factory asks)."""
    factory = auto_solver if solver is None else solver
    flag = getattr(factory, "takes_ordering", False)
    return bool(flag() if callable(flag) else flag)


#: The solver factories by the name the command line and a run folder's manifest use.
SOLVERS: dict[str, SolverFactory] = {
    "auto": auto_solver,
    "pardiso": pardiso_solver,
    "scipy": superlu_solver,
    "petsc": petsc_solver,
    "petsc-gamg": petsc_gamg_solver,
    "amg": amg_solver,
}


def solver_factory(name: str) -> SolverFactory:
    """The factory registered as ``name`` in :data:`SOLVERS`.

    Raises
    ------
    ValueError
        For an unknown name, listing the valid ones.
    """
    try:
        return SOLVERS[name]
    except (KeyError, TypeError):
        raise ValueError(
            f"unknown backend {name!r}; valid backends are {', '.join(SOLVERS)}"
        ) from None


def solver_name(solver: object) -> str:
    """The name under which ``solver`` (a factory) is registered in :data:`SOLVERS`.

    Raises
    ------
    ValueError
        If it is not registered (a run folder records its solver by name).
    """
    for name, factory in SOLVERS.items():
        if factory is solver:
            return name
    raise ValueError(
        f"solver {solver!r} is not a registered backend ({', '.join(SOLVERS)}): only those "
        "can be recorded by name"
    )


def available_backends(*, iterative: bool = False) -> tuple[str, ...]:
    """The registered backends (``"auto"`` aside) that make a solver on this machine, in the
    order of :data:`SOLVERS` (``"scipy"`` is always there): the direct ones, whose solves are
    exact to round-off, and with ``iterative=True`` also those that solve to a tolerance
    (:attr:`~.solvers.SPDSolver.rtol`, e.g. ``"petsc-gamg"``)."""
    names = []
    for name, factory in SOLVERS.items():
        if factory is auto_solver:
            continue
        try:
            solver = factory(SolverRequest())
        except BackendUnavailableError:
            continue
        solver.close()
        if iterative or solver.rtol is None:
            names.append(name)
    return tuple(names)


def make_solver(
    solver: SolverFactory | None = None,
    A: sp.spmatrix | None = None,
    *,
    symmetric: bool = True,
    check_symmetry: bool = True,
    ordering: Callable[[], np.ndarray] | None = None,
    rigid_modes: Callable[[], np.ndarray] | None = None,
    dimension: int = 2,
    size: int = 0,
    coupled: bool = False,
) -> SPDSolver:
    """A new solver from a factory, for symmetric positive definite or general matrices.

    Parameters
    ----------
    solver : SolverFactory, optional
        Default :func:`auto_solver`.
    A : scipy sparse matrix, shape (n, n), optional
        Factorized right away if given.
    symmetric, check_symmetry : bool
        As in :class:`~.solvers.SolverRequest`: Cholesky (with or without the symmetry
        check) or LU.
    ordering : callable () -> (n,) int array, optional
        A fill-reducing ordering offered to the factory, computed only if the backend uses
        it (PARDISO does, SuperLU does not). To impose an ordering on any backend, set
        :attr:`~.solvers.SPDSolver.ordering` on the solver instead.
    rigid_modes : callable () -> (n, k) float array, optional
        The rigid motions in the system's unknowns
        (:attr:`~.solvers.SolverRequest.rigid_modes`), computed only if the backend uses
        them (``"petsc-gamg"`` does).
    dimension, size : int
        The problem's dimension and number of unknowns (:class:`~.solvers.SolverRequest`).
    coupled : bool
        Whether the system couples bodies through contact pairs
        (:attr:`~.requests.SolverRequest.coupled`).

    Returns
    -------
    SPDSolver
        Its :attr:`~.solvers.SPDSolver.backend` names the backend taken; the caller closes it.

    Raises
    ------
    ValueError
        If ``solver`` is not a factory, or the factory returns no :class:`SPDSolver`.
    BackendUnavailableError
        If the factory's backend cannot be used here (a :class:`RuntimeError`).
    """
    factory = auto_solver if solver is None else solver
    if isinstance(factory, SPDSolver):
        raise ValueError(f"solver is a solver already ({factory!r}): make_solver takes a factory")
    if isinstance(factory, str) or not callable(factory):
        raise ValueError(
            "solver must be an SPDSolver or a solver factory (e.g. "
            f"signorini.algebra.superlu_solver), got {solver!r}"
        )
    request = SolverRequest(
        symmetric=bool(symmetric),
        check_symmetry=bool(check_symmetry),
        ordering=ordering,
        rigid_modes=rigid_modes,
        dimension=int(dimension),
        size=int(size),
        coupled=bool(coupled),
    )
    made = factory(request)
    if not isinstance(made, SPDSolver):
        raise ValueError(
            f"the solver factory {factory!r} returned {type(made).__name__}, not an SPDSolver"
        )
    if A is not None:
        made.factorize(A)
    return made


def solver_library(solver: object = None) -> str:
    """The sparse solver library a run uses: MKL PARDISO with MKL's version when the run's
    solver is ``pardiso`` or ``auto`` and MKL loads, PETSc's version and ranks for ``petsc``,
    else SciPy's SuperLU."""
    name = str(solver) if solver is not None else "auto"
    if name in ("auto", "pardiso"):
        version = mkl_version()
        if version is not None:
            return f"MKL PARDISO ({version})"
    if name in ("petsc", "petsc-gamg"):
        return petsc_library("MUMPS" if name == "petsc" else "GAMG (CG)")
    if name == "amg":
        from .amg import _pyamg

        return f"pyamg {_pyamg().__version__} (CG + smoothed aggregation)"
    if name in ("auto", "pardiso", "scipy", "superlu"):
        return f"SuperLU (SciPy {scipy.__version__})"
    return f"{name} (SciPy {scipy.__version__} installed)"
