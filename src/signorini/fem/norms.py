"""Per-cell squared errors of a P2 field against a known solution: energy norm ``a(e, e)``,
H^1 seminorm and L^2 norm (the error columns of the paper's Section 6).

The exact solution is called as it is given: callers pass functions whose output has been
checked (:func:`signorini.problem.fields.evaluate_field`).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from . import iso, p2
from .material import Material
from .quadrature import triangle_rule

__all__ = ["energy_error2", "h1_seminorm_error2", "l2_error2"]


def _error_setup(vertices, u_cell, degree):
    J, det = p2.jacobian(vertices)
    u = np.asarray(u_cell, dtype=np.float64)
    xi, w = triangle_rule(degree)
    v0 = np.asarray(vertices, dtype=np.float64)[:, 0]

    def point(p: int) -> np.ndarray:  # physical images of quadrature point p, (m, 2)
        return v0 + J[:, :, 0] * xi[p, 0] + J[:, :, 1] * xi[p, 1]

    return u, J, det, xi, w, point


def _grad_error_loop(vertices, u_cell, grad_exact, degree, density, curved=None):
    """Sum over quadrature points of density(grad u - grad u_h) * w * det, per cell
    (isoparametric cells ``curved`` with their per-point Jacobians)."""
    u, J, det, xi, w, point = _error_setup(vertices, u_cell, degree)
    coef = p2.gradient_coefficients(u, p2.inverse_transpose(J, det))  # (m, 3, 2, 2)
    out = np.zeros(det.shape[0])
    for p in range(w.size):
        ge = np.asarray(grad_exact(point(p)), dtype=np.float64)
        diff = ge - coef[:, 0]
        diff -= xi[p, 0] * coef[:, 1]
        diff -= xi[p, 1] * coef[:, 2]
        out += w[p] * density(diff)
    out *= det
    if curved is not None:
        cells, nodes = curved
        out[cells] = iso.gradient_errors(nodes, u[cells], grad_exact, degree, density)
    return out


def energy_error2(
    vertices: np.ndarray,
    u_cell: np.ndarray,
    grad_exact: Callable[[np.ndarray], np.ndarray],
    material: Material,
    degree: int = 10,
    curved: tuple[np.ndarray, np.ndarray] | None = None,
) -> np.ndarray:
    """Per-cell squared energy error ``a_T(e, e)``, ``e = u - u_h``.

    ``a_T(e, e) = int_T lam (div e)^2 + 2 mu eps(e) : eps(e)``.

    Parameters
    ----------
    vertices : ndarray of float, shape (m, 3, 2)
    u_cell : ndarray of float, shape (m, 12)
        Interleaved coefficients of ``u_h`` on each cell.
    grad_exact : callable
        ``grad_exact(x)`` with ``x (m, 2)`` returns ``grad u (m, 2, 2)``,
        ``[..., i, j] = d u_i / d x_j``.
    material : Material
    degree : int, optional
        Quadrature degree on each cell.
    curved : (cells (k,), nodes (k, 6, 2)), optional
        Isoparametric cells (:attr:`~signorini.fem.space.P2Space.curved`), integrated on
        their quadratic maps (the same for the other norms).

    Returns
    -------
    ndarray of float64, shape (m,)
        Non-negative; the energy error is ``sqrt(sum)``.
    """
    lam, mu = material.lam, material.mu

    def density(ge: np.ndarray) -> np.ndarray:
        e00 = ge[:, 0, 0]
        e11 = ge[:, 1, 1]
        e01 = 0.5 * (ge[:, 0, 1] + ge[:, 1, 0])
        return lam * (e00 + e11) ** 2 + 2.0 * mu * (e00**2 + e11**2 + 2.0 * e01**2)

    return _grad_error_loop(vertices, u_cell, grad_exact, degree, density, curved)


def h1_seminorm_error2(
    vertices: np.ndarray,
    u_cell: np.ndarray,
    grad_exact: Callable[[np.ndarray], np.ndarray],
    degree: int = 10,
    curved: tuple[np.ndarray, np.ndarray] | None = None,
) -> np.ndarray:
    """Per-cell squared H^1 seminorm error ``int_T |grad(u - u_h)|^2``.

    Parameters
    ----------
    vertices : ndarray of float, shape (m, 3, 2)
    u_cell : ndarray of float, shape (m, 12)
    grad_exact : callable
        ``grad_exact(x)`` with ``x (m, 2)`` returns ``(m, 2, 2)``.
    degree : int, optional

    Returns
    -------
    ndarray of float64, shape (m,)
    """
    return _grad_error_loop(
        vertices, u_cell, grad_exact, degree, lambda ge: np.einsum("mij,mij->m", ge, ge), curved
    )


def l2_error2(
    vertices: np.ndarray,
    u_cell: np.ndarray,
    u_exact: Callable[[np.ndarray], np.ndarray],
    degree: int = 10,
    curved: tuple[np.ndarray, np.ndarray] | None = None,
) -> np.ndarray:
    """Per-cell squared L^2 error ``int_T |u - u_h|^2``.

    Parameters
    ----------
    vertices : ndarray of float, shape (m, 3, 2)
    u_cell : ndarray of float, shape (m, 12)
    u_exact : callable
        ``u_exact(x)`` with ``x (m, 2)`` returns ``(m, 2)``.
    degree : int, optional

    Returns
    -------
    ndarray of float64, shape (m,)
    """
    u, _, det, xi, w, point = _error_setup(vertices, u_cell, degree)
    # u_h at all points: (m, 2, 6) @ (6, q) -> (m, 2, q)
    uh = np.matmul(np.swapaxes(u.reshape(-1, 6, 2), 1, 2), p2.basis(xi).T)
    out = np.zeros(det.shape[0])
    for p in range(w.size):
        d = np.asarray(u_exact(point(p)), dtype=np.float64) - uh[:, :, p]
        out += w[p] * np.einsum("mi,mi->m", d, d)
    out *= det
    if curved is not None:
        cells, nodes = curved
        out[cells] = iso.l2_errors(nodes, u[cells], u_exact, degree)
    return out
