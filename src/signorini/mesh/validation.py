"""The checks a :class:`~signorini.mesh.mesh.Mesh` passes when it is built from user arrays.

A mesh is valid when its arrays have the right shapes and finite entries, its cells are
counter-clockwise and not degenerate, every point is a vertex, no two points coincide, the
cells form a conforming triangulation (each interior edge shared by exactly two cells that
traverse it in opposite directions, no hanging node on the boundary), no two cells overlap,
and every boundary edge belongs to exactly one named part that owns at least one edge. Each
failure raises a :class:`MeshError` that names the offending cells, edges or points.

Every geometric tolerance is relative to the mesh's own size (its bounding box, or the
length of the edge in question), so that a mesh and its image under ``x -> s x + t`` pass or
fail together for any scale ``s`` and shift ``t`` representable in float64.

Refinement preserves validity by construction and skips these checks.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from scipy.spatial import cKDTree

from .geometry import signed_area
from .reference import TRIANGLE

if TYPE_CHECKING:
    from .curves import Curve
    from .mesh import Mesh

__all__ = [
    "MeshError",
    "as_cells",
    "as_points",
    "check_orientation",
    "nondegenerate_area",
    "check_on_curve",
    "format_indices",
    "validate_mesh",
    "winding_numbers",
]

#: Relative tolerance for a boundary point lying inside a boundary edge (a hanging node).
HANGING_TOL = 1e-10

#: Two points closer than this times the mesh's bounding-box diameter are duplicates.
DUPLICATE_TOL = 1e-10

#: Largest number of (point, edge) or (edge, edge) pairs held in memory at once.
_CHUNK = 2_000_000


class MeshError(ValueError):
    """Raised for a mesh that is not a valid conforming triangulation."""


def format_indices(indices: np.ndarray, limit: int = 5) -> str:
    """The first few entries of an index array, for an error message."""
    shown = ", ".join(str(int(i)) for i in indices[:limit])
    more = f" (and {indices.size - limit} more)" if indices.size > limit else ""
    return shown + more


def _as_number_array(value: object, what: str, expected: str, kinds: str) -> np.ndarray:
    """``value`` as an array whose dtype kind is in ``kinds``, or a :class:`MeshError` that
    names ``what`` and ``expected`` (strings, ragged lists and objects are refused)."""
    if isinstance(value, (str, bytes)):
        raise MeshError(f"{what} must be {expected}, got a string {value[:40]!r}")
    try:
        a = np.asarray(value)
    except (TypeError, ValueError) as exc:  # ragged nested sequences
        raise MeshError(f"{what} must be {expected}; NumPy says: {exc}") from None
    if a.dtype.kind not in kinds:
        kind = "strings" if a.dtype.kind in "US" else f"dtype {a.dtype}"
        raise MeshError(f"{what} must be {expected}, got an array of {kind}")
    return a


def as_points(points: np.ndarray) -> np.ndarray:
    """``points`` as a finite ``(n_points, d)`` float64 array, d = 2 or 3, or a MeshError."""
    p = _as_number_array(points, "points", "an (n_points, 2) array of numbers", "iuf")
    p = p.astype(np.float64, copy=False)
    if p.ndim != 2 or p.shape[1] not in (2, 3):
        raise MeshError(f"points must have shape (n_points, 2), got {p.shape} (3D: (n_points, 3))")
    if not np.isfinite(p).all():
        bad = np.flatnonzero(~np.isfinite(p).all(1))
        raise MeshError(f"point(s) {format_indices(bad)} have non-finite coordinates")
    return p


def as_cells(cells: np.ndarray, n_points: int, what: str = "cells", width: int = 0) -> np.ndarray:
    """Integer point indices ``(n, width)`` (by default ``(n, 3)``, ``(n, 2)`` for boundary
    edges) in ``0..n_points - 1`` as int64, or a :class:`MeshError`."""
    width = width or (3 if what == "cells" else 2)
    c = _as_number_array(cells, what, f"an (n, {width}) array of point indices", "iuf")
    if c.ndim != 2 or c.shape[1] != width:
        raise MeshError(f"{what} must have shape (n, {width}), got {c.shape}")
    if c.size and not np.issubdtype(c.dtype, np.integer):
        if not np.all(np.equal(np.mod(c, 1), 0)):
            raise MeshError(f"{what} must hold integer point indices")
        if np.abs(c).max() >= 2.0**62:
            raise MeshError(f"{what} refer to points outside 0..{n_points - 1}")
    c = c.astype(np.int64)
    if c.size and (c.min() < 0 or c.max() >= n_points):
        raise MeshError(f"{what} refer to points outside 0..{n_points - 1}")
    return c


#: the largest aspect ratio (longest edge / smallest height, ``h_max² / (2 |A|)``) of a cell
#: that is not refused as degenerate. The area computed from float64 coordinates carries an
#: error of about ``1e-16 h_max²``, so at this aspect ratio it has only 4 correct digits, and
#: so have the cell's stiffness (∝ 1/|A|) and every quantity computed from it; beyond it
#: the cell is numerically flat. Accuracy of the solve on cells below the bound is the
#: solver's concern (its residuals say when it fails).
MAX_ASPECT = 5e11


def aspect_ratios(points: np.ndarray, cells: np.ndarray, area: np.ndarray) -> np.ndarray:
    """``(n_cells,)`` each cell's longest edge over its smallest height, ``h_max² / (2|A|)``
    (``inf`` for a zero area): 2/√3 for an equilateral triangle."""
    p = points[cells]
    start, end = TRIANGLE.edges.T
    h2 = ((p[:, end] - p[:, start]) ** 2).sum(-1).max(axis=1)
    with np.errstate(divide="ignore"):
        return h2 / (2.0 * np.abs(area))


def degenerate_cells(points: np.ndarray, cells: np.ndarray, area: np.ndarray) -> np.ndarray:
    """``(n_cells,)`` bool: cells whose aspect ratio exceeds :data:`MAX_ASPECT` (their area is
    round-off relative to their longest edge²)."""
    return aspect_ratios(points, cells, area) >= MAX_ASPECT


def nondegenerate_area(points: np.ndarray, cells: np.ndarray) -> np.ndarray:
    """The signed areas ``(n_cells,)``; raise if there are no cells or one is degenerate."""
    if cells.shape[0] == 0:
        raise MeshError("the mesh has no cells")
    area = signed_area(points, cells)
    degenerate = degenerate_cells(points, cells, area)
    if degenerate.any():
        bad = np.flatnonzero(degenerate)
        c = bad[0]
        corners = ", ".join(f"({x:.12g}, {y:.12g})" for x, y in points[cells[c]])
        aspect = aspect_ratios(points, cells[c : c + 1], area[c : c + 1])[0]
        raise MeshError(
            f"degenerate triangle(s) {format_indices(bad)} (zero area, repeated vertex or a "
            f"sliver), e.g. cell {c} = {cells[c].tolist()} with vertices {corners}: aspect "
            f"ratio (longest edge / smallest height) {aspect:.3g}, beyond {MAX_ASPECT:.0e}, "
            "where its area is round-off of its coordinates"
        )
    return area


def check_orientation(points: np.ndarray, cells: np.ndarray) -> None:
    """Raise unless there are cells and all are counter-clockwise and non-degenerate."""
    area = nondegenerate_area(points, cells)
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
    # relative to the mesh's size, and never finer than the coordinates' own precision
    lo, hi = points.min(axis=0), points.max(axis=0)
    tol = max(
        DUPLICATE_TOL * float(np.hypot(*(hi - lo))),
        4 * np.finfo(np.float64).eps * float(np.abs(points).max()),
    )
    pairs = cKDTree(points - 0.5 * (lo + hi)).query_pairs(tol, output_type="ndarray")
    if pairs.size:
        dup = np.unique(pairs)
        raise MeshError(
            f"duplicate points {format_indices(dup)} (same coordinates {points[dup[0]].tolist()})"
        )


def _check_opposite_traversal(mesh: Mesh, is_bnd: np.ndarray) -> None:
    """Neighbouring cells traverse a shared edge in opposite directions (else they overlap)."""
    local = mesh.cells[:, TRIANGLE.edges].reshape(-1, 2)
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


def _candidate_pairs(lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Pairs ``(i, j)``, ``i != j``, of intervals ``[lo, hi]`` that overlap, each pair at least
    once: ``j`` is a candidate of ``i`` when ``lo[j]`` falls in ``[lo[i], hi[i]]``."""
    order = np.argsort(lo, kind="stable")
    start = np.searchsorted(lo[order], lo, "left")
    stop = np.searchsorted(lo[order], hi, "right")
    count = stop - start
    i = np.repeat(np.arange(lo.size), count)
    j = order[
        np.repeat(start, count) + (np.arange(i.size) - np.repeat(np.cumsum(count) - count, count))
    ]
    keep = i != j
    return i[keep], j[keep]


