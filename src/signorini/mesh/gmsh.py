"""Meshes from files: triangles and named boundary groups read through meshio (e.g. Gmsh)."""

from __future__ import annotations

import contextlib
import io as _io
import logging
import os
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from .curves import QuadraticBoundary
from .mesh import Mesh, MeshError
from .reference import INTERVAL, TETRAHEDRON, TRIANGLE
from .regions import DEFAULT_REGION
from .surfaces import Surface
from .topology import edge_keys

__all__ = ["read_mesh"]

logger = logging.getLogger(__name__)


#: Relative spread of z (against the mesh's extent in x and y) below which z is constant.
FLAT_TOL = 1e-10

#: Distance of a second-order midpoint from its chord's midpoint, relative to the mesh's
#: size (the larger of its diameter and its largest coordinate), below which it is straight.
STRAIGHT_TOL = 1e-12

#: A first-order part looks curved when its boundary turns by less than this (radians, 40°)
#: at two or more of its vertices and by more than round-off: the chords of an arc meshed
#: with three or more cells per quarter circle turn by 30° or less each; a polygon's corners
#: (an octagon's 45°, a rectangle's 90°) turn by more, and a straight part by none
CURVED_TURN = np.radians(40.0)


def read_mesh(
    path: str | os.PathLike,
    parts: Sequence[str] | None = None,
    *,
    surfaces: Mapping[str, Surface] | None = None,
) -> Mesh:
    """Read a triangular (or tetrahedral) mesh with named boundary parts from a file (e.g.
    Gmsh ``.msh``).

    A file with ``tetra`` or ``tetra10`` elements is read as a 3D mesh, its physical surface
    groups the parts and its physical volume groups the regions, second-order midpoints off
    their chords allowed on the parts given an exact surface in ``surfaces``
    (:func:`signorini.mesh.gmsh3d.read_tetrahedra`). What follows is the 2D reading.

    Triangles (``triangle`` or ``triangle6``) make the cells; line elements (``line`` or
    ``line3``) tagged with physical groups make the boundary parts, named after the groups
    (``gmsh:physical`` / field data; a physical group without a name is called
    ``"part<tag>"``). Physical tag 0 is Gmsh's mark for an element in *no* physical group
    (written when all elements are saved): such lines name no part. Triangles in physical
    surface groups carry those groups as cell regions (:attr:`Mesh.region_names`, e.g. one
    material each). The mesh must lie in a
    plane ``z = const``. Cells are oriented counter-clockwise (see
    :meth:`Mesh.from_arrays`) and each cell's longest edge becomes its refinement edge.

    A second-order mesh (``triangle6`` / ``line3``) gives each edge a midpoint node. A boundary
    part with a midpoint off its edge's chord (by more than :data:`STRAIGHT_TOL` times the
    mesh's size) carries the file's piecewise-quadratic boundary,
    :class:`~signorini.mesh.curves.QuadraticBoundary`: the P2 midpoint nodes of its edges
    are the file's midpoints, refinement places new vertices on the quadratics, and the cells
    along it are isoparametric (docs/method.md, *Curved boundaries*). A part whose midpoints
    all lie on the chords carries no curve, so a straight second-order file reads as the
    first-order one. :meth:`Mesh.with_curve` replaces the curve (e.g. by the exact circle).
    Only boundary edges may be curved: interior edges with midpoints off their chords (e.g.
    after Gmsh's high-order optimisation) are refused, since the P2 space puts interior
    midpoint nodes on the chords. A first-order file whose boundary parts look curved (their
    edges turn by less than :data:`CURVED_TURN` at two or more vertices) is read with those
    parts polygonal, and a warning is logged naming them and how to get curved cells.

    Parameters
    ----------
    path : file readable by meshio
    parts : names of the parts to keep (default: all named line groups)
    surfaces : mapping part name -> Surface, optional (3D files only)

    Returns
    -------
    Mesh

    Raises
    ------
    MeshError
        If the file cannot be read as a mesh, has a node with a NaN or infinite coordinate,
        has no triangles (e.g. only line groups were
        saved: add a physical surface group or save all elements), is not flat in the
        xy-plane, has no boundary lines in a physical group (every boundary edge must be in
        one), or lacks a requested part; or if a second-order midpoint is off the chord of
        an interior edge, differs between two elements, folds its quadratic edge back on
        itself, or turns a cell's quadratic map over at a vertex (its Jacobian determinant
        there is not positive; the midpoint is too far off the edge for the cell).
    """
    import meshio

    path = Path(path)
    if not path.is_file():
        raise MeshError(f"no mesh file at {path}")
    said = _io.StringIO()
    try:
        # meshio prints its diagnostics and calls sys.exit() on some foreign files
        with contextlib.redirect_stdout(said), contextlib.redirect_stderr(said):
            m = meshio.read(path)
    except (Exception, SystemExit) as exc:  # meshio raises many types for foreign files
        detail = " ".join(said.getvalue().split()) if isinstance(exc, SystemExit) else exc
        raise MeshError(f"{path} is not a mesh file meshio can read: {detail}") from None
    if any(b.type in (TETRAHEDRON.vtk_name, TETRAHEDRON.vtk_p2_name) for b in m.cells):
        from .gmsh3d import read_tetrahedra  # it builds on this module

        return read_tetrahedra(path, m, parts, surfaces)
    if surfaces:
        raise MeshError(f"{path} holds no tetrahedra: surfaces are for 3D meshes")
    names = (TRIANGLE.vtk_name, TRIANGLE.vtk_p2_name)
    tri = [(i, b) for i, b in enumerate(m.cells) if b.type in names]
    if not tri:
        found = sorted({b.type for b in m.cells})
        hint = (
            ": only line elements were saved; add a physical surface group holding the "
            "triangles (Gmsh: Physical Surface) or save all elements (Gmsh: Mesh.SaveAll = 1)"
            if found and set(found) <= {"line", "line3", "vertex"}
            else ""
        )
        raise MeshError(f"{path} contains no triangles (it has {found or 'no cells'}){hint}")
    cells = np.concatenate([b.data[:, :3] for _, b in tri]).astype(np.int64)
    xyz = np.asarray(m.points, dtype=np.float64)
    _check_finite(path, xyz)
    # drop points that no triangle uses (e.g. geometry points), renumber
    used = np.unique(cells)
    renumber = np.full(len(xyz), -1, dtype=np.int64)
    renumber[used] = np.arange(used.size)
    xyz, cells = xyz[used], renumber[cells]
    points = xyz[:, :2]
    if xyz.shape[1] > 2 and xyz.size:
        z = xyz[:, 2]
        extent = float(np.hypot(*np.ptp(points, axis=0)))
        if np.ptp(z) > FLAT_TOL * extent:
            raise MeshError(
                f"{path} is not flat in the xy-plane: z ranges over [{z.min():.6g}, "
                f"{z.max():.6g}]; a mesh must lie in a plane z = const (dropping z would "
                "distort it)"
            )
    tags = m.cell_data.get("gmsh:physical")
    names = {int(v[0]): k for k, v in (m.field_data or {}).items() if len(v) > 1 and v[1] == 1}
    groups: dict[str, list[np.ndarray]] = {}
    for i, block in enumerate(m.cells):
        if block.type not in ("line", "line3") or tags is None:
            continue
        for tag in np.unique(tags[i]):
            if tag == 0:  # in no physical group
                continue
            name = names.get(int(tag), f"part{int(tag)}")
            pairs = renumber[block.data[tags[i] == tag][:, :2]]
            if np.any(pairs < 0):
                raise MeshError(
                    f"boundary group {name!r} uses points that are not vertices of any triangle"
                )
            groups.setdefault(name, []).append(pairs)
    if not groups:
        raise MeshError(
            f"{path} has no tagged boundary lines (physical groups); the boundary "
            "parts cannot be named: put the boundary lines in physical line groups "
            "(Gmsh: Physical Curve)"
        )
    if parts is not None:
        missing = [p for p in parts if p not in groups]
        if missing:
            raise MeshError(f"{path} has no boundary group(s) {missing}; it has {sorted(groups)}")
        groups = {p: groups[p] for p in parts}
    regions = _surface_regions(m, tri, tags)
    try:
        boundary = {k: np.concatenate(v) for k, v in groups.items()}
        mesh = Mesh.from_arrays(points, cells, boundary, regions=regions)
        given = _given_midpoints(m, renumber)
        if not len(given[0]):
            _warn_if_polygonal(path, mesh)
        return _with_quadratic_boundaries(mesh, given)
    except MeshError as exc:
        raise MeshError(f"{path}: {exc}") from None


