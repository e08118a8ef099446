"""Newest vertex bisection (NVB) with closure, vectorized over the whole mesh (triangles; tetrahedra
dispatch to the tagged-simplex bisection of :mod:`signorini.mesh.refine3d`).

A cell ``[a, b, c]`` has refinement edge ``a–b`` and newest vertex ``c`` (see
:mod:`signorini.mesh`). Bisecting it at the midpoint ``m`` of ``a–b`` gives the children
``[c, a, m]`` and ``[b, c, m]``, whose refinement edges ``c–a`` and ``b–c`` are the parent's
other two edges and whose newest vertex is ``m``. Marking an edge of a cell forces its
refinement edge to be marked too (closure), which keeps the mesh conforming. A cell with
1, 2 or 3 marked edges is split into 2, 3 or 4 children.

References
----------
.. [1] W. F. Mitchell, Adaptive refinement for arbitrary finite-element spaces with
   hierarchical bases, J. Comput. Appl. Math. 36 (1991) 65–78.
.. [2] S. Funken, D. Praetorius, P. Wissgott, Efficient implementation of adaptive P1-FEM
   in Matlab, Comput. Methods Appl. Math. 11 (2011) 460–490.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .geometry import signed_area
from .mesh import Mesh
from .refine3d import UNIFORM_BISECTIONS, bisect_mesh
from .validation import MeshError, degenerate_cells

__all__ = ["Refinement", "refine_nvb", "refine_uniform", "closure"]


@dataclass(frozen=True)
class Refinement:
    """The result of one refinement step.

    Attributes
    ----------
    mesh : Mesh
        The refined mesh. Old points keep their indices; new points follow.
    parent : (n_cells_new,) int array
        The cell of the old mesh that contains each new cell.
    edge_point : (n_edges_old,) int array
        New point index at the midpoint of each bisected old edge, ``-1`` where the edge was
        not bisected.
    parent_edge : (n_points_new - n_points_old, 2) int array or None
        The ends of the edge each new point bisected (new point ``n_points_old + i`` of
        ``parent_edge[i]``; in 3D also the edges the bisection created and cut in the same
        step), where :func:`signorini.mesh.nesting.parent_barycentrics` reads the new
        points' places in their parent cells; None if not known.
    """

    mesh: Mesh
    parent: np.ndarray
    edge_point: np.ndarray
    parent_edge: np.ndarray | None = None


def closure(mesh: Mesh, marked_edges: np.ndarray) -> np.ndarray:
    """Close a set of marked edges under the NVB rule.

    Every cell with a marked edge gets its refinement edge marked, until nothing changes.

    Parameters
    ----------
    mesh : Mesh
    marked_edges : (n_edges,) bool array

    Returns
    -------
    (n_edges,) bool array
    """
    marked = np.array(marked_edges, dtype=bool, copy=True)
    if marked.shape != (mesh.n_edges,):
        raise ValueError(f"marked_edges needs shape ({mesh.n_edges},), got {marked.shape}")
    c2e = mesh.cell2edge
    ref = c2e[:, 0]
    candidates = np.arange(mesh.n_cells)
    while True:
        hit = marked[c2e[candidates]].any(axis=1) & ~marked[ref[candidates]]
        if not hit.any():
            return marked
        newly = ref[candidates[hit]]
        marked[newly] = True
        # only neighbours of newly marked edges can change next round
        # edge sense: the cells around a marked edge. In 2D an edge's cells are its facet's
        # cells (facet2cell); in 3D this needs an edge -> cells map
        nb = mesh.facet2cell[newly].ravel()
        candidates = np.unique(nb[nb >= 0])


def refine_nvb(mesh: Mesh, marked: np.ndarray) -> Refinement:
    """Refine the marked cells by newest vertex bisection, with closure.

    Every marked cell is bisected at least once (its refinement edge is bisected); further
    cells are bisected as needed to keep the mesh conforming. Boundary edges keep their part.

    Parameters
    ----------
    mesh : Mesh
    marked : (n_cells,) bool array or int array of cell indices

    Returns
    -------
    Refinement
    """
    marked = _as_cell_mask(mesh, marked)
    if mesh.dim == 3:  # tagged-simplex bisection, docs/method.md "Three dimensions"
        return Refinement(*bisect_mesh(mesh, marked))
    edges = np.zeros(mesh.n_edges, dtype=bool)
    edges[mesh.cell2edge[marked, 0]] = True
    return _bisect(mesh, closure(mesh, edges))


def refine_uniform(mesh: Mesh) -> Refinement:
    """Bisect every edge once: each cell splits into four similar-by-NVB children.

    This is NVB with all edges marked (three bisections per cell), so the mesh size halves
    and the sequence stays within the NVB family of shapes. In 3D, three bisections of every
    cell (:data:`~signorini.mesh.refine3d.UNIFORM_BISECTIONS`): ``h`` halves and the number
    of cells grows eightfold.
    """
    if mesh.dim == 3:
        marked = np.ones(mesh.n_cells, dtype=bool)
        return Refinement(*bisect_mesh(mesh, marked, UNIFORM_BISECTIONS))
    return _bisect(mesh, np.ones(mesh.n_edges, dtype=bool))


def _as_cell_mask(mesh: Mesh, marked: np.ndarray) -> np.ndarray:
    marked = np.asarray(marked)
    if marked.dtype == bool:
        if marked.shape != (mesh.n_cells,):
            raise ValueError(f"a boolean marking needs shape ({mesh.n_cells},), got {marked.shape}")
        return marked
    if marked.size and not np.issubdtype(marked.dtype, np.integer):
        raise ValueError("marked must be a boolean mask or an array of cell indices")
    idx = marked.astype(np.int64).ravel()
    if idx.size and (idx.min() < 0 or idx.max() >= mesh.n_cells):
        raise ValueError(f"marked cell indices must lie in 0..{mesh.n_cells - 1}")
    mask = np.zeros(mesh.n_cells, dtype=bool)
    mask[idx] = True
    return mask


def _bisect(mesh: Mesh, marked_edges: np.ndarray) -> Refinement:
    """Split every cell according to which of its edges are marked (closed set)."""
    n_points = mesh.n_points
    bisected = np.flatnonzero(marked_edges)
    edge_point = np.full(mesh.n_edges, -1, dtype=np.int64)
    edge_point[bisected] = n_points + np.arange(bisected.size)
    points = np.vstack([mesh.points, mesh.edge_midpoints[bisected]])
    curved = _curved_bisected(mesh, edge_point)  # bisected edges of parts with a curve
    if curved is not None:
        ends = mesh.edges[curved[0]]
        for index in np.unique(curved[1]):  # a loop over parts, not edges
            mine = curved[1] == index
            points[edge_point[curved[0][mine]]] = mesh.curves[index].halfway(
                mesh.points[ends[mine, 0]], mesh.points[ends[mine, 1]]
            )

    cells = mesh.cells
    a, b, c = cells[:, 0], cells[:, 1], cells[:, 2]
    m0, m1, m2 = (edge_point[mesh.cell2edge[:, k]] for k in range(3))
    r, e1, e2 = m0 >= 0, m1 >= 0, m2 >= 0
    if np.any((e1 | e2) & ~r):
        raise AssertionError("marked edges are not closed under the NVB rule")

    index = np.arange(mesh.n_cells)
    groups = []  # (children (k, 3), parent (k,))

    def add(mask: np.ndarray, *children: tuple[np.ndarray, np.ndarray, np.ndarray]) -> None:
        if mask.any():
            for child in children:
                groups.append((np.column_stack([v[mask] for v in child]), index[mask]))

    keep = ~r
    only = r & ~e1 & ~e2
    right = r & e1 & ~e2
    left = r & ~e1 & e2
    both = r & e1 & e2
    add(keep, (a, b, c))
    add(only, (c, a, m0), (b, c, m0))
    add(right, (c, a, m0), (m0, b, m1), (c, m0, m1))
    add(left, (m0, c, m2), (a, m0, m2), (b, c, m0))
    add(both, (m0, c, m2), (a, m0, m2), (m0, b, m1), (c, m0, m1))
    new_cells = np.concatenate([g[0] for g in groups])
    parent = np.concatenate([g[1] for g in groups])

    # boundary edges: a bisected one becomes two with the same part
    be = mesh.boundary_facet
    mid = edge_point[be]
    split = mid >= 0
    bnd = mesh.boundary
    new_boundary = np.concatenate(
        [
            bnd[~split],
            np.column_stack([bnd[split, 0], mid[split]]),
            np.column_stack([mid[split], bnd[split, 1]]),
        ]
    )
    part = mesh.boundary_part
    new_part = np.concatenate([part[~split], part[split], part[split]])
    if curved is not None:
        _check_curved_cells(mesh, points, new_cells, parent, curved)
    refined = Mesh(
        points,
        new_cells,
        new_boundary,
        new_part,
        mesh.part_names,
        validate=False,
        curves=mesh.curves,
        cell_region=mesh.cell_region[parent],  # a child takes its parent's region
        region_names=mesh.region_names,
    )
    return Refinement(refined, parent, edge_point, mesh.edges[bisected])


def _curved_bisected(mesh: Mesh, edge_point: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """The bisected edges of parts that carry a curve and their parts, or None if no part
    carries one (work proportional to the boundary, not to the mesh)."""
    with_curve = [i for i, c in enumerate(mesh.curves) if c is not None]
    if not with_curve:
        return None
    rows = np.flatnonzero(np.isin(mesh.boundary_part, with_curve))
    edge = mesh.boundary_facet[rows]
    split = edge_point[edge] >= 0
    return edge[split], mesh.boundary_part[rows[split]]


def _check_curved_cells(
    mesh: Mesh,
    points: np.ndarray,
    cells: np.ndarray,
    parent: np.ndarray,
    curved: tuple[np.ndarray, np.ndarray],
) -> None:
    """Raise if a new vertex placed on a curve leaves a cell clockwise or degenerate (only
    the children of cells with such a vertex are looked at)."""
    moved = np.zeros(mesh.n_cells, dtype=bool)
    moved[mesh.facet2cell[curved[0], 0]] = True
    touched = np.flatnonzero(moved[parent])
    area = signed_area(points, cells[touched])
    bad = (area <= 0) | degenerate_cells(points, cells[touched], area)
    if bad.any():
        cell = cells[touched[np.flatnonzero(bad)]]
        parts = [mesh.part_names[i] for i in np.unique(curved[1])]
        raise MeshError(
            f"refinement: placing new vertices on the curve of part(s) {parts} turns "
            f"{bad.sum()} new cell(s) clockwise or flat, e.g. {cell[0].tolist()} at "
            f"{points[cell[0]].tolist()}: the initial mesh is too coarse for the curve "
            "(refine it near the curve before attaching the curve)"
        )
