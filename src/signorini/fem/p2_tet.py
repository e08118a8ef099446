"""The quadratic Lagrange (P2) tetrahedron, VTK's ``tetra10``, vectorized over points and
cells (docs/method.md, *Three dimensions*).

Conventions (those of :mod:`signorini.fem.p2`, one dimension up)
----------------------------------------------------------------
* Reference tetrahedron :data:`~signorini.mesh.reference.TETRAHEDRON` (the owner of the local
  vertices, edges and faces) with vertices (0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1);
  barycentric coordinates ``l0 = 1 - x - y - z``, ``l1 = x``, ``l2 = y``, ``l3 = z``.
* Local node order: the 4 vertices, then the midpoints of the local edges
  ``TETRAHEDRON.edges`` = 01, 12, 20, 03, 13, 23 -- VTK's quadratic tetrahedron, meshio's
  ``tetra10``. Vertex basis ``l_i (2 l_i - 1)``, midpoint basis ``4 l_a l_b``: the
  formulas of the P2 triangle with one more barycentric coordinate.
* Vector fields are interleaved per node: local DOF ``3 a + c`` is component ``c`` at local
  node ``a`` (30 per tetrahedron).
* Affine map ``x = v0 + J xi`` with ``J = [v1 - v0, v2 - v0, v3 - v0]`` (columns); positively
  oriented cells have ``det J > 0`` (:mod:`signorini.mesh.jacobians`, d = 3).
* On a face the six P2 nodes are its three vertices in the order of ``TETRAHEDRON.facets``
  (outward by the right-hand rule), then the midpoints of its edges (a, b), (b, c), (c, a):
  the P2 triangle's order, so the face basis *is* :func:`signorini.fem.p2.basis`.

Gradients are stored last-axis-is-derivative: ``grad[..., i, j] = d u_i / d x_j``.
"""

from __future__ import annotations

import numpy as np

from ..mesh.reference import TETRAHEDRON, TRIANGLE
from . import p2

__all__ = [
    "FACE_EDGES",
    "GRAD_BARYCENTRIC",
    "REFERENCE_NODES",
    "barycentric",
    "basis",
    "basis_barycentric",
    "face_basis",
    "face_reference_points",
    "grad_basis",
    "hessian_basis",
]

#: Reference coordinates of the 10 local nodes, shape (10, 3): the vertices, then the
#: midpoints of the local edges (read-only).
REFERENCE_NODES = np.concatenate(
    [TETRAHEDRON.vertices, 0.5 * TETRAHEDRON.vertices[TETRAHEDRON.edges].sum(axis=1)]
)
REFERENCE_NODES.setflags(write=False)

