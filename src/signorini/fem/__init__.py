"""Finite element facts: quadrature, the P2 (and P1) Lagrange elements, their spaces on a mesh, and
plane-strain or plane-stress elasticity (materials, stiffness, loads, stresses of ``u_h``,
error norms)."""

from .element import ELEMENTS, Element
from .material import Material
from .space import P1Space, P2Space, space_of

__all__ = ["ELEMENTS", "Element", "Material", "P1Space", "P2Space", "space_of"]
