"""The problem a user states: boundary conditions on named parts (``conditions``), the
problem itself (``problem``), and the one place where user functions are evaluated and
checked (``fields``)."""

from .conditions import Contact, Dirichlet, ExactSolution, Neumann
from .fields import ProblemError
from .friction import Coulomb, Tresca
from .problem import ContactProblem, SlenderBodyWarning

__all__ = [
    "Contact",
    "ContactProblem",
    "Coulomb",
    "Dirichlet",
    "ExactSolution",
    "Neumann",
    "ProblemError",
    "SlenderBodyWarning",
    "Tresca",
]
