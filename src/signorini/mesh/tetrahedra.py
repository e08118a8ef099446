"""The facts of a mesh that depend on its dimension, for :class:`~signorini.mesh.mesh.Mesh`:
the reference cell read from the arrays, reorientation, edge lengths, facet measures, the
edges of a set of faces, and the hook for the initial vertex order of bisection.

Conventions for tetrahedra (``dim = 3``)
----------------------------------------
- ``points (n_points, 3)``, ``cells (n_cells, 4)`` positively oriented:
  ``det[x1 − x0, x2 − x0, x3 − x0] > 0``. Then local face ``k`` of
  :data:`~signorini.mesh.reference.TETRAHEDRON` (opposite vertex ``k``) runs
  counter-clockwise seen from outside: its right-hand normal points out of the cell.
- Reorienting a negative cell swaps its local vertices 1 and 2 (in 2D the same swap
  lists a clockwise triangle counter-clockwise).
- The vertex order of the cells is kept as given: the initial condition of 3D bisection
  (an ordered vertex quadruple per cell) is set by :func:`initial_vertex_order`.
"""

from __future__ import annotations

import numpy as np

from .geometry import facet_normals
from .reference import TETRAHEDRON, TRIANGLE, ReferenceCell
from .topology import entity_keys
from .validation import MeshError

__all__ = [
    "REFERENCES",
    "edge_lengths",
    "facet_edges",
    "facet_measures",
    "initial_vertex_order",
    "reference_of",
    "reoriented",
]

#: The reference cell of a mesh by its number of vertices per cell.
REFERENCES: dict[int, ReferenceCell] = {3: TRIANGLE, 4: TETRAHEDRON}


def reference_of(points: np.ndarray, cells: np.ndarray) -> ReferenceCell:
    """The reference cell of ``cells (n_cells, d + 1)`` on ``points (n_points, d)``.

    Raises
    ------
    MeshError
        If the cells' width is not that of a simplex of the points' dimension.
    """
    cell = REFERENCES.get(cells.shape[1])
    if cell is None or cell.dim != points.shape[1]:
        raise MeshError(
            f"cells {cells.shape} do not match points {points.shape}: triangles (n, 3) on "
            "points (n, 2), or tetrahedra (n, 4) on points (n, 3)"
        )
    return cell


def reoriented(cells: np.ndarray, measure: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``cells`` with the cells of negative signed ``measure`` listed positively (local
    vertices 1 and 2 swapped), and the indices ``(k,)`` of those cells."""
    flipped = np.flatnonzero(measure < 0)
    if flipped.size:
        swap = np.r_[0, 2, 1, 3 : cells.shape[1]]
        cells = cells.copy()
        cells[flipped] = cells[flipped][:, swap]
    return cells, flipped


def initial_vertex_order(points: np.ndarray, cells: np.ndarray) -> np.ndarray:
    """The vertex order of tetrahedra that 3D bisection starts from: the cells as given.

    The hook for the initial condition of tagged-simplex bisection (Maubach, Traxler,
    Stevenson): a Kuhn (Freudenthal) mesh of boxes as :func:`~signorini.mesh.builders3d.box`
    builds it satisfies it as it is; an arbitrary mesh needs an initialisation (e.g.
    Diening, Gehring, Storn, arXiv:2306.02674), which belongs here. (In 2D,
    :func:`~signorini.mesh.topology.longest_edge_first` plays this part.)

    Parameters
    ----------
    points : (n_points, 3) float array
    cells : (n_cells, 4) int array
        Positively oriented.

    Returns
    -------
    (n_cells, 4) int array
        Positively oriented, the same cells.
    """
    del points  # read by the initialisation to come
    return cells


def edge_lengths(points: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """``(n_edges,)`` the lengths of the segments ``edges (n_edges, 2)``: ``np.hypot`` in 2D
    (the package's 2D arithmetic), the root of the sum of squares in 3D."""
    d = points[edges[:, 1]] - points[edges[:, 0]]
    if points.shape[1] == 2:
        return np.hypot(d[:, 0], d[:, 1])
    return np.sqrt(np.einsum("ij,ij->i", d, d))


def facet_measures(points: np.ndarray, facets: np.ndarray) -> np.ndarray:
    """``(n_facets,)`` the measures |F| of straight facets ``(n_facets, d)``: lengths in 2D
    (:func:`edge_lengths`), triangle areas ``|(b − a) × (c − a)| / 2`` in 3D
    (:func:`~signorini.mesh.geometry.facet_normals`)."""
    if points.shape[1] == 2:
        return edge_lengths(points, facets)
    return facet_normals(points[facets])[0]


def facet_edges(edges: np.ndarray, faces: np.ndarray, n_points: int) -> np.ndarray:
    """``(n_faces, 3)`` the rows of ``edges (n_edges, 2)`` (sorted by key, as
    :func:`~signorini.mesh.topology.entity_topology` makes them) of the edges ``(a, b)``,
    ``(b, c)``, ``(c, a)`` of each triangle ``faces (n_faces, 3)``.

    Raises
    ------
    MeshError
        If a side of a face is not an edge.
    """
    sides = faces[:, TRIANGLE.edges].reshape(-1, 2)
    keys = entity_keys(edges, n_points)
    k = entity_keys(sides, n_points)
    pos = np.minimum(np.searchsorted(keys, k), max(keys.size - 1, 0))
    if keys.size == 0 or not np.array_equal(keys[pos], k):
        raise MeshError("a side of a face is not an edge of the mesh")
    return pos.reshape(-1, 3)