#: Gradients ``(4, 3)`` of the barycentric coordinates l0 … l3 on the reference tetrahedron.
GRAD_BARYCENTRIC = np.array([[-1.0, -1.0, -1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
GRAD_BARYCENTRIC.setflags(write=False)

_EDGE_VERTS = tuple(tuple(e) for e in TETRAHEDRON.edges.tolist())


def _face_edges() -> np.ndarray:
    """``(4, 3)`` the local edge of each side (a, b), (b, c), (c, a) of each local face."""
    key = {frozenset(e): k for k, e in enumerate(_EDGE_VERTS)}
    faces = TETRAHEDRON.facets
    sides = faces[:, TRIANGLE.edges]  # (4, 3, 2): the face's triangle edges, in local vertices
    out = np.array([[key[frozenset(s)] for s in face] for face in sides.tolist()])
    out.setflags(write=False)
    return out


#: ``FACE_EDGES[k, s]``: the local edge of the tetrahedron on side ``s`` of local face ``k``
#: (sides in the P2 triangle's order, ``TRIANGLE.edges``), shape (4, 3). The face's six
#: local nodes are ``TETRAHEDRON.facets[k]`` then ``4 + FACE_EDGES[k]``.
FACE_EDGES = _face_edges()


def _as_points(xi: np.ndarray) -> np.ndarray:
    xi = np.asarray(xi, dtype=np.float64)
    return xi[None, :] if xi.ndim == 1 else xi


def barycentric(xi: np.ndarray) -> np.ndarray:
    """Barycentric coordinates ``(1 - x - y - z, x, y, z)`` of reference points ``xi (..., 3)``;
    shape ``(..., 4)``."""
    xi = _as_points(xi)
    return np.concatenate([1.0 - xi.sum(axis=-1, keepdims=True), xi], axis=-1)


def basis_barycentric(bary: np.ndarray) -> np.ndarray:
    """Values ``(..., 10)`` of the 10 P2 basis functions at barycentric coordinates ``bary
    (..., 4)``: ``l_i (2 l_i - 1)`` at the vertices, ``4 l_a l_b`` at the midpoint of local
    edge (a, b)."""
    bary = np.asarray(bary, dtype=np.float64)
    out = np.empty(bary.shape[:-1] + (10,))
    out[..., :4] = bary * (2.0 * bary - 1.0)
    for k, (a, b) in enumerate(_EDGE_VERTS):
        out[..., 4 + k] = 4.0 * bary[..., a] * bary[..., b]
    return out


def basis(xi: np.ndarray) -> np.ndarray:
    """Values ``(q, 10)`` of the reference P2 basis at ``xi (q, 3)`` (local node order)."""
    return basis_barycentric(barycentric(xi))


def grad_basis(xi: np.ndarray) -> np.ndarray:
    """Reference gradients ``(q, 10, 3)`` of the P2 basis at ``xi (q, 3)``:
    ``g[p, a, j] = d phi_a / d xi_j``."""
    bary = barycentric(xi)
    out = np.empty((bary.shape[0], 10, 3))
    for i in range(4):
        out[:, i, :] = (4.0 * bary[:, i] - 1.0)[:, None] * GRAD_BARYCENTRIC[i]
    for k, (a, b) in enumerate(_EDGE_VERTS):
        out[:, 4 + k, :] = 4.0 * (
            bary[:, a, None] * GRAD_BARYCENTRIC[b] + bary[:, b, None] * GRAD_BARYCENTRIC[a]
        )
    return out


def hessian_basis() -> np.ndarray:
    """Constant reference Hessians ``(10, 3, 3)`` of the P2 basis functions."""
    out = np.empty((10, 3, 3))
    for i in range(4):
        out[i] = 4.0 * np.outer(GRAD_BARYCENTRIC[i], GRAD_BARYCENTRIC[i])
    for k, (a, b) in enumerate(_EDGE_VERTS):
        g = np.outer(GRAD_BARYCENTRIC[a], GRAD_BARYCENTRIC[b])
        out[4 + k] = 4.0 * (g + g.T)
    return out


def face_basis(s: np.ndarray) -> np.ndarray:
    """The P2 basis ``(q, 6)`` on a face at triangle reference points ``s (q, 2)``: the P2
    triangle's (:func:`signorini.fem.p2.basis`), in the face's node order (3 vertices, then
    the midpoints of sides (a, b), (b, c), (c, a))."""
    return p2.basis(s)


def face_reference_points(local_face: np.ndarray, s: np.ndarray) -> np.ndarray:
    """Reference coordinates in the tetrahedron of points ``s (q, 2)`` of the reference
    triangle on local faces ``local_face (k,)``: ``x = A + s_1 (B - A) + s_2 (C - A)`` with
    ``(A, B, C)`` the face's vertices ``TETRAHEDRON.facets[local_face]``.

    Returns
    -------
    (k, q, 3) float array (``(q, 3)`` for a scalar ``local_face``)
    """
    f = np.asarray(local_face)
    s = _as_points(s)
    corners = TETRAHEDRON.vertices[TETRAHEDRON.facets[f]]  # (..., 3, 3)
    a = corners[..., 0, :]
    return (
        a[..., None, :]
        + s[:, 0, None] * (corners[..., 1, :] - a)[..., None, :]
        + s[:, 1, None] * (corners[..., 2, :] - a)[..., None, :]
    )
