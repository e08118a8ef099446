"""The quadratic Lagrange (P2) triangle and affine geometry, vectorized over cells.

Conventions (fixed for the whole package)
-----------------------------------------
* Reference triangle :data:`~signorini.mesh.reference.TRIANGLE` (the owner of the local
  vertices and edges) with vertices (0, 0), (1, 0), (0, 1); barycentric
  coordinates ``l0 = 1 - x - y``, ``l1 = x``, ``l2 = y``.
* Local node order: the 3 vertices, then the midpoints of local edges
  0 (v0-v1), 1 (v1-v2), 2 (v2-v0) -- the VTK quadratic triangle, meshio's
  ``triangle6``.  Vertex basis ``l_i (2 l_i - 1)``, midpoint basis
  ``4 l_a l_b``.
* Vector fields are interleaved per node: local DOF ``2 * a + c`` is component
  ``c`` at local node ``a`` (12 per triangle).
* Affine map ``x = v0 + J xi`` with ``J = [v1 - v0, v2 - v0]`` (columns);
  counter-clockwise cells have ``det J > 0``.
* On an edge the three P2 nodes are ordered (start, end, midpoint), with the
  edge parameter ``t`` in [0, 1] running from start to end.

Arrays of cells are batched: ``vertices`` has shape ``(m, 3, 2)`` (``points[cells]``),
per-cell coefficients ``u_cell`` shape ``(m, 12)``; reference points ``xi`` shape
``(q, 2)``.  Gradients are stored last-axis-is-derivative:
``grad[..., i, j] = d u_i / d x_j``.

These are kernels on trusted arrays: cells come from a validated
:class:`~signorini.mesh.Mesh` (counter-clockwise, ``det J > 0``), so nothing here re-checks
shapes or orientation.
"""

from __future__ import annotations

import numpy as np

from ..mesh import jacobians
from ..mesh.reference import TRIANGLE

__all__ = [
    "GRAD_BARYCENTRIC",
    "REFERENCE_NODES",
    "barycentric",
    "basis",
    "basis_barycentric",
    "edge_basis",
    "edge_reference_points",
    "field_gradients",
    "field_hessian",
    "field_values",
    "gradient_coefficients",
    "grad_basis",
    "hessian_basis",
    "inverse_transpose",
    "jacobian",
    "physical_gradients",
    "physical_points",
]

#: Reference coordinates of the 6 local nodes, shape (6, 2): the vertices, then the
#: midpoints of the local edges.
REFERENCE_NODES = np.concatenate(
    [TRIANGLE.vertices, 0.5 * TRIANGLE.vertices[TRIANGLE.edges].sum(axis=1)]
)
REFERENCE_NODES.setflags(write=False)

#: Gradients ``(3, 2)`` of the barycentric coordinates l0, l1, l2 on the reference triangle:
#: the (constant) gradients of the P1 basis, from which those of the P2 basis are built.
GRAD_BARYCENTRIC = np.array([[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]])
GRAD_BARYCENTRIC.setflags(write=False)
# midpoint a = 3 + k lies on local edge k, joining vertices TRIANGLE.edges[k]
_EDGE_VERTS = tuple(tuple(e) for e in TRIANGLE.edges.tolist())


def _as_points(xi: np.ndarray) -> np.ndarray:
    """Reference points as a float array: ``(q, 2)`` shared by all cells (one point ``(2,)``
    becomes ``(1, 2)``), or ``(m, q, 2)`` given per cell."""
    xi = np.asarray(xi, dtype=np.float64)
    return xi[None, :] if xi.ndim == 1 else xi


def barycentric(xi: np.ndarray) -> np.ndarray:
    """Barycentric coordinates ``(1 - x - y, x, y)`` of reference points.

    Parameters
    ----------
    xi : array_like of float, shape (q, 2)

    Returns
    -------
    ndarray of float64, shape (q, 3)
    """
    xi = _as_points(xi)
    return np.column_stack([1.0 - xi[:, 0] - xi[:, 1], xi[:, 0], xi[:, 1]])


