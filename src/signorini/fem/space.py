"""The conforming Lagrange spaces on a mesh, P2 (the paper's) and P1: nodes, DOF maps,
interpolation, prolongation; :func:`space_of` chooses one by its element.

Global P2 nodes are the mesh vertices (node index = point index) followed by the edge
midpoints (node index = ``n_points + edge index``). Vector DOFs are interleaved:
``dof = d * node + component``, ``d = mesh.dim``. Local node order on a cell: its vertices, then the
midpoints of local edges 0, 1, 2 (the order of VTK's quadratic triangle / meshio ``triangle6``).
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
from . import iso
from .element import P1, P2, Element, element_of
from .mapping import CellMap, QuadraticEdges, StraightEdges, edge_groups
from .p2 import basis_barycentric

__all__ = ["LagrangeSpace", "P1Space", "P2Space", "node_dofs", "space_of"]


def node_dofs(nodes: np.ndarray, n_components: int) -> np.ndarray:
    """The interleaved DOFs ``n_components * node + c`` of ``nodes``.

    Parameters
    ----------
    nodes : (...) int array
        Global nodes.
    n_components : int
        The components per node, ``d``.

    Returns
    -------
    (..., d) int array
        ``[d * node, d * node + 1, …, d * node + d − 1]`` per node, in the dtype of ``nodes``.
    """
    nodes = np.asarray(nodes)
    return n_components * nodes[..., None] + np.arange(n_components, dtype=nodes.dtype)


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
        n = self.cell_nodes
        return node_dofs(n, self.n_components).reshape(len(n), -1)

    @cached_property
    def mapping(self) -> CellMap:
        """The cells' geometry (:mod:`signorini.fem.mapping`): affine cells, and the
        isoparametric cells of :attr:`curved` with their quadratic maps."""
        return CellMap(self.vertices, self.curved)

    @cached_property
    def vertices(self) -> np.ndarray:
        """``(n_cells, 3, 2)`` vertex coordinates of each cell."""
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
    def curved_edges(self) -> np.ndarray:
        """The boundary edges that are quadratics (on parts carrying a curve other than a
        line; :func:`signorini.fem.iso.curved_edges`)."""
        return iso.curved_edges(self.mesh)

    def dof_order(self, vertex_order: np.ndarray) -> np.ndarray:
        """The order of the DOFs that extends an order of the mesh's vertices
        (docs/method.md, *Ordering of the unknowns*): each edge's node right after the earlier
        of its two vertices, the two DOFs of a node together.

        A nested dissection of the vertex graph stays one of the P2 graph this way: the nodes
        of a cell are its vertices and edges, and an edge's node goes where its earlier vertex
        is, so no coupling crosses a separator.

        Parameters
        ----------
        vertex_order : (n_points,) int array
            ``vertex_order[k]``: the vertex eliminated k-th (a permutation).

        Returns
        -------
        (n_dofs,) int64 array
            ``order[k]``: the DOF eliminated k-th.
        """
        n_points = self.mesh.n_points
        position = np.empty(n_points, dtype=np.int64)
        position[vertex_order] = np.arange(n_points)
        edges = self.mesh.edges
        key = np.concatenate([2 * position, 2 * position[edges].min(axis=1) + 1])
        nodes = np.argsort(key, kind="stable")
        return node_dofs(nodes, self.n_components).ravel()

    def edge_nodes(self, edge_index: np.ndarray) -> np.ndarray:
        """``(k, 3)`` nodes ``[start, end, midpoint]`` of boundary edges, counter-clockwise."""
        edge_index = np.asarray(edge_index, dtype=np.int64)
        ab = self.mesh.oriented_boundary(edge_index)
        return np.column_stack([ab, self.mesh.n_points + edge_index])

    def mesh_edge_nodes(self, edge_index: np.ndarray) -> np.ndarray:
        """``(k, 3)`` nodes ``[vertex, vertex, midpoint]`` of any mesh edges (as stored)."""
        edge_index = np.asarray(edge_index, dtype=np.int64)
        return np.column_stack([self.mesh.edges[edge_index], self.mesh.n_points + edge_index])

    def boundary_edges(
        self, edge_index: np.ndarray
    ) -> Iterator[tuple[slice | np.ndarray, StraightEdges | QuadraticEdges]]:
        """The geometry of boundary edges (:mod:`signorini.fem.mapping`), counter-clockwise
        as :meth:`edge_nodes`: quadratic through the midpoint node on parts carrying a curve
        other than a line, straight elsewhere; ``(rows, edges)`` per kind."""
        edge_index = np.asarray(edge_index, dtype=np.int64)
        points = self.node_points[self.edge_nodes(edge_index)]
        return edge_groups(points, np.isin(edge_index, self.curved_edges))

    def part_nodes(self, names: Iterable[str]) -> np.ndarray:
        """Sorted nodes on the closure of the named boundary parts (vertices and midpoints)."""
        edges = np.concatenate([self.mesh.part_edges(n) for n in names] or [np.zeros(0, int)])
        nodes = np.concatenate([self.mesh.edges[edges].ravel(), self.mesh.n_points + edges])
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
        u = np.asarray(u, dtype=np.float64)
        if u.shape[0] != self.n_nodes:
            raise ValueError(f"u has {u.shape[0]} nodes, the space has {self.n_nodes}")
        fine = P2Space(refinement.mesh)
        parent = np.asarray(refinement.parent)
        if (
            parent.shape != (fine.mesh.n_cells,)
            or (parent.size and (parent.min() < 0 or parent.max() >= self.mesh.n_cells))
            or np.shape(refinement.edge_point) != (self.mesh.n_edges,)
            or fine.mesh.n_points < self.mesh.n_points
        ):
            raise ValueError(
                "the refinement is not a refinement of this space's mesh (its parent "
                f"cells do not index the {self.mesh.n_cells} cells, or its bisected edges or "
                "points do not match the mesh's)"
            )
        coarse_cells, fine_cells = self.mesh.cells, fine.mesh.cells
        coarse_nodes, fine_nodes = self.cell_nodes, fine.cell_nodes
        out = np.empty((fine.n_nodes,) + u.shape[1:])
        known = np.zeros(fine.n_nodes, dtype=bool)
        # a cell that was not refined keeps its vertices, edges and local order: copy its nodes
        same = np.flatnonzero((fine_cells == coarse_cells[parent]).all(axis=1))
        out[fine_nodes[same]] = u[coarse_nodes[parent[same]]]
        known[fine_nodes[same]] = True
        # the old vertices keep their numbers; a bisection's new vertex is the old edge's node
        n_old = self.mesh.n_points
        out[:n_old] = u[:n_old]
        split = np.flatnonzero(refinement.edge_point >= 0)
        out[refinement.edge_point[split]] = u[n_old + split]
        known[:n_old] = True
        known[refinement.edge_point[split]] = True
        # the other nodes (midpoints of new edges): the parent's quadratic where they lie
        cell, local = np.nonzero(~known[fine_nodes])
        if cell.size:
            nodes = fine_nodes[cell, local]
            P = self.vertices[parent[cell]]  # (k, 3, 2)
            X = _reference_nodes(self.mesh, refinement, fine)[nodes]  # (k, 2)
            J = np.stack([P[:, 1] - P[:, 0], P[:, 2] - P[:, 0]], axis=-1)  # columns
            xi = np.linalg.solve(J, (X - P[:, 0])[..., None])[..., 0]  # (k, 2)
            bary = np.concatenate([1 - xi.sum(-1, keepdims=True), xi], axis=-1)
            if bary.min(initial=0.0) < -1e-8:
                raise ValueError(
                    "the refinement is not a refinement of this space's mesh (a new "
                    "cell is not inside its parent cell)"
                )
            phi = basis_barycentric(bary)  # (k, 6): the parent's local nodes
            coarse = u[coarse_nodes[parent[cell]]]  # (k, 6) or (k, 6, 2)
            out[nodes] = np.einsum("kj,kj...->k...", phi, coarse)
        return out


def _reference_nodes(coarse: Mesh, refinement: Refinement, fine: P2Space) -> np.ndarray:
    """``(n_nodes_new, 2)`` where the new nodes lie in their parent cells: the fine node
    points, except that a vertex placed on a curve counts at the chord midpoint of the edge
    it bisected (its parent cells are straight-sided), and the edge nodes of the fine mesh at
    the chord midpoints of these positions."""
    if all(curve is None for curve in coarse.curves):
        return fine.node_points
    points = refinement.mesh.points.copy()
    split = refinement.edge_point >= 0
    points[refinement.edge_point[split]] = coarse.edge_midpoints[split]
    e = refinement.mesh.edges
    return np.vstack([points, 0.5 * (points[e[:, 0]] + points[e[:, 1]])])


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
    def curved_edges(self) -> np.ndarray:
        """No edge is a quadratic: every edge is its chord."""
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
        nodes = np.asarray(vertex_order, dtype=np.int64)
        return node_dofs(nodes, self.n_components).ravel()

    def edge_nodes(self, edge_index: np.ndarray) -> np.ndarray:
        """``(k, 2)`` nodes ``[start, end]`` of boundary edges, counter-clockwise."""
        return self.mesh.oriented_boundary(np.asarray(edge_index, dtype=np.int64))

    def mesh_edge_nodes(self, edge_index: np.ndarray) -> np.ndarray:
        """``(k, 2)`` the two vertices of any mesh edges (as stored)."""
        return self.mesh.edges[np.asarray(edge_index, dtype=np.int64)]

    def boundary_edges(
        self, edge_index: np.ndarray
    ) -> Iterator[tuple[slice | np.ndarray, StraightEdges | QuadraticEdges]]:
        """The boundary edges as straight edges, counter-clockwise as :meth:`edge_nodes`."""
        yield slice(None), StraightEdges(self.node_points[self.edge_nodes(edge_index)])

    def part_nodes(self, names: Iterable[str]) -> np.ndarray:
        """Sorted nodes (vertices) on the closure of the named boundary parts."""
        edges = np.concatenate([self.mesh.part_edges(n) for n in names] or [np.zeros(0, int)])
        return np.unique(self.mesh.edges[edges])

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
        u = np.asarray(u, dtype=np.float64)
        if u.shape[0] != self.n_nodes:
            raise ValueError(f"u has {u.shape[0]} nodes, the space has {self.n_nodes}")
        n_old = self.mesh.n_points
        edge_point = np.asarray(refinement.edge_point)
        split = (
            np.flatnonzero(edge_point >= 0) if edge_point.shape == (self.mesh.n_edges,) else None
        )
        if split is None or refinement.mesh.n_points != n_old + split.size:
            raise ValueError(
                "the refinement is not a refinement of this space's mesh (its bisected edges "
                "or points do not match the mesh's)"
            )
        out = np.empty((refinement.mesh.n_points,) + u.shape[1:])
        out[:n_old] = u
        ends = self.mesh.edges[split]
        out[edge_point[split]] = 0.5 * (u[ends[:, 0]] + u[ends[:, 1]])
        return out


def space_of(mesh: Mesh, element: str | Element = "P2") -> LagrangeSpace:
    """The space of ``element`` (``"P2"``, the default, or ``"P1"``) on ``mesh``: the one
    place where a caller's choice of element becomes a space.

    Raises
    ------
    ValueError
        If ``element`` is not one of :data:`~signorini.fem.element.ELEMENTS`.
    """
    return _SPACES[element_of(element).name](mesh)


_SPACES = {"P1": P1Space, "P2": P2Space}
