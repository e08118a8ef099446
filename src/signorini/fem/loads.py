"""Load vectors of the functional ``L(v) = int_Omega f . v dx + int_{Gamma_N} g . v ds``
(paper, Section 2).

The data ``f`` and ``g`` are called here as they are given: callers pass functions whose
output has been checked (:func:`signorini.problem.fields.evaluate_field`).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from .element import P2, Element
from .mapping import CellMap, Facets, QuadraticFacets, StraightFacets
from .quadrature import line_rule, triangle_rule

__all__ = ["assemble_body_force", "assemble_facet_load"]


def assemble_body_force(
    cells: CellMap | np.ndarray,
    cell_dofs: np.ndarray,
    n_dofs: int,
    f: Callable[[np.ndarray], np.ndarray],
    degree: int = 6,
    element: Element = P2,
) -> np.ndarray:
    """Load vector of a body force, ``F[2 z + c] = int_Omega f_c psi_z dx``.

    Parameters
    ----------
    cells : CellMap or ndarray of float, shape (m, 3, 2)
        The cells' geometry (:attr:`~signorini.fem.space.P2Space.mapping`; isoparametric
        cells are integrated on their quadratic maps), or the vertices of straight cells.
    cell_dofs : ndarray of int, shape (m, 12)
        Interleaved global DOFs.
    n_dofs : int
    f : callable
        ``f(x)`` with ``x (m, q, 2)`` (every cell's points, in one call) returns the force
        density, shape ``(m, q, 2)`` (or anything broadcastable to it, e.g. a constant
        ``(2,)``).
    degree : int, optional
        Quadrature degree on each cell (exact for ``f`` polynomial of degree
        ``degree - 2`` on straight cells).
    element : Element, optional
        The element of the DOFs (P2, the default, or P1 with ``cell_dofs (m, 6)``).

    Returns
    -------
    ndarray of float64, shape (n_dofs,)
    """
    mapping = cells if isinstance(cells, CellMap) else CellMap(cells)
    xi, w = triangle_rule(degree)
    x = mapping.points(xi)
    fx = np.broadcast_to(np.asarray(f(x), dtype=np.float64), x.shape)
    phi = element.basis(xi)  # (q, n_local)
    local = mapping.per_cell(
        lambda g: np.einsum("qa,mqc,mq->mac", phi, fx[g.cells], g.measure(w, xi))
    )
    return np.bincount(np.ravel(cell_dofs), weights=local.ravel(), minlength=n_dofs)


def assemble_facet_load(
    facets: Facets | np.ndarray,
    facet_dofs: np.ndarray,
    n_dofs: int,
    g: Callable[[np.ndarray, np.ndarray], np.ndarray],
    degree: int = 6,
    element: Element = P2,
) -> np.ndarray:
    """Load vector of boundary tractions, ``G[2 z + c] = int_{Gamma_N} g_c psi_z ds``.

    Parameters
    ----------
    facets : StraightFacets, QuadraticFacets or ndarray of float, shape (k, 2, 2)
        The boundary facets' geometry (edges in 2D; :mod:`signorini.fem.mapping`):
        straight, or the quadratics ``x(t)`` through start, midpoint (on the curve) and end;
        an array is the (start, end) of straight edges. Start to end runs in the
        counter-clockwise order of the facet's cell (so the normal is outward).
    facet_dofs : ndarray of int, shape (k, 6)
        Interleaved DOFs of the facet's P2 nodes in the order (start, end, midpoint).
    n_dofs : int
    g : callable
        ``g(x, normal)`` with points ``x (k, q, 2)`` and outward unit normals
        ``normal (k, 1, 2)`` on straight edges, ``(k, q, 2)`` on quadratic ones, returns the
        traction, shape ``(k, q, 2)`` (or broadcastable to it).
    degree : int, optional
        Gauss-Legendre degree along each facet (exact for ``g`` polynomial of
        degree ``degree - 2`` on straight edges); the integral is
        ``int_0^1 g psi |x'(t)| dt``.
    element : Element, optional
        The element of the DOFs (P2, the default, or P1 with ``facet_dofs (k, 4)``
        of ``(start, end)`` on straight edges).

    Returns
    -------
    ndarray of float64, shape (n_dofs,)
    """
    if not isinstance(facets, StraightFacets | QuadraticFacets):
        facets = StraightFacets(facets)
    t, w = line_rule(degree)
    x = facets.points(t)
    gx = np.broadcast_to(np.asarray(g(x, facets.normals(t)), dtype=np.float64), x.shape)
    ds = np.broadcast_to(facets.speeds(t) * w, x.shape[:2])
    local = np.einsum("qa,kqc,kq->kac", element.facet.basis(t), gx, ds)
    return np.bincount(np.ravel(facet_dofs), weights=local.ravel(), minlength=n_dofs)
