"""The trace of a P2 function on a straight edge: one quadratic per edge.

An edge is parametrised by ``t ∈ [0, 1]`` (``t = 0`` its start, ``t = 1`` its end). A P2
function restricted to it is the quadratic through its values at the edge's three nodes,
taken in the package's edge-node order ``[start, end, midpoint]`` (``P2Space.facet_nodes``,
``ContactSet.facet_nodes``, :func:`signorini.fem.p2.edge_basis`, meshio ``line3``;
docs/method.md, *Data conventions*). This module is the one owner of that quadratic's monomial
form, its values, its maximum on [0, 1] and its sign-changing roots in (0, 1); the estimator's
η6 and η7 (paper, Section 5) work with nothing else.

It keeps the edge's name: it is a 2D kernel, a univariate quadratic on one edge parameter
(a 2D facet is an edge). A 3D face carries a bivariate quadratic on two parameters, which
gets its own module rather than a door here.
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "TANGENT_TOL",
    "evaluate",
    "maximum_on_unit_interval",
    "monomial_coefficients",
    "roots_in_unit_interval",
]

#: a root is taken as double (a tangency, no sign change) when the quadratic's value at
#: its vertex is below this, relative to its largest coefficient: a sliver of that height
#: is below round-off of the nodal values, and cutting there would only create slivers
TANGENT_TOL = 1e-13


def monomial_coefficients(values: np.ndarray) -> np.ndarray:
    """Coefficients ``[a, b, c]`` of ``v(t) = a + b t + c t²`` from the nodal values.

    Parameters
    ----------
    values : (k, 3) float array
        ``v`` at ``[start, end, midpoint]`` of each edge.

    Returns
    -------
    (k, 3) float array
        ``[v_s, −3 v_s + 4 v_m − v_e, 2 v_s − 4 v_m + 2 v_e]``.
    """
    v0, v1, vm = values[:, 0], values[:, 1], values[:, 2]
    return np.stack([v0, -3.0 * v0 + 4.0 * vm - v1, 2.0 * v0 - 4.0 * vm + 2.0 * v1], axis=1)


def evaluate(coef: np.ndarray, t: np.ndarray) -> np.ndarray:
    """``a + t (b + t c)`` row by row.

    Parameters
    ----------
    coef : (k, 3) float array
        Monomial coefficients (:func:`monomial_coefficients`).
    t : (k, q) float array
        Parameters, one row per edge.

    Returns
    -------
    (k, q) float array
    """
    return coef[:, :1] + t * (coef[:, 1:2] + t * coef[:, 2:3])


def maximum_on_unit_interval(values: np.ndarray, coef: np.ndarray) -> np.ndarray:
    """The largest value of each quadratic on [0, 1].

    Parameters
    ----------
    values : (k, 3) float array
        Nodal values ``[start, end, midpoint]``.
    coef : (k, 3) float array
        The same quadratics in monomial form.

    Returns
    -------
    (k,) float array
        The maximum of the nodal values and, for a concave quadratic with its vertex inside
        (0, 1), of the value there.
    """
    a, b, c = coef.T
    with np.errstate(divide="ignore", invalid="ignore"):
        vertex = np.where(c < 0.0, -b / np.where(c < 0.0, 2.0 * c, 1.0), -1.0)
    inner = (vertex > 0.0) & (vertex < 1.0)
    at_vertex = np.where(inner, a + vertex * (b + vertex * c), -np.inf)
    return np.maximum(values.max(axis=1), at_vertex)


def roots_in_unit_interval(coef: np.ndarray, snap: np.ndarray | float = 0.0) -> np.ndarray:
    """Sign-changing real roots in ``(snap, 1 − snap)`` of ``a + b t + c t²``.

    The pair is computed without cancellation (``q = −(b + sign(b) √disc)/2``, roots ``q/c``
    and ``a/q``), after scaling each row by its largest coefficient, so a linear or
    nearly linear row loses nothing. Dropped: double roots (:data:`TANGENT_TOL`), roots
    within ``snap`` of an end point and pairs of roots closer than ``snap`` (the sliver
    between them does not change sign at the resolution ``snap``).

    Parameters
    ----------
    coef : (k, 3) float array
        Monomial coefficients.
    snap : float or (k,) float array
        Resolution in ``t``; ``0.0`` keeps every simple root in the open interval.

    Returns
    -------
    (k, 2) float array
        The roots, NaN where there is none.
    """
    scale = np.abs(coef).max(axis=1, keepdims=True)
    scale[scale == 0.0] = 1.0
    a, b, c = (coef / scale).T
    disc = b * b - 4.0 * a * c
    sq = np.sqrt(np.maximum(disc, 0.0))
    q = -0.5 * (b + np.copysign(sq, b))
    with np.errstate(divide="ignore", invalid="ignore"):
        r1 = np.where(c != 0.0, q / np.where(c != 0.0, c, 1.0), np.nan)
        r2 = np.where(q != 0.0, a / np.where(q != 0.0, q, 1.0), np.nan)
        # |v| at the vertex of the parabola is |disc / (4 c)|: tiny means a double root
        tangent = (c != 0.0) & (np.abs(disc) <= 4.0 * TANGENT_TOL * np.abs(c))
    roots = np.stack([r1, r2], axis=1)
    roots[(disc < 0.0) | tangent] = np.nan
    snap = np.broadcast_to(np.asarray(snap, dtype=np.float64), a.shape)[:, None]
    roots[~((roots > snap) & (roots < 1.0 - snap))] = np.nan
    roots[np.abs(roots[:, 0] - roots[:, 1]) <= snap[:, 0]] = np.nan
    return roots
