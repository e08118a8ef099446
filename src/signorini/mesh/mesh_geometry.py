"""The geometry of a :class:`~signorini.mesh.mesh.Mesh` read from its arrays, in 2D and 3D:
cell measures, edge lengths and midpoints, facet measures, diameters, the curved midpoints
of parts that carry a curve (2D) or a surface (3D), and the smallest angle.

:class:`MeshGeometry` is the part of :class:`~signorini.mesh.mesh.Mesh` that holds them
(cached, read-only); the dimension-dependent kernels are in :mod:`signorini.mesh.tetrahedra`
and :mod:`signorini.mesh.geometry`.
"""

from __future__ import annotations

from functools import cached_property

import numpy as np

from .geometry import min_angle, signed_area
from .tetrahedra import edge_lengths, facet_edges, facet_measures
from .topology import _frozen
from .validation import MeshError
from .validation3d import dihedral_angles

__all__ = ["MeshGeometry"]


class MeshGeometry:
    """The geometric facts of a mesh (a base of :class:`~signorini.mesh.mesh.Mesh`, which
    provides the arrays and the topology named below)."""

    points: np.ndarray
    cells: np.ndarray
    edges: np.ndarray
    facets: np.ndarray
    cell2edge: np.ndarray
    facet_part: np.ndarray
    curves: tuple
    dim: int
    n_points: int

    @cached_property
    def measure(self) -> np.ndarray:
        """``(n_cells,)`` signed measures |T| (positive for positively oriented cells): the
        areas :attr:`area` in 2D, the volumes :attr:`volume` in 3D."""
        return _frozen(signed_area(self.points, self.cells))

    @property
    def area(self) -> np.ndarray:
        """``(n_cells,)`` signed areas of triangles (positive for counter-clockwise ones)."""
        if self.dim != 2:
            raise MeshError("a tetrahedral mesh has cell volumes (Mesh.volume), not areas")
        return self.measure

    @property
    def volume(self) -> np.ndarray:
        """``(n_cells,)`` signed volumes of tetrahedra ``det[x1 − x0, x2 − x0, x3 − x0] / 6``."""
        if self.dim != 3:
            raise MeshError("a triangular mesh has cell areas (Mesh.area), not volumes")
        return self.measure

    @cached_property
    def edge_length(self) -> np.ndarray:
        """``(n_edges,)`` lengths."""
        return _frozen(edge_lengths(self.points, self.edges))

    @cached_property
    def facet_measure(self) -> np.ndarray:
        """``(n_facets,)`` the facets' measures |F|: :attr:`edge_length` in 2D (the same
        array), the faces' areas in 3D."""
        if self.dim == 2:
            return self.edge_length
        return _frozen(facet_measures(self.points, self.facets))

    @cached_property
    def h(self) -> np.ndarray:
        """``(n_cells,)`` diameters ``h_T`` (longest edge)."""
        return _frozen(self.edge_length[self.cell2edge].max(axis=1))

    @cached_property
    def edge_midpoints(self) -> np.ndarray:
        """``(n_edges, dim)`` midpoints."""
        return _frozen(0.5 * (self.points[self.edges[:, 0]] + self.points[self.edges[:, 1]]))

    @cached_property
    def curved_midpoints(self) -> np.ndarray:
        """``(n_edges, dim)`` edge midpoints, on the curve (surface) for edges of a part that
        carries one (:meth:`Curve.halfway` of the edge's ends; in 3D the edges of the part's
        faces): where refinement puts new vertices and the P2 space its edge nodes;
        :attr:`edge_midpoints` when no part carries a curve."""
        if all(c is None for c in self.curves):
            return self.edge_midpoints
        mid = self.edge_midpoints.copy()
        for index, curve in enumerate(self.curves):  # a loop over parts, not edges
            if curve is None:
                continue
            e = self.part_edge_indices(index)
            ends = self.edges[e]
            mid[e] = curve.halfway(self.points[ends[:, 0]], self.points[ends[:, 1]])
        return _frozen(mid)

    def part_edge_indices(self, index: int) -> np.ndarray:
        """The sorted indices of the edges of the part of index ``index``: its facets in 2D,
        the edges of its faces in 3D (their midpoints move onto the part's surface)."""
        if self.dim == 2:
            return np.flatnonzero(self.facet_part == index)
        faces = self.facets[self.facet_part == index]
        return np.unique(facet_edges(self.edges, faces, self.n_points))

    def min_angle(self) -> float:
        """Smallest interior angle (radians) over all cells (3D: dihedral angle)."""
        if self.dim == 3:
            return float(dihedral_angles(self.points, self.cells).min())
        return min_angle(self.points, self.cells)
