"""Where the refined cells lie in their parent cells, in the parents' reference coordinates
(docs/method.md, *Three dimensions: bisection*, *Prolongation on curved parts*).

Bisection cuts an edge at the midpoint of its two ends, and on the reference cell of an
ancestor the cut is the midpoint of the ends' reference points too, whether the new vertex
is placed at the chord's midpoint or (on a curved part) on the surface. So the barycentric
coordinates of every vertex of a refined cell in its parent cell of the coarse mesh follow
from the refinement record alone: an old vertex is a vertex of the parent, and a new vertex
``v`` with parent edge ``a–b`` (:attr:`~signorini.mesh.refine.Refinement.parent_edge`) has
``λ(v) = (λ(a) + λ(b)) / 2`` in every cell that contains it. The ends of a new vertex's edge
are older points, so the coordinates are built generation by generation (a loop over
generations, not over points or cells), each (cell, point) pair once.
"""

from __future__ import annotations

import numpy as np

__all__ = ["generations", "parent_barycentrics"]


def generations(n_old: int, parent_edge: np.ndarray) -> np.ndarray:
    """``(n_old + k,)`` the generation of every point: 0 for the old points, and ``1 +`` the
    larger of its edge's ends' for the ``k`` new points (``parent_edge (k, 2)``, new point
    ``n_old + i`` the midpoint of ``parent_edge[i]``; ends are older points)."""
    gen = np.zeros(n_old + parent_edge.shape[0], dtype=np.int64)
    while True:  # a loop over generations
        new = 1 + gen[parent_edge].max(axis=1, initial=0)
        if np.array_equal(new, gen[n_old:]):
            return gen
        gen[n_old:] = new


def parent_barycentrics(
    coarse_cells: np.ndarray,
    fine_cells: np.ndarray,
    parent: np.ndarray,
    parent_edge: np.ndarray,
    n_old: int,
) -> np.ndarray:
    """The barycentric coordinates ``(n, k, k)`` of the vertices of refined cells in their
    parent cells: row ``j`` of cell ``c`` the coordinates of ``fine_cells[c, j]`` with
    respect to the vertices ``coarse_cells[parent[c]]`` in their order (module docstring).

    Parameters
    ----------
    coarse_cells : (n_coarse, k) int array
    fine_cells : (n, k) int array
        Refined cells (all of the refined mesh, or some of them).
    parent : (n,) int array
        The coarse cell of each refined cell.
    parent_edge : (n_points_fine - n_old, 2) int array
        The ends of the edge each new point bisected.
    n_old : int
        The coarse mesh's points (they keep their indices).

    Returns
    -------
    (n, k, k) float64 array
        Exact dyadic fractions (sums of powers of two over the vertices).

    Raises
    ------
    ValueError
        If an old vertex of a refined cell is not a vertex of its parent cell, or a new
        vertex's edge does not lie in it (the record is not a refinement of the cells).
    """
    k = coarse_cells.shape[1]
    n_points = n_old + parent_edge.shape[0]
    if parent_edge.size and (
        parent_edge.min() < 0 or np.any(parent_edge >= np.arange(n_old, n_points)[:, None])
    ):
        raise ValueError(
            "the refinement is not a refinement of this mesh (a new point's edge ends are not "
            "older points)"
        )
    base = np.int64(n_points)
    # every (parent cell, point) pair the cells' vertices need, down to the old points
    level = np.unique(np.repeat(parent, k) * base + fine_cells.ravel())
    pairs = [level]
    while level.size:  # a loop over generations
        cell, point = np.divmod(level, base)
        new = point >= n_old
        ends = parent_edge[point[new] - n_old]
        level = np.unique((cell[new][:, None] * base + ends).ravel())
        pairs.append(level)
    key = np.unique(np.concatenate(pairs))
    cell, point = np.divmod(key, base)
    lam = np.zeros((key.size, k))
    old = np.flatnonzero(point < n_old)
    hit = coarse_cells[cell[old]] == point[old, None]
    if not hit.any(axis=1).all():
        raise ValueError(
            "the refinement is not a refinement of this mesh (a vertex of a new cell is not "
            "a vertex of its parent cell or inside it)"
        )
    lam[old] = hit
    gen = generations(n_old, parent_edge)[point]
    for g in range(1, int(gen.max(initial=0)) + 1):  # a loop over generations
        rows = np.flatnonzero(gen == g)
        ends = parent_edge[point[rows] - n_old]
        at = np.searchsorted(key, cell[rows, None] * base + ends)
        lam[rows] = 0.5 * (lam[at[:, 0]] + lam[at[:, 1]])
    at = np.searchsorted(key, np.repeat(parent, k) * base + fine_cells.ravel())
    return lam[at].reshape(fine_cells.shape[0], k, k)
