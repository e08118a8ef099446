"""``σ(u_h) n`` on the edges of straight cells, and the direction field the contact terms
split it along (docs/method.md, *Estimator*, "On curved boundaries"); used by the terms of
:mod:`signorini.estimator.terms` (which re-exports both)."""

from __future__ import annotations

import numpy as np

from ..fem.p2 import edge_basis
from ..mesh.geometry import segment_normals

__all__ = ["direction_field", "edge_traction"]


def edge_traction(
    sigma_vertex: np.ndarray,
    points: np.ndarray,
    cells: np.ndarray,
    cell: np.ndarray,
    k: np.ndarray,
    t: np.ndarray,
) -> np.ndarray:
    """``σ(u_h) n`` along local edge ``k`` of ``cell``, n the cell's outward normal.

    σ(u_h) is linear on each cell (P2 displacements), so it is interpolated from its
    values at the vertices.

    Parameters
    ----------
    sigma_vertex : (n_cells, 3, 2, 2) float array
        σ(u_h) of each cell at its vertices.
    points, cells : mesh arrays
    cell, k : (m,) int arrays
        Cell and local edge of each edge.
    t : (q,) float array
        Parameters along the edge, in the cell's counter-clockwise direction.

    Returns
    -------
    (m, q, 2) float array
    """
    # flat indices (one gather each, faster than indexing two axes)
    v0, v1 = 3 * cell + k, 3 * cell + (k + 1) % 3
    corners = cells.ravel()
    _, n = segment_normals(points[corners[v0]], points[corners[v1]])
    # σ n at the edge's two vertices, then linear along it (σ is linear on the cell)
    sigma = sigma_vertex.reshape(-1, 2, 2)
    a = np.einsum("eij,ej->ei", sigma[v0], n)
    b = np.einsum("eij,ej->ei", sigma[v1], n)
    return (1 - t)[None, :, None] * a[:, None] + t[None, :, None] * b[:, None]


def direction_field(direction: np.ndarray, t: np.ndarray) -> np.ndarray:
    """The constraint direction along contact edges: the normalised quadratic interpolant of
    the nodal directions n_z ``(k, 3, 2)`` at ``[start, end, midpoint]``, at parameters
    ``t (q,)``: ``(k, q, 2)`` unit vectors (docs/method.md, *Estimator*, "On curved
    boundaries"). Where the interpolant vanishes (nodal directions opposed across one edge,
    e.g. an edge spanning a slot of an obstacle) the midpoint node's direction is used."""
    d = np.einsum("qa,kac->kqc", edge_basis(t), direction)
    size = np.hypot(d[..., 0], d[..., 1])[..., None]
    small = size <= 1e-8
    if small.any():
        d = np.where(small, direction[:, None, 2], d)
        size = np.where(small, 1.0, size)
    return d / size
