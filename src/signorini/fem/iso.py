"""Isoparametric P2 cells on curved boundary parts.

A cell with an edge on a boundary part that carries a curve (other than a
:class:`~signorini.mesh.curves.Line`) is mapped from the reference triangle by the quadratic
``x(xi) = sum_a x_a phi_a(xi)`` through its six P2 node points (the curved edge's midpoint
node on the curve, :attr:`~signorini.fem.space.P2Space.node_points`). Its Jacobian varies
from point to point, so stiffness, loads and error norms on these cells use per-quadrature-
point Jacobians (:class:`signorini.fem.mapping.IsoparametricCells`, built on the kernels
here); every other cell keeps the affine formulas. All functions are vectorized over the
curved cells and the quadrature points.

Arrays: ``nodes (m, 6, 2)`` are the node points of the curved cells in local node order
(:mod:`signorini.fem.p2`).
"""

from __future__ import annotations

import numpy as np

from ..mesh.curves import Line
from ..mesh.geometry import spanned_normals
from ..mesh.jacobians import determinant, inverse
from ..mesh.mesh import Mesh
from . import p2
from .quadrature import triangle_rule

__all__ = [
    "STIFFNESS_DEGREE",
    "curved_facets",
    "curved_cells",
    "geometry",
    "folded",
    "edge_geometry",
    "field_derivatives",
]

#: Quadrature degree of the stiffness on a curved cell. ``det J * J^{-T}`` is the cofactor
#: matrix of ``J``, a polynomial of degree 1 for a quadratic map, so the integrand
#: ``det J * grad phi_a . C grad phi_b`` is a polynomial of degree 2 divided by ``det J``
#: (degree 2). Degree 2 (three points) already gives the optimal rate (Ciarlet-Raviart:
#: degree 2k - 2 suffices); degree 4 is used to make the rational part small as well.
STIFFNESS_DEGREE = 4


def curved_facets(mesh: Mesh) -> np.ndarray:
    """Sorted indices of the boundary facets (edges in 2D) on parts carrying a curve that is
    not a line."""
    curved = [i for i, c in enumerate(mesh.curves) if c is not None and not isinstance(c, Line)]
    if not curved:
        return np.zeros(0, dtype=np.int64)
    return np.flatnonzero(np.isin(mesh.facet_part, curved))


def curved_cells(mesh: Mesh) -> np.ndarray:
    """Sorted indices of the cells with a facet on a curved part (their isoparametric cells)."""
    facets = curved_facets(mesh)
    return np.unique(mesh.facet2cell[facets, 0])


def geometry(nodes: np.ndarray, xi: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Points, Jacobians and determinants of the quadratic maps at reference points ``xi``.

    Returns
    -------
    x : (m, q, 2)
    J : (m, q, 2, 2)
        ``J[..., i, j] = d x_i / d xi_j``.
    det : (m, q)
    """
    nodes = np.asarray(nodes, dtype=np.float64)
    x = np.einsum("qa,mai->mqi", p2.basis(xi), nodes)
    J = np.einsum("qaj,mai->mqij", p2.grad_basis(xi), nodes)
    return x, J, determinant(J)


def folded(nodes: np.ndarray) -> np.ndarray:
    """Indices of the cells whose quadratic map has a non-positive Jacobian determinant at
    one of its six nodes or at a point of the stiffness rule (the map folds over)."""
    xi = np.vstack([p2.REFERENCE_NODES, triangle_rule(STIFFNESS_DEGREE)[0]])
    _, _, det = geometry(nodes, xi)
    return np.flatnonzero(~(det > 0.0).all(axis=1))


def edge_geometry(
    ends: np.ndarray, midpoints: np.ndarray, t: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The quadratic edge ``x(t) = x_s psi_0 + x_e psi_1 + x_m psi_2`` at parameters ``t``.

    Returns points ``(k, q, 2)``, speeds ``|x'(t)|`` ``(k, q)`` and outward unit normals
    ``(k, q, 2)`` (the tangent turned clockwise; edges run counter-clockwise around their
    cell).
    """
    ends = np.asarray(ends, dtype=np.float64)
    nodes = np.concatenate([ends, np.asarray(midpoints, dtype=np.float64)[:, None, :]], axis=1)
    t = np.asarray(t, dtype=np.float64)
    dpsi = np.column_stack([4.0 * t - 3.0, 4.0 * t - 1.0, 4.0 - 8.0 * t])  # (q, 3)
    x = np.einsum("qa,kai->kqi", p2.edge_basis(t), nodes)
    dx = np.einsum("qa,kai->kqi", dpsi, nodes)
    speed, normal = spanned_normals(dx[..., None, :])
    return x, speed, normal


def field_derivatives(
    nodes: np.ndarray, u_cell: np.ndarray, xi: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Physical gradient and Hessian of a P2 field on the isoparametric cells at reference
    points ``xi``, shared ``(q, 2)`` or per cell ``(m, q, 2)``.

    With ``u_h(x(xi)) = u(xi) = sum_a u_a phi_a(xi)`` and the quadratic map ``x(xi)``, the chain
    rule gives ``D u = grad u_h J`` and ``D^2 u = J^T (Hess u_h) J + sum_i (grad u_h)_i D^2 x_i``,
    where ``D^2 x_i`` is constant (the map is quadratic), so
    ``Hess u_h = J^{-T} (D^2 u - sum_i (grad u_h)_i D^2 x_i) J^{-1}``: exact, not an
    approximation (docs/method.md, *Estimator*, "On curved boundaries").

    Parameters
    ----------
    nodes : (m, 6, 2) float array
        Node points of the cells.
    u_cell : (m, 12) float array
        Interleaved local coefficients.
    xi : (q, 2) or (m, q, 2) float array

    Returns
    -------
    grad : (m, q, 2, 2)
        ``grad[c, p, i, j] = d u_i / d x_j``.
    hess : (m, q, 2, 2, 2)
        ``hess[c, p, i, j, k] = d^2 u_i / d x_j d x_k``.
    """
    nodes = np.asarray(nodes, dtype=np.float64)
    u = np.asarray(u_cell, dtype=np.float64).reshape(-1, 6, 2)
    xi = np.asarray(xi, dtype=np.float64)
    if xi.ndim == 2:
        dphi = np.broadcast_to(p2.grad_basis(xi), (len(nodes),) + (len(xi), 6, 2))
    else:
        dphi = p2.grad_basis(xi.reshape(-1, 2)).reshape(xi.shape[:2] + (6, 2))
    m, q = dphi.shape[:2]
    # d/dxi of the map and of the field: (m, q, 2, 6) @ (m, 1, 6, 2) -> (m, q, 2, 2)
    dphi_t = np.swapaxes(dphi, -1, -2)
    J = np.swapaxes(np.matmul(dphi_t, nodes[:, None]), -1, -2)
    Du = np.swapaxes(np.matmul(dphi_t, u[:, None]), -1, -2)
    Jinv = inverse(J)
    grad = np.matmul(Du, Jinv)
    d2phi = p2.hessian_basis().reshape(6, 4)  # constant: (a, kl)
    D2u = np.swapaxes(u, 1, 2) @ d2phi  # (m, 2, 4): [c, kl]
    D2x = (np.swapaxes(nodes, 1, 2) @ d2phi)[:, None]  # (m, 1, 2, 4): [i, kl]
    inner = (D2u[:, None] - np.matmul(grad, D2x)).reshape(m, q, 2, 2, 2)
    Jinv = Jinv[:, :, None]
    hess = np.matmul(np.matmul(np.swapaxes(Jinv, -1, -2), inner), Jinv)
    return grad, hess
