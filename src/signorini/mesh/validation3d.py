"""The checks a tetrahedral :class:`~signorini.mesh.mesh.Mesh` (``dim = 3``) passes when it
is built from user arrays; :func:`~signorini.mesh.validation.validate_mesh` dispatches here.

A tetrahedral mesh is valid when its arrays have the right shapes and finite entries
(``points (n, 3)``, ``cells (n, 4)``, ``boundary (n_b, 3)``), its cells are positively
oriented (``det[x1 − x0, x2 − x0, x3 − x0] > 0``; :meth:`Mesh.from_arrays` fixes the others,
the constructor refuses them) and not degenerate, every point is a vertex, no two points and
no two cells coincide, every face belongs to one or two cells (no face of three: a
non-manifold mesh), the two cells of an interior face lie on its two sides, no boundary
vertex lies on another boundary face (a hanging node), and the boundary faces are exactly
the listed ones, each in one named part that owns at least one face. Each failure raises a
:class:`~signorini.mesh.validation.MeshError` naming the cell, face or point. Slivers (a
dihedral angle below :data:`SLIVER_ANGLE`) are warned about, not refused.

Tolerances are relative to the mesh's size or the face's, as in 2D.
"""

from __future__ import annotations

import warnings
from typing import TYPE_CHECKING

import numpy as np
from scipy.spatial import cKDTree

from .geometry import facet_normals, signed_area
from .labels import check_boundary_labelled, check_part_labels
from .reference import TETRAHEDRON
from .topology import entity_keys
from .validation import (
    DUPLICATE_TOL,
    HANGING_TOL,
    MAX_ASPECT,
    MeshError,
    as_cells,
    as_points,
    format_indices,
)

if TYPE_CHECKING:
    from .mesh import Mesh
    from .surfaces import Surface

__all__ = [
    "SLIVER_ANGLE",
    "SliverWarning",
    "check_on_surface",
    "dihedral_angles",
    "nondegenerate_volume",
    "solid_winding_numbers",
    "validate_tetrahedra",
]

#: A tetrahedron whose smallest dihedral angle is below this (radians; 5°) is warned about
#: as a sliver. The interpolation error and the conditioning of a cell's stiffness grow
#: without bound as its smallest dihedral angle goes to 0 (Shewchuk, *What is a good linear
#: finite element?*, 2002); a Kuhn cell has 45°, a regular one 70.5°, and the optimised
#: meshes of Gmsh and TetGen keep every cell above about 5–10°. A cell below 5° is a sliver
#: left by a generator without sliver removal: the solve still runs, but the user should
#: know. (Degenerate cells, beyond :data:`~signorini.mesh.validation.MAX_ASPECT`, are
#: refused.)
SLIVER_ANGLE = np.deg2rad(5.0)


class SliverWarning(UserWarning):
    """A tetrahedron with a dihedral angle below :data:`SLIVER_ANGLE`."""


def _corners(points: np.ndarray, cell: np.ndarray) -> str:
    return ", ".join("(" + ", ".join(f"{v:.12g}" for v in p) + ")" for p in points[cell])


def _face_text(points: np.ndarray, face: np.ndarray) -> str:
    """``face (a, b, c) with vertices (x, y, z), …`` for a vertex triple."""
    return f"face ({face[0]}, {face[1]}, {face[2]}) with vertices {_corners(points, face)}"


def flatness(points: np.ndarray, cells: np.ndarray, volume: np.ndarray) -> np.ndarray:
    """``(n_cells,)`` each cell's longest edge cubed over six times its volume,
    ``h_max³ / (6|V|)`` (``inf`` for a zero volume): √2 for a regular tetrahedron. The 3D
    counterpart of :func:`~signorini.mesh.validation.aspect_ratios`: the volume computed
    from float64 coordinates carries an error of about ``1e-16 h_max³``."""
    p = points[cells]
    start, end = TETRAHEDRON.edges.T
    h2 = ((p[:, end] - p[:, start]) ** 2).sum(-1).max(axis=1)
    with np.errstate(divide="ignore"):
        return h2**1.5 / (6.0 * np.abs(volume))


def nondegenerate_volume(points: np.ndarray, cells: np.ndarray) -> np.ndarray:
    """The signed volumes ``(n_cells,)`` of tetrahedra ``cells (n_cells, 4)``; raise if there
    are no cells or one is degenerate (its :func:`flatness` beyond ``MAX_ASPECT``, where its
    volume is round-off of its coordinates: four coplanar or repeated vertices)."""
    if cells.shape[0] == 0:
        raise MeshError("the mesh has no cells")
    volume = signed_area(points, cells)
    flat = flatness(points, cells, volume)
    if np.any(flat >= MAX_ASPECT):
        bad = np.flatnonzero(flat >= MAX_ASPECT)
        c = bad[0]
        raise MeshError(
            f"degenerate tetrahedra {format_indices(bad)} (zero volume: coplanar or repeated "
            f"vertices), e.g. cell {c} = {cells[c].tolist()} with vertices "
            f"{_corners(points, cells[c])}: h_max³ / (6 |V|) = {flat[c]:.3g}, beyond "
            f"{MAX_ASPECT:.0e}"
        )
    return volume


