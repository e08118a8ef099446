"""The P2 space on a tetrahedral mesh: the nodes, DOFs, geometry and boundary faces of the
P2 tetrahedron (:data:`~signorini.fem.element.P2_TET`), beside the 2D spaces of
:mod:`signorini.fem.space` and behind the same :func:`~signorini.fem.space.space_of`.

Global nodes are the mesh vertices (node = point index) followed by the edge midpoints
(node ``n_points + edge``); vector DOFs interleaved, ``3 node + component``
(:mod:`signorini.fem.dofs`). Local node order on a cell: its 4 vertices, then the midpoints of
``TETRAHEDRON.edges`` (VTK's ``tetra10``). A boundary face's six nodes: its vertices in the
cell's face order (outward normal), then the midpoints of its sides (a, b), (b, c), (c, a)
(:data:`~signorini.fem.p2_tet.FACE_EDGES`), the P2 triangle's order.

The edge nodes of a part that carries a surface lie on the surface
(:attr:`~signorini.mesh.Mesh.curved_midpoints`, the surface's ``halfway``); every cell with
such a moved edge node, by a face or by an edge only, is an isoparametric cell.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from functools import cached_property

import numpy as np

from ..mesh.refine import Refinement
from ..mesh.validation import MeshError
from .element import P2_TET
from .mapping3d import (
    FlatFaces,
    IsoparametricTetrahedra,
    QuadraticFaces,
    TetrahedronMap,
    face_groups,
)
from .p2_tet import FACE_EDGES, REFERENCE_NODES
from .prolongation import prolongate_p2
from .quadrature import tetrahedron_rule
from .space import P2Space

__all__ = ["P2TetSpace"]


class P2TetSpace(P2Space):
    """Vector-valued continuous P2 finite elements on a tetrahedral
    :class:`~signorini.mesh.Mesh` (``mesh.dim == 3``): 3 components per node, ``cell_dofs
    (n_cells, 30)``.

    Parameters
    ----------
    mesh : Mesh
        A validated tetrahedral mesh.
    """

    element = P2_TET

    @cached_property
    def mapping(self) -> TetrahedronMap:
        """The cells' geometry (:mod:`signorini.fem.mapping3d`): affine tetrahedra, and the
        isoparametric ones of :attr:`curved`."""
        return TetrahedronMap(self.vertices, self.curved)

    @cached_property
    def moved_edges(self) -> np.ndarray:
        """``(n_edges,)`` bool: the edges whose node is off the chord's midpoint (on a
        surface)."""
        mesh = self.mesh
        return np.any(mesh.curved_midpoints != mesh.edge_midpoints, axis=1)

    @cached_property
    def curved(self) -> tuple[np.ndarray, np.ndarray] | None:
        """The isoparametric cells ``(cells (k,), node points (k, 10, 3))``: those with a
        moved edge node; ``None`` if every cell is affine.

        Raises
        ------
        MeshError
            If the quadratic map of a curved cell folds over (``det J <= 0`` at a node or a
            point of the stiffness rule)."""
        cells = np.flatnonzero(self.moved_edges[self.mesh.cell2edge].any(axis=1))
        if cells.size == 0:
            return None
        nodes = self.node_points[self.cell_nodes[cells]]
        xi = np.vstack([REFERENCE_NODES, tetrahedron_rule(4)[0]])
        det = IsoparametricTetrahedra(nodes).jacobians(xi)[1]
        bad = np.flatnonzero(~(det > 0.0).all(axis=1))
        if bad.size:
            c = int(cells[bad[0]])
            raise MeshError(
                f"{bad.size} cell(s) along a curved boundary part fold over as isoparametric "
                f"cells (first: cell {c}, vertices {self.vertices[c].tolist()}): the surface "
                "bends by more than the cell's height; refine the mesh near it first"
            )
        return cells, nodes

    def _facet_edges(self, facet_index: np.ndarray) -> np.ndarray:
        """``(k, 3)`` the edges on the sides of facets, in their first cell's face order."""
        mesh = self.mesh
        cell = mesh.facet2cell[facet_index, 0]
        return mesh.cell2edge[cell[:, None], FACE_EDGES[mesh.facet_local[facet_index, 0]]]

    @property
    def curved_facets(self) -> np.ndarray:
        """The boundary faces with a moved edge node (quadratic faces)."""
        b = self.mesh.boundary_facet
        return b[self.moved_edges[self._facet_edges(b)].any(axis=1)]

    def facet_nodes(self, facet_index: np.ndarray) -> np.ndarray:
        """``(k, 6)`` nodes of boundary faces: the vertices in their cell's face order
        (outward normal), then the edge nodes of sides (a, b), (b, c), (c, a)."""
        facet_index = np.asarray(facet_index, dtype=np.int64)
        vertices = self.mesh.oriented_boundary(facet_index)
        return np.hstack([vertices, self.mesh.n_points + self._facet_edges(facet_index)])

    def mesh_facet_nodes(self, facet_index: np.ndarray) -> np.ndarray:
        """``(k, 6)`` nodes of any mesh faces, in the face order of their first cell
        (``facet2cell[:, 0]``), as :meth:`facet_nodes`."""
        facet_index = np.asarray(facet_index, dtype=np.int64)
        mesh = self.mesh
        cell = mesh.facet2cell[facet_index, 0]
        local = mesh.reference.facets[mesh.facet_local[facet_index, 0]]
        vertices = mesh.cells[cell[:, None], local]
        return np.hstack([vertices, mesh.n_points + self._facet_edges(facet_index)])

    def boundary_facets(
        self, facet_index: np.ndarray
    ) -> Iterator[tuple[slice | np.ndarray, FlatFaces | QuadraticFaces]]:
        """The geometry of boundary faces (:mod:`signorini.fem.mapping3d`) in the order of
        :meth:`facet_nodes`: quadratic where an edge node moved, flat elsewhere; ``(rows,
        faces)`` per kind."""
        facet_index = np.asarray(facet_index, dtype=np.int64)
        points = self.node_points[self.facet_nodes(facet_index)]
        return face_groups(points, np.isin(facet_index, self.curved_facets))

    def part_nodes(self, names: Iterable[str]) -> np.ndarray:
        """Sorted nodes on the closure of the named boundary parts (vertices and edge
        nodes)."""
        facets = np.concatenate([self.mesh.part_facets(n) for n in names] or [np.zeros(0, int)])
        return np.unique(self.facet_nodes(facets))

    def prolongate(self, u: np.ndarray, refinement: Refinement) -> np.ndarray:
        """Exact interpolation of a P2 field of this space on the bisected mesh
        (:func:`~signorini.fem.prolongation.prolongate_p2`, the parent's quadratic at each
        new node): P2 fields are reproduced exactly.

        Parameters
        ----------
        u : (n_nodes, 3) or (n_nodes,) array
        refinement : Refinement
            ``Refinement(mesh, parent, edge_point)`` of ``self.mesh``
            (:func:`signorini.mesh.refine3d.bisect_mesh`).

        Returns
        -------
        (n_nodes_new, 3) or (n_nodes_new,) array
        """
        return prolongate_p2(self, P2TetSpace(refinement.mesh), u, refinement)
