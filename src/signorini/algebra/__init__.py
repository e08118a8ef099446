"""Sparse linear algebra with no knowledge of meshes: symmetric elimination, SPD solvers and
their backends, and the primal-dual active set method (PDAS) for bound constraints."""

from .linsolve import available_backends, make_solver
from .pdas import PDASConvergenceError, PDASResult, solve_pdas

__all__ = ["PDASConvergenceError", "PDASResult", "available_backends", "make_solver", "solve_pdas"]