def dihedral_angles(points: np.ndarray, cells: np.ndarray) -> np.ndarray:
    """``(n_cells, 6)`` the dihedral angles (radians) at the local edges
    ``TETRAHEDRON.edges`` of positively oriented tetrahedra: ``π − ∠(n_k, n_l)`` for the
    outward normals of the two faces ``k, l`` that meet at the edge (the faces opposite the
    edge's other two vertices)."""
    _, normal = facet_normals(points[cells][:, TETRAHEDRON.facets])  # (n, 4, 3)
    edges = TETRAHEDRON.edges
    other = np.array([[v for v in range(4) if v not in e] for e in edges.tolist()])
    cos = -np.einsum("nei,nei->ne", normal[:, other[:, 0]], normal[:, other[:, 1]])
    return np.arccos(np.clip(cos, -1.0, 1.0))


def _check_points(points: np.ndarray, cells: np.ndarray) -> None:
    """Every point is a vertex of some cell, no two points coincide, no two cells."""
    used = np.zeros(len(points), dtype=bool)
    used[cells.ravel()] = True
    if not used.all():
        raise MeshError(
            f"unreferenced point(s) {format_indices(np.flatnonzero(~used))}: every point must "
            "be a vertex of some cell"
        )
    lo, hi = points.min(axis=0), points.max(axis=0)
    tol = max(
        DUPLICATE_TOL * float(np.linalg.norm(hi - lo)),
        4 * np.finfo(np.float64).eps * float(np.abs(points).max()),
    )
    pairs = cKDTree(points - 0.5 * (lo + hi)).query_pairs(tol, output_type="ndarray")
    if pairs.size:
        dup = np.unique(pairs)
        raise MeshError(
            f"duplicate points {format_indices(dup)} (same coordinates {points[dup[0]].tolist()})"
        )
    keys = entity_keys(cells, len(points))
    order = np.argsort(keys, kind="stable")
    same = np.flatnonzero(keys[order[1:]] == keys[order[:-1]])
    if same.size:
        a, b = order[same[0]], order[same[0] + 1]
        raise MeshError(f"duplicate cells {a} and {b}: both have the vertices {cells[a].tolist()}")


def _check_sides(mesh: Mesh, is_bnd: np.ndarray) -> None:
    """The two cells of each interior face lie on its two sides (else they overlap)."""
    inner = np.flatnonzero(~is_bnd)
    c0, c1 = mesh.facet2cell[inner].T
    k0, k1 = mesh.facet_local[inner].T
    face = mesh.cells[c0[:, None], TETRAHEDRON.facets[k0]]  # outward from c0
    far = mesh.cells[c1, k1]  # c1's vertex opposite the face
    p = mesh.points
    a, b, c = p[face[:, 0]], p[face[:, 1]], p[face[:, 2]]
    side = np.einsum("ij,ij->i", np.cross(b - a, c - a), p[far] - a)
    if np.any(side <= 0):
        f = np.flatnonzero(side <= 0)[0]
        raise MeshError(
            f"cells {c0[f]} and {c1[f]} overlap: both lie on one side of their common "
            f"{_face_text(p, mesh.facets[inner[f]])}"
        )


def _check_no_hanging_node(mesh: Mesh, is_bnd: np.ndarray) -> None:
    """No boundary vertex lies on a boundary face it is not a vertex of (a hanging node of a
    non-conforming interface, which shows as boundary faces on both of its sides)."""
    faces = mesh.facets[is_bnd]
    verts = np.unique(faces)
    p = mesh.points
    a, b, c = p[faces[:, 0]], p[faces[:, 1]], p[faces[:, 2]]
    centre = (a + b + c) / 3.0
    radius = np.sqrt(np.max([((v - centre) ** 2).sum(1) for v in (a, b, c)], axis=0))
    margin = 1e-9 * radius
    near = cKDTree(centre).sparse_distance_matrix(
        cKDTree(p[verts]), float(radius.max() + margin.max()), output_type="ndarray"
    )
    f, v = near["i"], verts[near["j"]]
    keep = (near["v"] <= radius[f] + margin[f]) & ~(faces[f] == v[:, None]).any(1)
    f, v = f[keep], v[keep]
    # barycentric coordinates of the vertex in the face's plane, and its distance to it
    e1, e2, d = (b - a)[f], (c - a)[f], p[v] - a[f]
    normal = np.cross(e1, e2)
    n2 = np.einsum("ij,ij->i", normal, normal)
    s = np.einsum("ij,ij->i", np.cross(d, e2), normal) / n2
    t = np.einsum("ij,ij->i", np.cross(e1, d), normal) / n2
    height = np.abs(np.einsum("ij,ij->i", d, normal)) / np.sqrt(n2)
    tol = HANGING_TOL
    on = (height <= tol * radius[f]) & (s >= -tol) & (t >= -tol) & (s + t <= 1 + tol)
    if on.any():
        i = np.flatnonzero(on)[0]
        raise MeshError(
            f"non-conforming mesh: point {v[i]} {p[v[i]].tolist()} lies on boundary "
            f"{_face_text(p, faces[f[i]])} (a hanging node)"
        )


