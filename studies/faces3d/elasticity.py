"""P2 tetrahedra for isotropic linear elasticity: quadrature, basis, assembly, energy norm.

Everything is vectorised over cells and faces; loops run over quadrature points or local
basis functions only. The bilinear form is a(u, v) = ∫ 2μ ε(u):ε(v) + λ div u div v
(the paper's (2.1) in 3D).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import scipy.sparse as sp

from .mesh import TET_EDGES, CubeMesh

Field = Callable[[np.ndarray], np.ndarray]


def tet_rule(m: int) -> tuple[np.ndarray, np.ndarray]:
    """Collapsed (Duffy) Gauss rule on the reference tetrahedron, exact to degree 2m − 3.

    Returns
    -------
    bary : ndarray, shape (m³, 4)
        Barycentric coordinates of the points.
    weights : ndarray, shape (m³,)
        Weights summing to 1/6 (the reference volume).
    """
    t, w = np.polynomial.legendre.leggauss(m)
    t, w = (t + 1) / 2, w / 2
    u, v, s = (a.ravel() for a in np.meshgrid(t, t, t, indexing="ij"))
    wu, wv, ws = (a.ravel() for a in np.meshgrid(w, w, w, indexing="ij"))
    x, y, z = u, v * (1 - u), s * (1 - u) * (1 - v)
    weights = wu * wv * ws * (1 - u) ** 2 * (1 - v)
    return np.stack([1 - x - y - z, x, y, z], axis=1), weights


def tri_rule(m: int) -> tuple[np.ndarray, np.ndarray]:
    """Collapsed Gauss rule on the reference triangle, exact to degree 2m − 2.

    Returns
    -------
    bary : ndarray, shape (m², 3)
    weights : ndarray, shape (m²,), summing to 1/2.
    """
    t, w = np.polynomial.legendre.leggauss(m)
    t, w = (t + 1) / 2, w / 2
    u, v = (a.ravel() for a in np.meshgrid(t, t, indexing="ij"))
    wu, wv = (a.ravel() for a in np.meshgrid(w, w, indexing="ij"))
    x, y = u, v * (1 - u)
    return np.stack([1 - x - y, x, y], axis=1), wu * wv * (1 - u)


def p2_values(bary: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """Lagrange P2 basis on a simplex from barycentrics: λ_i(2λ_i − 1), then 4 λ_a λ_b.

    Parameters
    ----------
    bary : ndarray, shape (n_points, d + 1)
    edges : ndarray, shape (n_edges, 2)
        Local vertex pairs of the midpoint functions.

    Returns
    -------
    ndarray, shape (n_points, d + 1 + n_edges)
    """
    return np.hstack([bary * (2 * bary - 1), 4 * bary[:, edges[:, 0]] * bary[:, edges[:, 1]]])


def p2_lambda_gradients(bary: np.ndarray) -> np.ndarray:
    """∂φ_a/∂λ_k of the tetrahedron's 10 P2 functions, shape (n_points, 10, 4)."""
    n = bary.shape[0]
    d = np.zeros((n, 10, 4))
    d[:, np.arange(4), np.arange(4)] = 4 * bary - 1
    for e, (a, b) in enumerate(TET_EDGES):
        d[:, 4 + e, a] = 4 * bary[:, b]
        d[:, 4 + e, b] = 4 * bary[:, a]
    return d


def geometry(mesh: CubeMesh) -> tuple[np.ndarray, np.ndarray]:
    """∇λ_k (constant per cell) and |det J| of each tetrahedron.

    Returns
    -------
    grad_bary : ndarray, shape (n_tets, 4, 3)
    det : ndarray, shape (n_tets,)
    """
    x = mesh.points[mesh.tets[:, :4]]
    jac = np.stack([x[:, 1] - x[:, 0], x[:, 2] - x[:, 0], x[:, 3] - x[:, 0]], axis=2)
    inv = np.linalg.inv(jac)  # rows: ∇λ_1, ∇λ_2, ∇λ_3
    grad = np.concatenate([-inv.sum(axis=1, keepdims=True), inv], axis=1)
    return grad, np.abs(np.linalg.det(jac))


def physical_gradients(mesh: CubeMesh, bary: np.ndarray) -> np.ndarray:
    """∇φ_a at the points ``bary`` of every cell, shape (n_tets, n_points, 10, 3)."""
    grad_bary, _ = geometry(mesh)
    return np.einsum("qak,tkj->tqaj", p2_lambda_gradients(bary), grad_bary)


