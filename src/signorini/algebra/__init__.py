"""Sparse linear algebra with no knowledge of meshes: symmetric elimination, SPD solvers and
their backends, the primal-dual active set method (PDAS) for bound constraints, and its
semismooth Newton extension to Tresca and Coulomb friction.

The active set core stays at the top: it is what both rooms build on (the backends on
``sparse`` and ``ranks``, the frictional solver on ``qp``, ``kkt``, ``active_system`` and
``inexact``). ``errors`` is the bottom, importing nothing of the package.

=====================  ==========================================================================
``errors``             every error and warning: factorization, backend, convergence
``sparse``             CSR helpers: checks, row indices, upper triangle, diagonal positions
``ranks``              the processes sharing a run's matrices: their collectives (``SERIAL``)
``elimination``        symmetric elimination of fixed DOFs in place (pattern kept)
``qp``                 the bound-constrained QP's data, checked at the public entry
``kkt``                KKT residuals of a point
``inexact``            the inexact stopping rule of an iterative solver: loose, then tight
``active_system``      one active set's linear system: refactorization or bordered update
``primal``             the primal active set fallback
``result``             the report of both solvers, PDAS steps and result
``pdas``               ``solve_pdas``: the PDAS iteration
``backends``           the SPD solvers (:mod:`.backends`): interface, SuperLU, PARDISO, PETSc,
                       the backends by name
``friction``           the frictional solver (:mod:`.friction`): laws, problem, Newton method
=====================  ==========================================================================
"""

from .backends.pardiso import pardiso_solver
from .backends.selection import (
    SOLVERS,
    auto_solver,
    available_backends,
    make_solver,
    solver_factory,
    solver_name,
)
from .backends.solvers import SolverFactory, SolverRequest, SPDSolver
from .backends.superlu import superlu_solver
from .elimination import SymmetricEliminator, eliminate_symmetric
from .errors import (
    BackendUnavailableError,
    ConvergenceError,
    FactorizationError,
    FrictionConvergenceError,
    IllConditionedWarning,
    PDASConvergenceError,
    SingularSystemError,
    SolverFallbackWarning,
)
from .friction.kkt import FrictionKKT, FrictionProblem, check_friction
from .friction.laws import FrictionLaw, LawGroups
from .friction.newton import INACTIVE, SLIP, STICK, FrictionOptions, solve_friction
from .friction.result import FrictionResult, FrictionStep
from .kkt import KKTResiduals, kkt_residuals
from .pdas import PDASOptions, solve_pdas
from .result import PDASResult, PDASStep, SolveReport

__all__ = [
    "BackendUnavailableError",
    "ConvergenceError",
    "FactorizationError",
    "FrictionConvergenceError",
    "FrictionKKT",
    "FrictionLaw",
    "FrictionOptions",
    "FrictionProblem",
    "FrictionResult",
    "FrictionStep",
    "IllConditionedWarning",
    "INACTIVE",
    "SLIP",
    "STICK",
    "SingularSystemError",
    "KKTResiduals",
    "LawGroups",
    "PDASConvergenceError",
    "PDASOptions",
    "PDASResult",
    "PDASStep",
    "SOLVERS",
    "SPDSolver",
    "SolveReport",
    "SolverFactory",
    "SolverFallbackWarning",
    "SolverRequest",
    "SymmetricEliminator",
    "auto_solver",
    "available_backends",
    "check_friction",
    "eliminate_symmetric",
    "kkt_residuals",
    "make_solver",
    "pardiso_solver",
    "solve_friction",
    "solve_pdas",
    "solver_factory",
    "solver_name",
    "superlu_solver",
]