def _check_boundary_crossings(points: np.ndarray, segments: np.ndarray) -> None:
    """No two boundary edges cross each other (they may only share end points).

    The candidates of an edge are the edges whose box starts inside its own box, along the
    axis that gives fewer candidates in total (near-linear for a mesh's boundary).
    """
    a, b = points[segments[:, 0]], points[segments[:, 1]]
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    counts = [
        np.searchsorted(np.sort(lo[:, k]), hi[:, k], "right").sum()
        - np.searchsorted(np.sort(lo[:, k]), lo[:, k], "left").sum()
        for k in range(2)
    ]
    axis = int(np.argmin(counts))
    i, j = _candidate_pairs(lo[:, axis], hi[:, axis])
    other = 1 - axis
    box = (lo[i, other] <= hi[j, other]) & (lo[j, other] <= hi[i, other])
    share = (segments[i, :, None] == segments[j, None, :]).any(axis=(1, 2))
    i, j = i[box & ~share], j[box & ~share]
    for s in range(0, i.size, _CHUNK):
        ii, jj = i[s : s + _CHUNK], j[s : s + _CHUNK]
        p1, p2, q1, q2 = a[ii], b[ii], a[jj], b[jj]
        d, e = p2 - p1, q2 - q1

        def side(u: np.ndarray, v: np.ndarray) -> np.ndarray:
            return np.sign(u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0])

        cross = (side(d, q1 - p1) * side(d, q2 - p1) < 0) & (
            side(e, p1 - q1) * side(e, p2 - q1) < 0
        )
        if cross.any():
            k = np.flatnonzero(cross)[0]
            s1, s2 = segments[ii[k]], segments[jj[k]]
            raise MeshError(
                f"cells overlap: boundary edges ({s1[0]}, {s1[1]}) and ({s2[0]}, {s2[1]}) "
                "cross each other"
            )


