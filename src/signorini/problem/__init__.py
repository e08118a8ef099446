"""The problem a user states: boundary conditions on named parts, material and data."""

from .problem import Contact, ContactProblem, Dirichlet, ExactSolution, Neumann, ProblemError

__all__ = ["Contact", "ContactProblem", "Dirichlet", "ExactSolution", "Neumann", "ProblemError"]
