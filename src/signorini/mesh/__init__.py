"""The mesh layer: the immutable triangulation (or tetrahedral mesh) with named boundary
parts, built-in meshes, meshes read from files, and newest vertex bisection (the REFINE
step)."""

from .builders import half_disc, rectangle
from .builders3d import box, eighth_ball, quarter_cylinder
from .curves import Circle, Curve, Line, ProjectedCurve, QuadraticBoundary
from .gmsh import read_mesh
from .matching3d import prepare_for_bisection
from .mesh import Mesh, MeshError
from .refine import Refinement, refine_nvb, refine_uniform
from .regions import with_regions
from .surfaces import Cylinder, Sphere, Surface

__all__ = [
    "Circle",
    "Curve",
    "Cylinder",
    "Line",
    "ProjectedCurve",
    "QuadraticBoundary",
    "Mesh",
    "MeshError",
    "Refinement",
    "Sphere",
    "Surface",
    "box",
    "eighth_ball",
    "half_disc",
    "prepare_for_bisection",
    "quarter_cylinder",
    "read_mesh",
    "rectangle",
    "refine_nvb",
    "refine_uniform",
    "with_regions",
]