def winding_numbers(points: np.ndarray, segments: np.ndarray, at: np.ndarray) -> np.ndarray:
    """Winding numbers ``(m,)`` of the closed chain of oriented ``segments`` around the points
    ``at (m, 2)`` (signed crossings of the ray to +x)."""
    a, b = points[segments[:, 0]], points[segments[:, 1]]
    rows = max(1, _CHUNK // max(1, len(segments)))
    out = np.zeros(len(at), dtype=np.int64)
    for s in range(0, len(at), rows):
        p = at[s : s + rows, None, :]
        up = (a[None, :, 1] <= p[..., 1]) & (b[None, :, 1] > p[..., 1])
        down = (b[None, :, 1] <= p[..., 1]) & (a[None, :, 1] > p[..., 1])
        d = (b - a)[None]
        left = d[..., 0] * (p[..., 1] - a[None, :, 1]) - d[..., 1] * (p[..., 0] - a[None, :, 0])
        out[s : s + rows] = (up & (left > 0)).sum(1) - (down & (left < 0)).sum(1)
    return out


def _check_no_overlap(mesh: Mesh, is_bnd: np.ndarray) -> None:
    """No two cells overlap: every point of the domain is covered by exactly one cell.

    The local checks (opposite traversal, no hanging node) leave out cells that overlap
    without sharing an edge: two separately meshed squares that overlap, a mesh that winds
    twice around a hole. The cells' areas then add up to more than the area that the boundary
    loops enclose. The sum of the cells' *signed* areas always equals the boundary's signed
    shoelace sum (interior edges cancel), so the check compares coverage instead: for
    counter-clockwise cells the winding number of the oriented boundary at a point is the
    number of cells covering it, and it must be 1 inside the domain. Boundary edges that
    cross are the first sign of an overlap; if none cross, the coverage is constant along the
    inner side of each boundary loop, and one point per loop (the centroid of a cell on it)
    plus the cells at pinch vertices (where several loops meet) settle it.
    """
    bnd = np.flatnonzero(is_bnd)
    segments = mesh.oriented_boundary(bnd)
    # work relative to the mesh's centre: differences keep their digits at any shift
    lo, hi = mesh.points.min(axis=0), mesh.points.max(axis=0)
    points = mesh.points - 0.5 * (lo + hi)
    _check_boundary_crossings(points, segments)
    # loops: cycles of "the edge that starts where this one ends" (pointer doubling)
    start_order = np.argsort(segments[:, 0], kind="stable")
    succ = start_order[np.searchsorted(segments[start_order, 0], segments[:, 1])]
    label, jump = np.arange(bnd.size), succ
    for _ in range(int(np.ceil(np.log2(max(bnd.size, 2)))) + 1):
        label = np.minimum(label, label[jump])
        jump = jump[jump]
    first = np.unique(label)
    outgoing = np.bincount(segments[:, 0], minlength=mesh.n_points)
    pinch = np.flatnonzero(outgoing[segments[:, 0]] > 1)
    test = np.union1d(first, pinch)
    cell = mesh.facet2cell[bnd[test], 0]
    centroid = points[mesh.cells[cell]].mean(axis=1)
    covered = winding_numbers(points, segments, centroid)
    if np.any(covered != 1):
        k = np.flatnonzero(covered != 1)[0]
        area = float(np.abs(mesh.area).sum())
        raise MeshError(
            f"cells overlap: the centroid {(centroid[k] + 0.5 * (lo + hi)).tolist()} of cell "
            f"{cell[k]} is covered by {covered[k]} cells, so the cells' areas (sum "
            f"{area:.6g}) add up to more than the area the boundary loops enclose"
        )


def validate_mesh(mesh: Mesh) -> None:
    """Check that ``mesh`` is a valid conforming triangulation with labelled boundary (in 3D
    the tetrahedral checks, :func:`~signorini.mesh.validation3d.validate_tetrahedra`).

    Raises
    ------
    MeshError
        At the first violation, naming the offending cells, edges or points.
    """
    if mesh.dim == 3:
        from .validation3d import validate_tetrahedra  # it builds on this module

        return validate_tetrahedra(mesh)
    points = as_points(mesh.points)
    cells = as_cells(mesh.cells, len(points))
    as_cells(mesh.boundary, len(points), what="boundary edges")
    from .labels import check_boundary_labelled, check_part_labels  # they build on this module

    check_orientation(points, cells)
    _check_points(points, cells)
    check_part_labels(mesh)
    is_bnd = mesh.facet2cell[:, 1] < 0  # building the topology raises on non-manifold edges
    _check_opposite_traversal(mesh, is_bnd)
    _check_no_hanging_node(mesh, is_bnd)
    _check_no_overlap(mesh, is_bnd)
    check_boundary_labelled(mesh, is_bnd)


def check_on_curve(
    points: np.ndarray, vertices: np.ndarray, curve: Curve, part: str, rtol: float
) -> None:
    """Check that the ``vertices`` of boundary part ``part`` lie on ``curve``: within ``rtol``
    times the diameter of ``points`` (the diagonal of their bounding box).

    Raises
    ------
    MeshError
        Naming the vertex farthest off the curve and its distance.
    """
    x = points[vertices]
    distance = np.hypot(*(curve.project(x) - x).T)
    diameter = float(np.hypot(*np.ptp(points, axis=0)))
    if np.any(distance > rtol * diameter):
        k = int(np.argmax(distance))
        raise MeshError(
            f"with_curve: vertex {vertices[k]} {x[k].tolist()} of part {part!r} lies "
            f"{distance[k]:.3g} from {curve!r}, more than rtol * diameter = "
            f"{rtol * diameter:.3g}"
        )
