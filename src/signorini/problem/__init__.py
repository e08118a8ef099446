"""The problem a user states: boundary conditions on named parts (``conditions``), rigid
obstacles as shapes (``obstacles``: the base :class:`Obstacle` a shape subclasses, and the
built-in shapes), the problem itself (``problem``), and the one place where user functions
are evaluated and checked (``fields``)."""

from .conditions import Contact, Dirichlet, ExactSolution, Neumann, Roller
from .fields import ProblemError
from .friction_laws import Coulomb, Tresca
from .obstacles import Disc, HalfPlane, Obstacle, Polyline, SignedDistance
from .problem import ContactProblem, SlenderBodyWarning

__all__ = [
    "Contact",
    "ContactProblem",
    "Coulomb",
    "Dirichlet",
    "Disc",
    "ExactSolution",
    "HalfPlane",
    "Neumann",
    "Obstacle",
    "Polyline",
    "ProblemError",
    "Roller",
    "SignedDistance",
    "SlenderBodyWarning",
    "Tresca",
]
