"""The topology of a triangulation as pure functions on its arrays (docs/method.md, *Data
conventions*): each undirected edge once, the edges of each cell and the cells of each edge,
the boundary edges, and the cell order that puts the refinement edge first.
:class:`~signorini.mesh.mesh.Mesh` caches their results.
"""

from __future__ import annotations

import numpy as np

from .reference import TRIANGLE
from .validation import MeshError

__all__ = ["boundary_edges", "edge_keys", "edge_topology", "longest_edge_first"]


def _frozen(a: np.ndarray) -> np.ndarray:
    """Mark a cached array read-only (a Mesh is immutable)."""
    a.flags.writeable = False
    return a


def edge_keys(pairs: np.ndarray, n_points: int) -> np.ndarray:
    """Unique int64 key of each undirected vertex pair ``(n, 2)``."""
    lo = np.minimum(pairs[:, 0], pairs[:, 1]).astype(np.int64)
    hi = np.maximum(pairs[:, 0], pairs[:, 1]).astype(np.int64)
    return lo * np.int64(n_points) + hi


def boundary_edges(cells: np.ndarray) -> np.ndarray:
    """Edges ``(n_boundary, 2)`` that belong to exactly one cell, oriented counter-clockwise.

    Parameters
    ----------
    cells : (n_cells, 3) int array
        Counter-clockwise triangles.
    """
    cells = np.asarray(cells, dtype=np.int64)
    local = cells[:, TRIANGLE.edges].reshape(-1, 2)
    n = int(cells.max()) + 1 if cells.size else 0
    keys = edge_keys(local, n)
    _, first, counts = np.unique(keys, return_index=True, return_counts=True)
    return local[first[counts == 1]]


def edge_topology(cells: np.ndarray, n_points: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``edges (n_edges, 2)`` (``min`` vertex first), ``cell2edge (n_cells, 3)`` (the edge of
    local edge ``k``, vertices ``TRIANGLE.edges[k]``) and ``edge2cell (n_edges, 2)`` (column 0
    the first cell seen, column 1 the other or ``-1``) of the triangles ``cells (n_cells, 3)``;
    read-only.

    Raises
    ------
    MeshError
        If an edge is shared by more than two cells.
    """
    local = cells[:, TRIANGLE.edges].reshape(-1, 2)
    keys = edge_keys(local, n_points)
    uniq, first, inverse, counts = np.unique(
        keys, return_index=True, return_inverse=True, return_counts=True
    )
    if counts.max(initial=0) > 2:
        bad = np.flatnonzero(counts > 2)
        pairs = local[first[bad]]
        raise MeshError(
            f"non-manifold mesh: {bad.size} edge(s) shared by more than two cells, first "
            f"({pairs[0, 0]}, {pairs[0, 1]})"
        )
    edges = np.sort(local[first], axis=1)
    cell2edge = inverse.reshape(-1, TRIANGLE.n_edges)
    n_edges = uniq.size
    # edge2cell: column 0 = the first cell seen, column 1 = the other (or -1)
    owner = np.repeat(np.arange(cells.shape[0], dtype=np.int64), TRIANGLE.n_edges)
    edge2cell = np.full((n_edges, 2), -1, dtype=np.int64)
    edge2cell[:, 0] = owner[first]
    second = np.ones(inverse.size, dtype=bool)
    second[first] = False
    edge2cell[inverse[second], 1] = owner[second]
    return _frozen(edges), _frozen(cell2edge), _frozen(edge2cell)


def longest_edge_first(points: np.ndarray, cells: np.ndarray) -> np.ndarray:
    """Rotate each cell's vertices cyclically so that local edge 0 is its longest edge (the
    rotation by ``k`` makes local edge ``k`` of :data:`TRIANGLE` local edge 0)."""
    p = points[cells]
    start, end = TRIANGLE.edges.T
    length2 = ((p[:, end] - p[:, start]) ** 2).sum(-1)  # local edge k
    k = np.argmax(length2, axis=1)
    rows = np.arange(len(cells))[:, None]
    return cells[rows, (k[:, None] + np.arange(3)[None, :]) % 3]
