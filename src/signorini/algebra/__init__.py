"""Sparse linear algebra with no knowledge of meshes: symmetric elimination, SPD solvers and
their backends, the primal-dual active set method (PDAS) for bound constraints, and its
semismooth Newton extension to Tresca and Coulomb friction.

=====================  ==========================================================================
``sparse``             CSR helpers: checks, row indices, upper triangle, diagonal positions
``elimination``        symmetric elimination of fixed DOFs in place (pattern kept)
``solvers``            the SPD solver interface (analysis once per pattern), its errors
``superlu``            SuperLU backends (always available): SPD, and LU for non-symmetric
``mkl``                how MKL's runtime library is found and loaded
``pardiso``            MKL PARDISO through ctypes (SPD, non-symmetric LU); METIS orderings
``backends``           ``make_solver``, ``make_lu_solver``, ``available_backends``
``qp``                 the bound-constrained QP's data, checked at the public entry
``kkt``                KKT residuals of a point
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
    BACKENDS,
    SolverFallbackWarning,
    available_backends,
    make_lu_solver,
    make_solver,
)
from .elimination import SymmetricEliminator, eliminate_symmetric
from .friction import INACTIVE, SLIP, STICK, FrictionOptions, solve_friction
from .friction_kkt import FrictionKKT, FrictionProblem, check_friction
from .friction_result import FrictionConvergenceError, FrictionResult, FrictionStep
from .kkt import KKTResiduals, kkt_residuals
from .laws import FrictionLaw, LawGroups
from .pdas import PDASOptions, solve_pdas
from .result import ConvergenceError, PDASConvergenceError, PDASResult, PDASStep, SolveReport
from .solvers import BackendUnavailableError, FactorizationError, SingularSystemError, SPDSolver

__all__ = [
    "BACKENDS",
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
    "SPDSolver",
    "SolveReport",
    "SolverFallbackWarning",
    "SymmetricEliminator",
    "available_backends",
    "check_friction",
    "eliminate_symmetric",
    "kkt_residuals",
    "make_lu_solver",
    "make_solver",
    "solve_friction",
    "solve_pdas",
]
