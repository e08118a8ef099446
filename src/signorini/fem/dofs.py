"""The DOF layout of the vector Lagrange spaces: interleaved components, the cells' DOFs, and
the orders of the DOFs that extend an order of the mesh's vertices.

Vector DOFs are interleaved per node: ``dof = d * node + component``, ``d`` the components
per node (``space.n_components = mesh.dim``). The one place where this layout is written;
:mod:`signorini.fem.space` and the contact layer read it through :func:`node_dofs`.
"""

from __future__ import annotations

import numpy as np

__all__ = ["cell_dofs", "node_dofs", "vertex_dof_order"]


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


def cell_dofs(cell_nodes: np.ndarray, n_components: int) -> np.ndarray:
    """``(n_cells, d n_local)`` interleaved global DOFs of the cells with global nodes
    ``cell_nodes (n_cells, n_local)``: local DOF ``d * a + c`` is component ``c`` at local
    node ``a``."""
    return node_dofs(cell_nodes, n_components).reshape(len(cell_nodes), -1)


def vertex_dof_order(
    vertex_order: np.ndarray, n_components: int, edges: np.ndarray | None = None
) -> np.ndarray:
    """The order of the DOFs that extends an order of the mesh's vertices (docs/method.md,
    *Ordering of the unknowns*): with ``edges`` (a P2 space, node ``n_points + e`` on edge
    ``e``) each edge's node right after the earlier of its two vertices; the ``d`` DOFs of a
    node together.

    A nested dissection of the vertex graph stays one of the P2 graph this way: the nodes of
    a cell are its vertices and edges, and an edge's node goes where its earlier vertex is,
    so no coupling crosses a separator.

    Parameters
    ----------
    vertex_order : (n_points,) int array
        ``vertex_order[k]``: the vertex eliminated k-th (a permutation).
    n_components : int
        The components per node, ``d``.
    edges : (n_edges, 2) int array, optional
        The mesh's edges, the carriers of the P2 nodes; ``None`` for a P1 space.

    Returns
    -------
    (n_dofs,) int64 array
        ``order[k]``: the DOF eliminated k-th.
    """
    if edges is None:
        nodes = np.asarray(vertex_order, dtype=np.int64)
        return node_dofs(nodes, n_components).ravel()
    n_points = len(vertex_order)
    position = np.empty(n_points, dtype=np.int64)
    position[vertex_order] = np.arange(n_points)
    key = np.concatenate([2 * position, 2 * position[edges].min(axis=1) + 1])
    nodes = np.argsort(key, kind="stable")
    return node_dofs(nodes, n_components).ravel()
