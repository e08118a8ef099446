"""σ(u_h) of a P2 tetrahedral solution on the faces of its cells, the faces' geometry and the
constraint direction field on contact faces: what the 3D terms of
:mod:`signorini.estimator.residual3d` integrate (docs/method.md, *Three dimensions: the
estimator on tetrahedra and faces*).

A face is given by its three vertices in a chosen order ``(a, b, c)`` and its six P2 nodes
``[a, b, c, m_ab, m_bc, m_ca]`` (:meth:`~signorini.fem.space3d.P2TetSpace.mesh_facet_nodes`:
the order of the face in its first cell, outward for that cell). A point of the face is its
barycentric ``(1 − s₁ − s₂, s₁, s₂)`` for the triangle reference point ``s``; each cell
beside the face maps the same ``s`` to the same physical point (the cell's reference point
``ξ = Σ_j b_j ξ̂_{v_j}``, its map restricted to the face being the face's own quadratic), so
the two sides of an interior face are evaluated at the same points, flat or curved.
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np

from ..fem.mapping3d import FlatFaces, QuadraticFaces, face_groups
from ..fem.material import CellMaterials, Material, on_cells, stress
from ..fem.p2_tet import REFERENCE_NODES, face_basis, grad_basis
from ..fem.space3d import P2TetSpace
from .residual import stress_unit

__all__ = ["TetStress", "direction_field_3d", "face_geometry"]

#: the reference tetrahedron's vertices ``(4, 3)``
_TET_VERTICES = REFERENCE_NODES[:4]
#: the reference gradients of the ten P2 basis functions at the four vertices ``(4, 10, 3)``
_VERTEX_GRADIENTS = grad_basis(_TET_VERTICES)


class TetStress:
    """σ(u_h) of a P2 field on tetrahedra, in the estimator's stress unit, at points of faces.

    Parameters
    ----------
    space : P2TetSpace
    u : (n_nodes, 3) float array
        Nodal displacements.
    material : Material or CellMaterials
    """

    def __init__(
        self, space: P2TetSpace, u: np.ndarray, material: Material | CellMaterials
    ) -> None:
        self.space, self.material = space, material
        self.u_cell = space.field_coefficients(u)  # (n_cells, 30)
        corners = space.mapping.per_cell(lambda g: self._corners(g, material))
        #: the stress unit σ₀ (1 for ordinary stresses; docs/method.md, *Estimator*, "Units")
        self.unit = stress_unit(float(np.abs(corners).max(initial=0.0)))
        #: σ(u_h) / σ₀ at the vertices of each cell ``(n_cells, 4, 3, 3)``: linear on the
        #: affine cells, so interpolated from these there
        self.vertex_stress = corners / self.unit if self.unit != 1.0 else corners

    def _corners(self, g, material: Material | CellMaterials) -> np.ndarray:
        """σ(u_h) at the four vertices of the cells of group ``g`` ``(m, 4, 3, 3)``. On
        affine cells the reference gradients are contracted with the coefficients first and
        ``J⁻ᵀ`` applied once per cell (``∇u = (Σ_a u_a ⊗ ∇̂φ_a) J⁻¹``), without the
        ``(m, 4, 10, 3)`` physical basis gradients; through the map elsewhere."""
        u_cell = self.u_cell[g.cells]
        if g.order != 1:
            return stress(on_cells(material, g.cells), g.field_gradients(u_cell, _TET_VERTICES))
        ref = np.tensordot(u_cell.reshape(-1, 10, 3), _VERTEX_GRADIENTS, axes=([1], [1]))
        jit = g.inverse_transpose()[:, 0]  # (m, 3, 3): [j, r]
        grad = ref.transpose(0, 2, 1, 3) @ jit.transpose(0, 2, 1)[:, None]  # (m, 4, i, j)
        return stress(on_cells(material, g.cells), grad)

    def at_vertices(self, cell: np.ndarray, vertices: np.ndarray) -> np.ndarray:
        """``(k, 3, 3, 3)`` σ(u_h) / σ₀ of affine cells ``cell (k,)`` at their face's
        vertices ``vertices (k, 3)`` (global numbers, in the face's order)."""
        local = (self.space.mesh.cells[cell][:, None, :] == vertices[:, :, None]).argmax(axis=2)
        return self.vertex_stress[cell[:, None], local]

    def at_faces(self, cell: np.ndarray, vertices: np.ndarray, s: np.ndarray) -> np.ndarray:
        """``(k, q, 3, 3)`` σ(u_h) / σ₀ of cells ``cell (k,)`` at the points ``s (q, 2)`` of
        their faces with vertices ``vertices (k, 3)`` (global vertex numbers, in the face's
        order), through each cell's map.

        On an affine cell σ(u_h) is linear: the barycentric combination of its values at the
        face's vertices. On an isoparametric cell it is taken through the map at the reference
        points ``ξ(s)`` of the face, by the position of the face's vertices among the cell's
        (at most 24 placements, a loop over them).
        """
        mesh = self.space.mesh
        local = (mesh.cells[cell][:, None, :] == vertices[:, :, None]).argmax(axis=2)
        bary = np.column_stack([1.0 - s[:, 0] - s[:, 1], s[:, 0], s[:, 1]])  # (q, 3)
        out = np.empty((len(cell), len(s), 3, 3))
        for sub, g, slot in self.space.mapping.split(cell):  # affine, isoparametric
            rows = np.arange(len(cell))[sub]
            if g.order == 1:
                at = self.vertex_stress[cell[rows][:, None], local[rows]]  # (r, 3, 3, 3)
                out[rows] = np.einsum("qj,rjab->rqab", bary, at)
                continue
            code = local[rows] @ np.array([16, 4, 1])
            for pattern in np.unique(code):  # a loop over the ≤ 24 placements of a face
                mine = np.flatnonzero(code == pattern)
                xi = bary @ _TET_VERTICES[local[rows[mine[0]]]]  # (q, 3)
                c = cell[rows[mine]]
                grad = g.rows(slot[mine]).field_gradients(self.u_cell[c], xi)
                sigma = stress(on_cells(self.material, c), grad)
                out[rows[mine]] = sigma / self.unit if self.unit != 1.0 else sigma
        return out


def face_geometry(
    space: P2TetSpace, nodes: np.ndarray
) -> Iterator[tuple[slice | np.ndarray, FlatFaces | QuadraticFaces]]:
    """The geometry of faces with P2 nodes ``nodes (k, 6)`` (vertices in the face's order):
    quadratic where one of its side nodes is off the chord (on a curved part: the boundary
    face, and the interior faces through such an edge), flat elsewhere; ``(rows, faces)``."""
    edges = nodes[:, 3:] - space.mesh.n_points
    quadratic = space.moved_edges[edges].any(axis=1)
    return face_groups(space.node_points[nodes], quadratic)


def direction_field_3d(direction: np.ndarray, s: np.ndarray) -> np.ndarray:
    """The constraint direction on contact faces: the normalised P2 interpolant of the nodal
    directions ``n_z (k, 6, 3)`` at the points ``s (q, 2)``, ``(k, q, 3)`` unit vectors (the
    face form of :func:`~signorini.estimator.traction.direction_field`; docs/method.md,
    *Estimator*, "On curved boundaries"). Where the interpolant vanishes (directions opposed
    across one face) the first midpoint's direction is used."""
    d = np.einsum("qa,kac->kqc", face_basis(s), direction)
    size = np.linalg.norm(d, axis=-1)[..., None]
    small = size <= 1e-8
    if small.any():
        d = np.where(small, direction[:, None, 3], d)
        size = np.where(small, 1.0, size)
    return d / size
