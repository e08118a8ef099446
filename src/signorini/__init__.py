"""signorini: adaptive quadratic finite elements for the Signorini contact problem.

The public API, from the mesh to the adaptive loop::

    from signorini import (Mesh, rectangle, read_mesh, Material, ContactProblem, Dirichlet,
                           Neumann, Contact, solve, estimate, mark_doerfler, refine_nvb,
                           adaptive)
"""

from .discrete import ContactResult, solve
from .driver import Level, LevelRecord, adaptive
from .elasticity import Material
from .estimator import Estimate, estimate
from .examples import example_6_1, example_6_2
from .io import read_mesh, write_vtu
from .marking import mark_doerfler
from .mesh import Mesh, MeshError
from .meshes import rectangle
from .pdas import PDASConvergenceError
from .problem import Contact, ContactProblem, Dirichlet, ExactSolution, Neumann, ProblemError
from .refine import refine_nvb, refine_uniform
from .space import P2Space

__version__ = "0.1.0"

__all__ = [
    "Contact", "ContactProblem", "ContactResult", "Dirichlet", "Estimate", "ExactSolution",
    "Level", "LevelRecord", "Material", "Mesh", "MeshError", "Neumann", "P2Space",
    "PDASConvergenceError", "ProblemError", "adaptive", "estimate", "example_6_1",
    "example_6_2", "mark_doerfler", "read_mesh", "rectangle", "refine_nvb", "refine_uniform",
    "solve", "write_vtu",
]