def stiffness(mesh: CubeMesh, lam: float, mu: float) -> sp.csr_matrix:
    """The P2 stiffness matrix, shape (3 n_nodes, 3 n_nodes), interleaved DOFs.

    K[(a,i),(b,j)] = ∫ λ ∂_i φ_a ∂_j φ_b + μ (δ_ij ∇φ_a·∇φ_b + ∂_j φ_a ∂_i φ_b), with the
    degree-3 rule (the integrand has degree 2).
    """
    bary, w = tet_rule(3)
    _, det = geometry(mesh)
    G = physical_gradients(mesh, bary)  # (t, q, 10, 3)
    W = det[:, None] * w[None, :]
    Ke = lam * np.einsum("tq,tqai,tqbj->taibj", W, G, G)
    Ke += mu * np.einsum("tq,tqaj,tqbi->taibj", W, G, G)
    dot = np.einsum("tq,tqak,tqbk->tab", W, G, G)
    Ke += mu * np.einsum("tab,ij->taibj", dot, np.eye(3))
    dofs = (3 * mesh.tets[:, :, None] + np.arange(3)).reshape(-1, 30)
    rows = np.repeat(dofs, 30, axis=1).ravel()
    cols = np.tile(dofs, (1, 30)).ravel()
    n = 3 * mesh.n_nodes
    return sp.coo_matrix((Ke.reshape(-1), (rows, cols)), shape=(n, n)).tocsr()


def body_load(mesh: CubeMesh, f: Field, m: int = 5) -> np.ndarray:
    """F[(a,i)] = ∫ f_i φ_a dx, shape (3 n_nodes,); ``f`` maps (..., 3) points to (..., 3)."""
    bary, w = tet_rule(m)
    _, det = geometry(mesh)
    phi = p2_values(bary, TET_EDGES)  # (q, 10)
    xq = np.einsum("qk,tkj->tqj", bary, mesh.points[mesh.tets[:, :4]])
    Fe = np.einsum("t,q,tqi,qa->tai", det, w, f(xq), phi)
    return np.bincount(
        (3 * mesh.tets[:, :, None] + np.arange(3)).ravel(), Fe.ravel(), 3 * mesh.n_nodes
    )


FACE_EDGES = np.array([[0, 1], [1, 2], [2, 0]])


def face_points(mesh: CubeMesh, faces: np.ndarray, bary: np.ndarray) -> np.ndarray:
    """Points of the barycentrics ``bary`` (q, 3) on each face, shape (n_faces, q, 3)."""
    return np.einsum("qk,fkj->fqj", bary, mesh.points[faces[:, :3]])


def face_areas(mesh: CubeMesh, faces: np.ndarray) -> np.ndarray:
    """|F| of each face, shape (n_faces,)."""
    x = mesh.points[faces[:, :3]]
    return 0.5 * np.linalg.norm(np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]), axis=1)


def face_load(mesh: CubeMesh, faces: np.ndarray, g: Field, m: int = 5) -> np.ndarray:
    """G[(a,i)] = ∫_F g_i φ_a ds summed over ``faces`` (n_faces, 6), shape (3 n_nodes,)."""
    bary, w = tri_rule(m)
    phi = p2_values(bary, FACE_EDGES)  # (q, 6)
    Ge = np.einsum(
        "f,q,fqi,qa->fai", 2 * face_areas(mesh, faces), w, g(face_points(mesh, faces, bary)), phi
    )
    return np.bincount((3 * faces[:, :, None] + np.arange(3)).ravel(), Ge.ravel(), 3 * mesh.n_nodes)


def energy_error(
    mesh: CubeMesh, u_h: np.ndarray, grad_u: Field, lam: float, mu: float, m: int = 5
) -> float:
    """‖u − u_h‖_E = a(u − u_h, u − u_h)^{1/2}.

    Parameters
    ----------
    u_h : ndarray, shape (n_nodes, 3)
        Nodal values.
    grad_u : callable
        Exact ∇u, (..., 3) points to (..., 3, 3) with [i, j] = ∂_j u_i.
    """
    bary, w = tet_rule(m)
    _, det = geometry(mesh)
    G = physical_gradients(mesh, bary)
    xq = np.einsum("qk,tkj->tqj", bary, mesh.points[mesh.tets[:, :4]])
    D = grad_u(xq) - np.einsum("tai,tqaj->tqij", u_h[mesh.tets], G)
    eps = 0.5 * (D + np.swapaxes(D, -1, -2))
    dens = 2 * mu * (eps**2).sum(axis=(-1, -2)) + lam * np.trace(eps, axis1=-2, axis2=-1) ** 2
    return float(np.sqrt(np.einsum("t,q,tq->", det, w, dens)))
