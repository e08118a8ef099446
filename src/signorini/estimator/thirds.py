"""Integrals over the thirds of contact facets (edges in 2D): η6's ``∫_{γ̃_p} v⁺ φ_p ds``
(paper (4.12); docs/method.md, *Estimator*) and η8's friction work defect ``∫_{γ̃_p} (max(b,
|p_t|) |u_t| − p_t u_t) ds`` (docs/method.md, *Estimator*, "With friction"), on straight
facets exactly and along quadratic facets with ``|x'(t)|`` (docs/method.md, *Estimator*, "On
curved boundaries")."""

from __future__ import annotations

import numpy as np

from ..fem.edge_trace import evaluate, monomial_coefficients, roots_in_unit_interval
from ..fem.element import P2
from ..fem.mapping import Facets, QuadraticFacets, StraightFacets
from ..fem.quadrature import gauss_legendre

__all__ = ["CURVED_THIRD_POINTS", "friction_work_thirds", "third_integrals"]

#: Gauss points per sub-interval of η6's integrals along a quadratic facet, where ``|x'(t)|``
#: makes the integrand non-polynomial (it is nearly constant: 5 points, degree 9)
CURVED_THIRD_POINTS = 5

#: sub-intervals of [0, 1] where a half-edge hat φ of Q^h (3.6) is linear:
#: ``(lo, hi, column, (φ(0), φ'))`` with column 0, 1, 2 = start, end, midpoint (P2's pieces;
#: an element states its own, :class:`~signorini.fem.facet_element.FacetElement`)
_HAT_PIECES = P2.facet.hat_pieces


def third_integrals(
    v: np.ndarray,
    measure: np.ndarray,
    points: np.ndarray | None = None,
    pieces: tuple = _HAT_PIECES,
) -> np.ndarray:
    """∫ v⁺ φ_p over the thirds γ̃_p of each facet (docs/method.md, *Estimator*, paper (4.12)).

    Exact on straight facets: each linear piece of φ is cut at the roots of v, and on each
    sub-interval the product of the quadratic and the linear hat is integrated by a 3-point
    Gauss rule (degree 5 ≥ 3). Along quadratic facets (``points`` given) the integrand also
    carries ``|x'(t)|`` (the square root of a quadratic, not a polynomial) and
    ``CURVED_THIRD_POINTS`` Gauss points are used on each sub-interval.

    Parameters
    ----------
    v : (k, 3) float array
        A quadratic on each facet, by its values at ``[start, end, midpoint]``.
    measure : (k,) float array or StraightFacets or QuadraticFacets
        Facet measures h_F = |F| (edge lengths in 2D; not used with ``points``), or the
        facets' geometry
        (:mod:`signorini.fem.mapping`).
    points : (k, 3, 2) float array, optional
        Node points ``[start, end, midpoint]`` of quadratic facets ``x(t)``.
    pieces : tuple, optional
        The pieces γ̃_p and hats of the element (:attr:`~signorini.fem.facet_element.
        FacetElement.hat_pieces`): P2's thirds (default) or P1's halves (column 2 then stays 0).

    Returns
    -------
    (k, 3) float array
        ``[∫_{start third} v⁺ φ_start, ∫_{end third} v⁺ φ_end, ∫_{middle third} v⁺ φ_mid]``
        where φ are the half-edge hats of Q^h (3.6).
    """
    v = np.asarray(v, dtype=np.float64)
    measure, facets = _geometry(measure, points)
    coef = monomial_coefficients(v)
    roots = roots_in_unit_interval(coef)  # (k, 2), NaN where none
    gt, gw = gauss_legendre(_points(facets))
    out = np.zeros(v.shape)
    for lo, hi, col, (p0, p1) in pieces:
        r = np.where(np.isnan(roots), lo, np.clip(roots, lo, hi))
        bounds = np.sort(np.column_stack([np.full(len(v), lo), r, np.full(len(v), hi)]), axis=1)
        for j in range(3):
            x0, x1 = bounds[:, j : j + 1], bounds[:, j + 1 : j + 2]
            tq = x0 + (x1 - x0) * gt
            vq = evaluate(coef, tq)
            hat = p0 + p1 * tq
            if facets is not None:
                hat = hat * facets.speed_at(tq)
            out[:, col] += (x1 - x0)[:, 0] * (gw * np.maximum(vq, 0.0) * hat).sum(axis=1)
    if facets is not None:
        return out
    return out * np.asarray(measure)[:, None]


