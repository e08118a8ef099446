"""The checks a :class:`~signorini.mesh.mesh.Mesh` passes when it is built from user arrays.

A mesh is valid when its arrays have the right shapes and finite entries, its cells are
counter-clockwise and not degenerate, every point is a vertex, no two points coincide, the
cells form a conforming triangulation (each interior edge shared by exactly two cells that
traverse it in opposite directions, no hanging node on the boundary), and every boundary edge
belongs to exactly one named part that owns at least one edge. Each failure raises a
:class:`MeshError` that names the offending cells, edges or points.

Refinement preserves validity by construction and skips these checks.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .geometry import signed_area

if TYPE_CHECKING:
    from .mesh import Mesh

__all__ = [
    "MeshError",
    "as_cells",
    "as_points",
    "check_orientation",
    "format_indices",
    "validate_mesh",
]

#: Relative tolerance for a boundary point lying inside a boundary edge (a hanging node).
HANGING_TOL = 1e-10


class MeshError(ValueError):
    """Raised for a mesh that is not a valid conforming triangulation."""


def format_indices(indices: np.ndarray, limit: int = 5) -> str:
    """The first few entries of an index array, for an error message."""
    shown = ", ".join(str(int(i)) for i in indices[:limit])
    more = f" (and {indices.size - limit} more)" if indices.size > limit else ""
    return shown + more


def as_points(points: np.ndarray) -> np.ndarray:
    """``points`` as a finite ``(n_points, 2)`` float64 array, or a :class:`MeshError`."""
    p = np.asarray(points, dtype=np.float64)
    if p.ndim != 2 or p.shape[1] != 2:
        raise MeshError(f"points must have shape (n_points, 2), got {p.shape}")
    if not np.isfinite(p).all():
        bad = np.flatnonzero(~np.isfinite(p).all(1))
        raise MeshError(f"point(s) {format_indices(bad)} have non-finite coordinates")
    return p


def as_cells(cells: np.ndarray, n_points: int, what: str = "cells") -> np.ndarray:
    """Integer point indices ``(n, 3)`` (``(n, 2)`` for boundary edges) in ``0..n_points - 1``
    as int64, or a :class:`MeshError`."""
    c = np.asarray(cells)
    width = 3 if what == "cells" else 2
    if c.ndim != 2 or c.shape[1] != width:
        raise MeshError(f"{what} must have shape (n, {width}), got {c.shape}")
    if c.size and not np.issubdtype(c.dtype, np.integer):
        if not np.all(np.equal(np.mod(c, 1), 0)):
            raise MeshError(f"{what} must hold integer point indices")
    c = c.astype(np.int64)
    if c.size and (c.min() < 0 or c.max() >= n_points):
        raise MeshError(f"{what} refer to points outside 0..{n_points - 1}")
    return c


def check_orientation(points: np.ndarray, cells: np.ndarray) -> None:
    """Raise unless there are cells and all are counter-clockwise and non-degenerate."""
    if cells.shape[0] == 0:
        raise MeshError("the mesh has no cells")
    area = signed_area(points, cells)
    p = points[cells]
    h2 = ((p - np.roll(p, 1, axis=1)) ** 2).sum(-1).max(axis=1)
    degenerate = np.abs(area) <= 1e-12 * h2
    if degenerate.any():
        bad = np.flatnonzero(degenerate)
        raise MeshError(
            f"degenerate triangle(s) {format_indices(bad)} (zero area or repeated vertex), "
            f"e.g. cell {bad[0]} = {cells[bad[0]].tolist()}"
        )
    if np.any(area < 0):
        bad = np.flatnonzero(area < 0)
        raise MeshError(
            f"clockwise triangle(s) {format_indices(bad)}: list each cell's vertices "
            "counter-clockwise"
        )


def _check_points(points: np.ndarray, cells: np.ndarray) -> None:
    """Every point is a vertex of some cell, and no two points coincide."""
    used = np.zeros(len(points), dtype=bool)
    used[cells.ravel()] = True
    if not used.all():
        raise MeshError(
            f"unreferenced point(s) {format_indices(np.flatnonzero(~used))}: every "
            "point must be a vertex of some cell"
        )
    scale = max(float(np.ptp(points, axis=0).max()), 1.0)
    q = np.round(points / (1e-10 * scale)).astype(np.int64)
    _, inverse, counts = np.unique(q, axis=0, return_inverse=True, return_counts=True)
    if counts.max() > 1:
        dup = np.flatnonzero(counts[inverse.reshape(-1)] > 1)
        raise MeshError(
            f"duplicate points {format_indices(dup)} (same coordinates {points[dup[0]].tolist()})"
        )


def _check_part_labels(mesh: Mesh) -> None:
    """Every boundary row has a valid part index, and every part owns an edge."""
    if mesh.boundary_part.shape != (len(mesh.boundary),):
        raise MeshError("boundary_part must have one entry per boundary edge")
    bad_part = (mesh.boundary_part < 0) | (mesh.boundary_part >= len(mesh.part_names))
    if bad_part.any():
        first = mesh.boundary[np.flatnonzero(bad_part)[0]]
        raise MeshError(
            f"{int(bad_part.sum())} boundary edge(s) have no part, first "
            f"({first[0]}, {first[1]}); label every boundary edge"
        )
    for index, name in enumerate(mesh.part_names):
        if not np.any(mesh.boundary_part == index):
            raise MeshError(f"boundary part {name!r} has no edges")


def _check_boundary_labelled(mesh: Mesh, is_bnd: np.ndarray) -> None:
    """The listed boundary edges are exactly the edges with one cell, each listed once."""
    be = mesh.boundary_edge  # raises for a listed pair that is not an edge
    if np.any(~is_bnd[be]):
        bad = mesh.boundary[np.flatnonzero(~is_bnd[be])[0]]
        raise MeshError(
            f"edge ({bad[0]}, {bad[1]}) is labelled as boundary but is shared by two cells"
        )
    if np.unique(be).size != be.size:
        raise MeshError("a boundary edge is listed twice")
    labelled = np.zeros(mesh.n_edges, dtype=bool)
    labelled[be] = True
    missing = np.flatnonzero(is_bnd & ~labelled)
    if missing.size:
        e = mesh.edges[missing[0]]
        raise MeshError(
            f"{missing.size} boundary edge(s) without a part, first "
            f"({e[0]}, {e[1]}); label every boundary edge"
        )


def _check_opposite_traversal(mesh: Mesh, is_bnd: np.ndarray) -> None:
    """Neighbouring cells traverse a shared edge in opposite directions (else they overlap)."""
    local = mesh.cells[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2)
    forward = local[:, 0] < local[:, 1]
    inner = ~is_bnd[mesh.cell2edge.ravel()]
    counts = np.bincount(mesh.cell2edge.ravel()[inner & forward], minlength=mesh.n_edges)
    if np.any(counts[~is_bnd] != 1):
        bad = np.flatnonzero((counts != 1) & ~is_bnd)[0]
        e = mesh.edges[bad]
        raise MeshError(
            f"cells overlap or are inconsistently oriented across edge ({e[0]}, {e[1]})"
        )


def _check_no_hanging_node(mesh: Mesh, is_bnd: np.ndarray) -> None:
    """No boundary vertex lies inside a boundary edge.

    The candidates of each edge are the boundary vertices inside its bounding box, found by
    sorting along the axis in which the box holds fewer (near-linear, not all pairs).
    """
    bnd = np.flatnonzero(is_bnd)
    verts = np.unique(mesh.edges[bnd])
    points = mesh.points
    a = points[mesh.edges[bnd, 0]]
    b = points[mesh.edges[bnd, 1]]
    margin = 1e-9 * np.hypot(*(b - a).T)
    first, count, by_axis = [], [], []
    for axis in range(2):
        order = verts[np.argsort(points[verts, axis], kind="stable")]
        coord = points[order, axis]
        lo = np.searchsorted(coord, np.minimum(a[:, axis], b[:, axis]) - margin, "left")
        hi = np.searchsorted(coord, np.maximum(a[:, axis], b[:, axis]) + margin, "right")
        first.append(lo)
        count.append(hi - lo)
        by_axis.append(order)
    use_y = count[1] < count[0]
    n_cand = np.where(use_y, count[1], count[0])
    edge_of = np.repeat(np.arange(bnd.size), n_cand)
    pos = np.where(use_y, first[1], first[0])[edge_of] + (
        np.arange(edge_of.size) - np.repeat(np.cumsum(n_cand) - n_cand, n_cand)
    )
    cand = np.where(use_y[edge_of], by_axis[1][pos], by_axis[0][pos])
    ab = (b - a)[edge_of]
    ap = points[cand] - a[edge_of]
    length2 = (ab**2).sum(-1)
    t = (ap * ab).sum(-1) / length2
    cross = ab[:, 0] * ap[:, 1] - ab[:, 1] * ap[:, 0]
    on = (np.abs(cross) <= HANGING_TOL * length2) & (t > HANGING_TOL) & (t < 1 - HANGING_TOL)
    if on.any():
        i = np.flatnonzero(on)[0]
        e = mesh.edges[bnd[edge_of[i]]]
        raise MeshError(
            f"non-conforming mesh: point {cand[i]} lies inside edge ({e[0]}, {e[1]}) (hanging node)"
        )


def validate_mesh(mesh: Mesh) -> None:
    """Check that ``mesh`` is a valid conforming triangulation with labelled boundary.

    Parameters
    ----------
    mesh : Mesh

    Raises
    ------
    MeshError
        At the first violation, naming the offending cells, edges or points.
    """
    points = as_points(mesh.points)
    cells = as_cells(mesh.cells, len(points))
    as_cells(mesh.boundary, len(points), what="boundary edges")
    check_orientation(points, cells)
    _check_points(points, cells)
    _check_part_labels(mesh)
    is_bnd = mesh.edge2cell[:, 1] < 0  # building the topology raises on non-manifold edges
    _check_opposite_traversal(mesh, is_bnd)
    _check_no_hanging_node(mesh, is_bnd)
    _check_boundary_labelled(mesh, is_bnd)
