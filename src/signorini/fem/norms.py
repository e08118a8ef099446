"""Per-cell squared errors of a P2 field against a known solution: energy norm ``a(e, e)``,
H^1 seminorm and L^2 norm (the error columns of the paper's Section 6).

The exact solution is called as it is given: callers pass functions whose output has been
checked (:func:`signorini.problem.fields.evaluate_field`).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from . import p2
from .mapping import CellMap, Cells
from .material import CellMaterials, Material, on_cells
from .quadrature import triangle_rule

__all__ = ["energy_error2", "h1_seminorm_error2", "l2_error2"]


def _pointwise(
    cells: CellMap | np.ndarray,
    u_cell: np.ndarray,
    degree: int,
    density: Callable[[Cells, np.ndarray], Callable[[np.ndarray, np.ndarray], np.ndarray]],
) -> np.ndarray:
    """``sum_q w_q det J(xi_q) e(x_q, xi_q)`` per cell with ``e = density(group, u_group)``,
    group by group and one quadrature point at a time (the exact solution is called with
    ``(m, 2)`` points); where ``det J`` is constant on each cell it multiplies the sum once."""
    mapping = cells if isinstance(cells, CellMap) else CellMap(cells)
    u = np.asarray(u_cell, dtype=np.float64)
    xi, w = triangle_rule(degree)

    def integral(g: Cells) -> np.ndarray:
        _, det = g.jacobians(xi)
        constant = det.shape[1] == 1
        error = density(g, u[g.cells])
        out = np.zeros(len(g))
        for p in range(w.size):
            at = xi[p : p + 1]
            value = error(g.points(at)[:, 0], at)
            out += w[p] * value if constant else w[p] * det[:, p] * value
        return out * det[:, 0] if constant else out

    return mapping.per_cell(integral)


def _grad_error_loop(cells, u_cell, grad_exact, degree, density):
    """Sum over quadrature points of density(grad u - grad u_h) * w * det, per cell."""

    def error(g: Cells, u: np.ndarray):
        gradient = g.gradient_field(u)
        return lambda x, xi: density(
            np.asarray(grad_exact(x), dtype=np.float64) - gradient(xi)[:, 0]
        )

    return _pointwise(cells, u_cell, degree, error)


def energy_error2(
    cells: CellMap | np.ndarray,
    u_cell: np.ndarray,
    grad_exact: Callable[[np.ndarray], np.ndarray],
    material: Material | CellMaterials,
    degree: int = 10,
) -> np.ndarray:
    """Per-cell squared energy error ``a_T(e, e)``, ``e = u - u_h``.

    ``a_T(e, e) = int_T lam (div e)^2 + 2 mu eps(e) : eps(e)``.

    Parameters
    ----------
    cells : CellMap or ndarray of float, shape (m, 3, 2)
        The cells' geometry (:attr:`~signorini.fem.space.P2Space.mapping`), or the vertices
        of straight cells.
    u_cell : ndarray of float, shape (m, 12)
        Interleaved coefficients of ``u_h`` on each cell.
    grad_exact : callable
        ``grad_exact(x)`` with ``x (m, 2)`` returns ``grad u (m, 2, 2)``,
        ``[..., i, j] = d u_i / d x_j``.
    material : Material
    degree : int, optional
        Quadrature degree on each cell.

    Returns
    -------
    ndarray of float64, shape (m,)
        Non-negative; the energy error is ``sqrt(sum)``.
    """

    def error(g: Cells, u: np.ndarray):
        gradient = g.gradient_field(u)
        here = on_cells(material, g.cells)  # one material, or the group's cells' own
        lam, mu = here.lam_eff, here.mu

        def density(x: np.ndarray, xi: np.ndarray) -> np.ndarray:
            ge = np.asarray(grad_exact(x), dtype=np.float64) - gradient(xi)[:, 0]
            e00, e11 = ge[:, 0, 0], ge[:, 1, 1]
            e01 = 0.5 * (ge[:, 0, 1] + ge[:, 1, 0])
            return lam * (e00 + e11) ** 2 + 2.0 * mu * (e00**2 + e11**2 + 2.0 * e01**2)

        return density

    return _pointwise(cells, u_cell, degree, error)


def h1_seminorm_error2(
    cells: CellMap | np.ndarray,
    u_cell: np.ndarray,
    grad_exact: Callable[[np.ndarray], np.ndarray],
    degree: int = 10,
) -> np.ndarray:
    """Per-cell squared H^1 seminorm error ``int_T |grad(u - u_h)|^2``.

    Parameters
    ----------
    cells : CellMap or ndarray of float, shape (m, 3, 2)
        The cells' geometry (:attr:`~signorini.fem.space.P2Space.mapping`), or the vertices
        of straight cells.
    u_cell : ndarray of float, shape (m, 12)
    grad_exact : callable
        ``grad_exact(x)`` with ``x (m, 2)`` returns ``(m, 2, 2)``.
    degree : int, optional

    Returns
    -------
    ndarray of float64, shape (m,)
    """
    return _grad_error_loop(
        cells, u_cell, grad_exact, degree, lambda ge: np.einsum("mij,mij->m", ge, ge)
    )


def l2_error2(
    cells: CellMap | np.ndarray,
    u_cell: np.ndarray,
    u_exact: Callable[[np.ndarray], np.ndarray],
    degree: int = 10,
) -> np.ndarray:
    """Per-cell squared L^2 error ``int_T |u - u_h|^2``.

    Parameters
    ----------
    cells : CellMap or ndarray of float, shape (m, 3, 2)
        The cells' geometry (:attr:`~signorini.fem.space.P2Space.mapping`), or the vertices
        of straight cells.
    u_cell : ndarray of float, shape (m, 12)
    u_exact : callable
        ``u_exact(x)`` with ``x (m, 2)`` returns ``(m, 2)``.
    degree : int, optional

    Returns
    -------
    ndarray of float64, shape (m,)
    """

    def error(g: Cells, u: np.ndarray):
        def squared(x: np.ndarray, xi: np.ndarray) -> np.ndarray:
            d = np.asarray(u_exact(x), dtype=np.float64) - p2.field_values(u, xi)[:, 0]
            return np.einsum("mi,mi->m", d, d)

        return squared

    return _pointwise(cells, u_cell, degree, error)
