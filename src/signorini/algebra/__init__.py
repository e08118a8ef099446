"""Sparse linear algebra with no knowledge of meshes: symmetric elimination, SPD solvers and
their backends, and the primal-dual active set method (PDAS) for bound constraints.

=================  ============================================================================
``sparse``         CSR helpers: checks, row indices, upper triangle, diagonal positions
``elimination``    symmetric elimination of fixed DOFs in place (pattern kept)
``solvers``        the SPD solver interface (analysis once per pattern), its errors
``superlu``        SuperLU backend (always available)
``pardiso``        MKL PARDISO backend through ctypes, and how MKL is found
``backends``       ``make_solver`` / ``available_backends``: the choice of backend
``qp``             the bound-constrained QP's data, checked at the public entry
``kkt``            KKT residuals of a point
``active_system``  one active set's linear system: refactorization or Woodbury update
``primal``         the primal active set fallback
``result``         steps, result and failure of an active set solve
``pdas``           ``solve_pdas``: the PDAS iteration
=================  ============================================================================
"""

from .backends import BACKENDS, SolverFallbackWarning, available_backends, make_solver
from .elimination import SymmetricEliminator, eliminate_symmetric
from .kkt import KKTResiduals, kkt_residuals
from .pdas import solve_pdas
from .result import PDASConvergenceError, PDASResult, PDASStep
from .solvers import BackendUnavailableError, FactorizationError, SingularSystemError, SPDSolver

__all__ = [
    "BACKENDS",
    "BackendUnavailableError",
    "FactorizationError",
    "SingularSystemError",
    "KKTResiduals",
    "PDASConvergenceError",
    "PDASResult",
    "PDASStep",
    "SPDSolver",
    "SolverFallbackWarning",
    "SymmetricEliminator",
    "available_backends",
    "eliminate_symmetric",
    "kkt_residuals",
    "make_solver",
    "solve_pdas",
]