def _check_finite(path: Path, xyz: np.ndarray) -> None:
    """Refuse a file with a NaN or infinite coordinate in any of its nodes (vertices, edge
    midpoints, geometry points alike: a corrupt file), naming the first."""
    bad = np.flatnonzero(~np.isfinite(xyz).all(axis=1))
    if bad.size:
        k = int(bad[0])
        more = f" (and {bad.size - 1} more)" if bad.size > 1 else ""
        raise MeshError(
            f"{path}: node {k + 1} of the file (in its order) has a non-finite coordinate, "
            f"{tuple(float(v) for v in xyz[k])}{more}; every node needs finite coordinates"
        )


def _warn_if_polygonal(path: Path, mesh: Mesh) -> None:
    """Log a warning naming the parts of a first-order ``mesh`` that look curved: boundary
    parts whose edges turn by less than :data:`CURVED_TURN` (and more than 1e-8 rad) at two
    or more of their vertices stay polygonal, however the mesh is refined."""
    curved = []
    for index, name in enumerate(mesh.part_names):  # a loop over parts, not edges
        ab = mesh.oriented_boundary(mesh.boundary_facet[mesh.boundary_part == index])
        if len(ab) < 3:
            continue
        d = mesh.points[ab[:, 1]] - mesh.points[ab[:, 0]]
        after = np.full(mesh.n_points, -1)
        after[ab[:, 0]] = np.arange(len(ab))  # the part's edge leaving each vertex
        nxt = after[ab[:, 1]]
        e = np.flatnonzero(nxt >= 0)
        u, v = d[e], d[nxt[e]]
        turn = np.abs(
            np.arctan2(u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0], np.einsum("ij,ij->i", u, v))
        )
        if np.count_nonzero((turn > 1e-8) & (turn < CURVED_TURN)) >= 2:
            curved.append(name)
    if curved:
        logger.warning(
            "%s is a first-order mesh (triangle and line elements): its boundary part(s) %s "
            "look curved (their edges turn by small angles) but stay polygonal, the chords "
            "between the file's vertices, on every refined mesh, and the cells along them "
            "are straight. For curved cells save the mesh second order (Gmsh: "
            "Mesh.ElementOrder = 2, or gmsh -order 2: triangle6 and line3 elements), or give "
            "the part its exact curve with Mesh.with_curve(part, Circle(...))",
            path,
            curved,
        )


