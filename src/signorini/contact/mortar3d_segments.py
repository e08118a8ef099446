"""The segmentation of a 3D mortar interface: each slave face against the master faces it
overlaps, projected into the slave face's plane (docs/method.md, *Two bodies in three
dimensions: the dual mortar coupling on faces*).

A slave face S (its three vertices: the integrals of the coupling are taken on the straight
triangles) has the plane through its vertices with the unit normal ``n_S``. A master face
M is projected into that plane along ``n_S``; the polygon ``S ∩ proj M`` is found by
Sutherland–Hodgman clipping of S against the three sides of ``proj M`` (at most six
vertices), and cut from its vertex mean into triangles, the integration cells, on which a
triangle rule integrates ``ψ_j (φ_k ∘ π)``: π maps a point of the slave plane to the master
face along ``n_S``, affine on each cell, so every integrand on a flat interface is a
polynomial on the cell.

Everything is vectorised over the (slave, master) pairs: candidate pairs from a k-d tree of
the master faces' centres, a fixed number of clipping steps on arrays of polygons of up to
:data:`MAX_VERTICES` vertices, the cells as arrays (Python loops only over the three clip
sides and the polygon slots).

References
----------
I. E. Sutherland, G. W. Hodgman, *Reentrant polygon clipping*, Commun. ACM 17 (1974).
M. A. Puso, T. A. Laursen, *A mortar segment-to-segment contact method for large
deformation solid mechanics*, CMAME 193 (2004) (segmentation in the slave plane).
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import chain

import numpy as np
from scipy.spatial import cKDTree

__all__ = [
    "MAX_VERTICES",
    "Segments",
    "candidate_pairs",
    "clip_polygons",
    "plane_frames",
    "polygon_areas",
    "segments",
]

#: slots of a clipped polygon: a triangle clipped by three half-planes has at most six
#: vertices; each step adds at most one, so nine slots never overflow
MAX_VERTICES = 9
#: a polygon vertex within this distance (relative to the slave face's size) outside a
#: clipping line counts as on it (shared or coincident sides clip without slivers)
ON_LINE = 1e-13
#: a clipped polygon whose area is below this share of its slave face's area is dropped
TINY_AREA = 1e-14


@dataclass(frozen=True)
class Segments:
    """The integration cells of an interface: triangles in the slave faces' planes.

    Attributes
    ----------
    slave, master : (c,) int arrays
        The slave face and the master face of each cell (indices into the arrays given to
        :func:`segments`).
    points : (c, 3, 3) float array
        The cell's vertices (in its slave face's plane).
    area : (c,) float array
        The cells' areas (positive).
    """

    slave: np.ndarray
    master: np.ndarray
    points: np.ndarray
    area: np.ndarray


def plane_frames(triangles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The in-plane frames of triangles ``(t, 3, 3)``: origin their first vertex and rows
    ``(e1, e2, n)`` ``(t, 3, 3)``, ``e1`` along the first side, ``n`` the unit normal of the
    vertex order (right-handed). Returns ``(origin (t, 3), frame (t, 3, 3))``."""
    origin = triangles[:, 0]
    a, b = triangles[:, 1] - origin, triangles[:, 2] - origin
    n = np.cross(a, b)
    n /= np.linalg.norm(n, axis=1)[:, None]
    e1 = a / np.linalg.norm(a, axis=1)[:, None]
    return origin, np.stack([e1, np.cross(n, e1), n], axis=1)


def polygon_areas(poly: np.ndarray, count: np.ndarray) -> np.ndarray:
    """Signed areas ``(p,)`` of plane polygons ``poly (p, MAX_VERTICES, 2)`` with ``count``
    vertices each (the shoelace sum over the filled slots, counter-clockwise positive)."""
    slots = np.arange(poly.shape[1])
    nxt = np.where(slots[None] + 1 < count[:, None], slots[None] + 1, 0)
    q = np.take_along_axis(poly, nxt[..., None], axis=1)
    cross = poly[..., 0] * q[..., 1] - poly[..., 1] * q[..., 0]
    return 0.5 * np.where(slots[None] < count[:, None], cross, 0.0).sum(axis=1)