def basis_barycentric(bary: np.ndarray) -> np.ndarray:
    """Values of the 6 P2 basis functions at points given by barycentric coordinates.

    Vertex functions ``l_i (2 l_i - 1)``, midpoint functions ``4 l_a l_b`` of local edge
    ``(a, b)`` -- the one place where the P2 basis is written down.

    Parameters
    ----------
    bary : array_like of float, shape (..., 3)
        Barycentric coordinates ``(l0, l1, l2)``.

    Returns
    -------
    ndarray of float64, shape (..., 6)
        In the local node order (3 vertices, then the midpoints of local edges 0, 1, 2).
    """
    bary = np.asarray(bary, dtype=np.float64)
    out = np.empty(bary.shape[:-1] + (6,))
    out[..., :3] = bary * (2.0 * bary - 1.0)
    for k, (a, b) in enumerate(_EDGE_VERTS):
        out[..., 3 + k] = 4.0 * bary[..., a] * bary[..., b]
    return out


def basis(xi: np.ndarray) -> np.ndarray:
    """Values of the 6 reference P2 basis functions.

    Parameters
    ----------
    xi : array_like of float, shape (q, 2)
        Reference points.

    Returns
    -------
    ndarray of float64, shape (q, 6)
        ``phi[p, a]`` = basis function ``a`` at point ``p`` (project node order).
    """
    return basis_barycentric(barycentric(xi))


def grad_basis(xi: np.ndarray) -> np.ndarray:
    """Reference gradients of the 6 P2 basis functions.

    Parameters
    ----------
    xi : array_like of float, shape (q, 2)
        Reference points.

    Returns
    -------
    ndarray of float64, shape (q, 6, 2)
        ``g[p, a, j] = d phi_a / d xi_j`` at point ``p``.
    """
    bary = barycentric(xi)
    out = np.empty((bary.shape[0], 6, 2))
    for i in range(3):
        out[:, i, :] = (4.0 * bary[:, i] - 1.0)[:, None] * GRAD_BARYCENTRIC[i]
    for k, (a, b) in enumerate(_EDGE_VERTS):
        out[:, 3 + k, :] = 4.0 * (
            bary[:, a, None] * GRAD_BARYCENTRIC[b] + bary[:, b, None] * GRAD_BARYCENTRIC[a]
        )
    return out


def hessian_basis() -> np.ndarray:
    """Constant reference Hessians of the 6 P2 basis functions.

    Returns
    -------
    ndarray of float64, shape (6, 2, 2)
        ``h[a, j, k] = d^2 phi_a / d xi_j d xi_k``.
    """
    out = np.empty((6, 2, 2))
    for i in range(3):
        out[i] = 4.0 * np.outer(GRAD_BARYCENTRIC[i], GRAD_BARYCENTRIC[i])
    for k, (a, b) in enumerate(_EDGE_VERTS):
        g = np.outer(GRAD_BARYCENTRIC[a], GRAD_BARYCENTRIC[b])
        out[3 + k] = 4.0 * (g + g.T)
    return out


def edge_basis(t: np.ndarray) -> np.ndarray:
    """P2 basis on an edge in the node order (start, end, midpoint).

    Parameters
    ----------
    t : array_like of float, shape (q,)
        Edge parameters in [0, 1] (0 = start, 1 = end).

    Returns
    -------
    ndarray of float64, shape (q, 3)
        ``(1 - t)(1 - 2 t)``, ``t (2 t - 1)``, ``4 t (1 - t)``.
    """
    t = np.asarray(t, dtype=np.float64)
    return np.column_stack([(1.0 - t) * (1.0 - 2.0 * t), t * (2.0 * t - 1.0), 4.0 * t * (1.0 - t)])