def _surface_regions(m: object, tri: list, tags: list | None) -> np.ndarray | None:
    """The cell regions of the triangles ``tri`` (their blocks, in order): the names of their
    physical surface groups (``"region<tag>"`` for an unnamed one, ``"body"`` for triangles
    in none); ``None`` (one region) if no triangle is in a physical group."""
    if tags is None:
        return None
    surface = np.concatenate([np.asarray(tags[i]).reshape(-1) for i, _ in tri]).astype(int)
    if not surface.any():
        return None
    names = {int(v[0]): k for k, v in (m.field_data or {}).items() if len(v) > 1 and v[1] == 2}
    tag, index = np.unique(surface, return_inverse=True)
    label = [DEFAULT_REGION if t == 0 else names.get(int(t), f"region{int(t)}") for t in tag]
    return np.asarray(label, dtype=object)[index.reshape(-1)].astype(str)


def _given_midpoints(m: object, renumber: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The vertex pairs ``(k, 2)`` (new numbering) and midpoints ``(k, 2)`` of every edge of
    the ``triangle6`` and ``line3`` elements of the meshio mesh ``m`` (repeats included)."""
    pairs, mids = [np.zeros((0, 2), dtype=np.int64)], [np.zeros((0, 2))]
    for block in m.cells:
        if block.type == TRIANGLE.vtk_p2_name:  # each edge's two ends and its midpoint node
            local = TRIANGLE.edge_nodes
        elif block.type == INTERVAL.vtk_p2_name:
            local = INTERVAL.edge_nodes
        else:
            continue
        nodes = block.data[:, local].reshape(-1, 3)
        pairs.append(renumber[nodes[:, :2]])
        mids.append(np.asarray(m.points, dtype=np.float64)[nodes[:, 2], :2])
    pairs, mids = np.concatenate(pairs), np.concatenate(mids)
    keep = (pairs >= 0).all(1)  # lines whose ends no triangle uses name no part
    return pairs[keep], mids[keep]


def _with_quadratic_boundaries(mesh: Mesh, given: tuple[np.ndarray, np.ndarray]) -> Mesh:
    """``mesh`` with a :class:`QuadraticBoundary` on each part whose given midpoints are off
    the chords; the checks of :func:`read_mesh` on the midpoints."""
    pairs, mids = given
    if not len(pairs):
        return mesh
    mesh_keys = edge_keys(mesh.edges, mesh.n_points)  # sorted by construction
    keys = edge_keys(pairs, mesh.n_points)
    pos = np.minimum(np.searchsorted(mesh_keys, keys), mesh.n_edges - 1)
    found = mesh_keys[pos] == keys
    edge, mids = pos[found], mids[found]
    scale = max(float(np.hypot(*np.ptp(mesh.points, axis=0))), float(np.abs(mesh.points).max()))
    tol = STRAIGHT_TOL * scale
    mid = mesh.edge_midpoints.copy()
    mid[edge] = mids
    spread = np.hypot(*(mids - mid[edge]).T)  # two elements giving one edge two midpoints
    if np.any(spread > tol):
        e = int(edge[np.argmax(spread)])
        raise MeshError(
            f"edge {mesh.edges[e].tolist()} from {mesh.points[mesh.edges[e, 0]].tolist()} to "
            f"{mesh.points[mesh.edges[e, 1]].tolist()} has two midpoints {np.max(spread):.3g} "
            "apart in different elements"
        )
    offset = np.hypot(*(mid - mesh.edge_midpoints).T)
    curved = offset > tol
    inside = np.flatnonzero(curved & (mesh.facet2cell[:, 1] >= 0))
    if inside.size:
        e = int(inside[0])
        raise MeshError(
            f"{inside.size} interior edge(s) have their midpoint off the chord (first: edge "
            f"{mesh.edges[e].tolist()} from {mesh.points[mesh.edges[e, 0]].tolist()} to "
            f"{mesh.points[mesh.edges[e, 1]].tolist()}, midpoint {mid[e].tolist()}, "
            f"{offset[e]:.3g} off): only boundary edges may be curved (save the mesh without "
            "high-order optimisation)"
        )
    if not curved.any():
        return mesh
    curves = {}
    for index, name in enumerate(mesh.part_names):  # a loop over parts, not edges
        e = mesh.boundary_facet[mesh.boundary_part == index]
        if not curved[e].any():
            continue
        ends = mesh.points[mesh.oriented_boundary(e)]  # counter-clockwise: normals outward
        try:
            curves[name] = QuadraticBoundary(np.concatenate([ends, mid[e][:, None]], axis=1))
        except MeshError as exc:
            raise MeshError(f"boundary part {name!r}: {exc}") from None
    _check_vertex_jacobians(mesh, mid, curved)
    for name, curve in curves.items():
        mesh = mesh.with_curve(name, curve)
    return mesh


def _check_vertex_jacobians(mesh: Mesh, mid: np.ndarray, curved: np.ndarray) -> None:
    """Raise if a cell with a curved edge has a non-positive Jacobian determinant of its
    quadratic map at a vertex, where it is (up to a positive factor) the cross product of
    the tangents of the cell's two edges leaving the vertex, ``X'(0) = 4 m - 3 a - b`` for
    the edge from ``a`` to ``b`` with midpoint ``m`` (``mid (n_edges, 2)``, ``curved
    (n_edges,)`` bool)."""
    cells = np.flatnonzero(curved[mesh.cell2edge].any(1))
    x = mesh.points[mesh.cells[cells]]  # (c, 3, 2)
    m = mid[mesh.cell2edge[cells]]  # (c, 3, 2): local edge k joins TRIANGLE.edges[k]
    leaving = np.argsort(TRIANGLE.edges[:, 0])  # the local edge leaving vertex k: k
    arriving = np.argsort(TRIANGLE.edges[:, 1])  # the one arriving at vertex k: k - 1
    forward = 4 * m[:, leaving] - 3 * x - x[:, TRIANGLE.edges[leaving, 1]]
    back = 4 * m[:, arriving] - 3 * x - x[:, TRIANGLE.edges[arriving, 0]]
    det = forward[..., 0] * back[..., 1] - forward[..., 1] * back[..., 0]
    bad = np.flatnonzero(~(det > 0).all(1))
    if bad.size:
        c = int(cells[bad[0]])
        raise MeshError(
            f"{bad.size} cell(s) turn over at a vertex of their quadratic map (first: cell "
            f"{c}, vertices {mesh.points[mesh.cells[c]].tolist()}, edge midpoints "
            f"{mid[mesh.cell2edge[c]].tolist()}): a midpoint is too far off its edge for the "
            "cell"
        )
