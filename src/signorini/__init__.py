"""signorini: adaptive quadratic finite elements for the Signorini contact problem.

The public API, from the mesh to the adaptive loop::

    from signorini import (Mesh, rectangle, read_mesh, Circle, Material, ContactProblem,
                           Dirichlet, Neumann, Contact, HalfPlane, Coulomb, Tresca, solve,
                           solve_path, estimate, mark_doerfler, refine_nvb, adaptive)

A boundary curve of one's own subclasses :class:`Curve` (like :class:`Line`, :class:`Circle`,
:class:`ProjectedCurve`), a rigid obstacle of one's own :class:`Obstacle` (like
:class:`HalfPlane`, :class:`Disc`, :class:`Polyline`, :class:`SignedDistance`).
"""

from .algebra import ConvergenceError, FrictionConvergenceError, PDASConvergenceError
from .contact import ContactResult, solve, solve_path
from .estimator import Estimate, estimate, mark_doerfler
from .examples import example_6_1, example_6_2
from .fem import Material, P2Space
from .loop import Level, LevelRecord, adaptive
from .mesh import Mesh, MeshError, read_mesh, rectangle, refine_nvb, refine_uniform
from .mesh.curves import Circle, Curve, Line, ProjectedCurve
from .output import write_vtu
from .problem import (
    Contact,
    ContactProblem,
    Coulomb,
    Dirichlet,
    ExactSolution,
    Neumann,
    ProblemError,
    Roller,
    Tresca,
)
from .problem.obstacles import Disc, HalfPlane, Obstacle, Polyline, SignedDistance
from .version import __version__ as __version__  # the package's version, kept in one place

__all__ = [
    "Circle",
    "Contact",
    "ContactProblem",
    "ContactResult",
    "ConvergenceError",
    "Coulomb",
    "Curve",
    "Dirichlet",
    "Disc",
    "Estimate",
    "ExactSolution",
    "FrictionConvergenceError",
    "HalfPlane",
    "Level",
    "LevelRecord",
    "Line",
    "Material",
    "Mesh",
    "MeshError",
    "Neumann",
    "Obstacle",
    "P2Space",
    "PDASConvergenceError",
    "Polyline",
    "ProblemError",
    "ProjectedCurve",
    "Roller",
    "SignedDistance",
    "Tresca",
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
    "solve_path",
    "write_vtu",
]
