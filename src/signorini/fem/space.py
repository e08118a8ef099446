"""The conforming Lagrange spaces on a mesh, P2 (the paper's) and P1: nodes, DOF maps,
interpolation, prolongation; :func:`space_of` chooses one by its element.

Global P2 nodes are the mesh vertices (node index = point index) followed by the edge
midpoints (node index = ``n_points + edge index``). Vector DOFs are interleaved:
``dof = d * node + component``, ``d = mesh.dim`` (:mod:`signorini.fem.dofs`, the layout;
:mod:`signorini.fem.prolongation`, the interpolation on a refined mesh). Local node order on
a cell: its vertices, then the midpoints of local edges 0, 1, 2 (the order of VTK's quadratic
triangle / meshio ``triangle6``).
Global P1 nodes are the mesh vertices; a P1 space is affine on every cell (a curved boundary
part is approximated by its chords; docs/method.md, *P1 elements and their estimator*).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator
from functools import cached_property

import numpy as np

from ..mesh.mesh import Mesh
from ..mesh.reference import TRIANGLE
from ..mesh.refine import Refinement
from ..mesh.validation import MeshError
from . import dofs, iso
from .dofs import node_dofs
from .element import P1, P2, Element, element_of
from .mapping import CellMap, QuadraticFacets, StraightFacets, facet_groups
from .prolongation import prolongate_p1, prolongate_p2

__all__ = ["LagrangeSpace", "P1Space", "P2Space", "node_dofs", "space_of"]


class LagrangeSpace:
    """What every space shares: the mesh, the interleaved DOFs of its cells, the cells'
    geometry, nodal interpolation; the subclasses number the nodes.

    Parameters
    ----------
    mesh : Mesh
        A validated mesh; the space trusts it (built inside the package, not a user entry).
    """

    element: Element
    n_nodes: int
    cell_nodes: np.ndarray
    node_points: np.ndarray
    curved: tuple[np.ndarray, np.ndarray] | None

    def __init__(self, mesh: Mesh) -> None:
        self.mesh = mesh

    @property
    def n_components(self) -> int:
        """The components of a displacement per node, ``mesh.dim`` (elasticity)."""
        return self.mesh.dim

    @property
    def n_dofs(self) -> int:
        return self.n_components * self.n_nodes

    @cached_property
    def cell_dofs(self) -> np.ndarray:
        """``(n_cells, d n_local)`` interleaved global DOFs (local DOF ``d * node + component``,
        ``d = n_components``)."""
        return dofs.cell_dofs(self.cell_nodes, self.n_components)

    @cached_property
    def mapping(self) -> CellMap:
        """The cells' geometry (:mod:`signorini.fem.mapping`): affine cells, and the
        isoparametric cells of :attr:`curved` with their quadratic maps."""
        return CellMap(self.vertices, self.curved)

    @cached_property
    def vertices(self) -> np.ndarray:
        """``(n_cells, d + 1, d)`` vertex coordinates of each cell."""
        return self.mesh.points[self.mesh.cells]

    def interpolate(self, func: Callable[[np.ndarray], np.ndarray]) -> np.ndarray:
        """Nodal interpolant ``(n_nodes, d)`` of a vector field ``func(x (n, d)) -> (n, d)``."""
        values = np.asarray(func(self.node_points), dtype=np.float64)
        if values.shape != (self.n_nodes, self.n_components):
            raise ValueError(
                f"the function to interpolate must return shape {(self.n_nodes, self.n_components)}"
                f" for {self.n_nodes} points, got {values.shape}"
            )
        return values

    def cell_values(self, u: np.ndarray) -> np.ndarray:
        """Per-cell interleaved coefficients ``(n_cells, 2 n_local)`` of nodal values
        ``(n_nodes, 2)``."""
        return np.asarray(u).reshape(-1)[self.cell_dofs]

    def field_coefficients(self, u: np.ndarray) -> np.ndarray:
        """The P2 coefficients ``(n_cells, 12)`` of the field with nodal values ``u (n_nodes,
        2)`` on each cell's map, what the field kernels (:mod:`signorini.fem.mapping`,
        stresses, norms) read (:meth:`~signorini.fem.element.Element.cell_coefficients`)."""
        return self.element.cell_coefficients(self.cell_values(u))

    @property
    def cell_map_nodes(self) -> np.ndarray:
        """``(n_cells, 6, 2)`` the six P2 node points of each cell's map: its vertices and
        edge midpoints (on a curved part's cells of a P2 space the midpoint on the curve)."""
        return self.node_points[self.cell_nodes]


class P2Space(LagrangeSpace):
    """Vector-valued continuous P2 finite elements on a :class:`~signorini.mesh.Mesh`.

    Parameters
    ----------
    mesh : Mesh
        A validated mesh; the space trusts it (built inside the package, not a user entry).
    """

    element = P2

    @property
    def n_nodes(self) -> int:
        return self.mesh.n_points + self.mesh.n_edges

    @cached_property
    def cell_nodes(self) -> np.ndarray:
        """``(n_cells, 6)`` global node of each local node."""
        return np.hstack([self.mesh.cells, self.mesh.n_points + self.mesh.cell2edge])

    @cached_property
    def node_points(self) -> np.ndarray:
        """``(n_nodes, 2)`` coordinates of the P2 nodes.

        The midpoint node of an edge on a boundary part that carries a curve lies on the
        curve (:attr:`~signorini.mesh.Mesh.curved_midpoints`): the isoparametric cells
        (:attr:`curved`) are the quadratic maps through these points."""
        return np.vstack([self.mesh.points, self.mesh.curved_midpoints])

    @cached_property
    def curved(self) -> tuple[np.ndarray, np.ndarray] | None:
        """The isoparametric cells: ``(cells (k,), node points (k, 6, 2))`` of the cells with
        an edge on a part carrying a curve other than a line (:mod:`signorini.fem.iso`), or
        ``None`` if there are none (every cell is affine).

        Raises
        ------
        MeshError
            If the quadratic map of a curved cell folds over (its Jacobian determinant is
            not positive at a node or a quadrature point): the mesh is too coarse for the
            curve there."""
        cells = iso.curved_cells(self.mesh)
        if cells.size == 0:
            return None
        nodes = self.node_points[self.cell_nodes[cells]]
        bad = iso.folded(nodes)
        if bad.size:
            c = int(cells[bad[0]])
            raise MeshError(
                f"{bad.size} cell(s) along a curved boundary part fold over as isoparametric "
                f"cells (first: cell {c}, vertices {self.vertices[c].tolist()}): the curve "
                "bends by more than the cell's height; refine the mesh near the curve before "
                "attaching it"
            )
        return cells, nodes

    @property
    def curved_facets(self) -> np.ndarray:
        """The boundary facets (edges in 2D) that are quadratics (on parts carrying a curve
        other than a line; :func:`signorini.fem.iso.curved_facets`)."""
        return iso.curved_facets(self.mesh)

    def dof_order(self, vertex_order: np.ndarray) -> np.ndarray:
        """The order of the DOFs that extends an order of the mesh's vertices
        (:func:`signorini.fem.dofs.vertex_dof_order`): each edge's node right after the
        earlier of its two vertices, the ``d`` DOFs of a node together.

        Parameters
        ----------
        vertex_order : (n_points,) int array
            ``vertex_order[k]``: the vertex eliminated k-th (a permutation).

        Returns
        -------
        (n_dofs,) int64 array
            ``order[k]``: the DOF eliminated k-th.
        """
        return dofs.vertex_dof_order(vertex_order, self.n_components, self.mesh.edges)

    def facet_nodes(self, facet_index: np.ndarray) -> np.ndarray:
        """``(k, 3)`` nodes ``[start, end, midpoint]`` of boundary facets (edges in 2D),
        counter-clockwise around their cells."""
        facet_index = np.asarray(facet_index, dtype=np.int64)
        ab = self.mesh.oriented_boundary(facet_index)
        return np.column_stack([ab, self.mesh.n_points + facet_index])  # 2D: the facet's edge

    def mesh_facet_nodes(self, facet_index: np.ndarray) -> np.ndarray:
        """``(k, 3)`` nodes ``[vertex, vertex, midpoint]`` of any mesh facets (as stored)."""
        facet_index = np.asarray(facet_index, dtype=np.int64)
        return np.column_stack([self.mesh.facets[facet_index], self.mesh.n_points + facet_index])

    def boundary_facets(
        self, facet_index: np.ndarray
    ) -> Iterator[tuple[slice | np.ndarray, StraightFacets | QuadraticFacets]]:
        """The geometry of boundary facets (edges in 2D; :mod:`signorini.fem.mapping`),
        counter-clockwise as :meth:`facet_nodes`: quadratic through the midpoint node on parts
        carrying a curve other than a line, straight elsewhere; ``(rows, facets)`` per kind."""
        facet_index = np.asarray(facet_index, dtype=np.int64)
        points = self.node_points[self.facet_nodes(facet_index)]
        return facet_groups(points, np.isin(facet_index, self.curved_facets))

    def part_nodes(self, names: Iterable[str]) -> np.ndarray:
        """Sorted nodes on the closure of the named boundary parts (vertices and midpoints)."""
        facets = np.concatenate([self.mesh.part_facets(n) for n in names] or [np.zeros(0, int)])
        nodes = np.concatenate([self.mesh.facets[facets].ravel(), self.mesh.n_points + facets])
        return np.unique(nodes)

    def prolongate(self, u: np.ndarray, refinement: Refinement) -> np.ndarray:
        """Exact interpolation of a P2 field of this space on the refined mesh.

        A node of the refined mesh that is a node of this one keeps its value: the old
        vertices, a bisection's new vertex (the node of the bisected edge), the nodes of the
        cells that were not refined. Each other node lies in the parent cell of a new cell,
        where the parent's quadratic is evaluated; so P2 functions are reproduced exactly
        (docs/method.md, *Marking and refinement*), and the work grows with the new nodes.

        Parameters
        ----------
        u : (n_nodes, 2) or (n_nodes,) array
            Nodal values on this space (vector or scalar field).
        refinement : Refinement
            The refinement of ``self.mesh``.

        Returns
        -------
        (n_nodes_new, 2) or (n_nodes_new,) array

        Raises
        ------
        ValueError
            If ``u`` does not have one row per node, or ``refinement`` is not a refinement of
            this space's mesh.
        """
        return prolongate_p2(self, P2Space(refinement.mesh), u, refinement)


class P1Space(LagrangeSpace):
    """Vector-valued continuous P1 finite elements on a :class:`~signorini.mesh.Mesh`: one
    node per vertex (node index = point index), affine on every cell (a curved boundary part
    is approximated by its chords; docs/method.md, *P1 elements and their estimator*).

    Parameters
    ----------
    mesh : Mesh
        A validated mesh; the space trusts it.
    """

    element = P1
    curved = None

    @property
    def n_nodes(self) -> int:
        return self.mesh.n_points

    @property
    def cell_nodes(self) -> np.ndarray:
        """``(n_cells, 3)`` global node of each local node: the cell's vertices."""
        return self.mesh.cells

    @property
    def node_points(self) -> np.ndarray:
        """``(n_nodes, 2)`` the mesh's points."""
        return self.mesh.points

    @property
    def curved_facets(self) -> np.ndarray:
        """No facet is a quadratic: every boundary edge is its chord."""
        return np.zeros(0, dtype=np.int64)

    @property
    def cell_map_nodes(self) -> np.ndarray:
        """``(n_cells, 6, 2)`` each cell's vertices and chord midpoints: the P2 node points of
        its (affine) map."""
        v = self.vertices
        start, end = TRIANGLE.edges.T
        return np.concatenate([v, 0.5 * (v[:, start] + v[:, end])], axis=1)

    def dof_order(self, vertex_order: np.ndarray) -> np.ndarray:
        """The order of the DOFs of an order of the vertices, the two DOFs of a node
        together (as :meth:`P2Space.dof_order`)."""
        return dofs.vertex_dof_order(vertex_order, self.n_components)

    def facet_nodes(self, facet_index: np.ndarray) -> np.ndarray:
        """``(k, 2)`` nodes ``[start, end]`` of boundary facets (edges in 2D),
        counter-clockwise."""
        return self.mesh.oriented_boundary(np.asarray(facet_index, dtype=np.int64))

    def mesh_facet_nodes(self, facet_index: np.ndarray) -> np.ndarray:
        """``(k, 2)`` the two vertices of any mesh facets (as stored)."""
        return self.mesh.facets[np.asarray(facet_index, dtype=np.int64)]

    def boundary_facets(
        self, facet_index: np.ndarray
    ) -> Iterator[tuple[slice | np.ndarray, StraightFacets | QuadraticFacets]]:
        """The boundary facets as straight edges, counter-clockwise as :meth:`facet_nodes`."""
        yield slice(None), StraightFacets(self.node_points[self.facet_nodes(facet_index)])

    def part_nodes(self, names: Iterable[str]) -> np.ndarray:
        """Sorted nodes (vertices) on the closure of the named boundary parts."""
        facets = np.concatenate([self.mesh.part_facets(n) for n in names] or [np.zeros(0, int)])
        return np.unique(self.mesh.facets[facets])

    def prolongate(self, u: np.ndarray, refinement: Refinement) -> np.ndarray:
        """Exact interpolation of a P1 field of this space on the refined mesh: the old
        vertices keep their values, a bisection's new vertex gets the mean of the bisected
        edge's two (the field at the chord's midpoint).

        Parameters
        ----------
        u : (n_nodes, 2) or (n_nodes,) array
        refinement : Refinement
            The refinement of ``self.mesh``.

        Returns
        -------
        (n_nodes_new, 2) or (n_nodes_new,) array

        Raises
        ------
        ValueError
            If ``u`` does not have one row per node, or ``refinement`` is not a refinement
            of this space's mesh.
        """
        return prolongate_p1(self, u, refinement)


def space_of(mesh: Mesh, element: str | Element = "P2") -> LagrangeSpace:
    """The space of ``element`` (``"P2"``, the default, or ``"P1"``) on ``mesh``: the one
    place where a caller's choice of element becomes a space. The element is looked up on
    the mesh's reference cell (``mesh.reference``): on a tetrahedral mesh ``"P2"`` is the P2
    tetrahedron (:class:`~signorini.fem.space3d.P2TetSpace`).

    Raises
    ------
    ValueError
        If ``element`` is not one of the elements of ``mesh.reference``
        (:data:`~signorini.fem.element.ELEMENTS_ON`).
    """
    chosen = element_of(element, reference=mesh.reference)
    if mesh.dim == 3:
        from .space3d import P2TetSpace  # the 3D space builds on P2Space (this module)

        return P2TetSpace(mesh)
    return _SPACES[chosen.name](mesh)


_SPACES = {"P1": P1Space, "P2": P2Space}
