r"""Panels: sub-intervals of the pieces of S, their geometry, and ``∫ |x − y|^{-2}`` in closed form.

A *panel* is the part ``u ∈ [u_0, u_1] ⊂ [0, 1]`` of a piece of S
(:class:`.pieces.PositivePartPieces`); the pair integrals subdivide pieces into panels
until a rule applies (:mod:`.subdivision`). This module holds what the rules need to
know about a panel: its end points and nodes, the values of v there, distances between
panels, whether two panels touch, and the analytic inner integral over a straight
segment (:func:`segment_inverse_square_integral`).
"""

from __future__ import annotations

import numpy as np

from ...fem.edge_trace import evaluate
from . import parameters
from .pieces import PositivePartPieces

__all__ = ["segment_inverse_square_integral"]


def segment_inverse_square_integral(x, a, b) -> np.ndarray:
    """``∫_{[a, b]} |x - y|^{-2} ds_y`` in closed form.

    Equal to ``L θ / |(a - x) × (b - x)|`` where ``L = |b - a|`` and ``θ`` is
    the angle subtended by the segment at ``x``; for ``x`` on the line of the
    segment (outside it) this is ``1/(ξ - L) - 1/ξ`` (``ξ`` = signed position
    along the segment), evaluated without cancellation.

    Parameters
    ----------
    x : array_like of float64, shape (..., 2)
        Evaluation points.
    a, b : array_like of float64, shape (..., 2)
        Segment end points, broadcast against ``x``.

    Returns
    -------
    ndarray of float64, shape (...)
        The integral; ``inf`` for points on the closed segment.
    """
    x = np.asarray(x, dtype=np.float64)
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    if x.shape[-1:] != (2,) or a.shape[-1:] != (2,) or b.shape[-1:] != (2,):
        raise ValueError("x, a and b must have a last axis of length 2")
    return inverse_square_integral(x, a, b)


def inverse_square_integral(x: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """:func:`segment_inverse_square_integral` on trusted float64 arrays."""
    ax0, ax1 = a[..., 0] - x[..., 0], a[..., 1] - x[..., 1]
    bx0, bx1 = b[..., 0] - x[..., 0], b[..., 1] - x[..., 1]
    cr = np.abs(ax0 * bx1 - ax1 * bx0)
    dt = ax0 * bx0 + ax1 * bx1
    length = np.hypot(b[..., 0] - a[..., 0], b[..., 1] - a[..., 1])
    with np.errstate(divide="ignore", invalid="ignore"):
        r = cr / dt
        small = (dt > 0.0) & (r < parameters.SERIES_SWITCH)
        r2 = r * r
        series = (1.0 - r2 * (1.0 / 3.0 - r2 * (1.0 / 5.0 - r2 / 7.0))) / dt
        out = np.where(small, series, np.arctan2(cr, dt) / cr)
    return length * out


# --------------------------------------------------------------------------- panels


def panel_points(pc: PositivePartPieces, idx: np.ndarray, u: np.ndarray):
    """End points ``(n, 2)`` and ``(n, 2)`` of the panels ``u (n, 2)`` of pieces ``idx (n,)``."""
    A, B = pc.start[idx], pc.end[idx]
    return A * (1.0 - u[:, :1]) + B * u[:, :1], A * (1.0 - u[:, 1:]) + B * u[:, 1:]


def panel_nodes(pc: PositivePartPieces, idx: np.ndarray, u: np.ndarray, t: np.ndarray):
    """Coordinates ``x, y (n, q)`` and values ``v (n, q)`` at local nodes ``t (q,)``."""
    uu = u[:, :1] + (u[:, 1:] - u[:, :1]) * t
    A = pc.start[idx]
    D = pc.end[idx] - A
    return A[:, :1] + D[:, :1] * uu, A[:, 1:] + D[:, 1:] * uu, evaluate(pc.coef[idx], uu)


def panel_lengths(pc: PositivePartPieces, idx: np.ndarray, u: np.ndarray) -> np.ndarray:
    """``(n,)`` lengths of the panels ``u (n, 2)`` of pieces ``idx``."""
    return (u[:, 1] - u[:, 0]) * pc.length[idx]


def expansion(pc: PositivePartPieces, idx: np.ndarray, u: np.ndarray, at_end: np.ndarray):
    """A panel seen from its touching end ``c``.

    Returns its length, ``v(c)``, the coefficients ``p1, p2`` of
    ``v(c + t d) = v(c) + p1 t + p2 t²`` (``t`` = distance from ``c``) and the unit
    direction ``d (n, 2)`` pointing into the panel.
    """
    lpc = pc.length[idx]
    uc = np.where(at_end, u[:, 1], u[:, 0])
    sigma = np.where(at_end, -1.0, 1.0)
    c0, c1, c2 = pc.coef[idx].T
    vc = evaluate(pc.coef[idx], uc[:, None])[:, 0]
    p1 = sigma * (c1 + 2.0 * c2 * uc) / lpc
    p2 = c2 / lpc**2
    d = sigma[:, None] * (pc.end[idx] - pc.start[idx]) / lpc[:, None]
    return (u[:, 1] - u[:, 0]) * lpc, vc, p1, p2, d


def _point_segment_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    d = b - a
    dd = np.einsum("ij,ij->i", d, d)
    t = np.einsum("ij,ij->i", p - a, d) / np.where(dd > 0.0, dd, 1.0)
    t = np.clip(t, 0.0, 1.0)
    return np.hypot(*(p - a - t[:, None] * d).T)


def segment_distance(a1, b1, a2, b2) -> np.ndarray:
    """Distance between non-crossing segments ``[a1, b1]`` and ``[a2, b2]`` (row by row)."""
    return np.minimum.reduce(
        [
            _point_segment_distance(a1, a2, b2),
            _point_segment_distance(b1, a2, b2),
            _point_segment_distance(a2, a1, b1),
            _point_segment_distance(b2, a1, b1),
        ]
    )


def touching_ends(a1, b1, a2, b2, tol: float):
    """Whether two segments share an end point, and which end of each (True = end)."""
    dists = np.stack(
        [
            np.hypot(*(a1 - a2).T),
            np.hypot(*(a1 - b2).T),
            np.hypot(*(b1 - a2).T),
            np.hypot(*(b1 - b2).T),
        ],
        axis=1,
    )
    k = dists.argmin(axis=1)
    touching = dists[np.arange(k.size), k] <= tol
    return touching, k >= 2, (k % 2) == 1


def cut_at_touch(u: np.ndarray, at_end: np.ndarray, frac: np.ndarray):
    """Cut panels ``u (n, 2)`` at relative length ``frac`` from their touching end."""
    width = u[:, 1] - u[:, 0]
    cut = np.where(at_end, u[:, 1] - width * frac, u[:, 0] + width * frac)
    return np.stack([u[:, 0], cut], axis=1), np.stack([cut, u[:, 1]], axis=1)


def split_half(u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The two halves of panels ``u (n, 2)``."""
    mid = 0.5 * (u[:, 0] + u[:, 1])
    return np.stack([u[:, 0], mid], axis=1), np.stack([mid, u[:, 1]], axis=1)


def far_order(ratio: np.ndarray) -> np.ndarray:
    """Gauss points per pair from the separation ratio, ``parameters.FAR_TIERS`` (0 = too close)."""
    order = np.zeros(ratio.shape, dtype=np.int64)
    for min_ratio, n in reversed(parameters.FAR_TIERS):
        order[ratio >= min_ratio] = n
    return order
