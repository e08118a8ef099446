"""The P2 function on a triangular face as a bivariate quadratic in the reference coordinates
``s = (s₁, s₂)``: its monomial form, values, restriction to lines, critical point, range on
triangles and roots along sides (the face's analogue of :mod:`signorini.fem.edge_trace`;
docs/method.md, *Three dimensions: positive parts on faces and η7 on surfaces*).

Coefficients ``c (n, 6)`` of ``v(s) = c₀ + c₁ s₁ + c₂ s₂ + c₃ s₁² + c₄ s₁ s₂ + c₅ s₂²``, one
row per face or per cell of a face; points ``(n, r, 2)``, one row per cell.
"""

from __future__ import annotations

import numpy as np

from ...fem.edge_trace import roots_in_unit_interval
from ...fem.p2 import REFERENCE_NODES

__all__ = [
    "along",
    "barycentric_in",
    "cross",
    "face_monomials",
    "interior_critical",
    "norm",
    "range_on_triangles",
    "side_root",
    "value",
]

#: the monomials 1, s₁, s₂, s₁², s₁s₂, s₂² at the six nodes; its inverse maps nodal values to
#: the monomial coefficients of the P2 function (integers; rounded so that they are exact)
_MONOMIALS_AT_NODES = np.column_stack(
    [
        np.ones(6),
        *REFERENCE_NODES.T,
        REFERENCE_NODES[:, 0] ** 2,
        np.prod(REFERENCE_NODES, axis=1),
        REFERENCE_NODES[:, 1] ** 2,
    ]
)
_NODAL_TO_MONOMIAL = np.rint(np.linalg.inv(_MONOMIALS_AT_NODES))
_NODAL_TO_MONOMIAL.setflags(write=False)


def face_monomials(v: np.ndarray) -> np.ndarray:
    """``(k, 6)`` coefficients of ``v(s) = c₀ + c₁ s₁ + c₂ s₂ + c₃ s₁² + c₄ s₁ s₂ + c₅ s₂²``
    from the P2 nodal values ``v (k, 6)`` (vertices, then side midpoints)."""
    return np.asarray(v, dtype=np.float64) @ _NODAL_TO_MONOMIAL.T


def value(c: np.ndarray, s: np.ndarray) -> np.ndarray:
    """``v(s) (n, r)`` for coefficients ``c (n, 6)`` and points ``s (n, r, 2)``."""
    c = c[:, None, :]
    x, y = s[..., 0], s[..., 1]
    return (
        c[..., 0]
        + x * (c[..., 1] + c[..., 3] * x + c[..., 4] * y)
        + y * (c[..., 2] + c[..., 5] * y)
    )


def along(c: np.ndarray, p: np.ndarray, d: np.ndarray) -> np.ndarray:
    """``(n, r, 3)``: ``(a, b, q)`` of ``v(p + t d) = a + b t + q t²`` for coefficients
    ``c (n, 6)``, points ``p (n, r, 2)`` (or ``(n, 1, 2)``) and directions ``d (n, r, 2)``."""
    a = value(c, p)
    c = c[:, None, :]
    x, y, dx, dy = p[..., 0], p[..., 1], d[..., 0], d[..., 1]
    gx = c[..., 1] + 2.0 * c[..., 3] * x + c[..., 4] * y
    gy = c[..., 2] + c[..., 4] * x + 2.0 * c[..., 5] * y
    q = c[..., 3] * dx * dx + c[..., 4] * dx * dy + c[..., 5] * dy * dy
    return np.stack(np.broadcast_arrays(a, gx * dx + gy * dy, q), axis=-1)


def interior_critical(c: np.ndarray) -> np.ndarray:
    """``(k, 2)`` the point where ``∇v = 0``, NaN where the Hessian is singular."""
    det = 4.0 * c[:, 3] * c[:, 5] - c[:, 4] ** 2
    with np.errstate(divide="ignore", invalid="ignore"):
        x = (c[:, 4] * c[:, 2] - 2.0 * c[:, 5] * c[:, 1]) / det
        y = (c[:, 4] * c[:, 1] - 2.0 * c[:, 3] * c[:, 2]) / det
    point = np.column_stack([x, y])
    point[det == 0.0] = np.nan
    return point


def range_on_triangles(
    c: np.ndarray, critical: np.ndarray, corners: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The least and largest value of ``v`` on each triangle ``corners (n, 3, 2)``: at the
    corners, the critical points on the sides and the interior critical point if inside."""
    side = np.roll(corners, -1, axis=1) - corners  # side j from corner j to corner j + 1
    a, b, q = np.moveaxis(along(c, corners, side), -1, 0)  # (n, 3) each
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(q != 0.0, -b / np.where(q != 0.0, 2.0 * q, 1.0), -1.0)
    on_side = np.where((t > 0.0) & (t < 1.0), a + t * (b + t * q), a)  # a corner where none
    inside = np.all(barycentric_in(corners, critical) >= 0.0, axis=1)  # False with NaN
    at = np.where(inside, value(c, np.nan_to_num(critical)[:, None])[:, 0], a[:, 0])
    values = np.column_stack([a, on_side, at])
    return values.min(axis=1), values.max(axis=1)


def barycentric_in(corners: np.ndarray, point: np.ndarray) -> np.ndarray:
    """``(n, 3)`` barycentric coordinates of ``point (n, 2)`` in the triangles ``corners``."""
    e1, e2 = corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]
    r = point - corners[:, 0]
    det = cross(e1, e2)
    with np.errstate(divide="ignore", invalid="ignore"):  # a degenerate triangle: NaN
        l1, l2 = cross(r, e2) / det, cross(e1, r) / det
        return np.column_stack([1.0 - l1 - l2, l1, l2])


def cross(u: np.ndarray, w: np.ndarray) -> np.ndarray:
    """The scalar cross product ``u₁ w₂ − u₂ w₁`` over the last axis."""
    return u[..., 0] * w[..., 1] - u[..., 1] * w[..., 0]


def norm(d: np.ndarray) -> np.ndarray:
    """The length of vectors ``d (..., 2)``."""
    return np.hypot(d[..., 0], d[..., 1])


def side_root(cf: np.ndarray, p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """``(n,)`` the root in [0, 1] of ``v(p + t (q − p))`` where ``v(p)`` and ``v(q)`` differ
    in sign (one of them may be 0): closed form, the chord's root where round-off hides it."""
    coef = along(cf, p[:, None], (q - p)[:, None])[:, 0]
    roots = roots_in_unit_interval(coef)
    a, end = coef[:, 0], coef.sum(axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        chord = np.clip(np.nan_to_num(a / (a - end), nan=0.0), 0.0, 1.0)
    found = ~np.isnan(roots).all(axis=1)
    return np.where(found, np.nanmin(np.where(found[:, None], roots, 0.0), axis=1), chord)
