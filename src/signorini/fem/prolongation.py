"""Prolongation: the exact interpolation of a field of a Lagrange space on the refined mesh
(docs/method.md, *Marking and refinement*), for :meth:`~signorini.fem.space.P2Space.prolongate`
and :meth:`~signorini.fem.space.P1Space.prolongate`.

A node of the refined mesh that is a node of the coarse one keeps its value; each other node
takes the coarse field where it lies, so the coarse space's functions are reproduced exactly
and the work grows with the new nodes.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..mesh.jacobians import affine_jacobian
from ..mesh.mesh import Mesh
from ..mesh.nesting import parent_barycentrics
from ..mesh.reference import TETRAHEDRON
from ..mesh.refine import Refinement
from . import p2_tet
from .p2 import basis_barycentric

if TYPE_CHECKING:
    from .space import P1Space, P2Space

__all__ = ["prolongate_p1", "prolongate_p2"]


def prolongate_p2(
    coarse: P2Space, fine: P2Space, u: np.ndarray, refinement: Refinement
) -> np.ndarray:
    """Exact interpolation of the P2 field ``u`` of ``coarse`` on ``fine``, the P2 space of
    ``refinement.mesh``.

    The old vertices, a bisection's new vertex (the node of the bisected edge) and the nodes
    of the cells that were not refined keep their values; each other node lies in the parent
    cell of a new cell, where the parent's quadratic is evaluated.

    Parameters
    ----------
    coarse, fine : P2Space
        The spaces of ``refinement``'s coarse and refined meshes.
    u : (n_nodes, d) or (n_nodes,) array
        Nodal values on ``coarse`` (vector or scalar field).
    refinement : Refinement

    Returns
    -------
    (n_nodes_new, d) or (n_nodes_new,) array

    Raises
    ------
    ValueError
        If ``u`` does not have one row per node, or ``refinement`` is not a refinement of
        the coarse mesh.
    """
    u = _nodal_values(coarse, u)
    parent = np.asarray(refinement.parent)
    if (
        parent.shape != (fine.mesh.n_cells,)
        or (parent.size and (parent.min() < 0 or parent.max() >= coarse.mesh.n_cells))
        or np.shape(refinement.edge_point) != (coarse.mesh.n_edges,)
        or fine.mesh.n_points < coarse.mesh.n_points
    ):
        raise ValueError(
            "the refinement is not a refinement of this space's mesh (its parent "
            f"cells do not index the {coarse.mesh.n_cells} cells, or its bisected edges or "
            "points do not match the mesh's)"
        )
    coarse_cells, fine_cells = coarse.mesh.cells, fine.mesh.cells
    coarse_nodes, fine_nodes = coarse.cell_nodes, fine.cell_nodes
    out = np.empty((fine.n_nodes,) + u.shape[1:])
    known = np.zeros(fine.n_nodes, dtype=bool)
    # a cell that was not refined keeps its vertices, edges and local order: copy its nodes
    same = np.flatnonzero((fine_cells == coarse_cells[parent]).all(axis=1))
    out[fine_nodes[same]] = u[coarse_nodes[parent[same]]]
    known[fine_nodes[same]] = True
    # the old vertices keep their numbers; a bisection's new vertex is the old edge's node
    n_old = coarse.mesh.n_points
    out[:n_old] = u[:n_old]
    split = np.flatnonzero(refinement.edge_point >= 0)
    out[refinement.edge_point[split]] = u[n_old + split]
    known[:n_old] = True
    known[refinement.edge_point[split]] = True
    # the other nodes (midpoints of new edges): the parent's quadratic where they lie
    cell, local = np.nonzero(~known[fine_nodes])
    if cell.size:
        nodes = fine_nodes[cell, local]
        if coarse.mesh.dim == 3:
            bary = _tetrahedron_barycentrics(coarse.mesh, fine.mesh, refinement, cell, local)
        else:
            bary = _triangle_barycentrics(coarse, fine, refinement, parent[cell], nodes)
        tet = bary.shape[-1] == 4  # the P2 tetrahedron's ten nodes, else the triangle's six
        phi = (p2_tet.basis_barycentric if tet else basis_barycentric)(bary)  # (k, n_local)
        parent_values = u[coarse_nodes[parent[cell]]]  # (k, 6) or (k, 6, d)
        out[nodes] = np.einsum("kj,kj...->k...", phi, parent_values)
    return out


def _tetrahedron_barycentrics(
    coarse: Mesh, fine: Mesh, refinement: Refinement, cell: np.ndarray, local: np.ndarray
) -> np.ndarray:
    """``(k, 4)`` the barycentric coordinates, in the parent cell, of the local nodes
    ``local`` of the refined cells ``cell``: those of the cell's vertices
    (:func:`~signorini.mesh.nesting.parent_barycentrics`, from the refinement's parent
    edges) and the midpoints of its edges' (docs/method.md, *Prolongation on curved parts*):
    the reference point where the parent's (isoparametric or affine) map puts the node, so
    the parent's P2 field is reproduced on curved parts too."""
    if refinement.parent_edge is None:
        raise ValueError(
            "the refinement does not give the parent edges of its new points "
            "(Refinement.parent_edge), which the prolongation on tetrahedra needs"
        )
    parent_edge = np.asarray(refinement.parent_edge, dtype=np.int64)
    if parent_edge.shape != (fine.n_points - coarse.n_points, 2):
        raise ValueError(
            f"the refinement's parent_edge needs shape ({fine.n_points - coarse.n_points}, 2) "
            f"(one row per new point), got {parent_edge.shape}"
        )
    rows, at = np.unique(cell, return_inverse=True)
    vertex = parent_barycentrics(
        coarse.cells, fine.cells[rows], refinement.parent[rows], parent_edge, coarse.n_points
    )
    e = TETRAHEDRON.edges
    nodes = np.concatenate([vertex, 0.5 * (vertex[:, e[:, 0]] + vertex[:, e[:, 1]])], axis=1)
    return nodes[at, local]