def validate_tetrahedra(mesh: Mesh) -> None:
    """Check that ``mesh`` (``dim = 3``) is a valid conforming tetrahedral mesh with labelled
    boundary faces (module docstring); warn about slivers (:class:`SliverWarning`).

    Raises
    ------
    MeshError
        At the first violation, naming the offending cells, faces or points.
    """
    points = as_points(mesh.points)
    cells = as_cells(mesh.cells, len(points), width=4)
    as_cells(mesh.boundary, len(points), what="boundary faces", width=3)
    volume = nondegenerate_volume(points, cells)
    if np.any(volume < 0):
        bad = np.flatnonzero(volume < 0)
        raise MeshError(
            f"negatively oriented tetrahedra {format_indices(bad)}: list each cell's vertices "
            "so that det[x1 - x0, x2 - x0, x3 - x0] > 0 (Mesh.from_arrays reorients them)"
        )
    _check_points(points, cells)
    angle = dihedral_angles(points, cells).min(axis=1)
    if np.any(angle < SLIVER_ANGLE):
        bad = np.flatnonzero(angle < SLIVER_ANGLE)
        warnings.warn(
            f"{bad.size} sliver tetrahedra (a dihedral angle below "
            f"{np.rad2deg(SLIVER_ANGLE):.0f}°), e.g. cell {bad[0]} with "
            f"{np.rad2deg(angle[bad[0]]):.3g}°: {format_indices(bad)}",
            SliverWarning,
            stacklevel=3,
        )
    check_part_labels(mesh, "face", _face_text)
    is_bnd = mesh.facet2cell[:, 1] < 0  # building the topology raises on non-manifold faces
    _check_sides(mesh, is_bnd)
    _check_no_hanging_node(mesh, is_bnd)
    check_boundary_labelled(mesh, is_bnd, "face", _face_text, _face_text)


def check_on_surface(
    points: np.ndarray, vertices: np.ndarray, surface: Surface, part: str, rtol: float
) -> None:
    """Check that the ``vertices`` of boundary part ``part`` lie on ``surface``: within
    ``rtol`` times the diameter of ``points`` (the diagonal of their bounding box); the 3D
    :func:`~signorini.mesh.validation.check_on_curve`.

    Raises
    ------
    MeshError
        Naming the vertex farthest off the surface and its distance.
    """
    x = points[vertices]
    distance = np.linalg.norm(surface.project(x) - x, axis=1)
    diameter = float(np.linalg.norm(np.ptp(points, axis=0)))
    if np.any(distance > rtol * diameter):
        k = int(np.argmax(distance))
        raise MeshError(
            f"with_curve: vertex {vertices[k]} {x[k].tolist()} of part {part!r} lies "
            f"{distance[k]:.3g} from {surface!r}, more than rtol * diameter = "
            f"{rtol * diameter:.3g}"
        )


#: point-face pairs per block of :func:`solid_winding_numbers`
_WINDING_BLOCK = 2_000_000


def solid_winding_numbers(points: np.ndarray, faces: np.ndarray, at: np.ndarray) -> np.ndarray:
    """Winding numbers ``(m,)`` of the closed surface of outward ``faces (n_f, 3)`` around
    the points ``at (m, 3)``: the solid angles of the faces seen from each point, summed and
    divided by 4π (Van Oosterom–Strackee), rounded; 1 inside a body, 0 outside.

    References
    ----------
    A. van Oosterom, J. Strackee, *The solid angle of a plane triangle*, IEEE Trans. Biomed.
    Eng. 30 (1983).
    """
    tri = points[faces]  # (n_f, 3, 3)
    rows = max(1, _WINDING_BLOCK // max(1, len(faces)))
    out = np.zeros(len(at), dtype=np.int64)
    for s in range(0, len(at), rows):  # blocks of points, a bounded memory
        r = tri[None] - at[s : s + rows, None, None, :]  # (m, n_f, 3, 3)
        length = np.linalg.norm(r, axis=-1)
        a, b, c = r[..., 0, :], r[..., 1, :], r[..., 2, :]
        la, lb, lc = length[..., 0], length[..., 1], length[..., 2]
        numerator = np.einsum("...i,...i->...", a, np.cross(b, c))
        denominator = (
            la * lb * lc
            + lc * np.einsum("...i,...i->...", a, b)
            + lb * np.einsum("...i,...i->...", a, c)
            + la * np.einsum("...i,...i->...", b, c)
        )
        angle = 2.0 * np.arctan2(numerator, denominator).sum(axis=1)
        out[s : s + rows] = np.rint(angle / (4.0 * np.pi)).astype(np.int64)
    return out