def clip_polygons(
    poly: np.ndarray, count: np.ndarray, clip: np.ndarray, tol: np.ndarray | float = 0.0
) -> tuple[np.ndarray, np.ndarray]:
    """Sutherland–Hodgman: the convex plane polygons ``poly (p, MAX_VERTICES, 2)`` (``count
    (p,)`` vertices, counter-clockwise) clipped by the counter-clockwise triangles ``clip
    (p, 3, 2)``, one clipping step per side of the triangle.

    A vertex within ``tol`` (``(p,)`` or a number) outside a side's line counts as inside,
    and a side from such a vertex to one outside gives no crossing point (it would repeat
    the vertex).
    Returns the clipped polygons and their vertex counts (0 where they do not meet).
    """
    poly = np.array(poly, dtype=np.float64)
    count = np.asarray(count, dtype=np.int64).copy()
    tol = np.broadcast_to(np.asarray(tol, dtype=np.float64), count.shape)
    slots = np.arange(MAX_VERTICES)
    for side in range(3):  # the three sides of the clipping triangle
        a = clip[:, side]
        edge = clip[:, (side + 1) % 3] - a
        length = np.linalg.norm(edge, axis=1)
        # signed distance to the side's line, positive inside (to its left)
        d = (edge[:, None, 0] * (poly[..., 1] - a[:, None, 1])
             - edge[:, None, 1] * (poly[..., 0] - a[:, None, 0])) / length[:, None]  # fmt: skip
        live = slots[None] < count[:, None]
        inside = (d >= -tol[:, None]) & live
        nxt = np.where(slots[None] + 1 < count[:, None], slots[None] + 1, 0)
        d_next = np.take_along_axis(d, nxt, axis=1)
        in_next = np.take_along_axis(inside, nxt, axis=1) & live
        p_next = np.take_along_axis(poly, nxt[..., None], axis=1)
        # a crossing point where the inside end lies on the line would repeat that end
        firm = np.where(inside, d, d_next) > tol[:, None]
        crossing = live & (inside != in_next) & firm
        with np.errstate(divide="ignore", invalid="ignore"):
            t = np.where(crossing, d / (d - d_next), 0.0)
        cut = poly + t[..., None] * (p_next - poly)
        # per slot: the crossing point of side (i, i+1) where it crosses, then vertex i+1
        candidates = np.stack([cut, p_next], axis=2).reshape(len(poly), -1, 2)
        valid = np.stack([crossing, in_next], axis=2).reshape(len(poly), -1)
        order = np.argsort(~valid, axis=1, kind="stable")[:, :MAX_VERTICES]
        poly = np.take_along_axis(candidates, order[..., None], axis=1)
        count = valid.sum(axis=1)
        poly[slots[None] >= count[:, None]] = 0.0
    return poly, count