def _triangle_barycentrics(
    coarse: P2Space, fine: P2Space, refinement: Refinement, parent: np.ndarray, nodes: np.ndarray
) -> np.ndarray:
    """``(k, 3)`` the barycentric coordinates of the refined mesh's ``nodes`` in their
    ``parent`` triangles, from the node positions (:func:`_reference_nodes`)."""
    P = coarse.vertices[parent]  # (k, 3, 2)
    X = _reference_nodes(coarse.mesh, refinement, fine)[nodes]  # (k, 2)
    J, _ = affine_jacobian(P)  # columns v_k − v_0
    xi = np.linalg.solve(J, (X - P[:, 0])[..., None])[..., 0]  # (k, 2)
    bary = np.concatenate([1 - xi.sum(-1, keepdims=True), xi], axis=-1)
    if bary.min(initial=0.0) < -1e-8:
        raise ValueError(
            "the refinement is not a refinement of this space's mesh (a new "
            "cell is not inside its parent cell)"
        )
    return bary


def _nodal_values(space: P1Space | P2Space, u: np.ndarray) -> np.ndarray:
    """``u`` as float64 ``(n_nodes, d)`` or ``(n_nodes,)``; raise ``ValueError`` unless it
    has one row per node of ``space``."""
    u = np.asarray(u, dtype=np.float64)
    if u.shape[0] != space.n_nodes:
        raise ValueError(f"u has {u.shape[0]} nodes, the space has {space.n_nodes}")
    return u


def _reference_nodes(coarse: Mesh, refinement: Refinement, fine: P2Space) -> np.ndarray:
    """``(n_nodes_new, d)`` where the new nodes lie in their parent cells: the fine node
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


def prolongate_p1(coarse: P1Space, u: np.ndarray, refinement: Refinement) -> np.ndarray:
    """Exact interpolation of the P1 field ``u`` of ``coarse`` on the refined mesh: the old
    vertices keep their values, a bisection's new vertex gets the mean of the bisected
    edge's two (the field at the chord's midpoint).

    Parameters
    ----------
    coarse : P1Space
    u : (n_nodes, d) or (n_nodes,) array
    refinement : Refinement
        The refinement of ``coarse.mesh``.

    Returns
    -------
    (n_nodes_new, d) or (n_nodes_new,) array

    Raises
    ------
    ValueError
        If ``u`` does not have one row per node, or ``refinement``'s bisected edges or
        points do not match the coarse mesh.
    """
    u = _nodal_values(coarse, u)
    n_old = coarse.mesh.n_points
    edge_point = np.asarray(refinement.edge_point)
    split = np.flatnonzero(edge_point >= 0) if edge_point.shape == (coarse.mesh.n_edges,) else None
    if split is None or refinement.mesh.n_points != n_old + split.size:
        raise ValueError(
            "the refinement is not a refinement of this space's mesh (its bisected edges "
            "or points do not match the mesh's)"
        )
    out = np.empty((refinement.mesh.n_points,) + u.shape[1:])
    out[:n_old] = u
    ends = coarse.mesh.edges[split]
    out[edge_point[split]] = 0.5 * (u[ends[:, 0]] + u[ends[:, 1]])
    return out