#: the thirds of [0, 1] as ``(lo, hi, column)``, column 0, 1, 2 = start, end, midpoint
_THIRDS = P2.facet.node_parts


def friction_work_thirds(
    slip: np.ndarray,
    force: np.ndarray,
    bound: np.ndarray,
    measure: np.ndarray,
    points: np.ndarray | None = None,
    parts: tuple = _THIRDS,
) -> np.ndarray:
    """``∫ (max(b, |p_t|) |u_t| − p_t u_t) ds`` over each third of each facet (η8); over
    each half with P1's ``parts`` (:attr:`~signorini.fem.facet_element.FacetElement.node_parts`).

    The three quadratics are given by their values at ``[start, end, midpoint]``. Each third
    is cut at the roots of ``u_t``, ``p_t − b`` and ``p_t + b``, so that on each piece the
    integrand is one polynomial of degree 4 and the 3-point Gauss rule (degree 5) is exact.
    Along quadratic facets (``points`` given) the integrand carries ``|x'(t)|`` and
    ``CURVED_THIRD_POINTS`` Gauss points are used on each piece.

    Parameters
    ----------
    slip : (k, 3) float array
        ``u_t`` (displacement).
    force : (k, 3) float array
        ``p_t`` (stress).
    bound : (k, 3) float array
        ``b``, the slip bound (stress).
    measure : (k,) float array or StraightFacets or QuadraticFacets
        Facet measures h_F = |F| (edge lengths in 2D; not used with ``points``), or the
        facets' geometry
        (:mod:`signorini.fem.mapping`).
    points : (k, 3, 2) float array, optional
        Node points ``[start, end, midpoint]`` of quadratic facets ``x(t)``.

    Returns
    -------
    (k, 3) float array
        The integrals over the start, end and middle thirds: each ``≥ 0`` (the integrand
        is, pointwise).
    """
    measure, facets = _geometry(measure, points)
    cu, cp, cb = (
        monomial_coefficients(np.asarray(v, dtype=np.float64)) for v in (slip, force, bound)
    )
    roots = np.column_stack([roots_in_unit_interval(c) for c in (cu, cp - cb, cp + cb)])
    gt, gw = gauss_legendre(_points(facets))
    out = np.zeros(cu.shape)
    for lo, hi, col in parts:
        r = np.where(np.isnan(roots), lo, np.clip(roots, lo, hi))
        ends = np.sort(np.column_stack([np.full(len(cu), lo), r, np.full(len(cu), hi)]), axis=1)
        for j in range(ends.shape[1] - 1):
            x0, x1 = ends[:, j : j + 1], ends[:, j + 1 : j + 2]
            tq = x0 + (x1 - x0) * gt
            u, p, b = evaluate(cu, tq), evaluate(cp, tq), evaluate(cb, tq)
            work = np.maximum(np.maximum(b, np.abs(p)) * np.abs(u) - p * u, 0.0)
            if facets is not None:
                work = work * facets.speed_at(tq)
            out[:, col] += (x1 - x0)[:, 0] * (gw * work).sum(axis=1)
    if facets is not None:
        return out
    return out * np.asarray(measure)[:, None]


def _geometry(
    measure: np.ndarray | Facets, points: np.ndarray | None
) -> tuple[np.ndarray | None, QuadraticFacets | None]:
    """``(lengths, None)`` for straight facets (their constant ``|x'(t)|`` multiplies the
    integrals once), ``(None, facets)`` for quadratic ones (``|x'(t)|`` at every point)."""
    if isinstance(measure, StraightFacets):
        return measure.length, None
    if isinstance(measure, QuadraticFacets):
        return None, measure
    return (measure, None) if points is None else (None, QuadraticFacets(points))


def _points(facets: QuadraticFacets | None) -> int:
    """Gauss points per piece: 3 (exact) on straight facets, ``CURVED_THIRD_POINTS`` along
    quadratic ones, where ``|x'(t)|`` makes the integrand non-polynomial."""
    return 3 if facets is None else CURVED_THIRD_POINTS
