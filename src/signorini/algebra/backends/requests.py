"""What a caller asks of a solver backend: :class:`SolverRequest`, and the
:class:`SolverFactory` that answers it with a new :class:`~.solvers.SPDSolver`
(:mod:`.solvers`, which re-exports both)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Protocol

import numpy as np

if TYPE_CHECKING:
    from .solvers import SPDSolver

__all__ = ["SolverFactory", "SolverRequest"]


@dataclass(frozen=True)
class SolverRequest:
    """What a caller asks of a :class:`SolverFactory` for one sequence of linear systems.

    New fields get defaults, so that a factory written today keeps working when the request
    grows (a distributed backend may read more of it).

    Attributes
    ----------
    symmetric : bool
        True: the matrices are symmetric positive definite (a Cholesky factorization, e.g.
        the frictionless and Tresca systems); False: general matrices (an LU factorization,
        e.g. Coulomb's non-symmetric systems), whose symmetry is not checked.
    check_symmetry : bool
        With ``symmetric``: check ``max |A - A^T| <= 1e-12 max |A|`` at each analysis (the
        contact layer's assembled matrices are symmetric by construction and skip it).
    ordering : callable () -> (n,) int array, optional
        A fill-reducing ordering of the unknowns (:attr:`~.solvers.SPDSolver.ordering`),
        computed only when called: a factory whose backend orders better by itself, or
        cannot use a given ordering, does not call it (the contact layer's METIS ordering
        of the mesh's vertex graph, :func:`signorini.contact.ordering.dof_ordering`, needs
        MKL).
    rigid_modes : callable () -> (n, k) float array, optional
        The rigid motions of the bodies written in the system's unknowns (node frames, the
        relative displacement of contact pairs): the near-nullspace of the matrix before
        its Dirichlet DOFs are fixed, computed only when called (an algebraic multigrid
        needs it, :mod:`.petsc_gamg`; the contact layer's
        :func:`signorini.contact.rigid_modes.system_rigid_modes`).
    dimension : int
        The space dimension of the elasticity problem, 2 or 3: the number of interleaved
        DOFs of a node (an algebraic multigrid reads the matrix in ``dimension ×
        dimension`` node blocks, :mod:`.amg`).
    size : int
        The number of unknowns, 0 when not known: :func:`~.selection.auto_solver` chooses
        by it in 3D (docs/method.md, *Three dimensions: the linear solver (measured)*).
    coupled : bool
        True: the system couples bodies through contact pairs (the dual mortar change of
        basis). The automatic choices then keep a direct factorization at every size: CG +
        smoothed aggregation failed to converge on an adaptive two-spheres level of 2.5·10⁵
        unknowns (docs/method.md, *Two bodies in three dimensions: the estimator*).
    """

    symmetric: bool = True
    check_symmetry: bool = True
    ordering: Callable[[], np.ndarray] | None = None
    rigid_modes: Callable[[], np.ndarray] | None = None
    dimension: int = 2
    size: int = 0
    coupled: bool = False

    def multigrid_from(self, size: int) -> bool:
        """Whether a backend that takes an algebraic multigrid for symmetric 3D systems of
        ``size`` unknowns or more (its crossover with a direct factorization, measured:
        :data:`~.selection.AMG_FROM_3D`, :data:`~.petsc.GAMG_FROM_3D`) takes it for these;
        never for :attr:`coupled` systems."""
        return self.dimension == 3 and self.symmetric and self.size >= size and not self.coupled


class SolverFactory(Protocol):
    """A callable that makes a new solver for one sequence of linear systems.

    ``factory(request) -> SPDSolver``: a solver that has not factorized yet, for the kind of
    matrices :class:`SolverRequest` describes. Whoever calls the factory owns the solver and
    closes it (:meth:`~.solvers.SPDSolver.close`). A factory may raise
    :class:`~.errors.BackendUnavailableError` when its backend cannot be used here.

    A backend is an :class:`SPDSolver` subclass (or two: Cholesky and LU) and a factory
    function in one module; registering it by name is one line of
    :data:`signorini.algebra.backends.selection.SOLVERS`.
    """

    def __call__(self, request: SolverRequest, /) -> SPDSolver: ...
