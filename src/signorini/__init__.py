"""signorini: adaptive quadratic finite elements for the Signorini contact problem.

The public API, from the mesh to the adaptive loop::

    from signorini import (Mesh, rectangle, read_mesh, Material, ContactProblem, Dirichlet,
                           Neumann, Contact, solve, estimate, mark_doerfler, refine_nvb,
                           adaptive)
"""

from .algebra import PDASConvergenceError
from .contact import ContactResult, solve
from .estimator import Estimate, estimate, mark_doerfler
from .examples import example_6_1, example_6_2
from .fem import Material, P2Space
from .loop import Level, LevelRecord, adaptive
from .mesh import Mesh, MeshError, read_mesh, rectangle, refine_nvb, refine_uniform
from .output import write_vtu
from .problem import Contact, ContactProblem, Dirichlet, ExactSolution, Neumann, ProblemError

__version__ = "0.1.0"

__all__ = [
    "Contact",
    "ContactProblem",
    "ContactResult",
    "Dirichlet",
    "Estimate",
    "ExactSolution",
    "Level",
    "LevelRecord",
    "Material",
    "Mesh",
    "MeshError",
    "Neumann",
    "P2Space",
    "PDASConvergenceError",
    "ProblemError",
    "adaptive",
    "estimate",
    "example_6_1",
    "example_6_2",
    "mark_doerfler",
    "read_mesh",
    "rectangle",
    "refine_nvb",
    "refine_uniform",
    "solve",
    "write_vtu",
]
