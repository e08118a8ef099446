"""Load vectors of the functional ``L(v) = int_Omega f . v dx + int_{Gamma_N} g . v ds``
(paper, Section 2).

The data ``f`` and ``g`` are called here as they are given: callers pass functions whose
output has been checked (:func:`signorini.problem.fields.evaluate_field`).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..mesh.geometry import segment_normals
from . import iso, p2
from .quadrature import line_rule, triangle_rule

__all__ = ["assemble_body_force", "assemble_edge_load"]


def assemble_body_force(
    vertices: np.ndarray,
    cell_dofs: np.ndarray,
    n_dofs: int,
    f: Callable[[np.ndarray], np.ndarray],
    degree: int = 6,
    curved: tuple[np.ndarray, np.ndarray] | None = None,
) -> np.ndarray:
    """Load vector of a body force, ``F[2 z + c] = int_Omega f_c psi_z dx``.

    Parameters
    ----------
    vertices : ndarray of float, shape (m, 3, 2)
        Cell vertices, counter-clockwise.
    cell_dofs : ndarray of int, shape (m, 12)
        Interleaved global DOFs.
    n_dofs : int
    f : callable
        ``f(x)`` with ``x (m, q, 2)`` returns the force density, shape
        ``(m, q, 2)`` (or anything broadcastable to it, e.g. a constant ``(2,)``).
    degree : int, optional
        Quadrature degree on each cell (exact for ``f`` polynomial of degree
        ``degree - 2``).
    curved : (cells (k,), nodes (k, 6, 2)), optional
        Isoparametric cells (:attr:`~signorini.fem.space.P2Space.curved`), integrated on
        their quadratic maps with per-point Jacobians.

    Returns
    -------
    ndarray of float64, shape (n_dofs,)
    """
    _, det = p2.jacobian(vertices)
    xi, w = triangle_rule(degree)
    x = p2.physical_points(vertices, xi)
    if curved is not None:  # f is called once, at the curved cells' own points
        cells, nodes = curved
        x_curved, _, det_curved = iso.geometry(nodes, xi)
        x[cells] = x_curved
    fx = np.broadcast_to(np.asarray(f(x), dtype=np.float64), x.shape)
    phi = p2.basis(xi) * w[:, None]  # (q, 6)
    local = np.einsum("qa,mqc->mac", phi, fx) * det[:, None, None]
    if curved is not None:
        local[cells] = np.einsum("qa,mqc,mq->mac", phi, fx[cells], det_curved)
    return np.bincount(np.ravel(cell_dofs), weights=local.ravel(), minlength=n_dofs)


def assemble_edge_load(
    edge_vertices: np.ndarray,
    edge_dofs: np.ndarray,
    n_dofs: int,
    g: Callable[[np.ndarray, np.ndarray], np.ndarray],
    degree: int = 6,
    midpoints: np.ndarray | None = None,
) -> np.ndarray:
    """Load vector of boundary tractions, ``G[2 z + c] = int_{Gamma_N} g_c psi_z ds``.

    Parameters
    ----------
    edge_vertices : ndarray of float, shape (k, 2, 2)
        (start, end) of each straight boundary edge, in the counter-clockwise
        order of its cell (so the outward normal is ``(dy, -dx) / |e|``).
    edge_dofs : ndarray of int, shape (k, 6)
        Interleaved DOFs of the edge's P2 nodes in the order (start, end, midpoint).
    n_dofs : int
    g : callable
        ``g(x, normal)`` with points ``x (k, q, 2)`` and outward unit normals
        ``normal (k, 1, 2)`` returns the traction, shape ``(k, q, 2)`` (or
        broadcastable to it).
    degree : int, optional
        Gauss-Legendre degree along each edge (exact for ``g`` polynomial of
        degree ``degree - 2``).
    midpoints : ndarray of float, shape (k, 2), optional
        Midpoint nodes of curved edges (on the curve): each edge is then the quadratic
        ``x(t)`` through start, midpoint and end, ``g`` gets the points ``x(t)`` and the
        normals of that curve ``(k, q, 2)``, and the integral is ``int_0^1 g psi |x'(t)| dt``.

    Returns
    -------
    ndarray of float64, shape (n_dofs,)
    """
    ev = np.asarray(edge_vertices, dtype=np.float64)
    t, w = line_rule(degree)
    if midpoints is not None:
        x, speed, normal = iso.edge_geometry(ev, midpoints, t)
        gx = np.broadcast_to(np.asarray(g(x, normal), dtype=np.float64), x.shape)
        local = np.einsum("qa,kqc,kq->kac", p2.edge_basis(t), gx, speed * w[None, :])
        return np.bincount(np.ravel(edge_dofs), weights=local.ravel(), minlength=n_dofs)
    length, normal = segment_normals(ev[:, 0], ev[:, 1])
    x = ev[:, None, 0, :] + t[None, :, None] * (ev[:, 1] - ev[:, 0])[:, None, :]
    gx = np.broadcast_to(np.asarray(g(x, normal[:, None, :]), dtype=np.float64), x.shape)
    psi = p2.edge_basis(t) * w[:, None]  # (q, 3)
    local = np.einsum("qa,kqc->kac", psi, gx) * length[:, None, None]
    return np.bincount(np.ravel(edge_dofs), weights=local.ravel(), minlength=n_dofs)
