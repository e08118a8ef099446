"""The mesh layer: the immutable triangulation with named boundary parts, built-in meshes,
meshes read from files, and newest vertex bisection (the REFINE step)."""

from .builders import half_disc, rectangle
from .curves import Circle, Curve, Line, ProjectedCurve, QuadraticBoundary
from .gmsh import read_mesh
from .mesh import Mesh, MeshError
from .refine import Refinement, refine_nvb, refine_uniform
from .regions import with_regions

__all__ = [
    "Circle",
    "Curve",
    "Line",
    "ProjectedCurve",
    "QuadraticBoundary",
    "Mesh",
    "MeshError",
    "Refinement",
    "half_disc",
    "read_mesh",
    "rectangle",
    "refine_nvb",
    "refine_uniform",
    "with_regions",
]
