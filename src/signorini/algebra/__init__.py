"""Sparse linear algebra with no knowledge of meshes: symmetric elimination, SPD solvers and
their backends, the primal-dual active set method (PDAS) for bound constraints, and its
semismooth Newton extension to Tresca and Coulomb friction.

=====================  ==========================================================================
``sparse``             CSR helpers: checks, row indices, upper triangle, diagonal positions
``elimination``        symmetric elimination of fixed DOFs in place (pattern kept)
``solvers``            the SPD solver interface (analysis once per pattern), its errors; the
                       solver factory protocol and its request
``superlu``            SuperLU backend (always available): SPD, LU for non-symmetric; factory
``mkl``                how MKL's runtime library is found and loaded
``pardiso``            MKL PARDISO through ctypes (SPD, non-symmetric LU), its factory; METIS
``petsc_gamg``         CG + GAMG through PETSc, the rigid-body near-nullspace (``"petsc-gamg"``)
``backends``           the backends by name (``SOLVERS``, ``"auto"``), ``make_solver``
``ranks``              the processes sharing a run's matrices: their collectives (``SERIAL``)
``qp``                 the bound-constrained QP's data, checked at the public entry
``kkt``                KKT residuals of a point
``inexact``            the inexact stopping rule of an iterative solver: loose, then tight
``active_system``      one active set's linear system: refactorization or bordered update
``primal``             the primal active set fallback
``result``             the report of both solvers, PDAS steps and result, the convergence errors
``pdas``               ``solve_pdas``: the PDAS iteration
``laws``               the friction-law protocol and per-node law groups
``friction_kkt``       the frictional contact problem's data, checks and KKT residuals
``friction_system``    one iteration's system: symmetric, or non-symmetric where s' ≠ 0
``friction_result``    node states, steps, result and failure of a frictional solve
``friction``           ``solve_friction``: semismooth Newton for Tresca and Coulomb friction
=====================  ==========================================================================
"""

from .backends import (
    SOLVERS,
    SolverFallbackWarning,
    auto_solver,
    available_backends,
    make_solver,
    solver_factory,
    solver_name,
)
from .elimination import SymmetricEliminator, eliminate_symmetric
from .friction import INACTIVE, SLIP, STICK, FrictionOptions, solve_friction
from .friction_kkt import FrictionKKT, FrictionProblem, check_friction
from .friction_result import FrictionConvergenceError, FrictionResult, FrictionStep
from .kkt import KKTResiduals, kkt_residuals
from .laws import FrictionLaw, LawGroups
from .pardiso import pardiso_solver
from .pdas import PDASOptions, solve_pdas
from .result import ConvergenceError, PDASConvergenceError, PDASResult, PDASStep, SolveReport
from .solvers import (
    BackendUnavailableError,
    FactorizationError,
    IllConditionedWarning,
    SingularSystemError,
    SolverFactory,
    SolverRequest,
    SPDSolver,
)
from .superlu import superlu_solver

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