def candidate_pairs(slave: np.ndarray, master: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Slave and master faces ``(i, j)`` that may overlap after projection: master face j is
    a candidate of slave face i if its centre is within ``2 (r_i + d_i) + r_j`` of the slave
    face's centre (``r`` a face's radius about its centre, ``d_i`` the distance from the
    slave centre to the nearest master vertex), by a k-d tree of the master faces' centres;
    only master faces facing the slave (``n_M · n_S < 0``) are kept. A point of ``proj M``
    in S is at most ``r_i`` from the slave centre in the plane; its master point lies a
    normal distance of about the local gap, within ``r_i + d_i`` for surfaces that are near
    parallel (small sliding), and the master face's centre ``r_j`` from it."""
    cs, cm = slave.mean(axis=1), master.mean(axis=1)
    rs = np.linalg.norm(slave - cs[:, None], axis=2).max(axis=1)
    rm = np.linalg.norm(master - cm[:, None], axis=2).max(axis=1)
    d, _ = cKDTree(master.reshape(-1, 3)).query(cs)
    reach = (2.0 * (rs + d) + rm.max()) * (1 + 1e-9)
    tree = cKDTree(cm)
    counts = tree.query_ball_point(cs, reach, return_length=True)
    found = chain.from_iterable(tree.query_ball_point(cs, reach))
    j = np.fromiter(found, np.int64, counts.sum())
    i = np.repeat(np.arange(len(slave)), counts)
    near = np.linalg.norm(cm[j] - cs[i], axis=1) <= 2.0 * (rs[i] + d[i]) + rm[j] * (1 + 1e-9)
    i, j = i[near], j[near]
    ns = np.cross(slave[i, 1] - slave[i, 0], slave[i, 2] - slave[i, 0])
    nm = np.cross(master[j, 1] - master[j, 0], master[j, 2] - master[j, 0])
    facing = np.einsum("pc,pc->p", ns, nm) < 0
    return i[facing], j[facing]


def segments(slave: np.ndarray, master: np.ndarray) -> Segments:
    """The integration cells of the slave faces ``slave (s, 3, 3)`` against the master faces
    ``master (m, 3, 3)`` (vertices, outward order): for each candidate pair
    (:func:`candidate_pairs`) the polygon ``S ∩ proj M`` in the slave face's plane
    (:func:`clip_polygons`), cut from its vertex mean into triangles.

    The cells of a slave face tile the part of it that the projected master covers, so their
    areas sum to the slave face's area where the master covers it wholly.
    """
    i, j = candidate_pairs(slave, master)
    origin, frame = plane_frames(slave)
    o, e = origin[i], frame[i, :2]  # (p, 3), (p, 2, 3)

    def in_plane(x: np.ndarray) -> np.ndarray:  # (p, k, 3) -> (p, k, 2)
        return np.einsum("pdc,pkc->pkd", e, x - o[:, None])

    s2, m2 = in_plane(slave[i]), in_plane(master[j])
    turned = polygon_areas(np.pad(m2, ((0, 0), (0, MAX_VERTICES - 3), (0, 0))),
                           np.full(i.size, 3)) < 0  # fmt: skip
    m2[turned] = m2[turned][:, [0, 2, 1]]  # counter-clockwise in the slave's plane
    poly = np.zeros((i.size, MAX_VERTICES, 2))
    poly[:, :3] = s2
    size = np.linalg.norm(slave[i] - slave[i].mean(axis=1)[:, None], axis=2).max(axis=1)
    poly, count = clip_polygons(poly, np.full(i.size, 3), m2, ON_LINE * size)
    area = polygon_areas(poly, count)
    slave_area = polygon_areas(np.pad(s2, ((0, 0), (0, MAX_VERTICES - 3), (0, 0))),
                               np.full(i.size, 3))  # fmt: skip
    keep = (count >= 3) & (area > TINY_AREA * slave_area)
    poly, count, i, j = poly[keep], count[keep], i[keep], j[keep]
    slots = np.arange(MAX_VERTICES)
    live = slots[None] < count[:, None]
    centre = (poly * live[..., None]).sum(axis=1) / count[:, None]
    nxt = np.where(slots[None] + 1 < count[:, None], slots[None] + 1, 0)
    p, k = np.nonzero(live)  # one cell per polygon side
    tri2 = np.stack([centre[p], poly[p, k], poly[p, nxt[p, k]]], axis=1)  # (c, 3, 2)
    a, b = tri2[:, 1] - tri2[:, 0], tri2[:, 2] - tri2[:, 0]
    cell_area = 0.5 * (a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0])
    points = origin[i[p], None] + np.einsum("ckd,cdx->ckx", tri2, frame[i[p], :2])
    good = cell_area > 0
    return Segments(i[p][good], j[p][good], points[good], cell_area[good])
