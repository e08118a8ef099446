"""Finite element facts: quadrature, the P2 Lagrange element, the P2 space on a mesh, and
plane-strain or plane-stress elasticity (materials, stiffness, loads, stresses of ``u_h``,
error norms)."""

from .material import Material
from .space import P2Space

__all__ = ["Material", "P2Space"]