def edge_reference_points(local_edge: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Reference coordinates of points on local edges.

    Local edge ``k`` runs from local vertex ``TRIANGLE.edges[k, 0]`` (``k``) to
    ``TRIANGLE.edges[k, 1]`` (``k + 1`` mod 3), counter-clockwise around the cell; ``t = 0``
    is its start.

    Parameters
    ----------
    local_edge : array_like of int, shape (k,) or scalar
        Local edge numbers in {0, 1, 2}.
    t : array_like of float, shape (q,)
        Edge parameters in [0, 1].

    Returns
    -------
    ndarray of float64, shape (k, q, 2) (or (q, 2) for a scalar ``local_edge``)
        Reference points.
    """
    le = np.asarray(local_edge)
    t = np.asarray(t, dtype=np.float64)
    start = TRIANGLE.vertices[TRIANGLE.edges[le, 0]]  # (..., 2)
    end = TRIANGLE.vertices[TRIANGLE.edges[le, 1]]
    return start[..., None, :] + t[:, None] * (end - start)[..., None, :]


def jacobian(vertices: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Jacobians of the affine maps from the reference triangle
    (:func:`signorini.mesh.jacobians.affine_jacobian`).

    Parameters
    ----------
    vertices : array_like of float, shape (m, 3, 2)
        Cell vertex coordinates (``points[cells]``), counter-clockwise.

    Returns
    -------
    J : ndarray of float64, shape (m, 2, 2)
        ``J[:, :, 0] = v1 - v0``, ``J[:, :, 1] = v2 - v0``.
    det : ndarray of float64, shape (m,)
        ``det J`` = twice the cell area (positive for counter-clockwise cells).
    """
    return jacobians.affine_jacobian(vertices)


def inverse_transpose(J: np.ndarray, det: np.ndarray | None = None) -> np.ndarray:
    """Inverse transposes ``J^{-T}`` of a batch of affine Jacobians, the cofactors times
    ``1 / det J`` (:func:`signorini.mesh.jacobians.inverse_transpose`).

    Parameters
    ----------
    J : ndarray of float64, shape (m, 2, 2)
        Jacobians, as returned by :func:`jacobian`.
    det : ndarray of float64, shape (m,), optional
        Their determinants (computed if omitted).

    Returns
    -------
    ndarray of float64, shape (m, 2, 2)
        ``J^{-T}``; physical gradients are ``J^{-T} grad_xi``.
    """
    return jacobians.inverse_transpose(J, det, reciprocal=True)


def physical_points(vertices: np.ndarray, xi: np.ndarray) -> np.ndarray:
    """Images of reference points under each cell's affine map.

    Parameters
    ----------
    vertices : array_like of float, shape (m, 3, 2)
        Cell vertices.
    xi : array_like of float, shape (q, 2)
        Reference points.

    Returns
    -------
    ndarray of float64, shape (m, q, 2)
        ``x = v0 + J xi``.
    """
    v = np.asarray(vertices, dtype=np.float64)
    xi = _as_points(xi)
    v0 = v[:, None, 0, :]
    return (
        v0
        + xi[None, :, 0, None] * (v[:, None, 1, :] - v0)
        + xi[None, :, 1, None] * (v[:, None, 2, :] - v0)
    )


def physical_gradients(vertices: np.ndarray, xi: np.ndarray) -> np.ndarray:
    """Physical gradients of the 6 P2 basis functions.

    Parameters
    ----------
    vertices : array_like of float, shape (m, 3, 2)
        Cell vertices, counter-clockwise.
    xi : array_like of float, shape (q, 2)
        Reference points.

    Returns
    -------
    ndarray of float64, shape (m, q, 6, 2)
        ``G[c, p, a, :] = J_c^{-T} grad phi_a(xi_p)``.
    """
    J, det = jacobian(vertices)
    jit = inverse_transpose(J, det)
    return np.einsum("mij,qaj->mqai", jit, grad_basis(xi))


def field_values(u_cell: np.ndarray, xi: np.ndarray) -> np.ndarray:
    """Values of a P2 vector field at reference points of each cell.

    Parameters
    ----------
    u_cell : array_like of float, shape (m, 12)
        Interleaved local coefficients (``u[cell_dofs]``).
    xi : array_like of float, shape (q, 2) or (m, q, 2)
        Reference points, shared by all cells or given per cell.

    Returns
    -------
    ndarray of float64, shape (m, q, 2)
        ``u_h`` at the image of each reference point.
    """
    u = np.asarray(u_cell, dtype=np.float64).reshape(-1, 6, 2)
    xi = _as_points(xi)
    if xi.ndim == 3:
        phi = basis(xi.reshape(-1, 2)).reshape(xi.shape[0], xi.shape[1], 6)
        return np.einsum("mqa,mac->mqc", phi, u)
    return np.einsum("qa,mac->mqc", basis(xi), u)


def field_gradients(vertices: np.ndarray, u_cell: np.ndarray, xi: np.ndarray) -> np.ndarray:
    """Gradients of a P2 vector field at reference points of each cell.

    Parameters
    ----------
    vertices : array_like of float, shape (m, 3, 2)
        Cell vertices, counter-clockwise.
    u_cell : array_like of float, shape (m, 12)
        Interleaved local coefficients.
    xi : array_like of float, shape (q, 2) or (m, q, 2)
        Reference points, shared by all cells or given per cell.

    Returns
    -------
    ndarray of float64, shape (m, q, 2, 2)
        ``grad[c, p, i, j] = d u_i / d x_j``.
    """
    J, det = jacobian(vertices)
    u = np.asarray(u_cell, dtype=np.float64)
    xi = _as_points(xi)
    coef = gradient_coefficients(u, inverse_transpose(J, det))  # (m, 3, 2, 2)
    if xi.ndim == 3:
        return (
            coef[:, None, 0]
            + xi[:, :, 0, None, None] * coef[:, None, 1]
            + xi[:, :, 1, None, None] * coef[:, None, 2]
        )
    return (
        coef[:, None, 0]
        + xi[None, :, 0, None, None] * coef[:, None, 1]
        + xi[None, :, 1, None, None] * coef[:, None, 2]
    )


def gradient_coefficients(u_cell: np.ndarray, inv_t: np.ndarray) -> np.ndarray:
    """Affine coefficients of the (linear) gradient of a P2 field on each cell.

    On a straight triangle ``grad u_h(x(xi)) = G0 + xi_1 G1 + xi_2 G2``.

    Parameters
    ----------
    u_cell : ndarray of float64, shape (m, 12)
        Interleaved local coefficients.
    inv_t : ndarray of float64, shape (m, 2, 2)
        ``J^{-T}`` of each cell (:func:`inverse_transpose`).

    Returns
    -------
    ndarray of float64, shape (m, 3, 2, 2)
        ``[G0, G1, G2]``; entry ``[i, j]`` of each is a coefficient of ``d u_i / d x_j``.
    """
    u = np.asarray(u_cell, dtype=np.float64).reshape(-1, 6, 2)
    jit = np.asarray(inv_t, dtype=np.float64)
    # reference gradient = ref[0] + xi_1 ref[1] + xi_2 ref[2], ref (3, 6, 2)
    ref = grad_basis(np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]))
    ref[1:] -= ref[0]
    # d u_i / d xi_k of each coefficient c: dref[m, i, c, k] = sum_a u[m, a, i] ref[c, a, k]
    dref = np.tensordot(u, ref, axes=([1], [1]))  # (m, 2, 3, 2)
    # physical: d u_i / d x_j = sum_k dref[..., k] Jit[j, k]
    out = np.empty((u.shape[0], 3, 2, 2))
    for j in range(2):
        out[:, :, :, j] = np.swapaxes(
            dref[..., 0] * jit[:, None, None, j, 0] + dref[..., 1] * jit[:, None, None, j, 1], 1, 2
        )
    return out


def field_hessian(vertices: np.ndarray, u_cell: np.ndarray) -> np.ndarray:
    """Constant Hessian of a P2 vector field on each (straight) cell.

    Parameters
    ----------
    vertices : array_like of float, shape (m, 3, 2)
        Cell vertices, counter-clockwise.
    u_cell : array_like of float, shape (m, 12)
        Interleaved local coefficients.

    Returns
    -------
    ndarray of float64, shape (m, 2, 2, 2)
        ``H[c, i, j, k] = d^2 u_i / d x_j d x_k``.
    """
    J, det = jacobian(vertices)
    u = np.asarray(u_cell, dtype=np.float64).reshape(-1, 6, 2)
    jit = inverse_transpose(J, det)
    href = np.tensordot(u, hessian_basis(), axes=([1], [0]))  # (m, i, r, s)
    # H_i = J^{-T} href_i J^{-1}
    return np.matmul(np.matmul(jit[:, None], href), np.swapaxes(jit, 1, 2)[:, None])
