r"""Quadrature of the positive set of a quadratic on each triangular face (docs/method.md,
*Three dimensions: positive parts on faces and η7 on surfaces*).

η6 (``∫_{γ̃_p} (ψ_h − u_h·n)⁺ φ_p``, paper (4.12), (5.1)) and η7 (``‖(u_h·n − ψ_h)⁺‖``,
Section 5) integrate the positive part of a P2 function on the faces of Γ_C. On a face
``v`` is a quadratic in the reference coordinates ``s``; its zero set is a conic, with no
closed-form split of the triangle. :func:`positive_region_rule` returns a quadrature of
``{s ∈ T̂ : v(s) > 0}`` on each face, every cell of it inside one of the four triangles of
the once-refined face (corners 0, 1, 2 at the vertices, 3 in the middle), where the P1 hats
of the refined face (:func:`refined_face_hats`, the 3D ``Q^h`` of (4.1)) are linear:

1. **Sign from the extrema, in closed form.** On a triangle the extrema of ``v`` lie at its
   corners, at the critical points of ``v`` along its sides (a quadratic in one variable) or
   at the interior critical point of ``v`` (``∇v = 0``, one per face where the Hessian is
   regular). ``min ≥ 0`` (and ``max > 0``): the cell's exact rule of ``degree``
   (:func:`~signorini.fem.quadrature.triangle_rule`); ``max ≤ 0``: nothing; otherwise the
   sign changes.
2. **Subdivision** of the straddling cells only, by their midpoints into four, ``depth``
   times (vectorized over all straddling cells of a level).
3. **Leaves.** Where one corner ``X`` has the sign opposite to the other two, the zero set
   enters through the roots ``R₁, R₂`` of ``v`` on the two sides at ``X`` (closed form).
   The positive part is a curved triangle with a positive apex and base ``R₁R₂``, plus, when
   ``X`` is negative, the straight triangle between the base's far end and the positive
   side. The curved triangle is integrated along the rays from its apex to the points of
   the chord ``R₁R₂``: on each ray ``v`` is a quadratic in the ray parameter ``t`` and the
   ray ends at its first root ``t*`` (closed form), ``∫ f = |R₁ − X × R₂ − R₁| ∫₀¹ ∫₀^{t*(σ)}
   f t dt dσ``, Gauss–Legendre in ``t`` (exact: the integrand is a polynomial in ``t``) and
   in ``σ`` (``t*(σ) ≡ 1`` for a linear ``v``, so a linear ``v`` is integrated exactly; for
   a quadratic ``t*`` is smooth and close to 1). The leaves that are still not simple (below)
   after ``EXTRA_DEPTH`` further subdivisions take rays from one corner to the opposite
   side, each cut at its (at most two) roots.

A leaf is taken when its arc is *simple*: one corner of the opposite sign, no root on the
side opposite it, no critical point inside, the straight triangle positive, and the arc's
bulge from its chord at most ``ARC_RATIO`` of the apex's distance from the chord; otherwise the
cell is subdivided further, up to ``EXTRA_DEPTH`` more times (near a saddle of ``v``, where
the zero set passes close to a corner or runs along a side).

Accuracy (``tests/estimator3d/test_positive_part.py``, against an independent scan-line
reference converged to 10⁻¹¹): over 600 random quadratics ``v`` with N(0, 1) nodal values
(seed 8, 584 of them changing sign at the nodes), with the defaults (``depth = 1``, 6 extra
points in σ, degree 3), the largest relative errors are 1.7·10⁻⁶ for the area
``∫_{v>0} 1``, 2.4·10⁻⁹ for ``∫_{v>0} v`` and 2.9·10⁻⁹ for ``∫_{v>0} v φ_p``, at 250
points a face (where every face is cut; a face of one sign takes 4 × the triangle rule).
``v⁺`` vanishes on the cut, so the integrals with a factor ``v`` are far less sensitive to
the curve than the area. A linear ``v`` is integrated exactly (the cut polygon, to 10⁻¹²).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ...fem.edge_trace import roots_in_unit_interval
from ...fem.p2 import REFERENCE_NODES, barycentric
from ...fem.quadrature import gauss_legendre, triangle_rule
from .face_quadratic import (
    along,
    barycentric_in,
    cross,
    face_monomials,
    interior_critical,
    norm,
    range_on_triangles,
    side_root,
    value,
)

__all__ = [
    "DEPTH",
    "PIECE_NODES",
    "RAY_POINTS",
    "PositiveRule",
    "face_monomials",
    "positive_region_rule",
    "refined_face_hats",
]

#: the default number of subdivisions of a sub-triangle where ``v`` changes sign before a
#: simple cell is taken as a leaf: 1 (measured: 0 gives 10⁻⁷, 1 gives 3·10⁻⁹ and 2 gives
#: 3·10⁻¹¹ for ``∫ v φ_p``, at 170, 260 and 460 points a cut face)
DEPTH = 1

#: further subdivisions of the cut cells where the zero set is not one simple arc across two
#: sides (:func:`_cut`: near a saddle, an oval, a side cut twice, a strongly bent arc); the
#: leaves then take the rays of step 3 as they are
EXTRA_DEPTH = 6

#: a cut cell is a leaf when its arc's bulge from the chord ``r1 r2`` is at most this share
#: of the apex's distance from the chord: the rays' ``t*(σ)`` then stays within 1 ± 0.1
ARC_RATIO = 0.1

#: Gauss points in σ beyond those that make the rays' rule exact for a linear ``v``: the
#: curved ``t*(σ)`` of a quadratic converges geometrically (measured with depth 1: 2, 4, 6
#: extra points give 2·10⁻⁷, 4·10⁻⁹, 3·10⁻¹⁰ for ``∫ v``)
RAY_POINTS = 6

#: the largest exit parameter ``1/μ`` of a ray (:func:`_curved`), in units of its distance to
#: the chord: its square scales the ray's quadratic and the discriminant squares that again,
#: so 10⁵⁰ keeps every product finite (a root at ``ρ = 10⁻¹⁷`` from the apex overflowed
#: ``1/(1 − (1 − ρ))`` to 10³⁰⁰ and gave infinite weights)
EXIT_BOUND = 1e50

#: the four triangles of the once-refined face by local nodes (P2 order: vertices, then the
#: midpoints of local edges 0 (v0–v1), 1 (v1–v2), 2 (v2–v0)): corner p is ``[p, midpoint of
#: edge p, midpoint of edge p − 1]``, the middle one the three midpoints; all counter-clockwise
PIECE_NODES = np.array(
    [[p, 3 + p, 3 + (p - 1) % 3] for p in range(3)] + [[3, 4, 5]], dtype=np.int64
)
PIECE_NODES.setflags(write=False)

#: the corners of the pieces in reference coordinates, (4, 3, 2)
_PIECE_CORNERS = REFERENCE_NODES[PIECE_NODES]


def _hat_barycentric() -> np.ndarray:
    """``(4, 6, 3)``: on piece p the P1 hat of node a is ``λ(s) · table[p, a]`` (λ the face's
    barycentric coordinates): 1 at node a, 0 at the piece's other corners, 0 if a is not one."""
    table = np.zeros((4, 6, 3))
    for p in range(4):
        corners = barycentric(_PIECE_CORNERS[p])  # (3, 3): rows the corners
        table[p, PIECE_NODES[p]] = np.linalg.inv(corners).T
    table.setflags(write=False)
    return table


_HAT_BARYCENTRIC = _hat_barycentric()


class PositiveRule(NamedTuple):
    """A quadrature of ``{v > 0}`` on each face, in the reference coordinates of the faces.

    ``Σ_{i: face[i] = F} w[i] f(s[i]) ≈ ∫_{T̂ ∩ {v_F > 0}} f(s) ds`` (area of ``T̂`` 1/2);
    on a face of area element ``J(s)`` multiply ``w`` by ``J(s)`` (``2 |F|`` if flat).

    Attributes
    ----------
    face : (m,) int array
        The face of each point, non-decreasing.
    piece : (m,) int array
        The triangle of the once-refined face it lies in (0, 1, 2 the corners, 3 the middle).
    s : (m, 2) float array
        Reference points.
    w : (m,) float array
        Positive weights.
    n_faces : int
        The number of faces (for ``np.bincount(face, ..., minlength=n_faces)``).
    """

    face: np.ndarray
    piece: np.ndarray
    s: np.ndarray
    w: np.ndarray
    n_faces: int


def refined_face_hats(s: np.ndarray, piece: np.ndarray) -> np.ndarray:
    """The P1 hats of the once-refined face at points of its triangles, ``(m, 6)``.

    The hat of a vertex lives on its corner triangle, the hat of a side midpoint on the three
    triangles at it; each is linear there, 1 at its node and 0 at the other corners. Their
    integrals over the face are ``P2_TRIANGLE.hat_share`` × area (``(1/12, …, 1/4, …)``).

    Parameters
    ----------
    s : (m, 2) float array
        Reference points.
    piece : (m,) int array
        The triangle of the once-refined face each lies in (:class:`PositiveRule`).
    """
    s = np.asarray(s, dtype=np.float64)
    return np.einsum("mi,mai->ma", barycentric(s), _HAT_BARYCENTRIC[np.asarray(piece)])


# --------------------------------------------------------------------------- the rule


def positive_region_rule(v: np.ndarray, degree: int, *, depth: int = DEPTH) -> PositiveRule:
    """A quadrature of ``{s ∈ T̂ : v(s) > 0}`` on each face, by the triangles of the
    once-refined face (module notes: sign from the extrema, subdivision where it changes,
    rays at the leaves).

    Parameters
    ----------
    v : (k, 6) float array
        The P2 nodal values of a quadratic on each face (``P2_TRIANGLE``'s order: the
        vertices, then the midpoints of the sides v0–v1, v1–v2, v2–v0).
    degree : int
        Polynomials of this degree are integrated exactly on the cells where ``v`` keeps its
        sign and on the straight parts of the cut cells (``∫ v⁺ φ_p``: 3, ``∫ (v⁺)²``: 4).
    depth : int
        Subdivisions of a sub-triangle where ``v`` changes sign, before the leaves' rays.

    Returns
    -------
    PositiveRule

    Raises
    ------
    ValueError
        If ``v`` is not a finite ``(k, 6)`` array, ``degree`` or ``depth`` not an integer
        ``≥ 0``.
    """
    v = np.asarray(v, dtype=np.float64)
    if v.ndim != 2 or v.shape[1] != 6:
        raise ValueError(f"positive_region_rule: v must have shape (k, 6), got {v.shape}")
    if not np.isfinite(v).all():
        raise ValueError("positive_region_rule: v has non-finite values")
    if isinstance(depth, bool) or not isinstance(depth, int | np.integer) or depth < 0:
        raise ValueError(f"positive_region_rule: depth must be an integer >= 0, got {depth!r}")
    xi, wq = triangle_rule(degree)  # refuses a bad degree
    c = face_monomials(v)
    critical = interior_critical(c)
    face = np.repeat(np.arange(len(v)), 4)
    piece = np.tile(np.arange(4), len(v))
    corners = _PIECE_CORNERS[piece]
    parts = []
    for level in range(depth + EXTRA_DEPTH + 1):
        lo, hi = range_on_triangles(c[face], critical[face], corners)
        full = (lo >= 0.0) & (hi > 0.0)
        parts.append(_triangle_points(face[full], piece[full], corners[full], xi, wq))
        cut = (lo < 0.0) & (hi > 0.0)
        face, piece, corners = face[cut], piece[cut], corners[cut]
        if level >= depth:
            cut = _cut(c, critical, face, corners)
            last = level == depth + EXTRA_DEPTH
            leaf = np.ones(len(face), dtype=bool) if last else cut.simple
            parts.extend(
                _leaf_points(c, face[leaf], piece[leaf], corners[leaf], cut, leaf, degree, (xi, wq))
            )
            face, piece, corners = face[~leaf], piece[~leaf], corners[~leaf]
        face, piece, corners = np.repeat(face, 4), np.repeat(piece, 4), _split(corners)
    f, p, s, w = (np.concatenate(a) for a in zip(*parts, strict=True))
    order = np.argsort(f, kind="stable")
    return PositiveRule(f[order], p[order], s[order], w[order], len(v))


def _triangle_points(face, piece, corners, xi, wq) -> tuple:
    """The triangle rule ``(xi, wq)`` on the triangles ``corners (n, 3, 2)``, flattened."""
    span = corners[:, 1:] - corners[:, :1]
    s = corners[:, :1] + np.einsum("qk,nki->nqi", xi, span)
    w = np.abs(cross(span[:, 0], span[:, 1]))[:, None] * wq
    q = len(wq)
    return np.repeat(face, q), np.repeat(piece, q), s.reshape(-1, 2), w.ravel()


def _split(corners: np.ndarray) -> np.ndarray:
    """``(4 n, 3, 2)``: each triangle cut by its side midpoints, its four children in a row."""
    a, b, c = corners[:, 0], corners[:, 1], corners[:, 2]
    ab, bc, ca = 0.5 * (a + b), 0.5 * (b + c), 0.5 * (c + a)
    children = np.stack(
        [np.stack(t, axis=1) for t in ((a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca))],
        axis=1,
    )
    return children.reshape(-1, 3, 2)


class _Cut(NamedTuple):
    """The zero set's entry into cut cells (step 3): the corners turned so that ``x`` has
    the sign opposite to ``b`` and ``cc``, the roots ``r1 = x + rho1 (b − x)`` and
    ``r2 = x + rho2 (cc − x)``, the positive corners, which diagonal a cell with a negative
    ``x`` is split along (``apex_c``: the straight triangle ``r1 b cc``, else ``b cc r2``),
    and whether the cell is ``simple`` (one arc from ``r1`` to ``r2``, the straight triangle
    positive)."""

    x: np.ndarray
    b: np.ndarray
    cc: np.ndarray
    rho1: np.ndarray
    rho2: np.ndarray
    n_pos: np.ndarray
    apex_c: np.ndarray
    simple: np.ndarray

    def __getitem__(self, rows):  # type: ignore[override]
        return _Cut(*(a[rows] for a in self))


def _cut(c, critical, face, corners) -> _Cut:
    """The entry of the zero set into the cut cells ``corners (n, 3, 2)`` (:class:`_Cut`):
    simple where one corner has the sign opposite to the others, the side opposite it has
    no root, no critical point lies inside, and (a negative corner) one of the two straight
    triangles of the positive quadrilateral is positive throughout."""
    cf = c[face]
    pos = value(cf, corners) > 0.0
    n_pos = pos.sum(axis=1)
    odd = np.where(n_pos == 1, pos.argmax(axis=1), (~pos).argmax(axis=1))
    turn = (odd[:, None] + np.arange(3)) % 3
    x, b, cc = np.moveaxis(np.take_along_axis(corners, turn[..., None], axis=1), 1, 0)
    far = along(cf, b[:, None], (cc - b)[:, None])[:, 0]
    crossed = ~np.isnan(roots_in_unit_interval(far)).all(axis=1)
    inside = np.all(barycentric_in(corners, critical[face]) >= 0.0, axis=1)
    rho1, rho2 = side_root(cf, x, b), side_root(cf, x, cc)
    r1, r2 = x + rho1[:, None] * (b - x), x + rho2[:, None] * (cc - x)
    ok_c = _positive(c, critical, face, np.stack([r1, b, cc], axis=1))
    ok_b = _positive(c, critical, face, np.stack([b, cc, r2], axis=1))
    height = [_height(p, r1, r2) for p in (x, cc, b)]  # the apex's distance from the chord
    apex_c = ok_c & (~ok_b | (height[1] >= height[2]))
    apex = np.where(n_pos == 1, height[0], np.where(apex_c, height[1], height[2]))
    one_arc = ((n_pos == 1) | ((n_pos == 2) & (ok_c | ok_b))) & ~crossed & ~inside
    flat = _sagitta(cf, r1, r2) <= ARC_RATIO * apex
    return _Cut(x, b, cc, rho1, rho2, n_pos, apex_c, one_arc & flat)


def _height(p: np.ndarray, r1: np.ndarray, r2: np.ndarray) -> np.ndarray:
    """``(n,)`` the distance of ``p`` from the line ``r1 r2``."""
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.nan_to_num(np.abs(cross(p - r1, r2 - r1)) / norm(r2 - r1))


def _sagitta(cf: np.ndarray, r1: np.ndarray, r2: np.ndarray) -> np.ndarray:
    """``(n,)`` the distance of the chord's midpoint from the zero set to first order,
    ``|v| / |∇v|`` there (the arc's bulge from its chord)."""
    m = 0.5 * (r1 + r2)[:, None]
    a, bx, _ = np.moveaxis(along(cf, m, np.broadcast_to([1.0, 0.0], m.shape)), -1, 0)
    by = along(cf, m, np.broadcast_to([0.0, 1.0], m.shape))[..., 1]
    with np.errstate(divide="ignore", invalid="ignore"):
        return (np.abs(a) / np.hypot(bx, by))[:, 0]


def _positive(c, critical, face, corners) -> np.ndarray:
    """``(n,)`` whether ``v ≥ 0`` on the triangles ``corners`` (to round-off of its range)."""
    lo, hi = range_on_triangles(c[face], critical[face], corners)
    return lo >= -1e-12 * (np.abs(lo) + np.abs(hi))


def _leaf_points(c, face, piece, corners, cut, rows, degree, rule) -> list[tuple]:
    """The rules of the leaves ``rows`` of the cut cells (module notes, step 3): the simple
    ones by a curved triangle (and a straight one), the others by rays from a corner."""
    xi, wq = rule
    cf = c[face]
    x, b, cc, rho1, rho2, n_pos, apex_c, simple = cut[rows]
    r1, r2 = x + rho1[:, None] * (b - x), x + rho2[:, None] * (cc - x)
    n_t = (degree + 3) // 2  # Gauss points in t: exact for degree + 1 (the Jacobian t)
    one = simple & (n_pos == 1)
    out = [_curved(cf, face, piece, (x, r1, r2), (rho1, rho2), one, n_t)]
    whole = np.ones_like(rho1)
    for choice, tri, ray, mu in (
        (simple & (n_pos == 2) & apex_c, (r1, b, cc), (cc, r2, r1), (1 - rho2, whole)),
        (simple & (n_pos == 2) & ~apex_c, (b, cc, r2), (b, r1, r2), (1 - rho1, whole)),
    ):
        tri = np.stack([p[choice] for p in tri], axis=1)
        out.append(_triangle_points(face[choice], piece[choice], tri, xi, wq))
        out.append(_curved(cf, face, piece, ray, mu, choice, n_t))
    out.append(_rays(cf[~simple], face[~simple], piece[~simple], corners[~simple], n_t))
    return out


def _curved(cf, face, piece, ray, mu, rows, n_t) -> tuple:
    """The curved triangle with positive apex ``X`` and base ``R₁R₂`` along the rays from
    ``X`` to the base, each cut at its first root (module notes, step 3); ``mu`` one minus
    the apex's barycentric coordinate in the leaf at ``R₁`` and ``R₂``, so a ray leaves the
    leaf at ``t = 1/μ``. ``μ`` is passed as such (a root's ``ρ`` itself, not ``1 − (1 − ρ)``)
    and ``1/μ`` held below ``EXIT_BOUND``: for a root at ``ρ → 0`` beside the apex the
    exit lies far out, and its square in the ray's polynomial must stay finite (the ray's
    root ``t ≈ 1`` is found either way; the arc then spans an area of order ``ρ²``)."""
    cf, face, piece = cf[rows], face[rows], piece[rows]
    x, r1, r2 = (p[rows] for p in ray)
    m1, m2 = (m[rows] for m in mu)
    sig, ws = gauss_legendre(n_t + RAY_POINTS)
    tau, wt = gauss_legendre(n_t)
    base = r1[:, None] + sig[:, None] * (r2 - r1)[:, None]  # (n, nσ, 2)
    d = base - x[:, None]
    exit_t = 1.0 / np.maximum((1.0 - sig) * m1[:, None] + sig * m2[:, None], 1.0 / EXIT_BOUND)
    coef = along(cf, x[:, None], d) * np.stack([np.ones_like(exit_t), exit_t, exit_t**2], -1)
    roots = roots_in_unit_interval(coef.reshape(-1, 3)).reshape(coef.shape[:2] + (2,))
    u = np.fmin(np.fmin(roots[..., 0], roots[..., 1]), 1.0)  # NaN-ignoring: 1 where none
    t_end = exit_t * np.where(np.isnan(u), 1.0, u)  # (n, nσ)
    t = t_end[..., None] * tau  # (n, nσ, nτ)
    s = x[:, None, None] + t[..., None] * d[:, :, None]
    jac = np.abs(cross(r1 - x, r2 - r1))
    w = jac[:, None, None] * ws[:, None] * (t_end[..., None] * wt) * t
    q = t.shape[1] * t.shape[2]
    return np.repeat(face, q), np.repeat(piece, q), s.reshape(-1, 2), w.ravel()


def _rays(cf, face, piece, corners, n_t) -> tuple:
    """Leaves whose corners share one sign: rays from corner 0 to the opposite side, each
    cut at its roots, the positive intervals integrated (module notes, step 3)."""
    sig, ws = gauss_legendre(n_t + RAY_POINTS)
    tau, wt = gauss_legendre(n_t)
    x, b, cc = corners[:, 0], corners[:, 1], corners[:, 2]
    d = b[:, None] + sig[:, None] * (cc - b)[:, None] - x[:, None]  # (n, nσ, 2)
    coef = along(cf, x[:, None], d)
    roots = roots_in_unit_interval(coef.reshape(-1, 3)).reshape(coef.shape[:2] + (2,))
    ends = np.sort(
        np.concatenate(
            [
                np.zeros_like(roots[..., :1]),
                np.nan_to_num(roots, nan=1.0),
                np.ones_like(roots[..., :1]),
            ],
            axis=-1,
        ),
        axis=-1,
    )
    jac = np.abs(cross(b - x, cc - b))
    out = []
    for j in range(3):
        t0, t1 = ends[..., j : j + 1], ends[..., j + 1 : j + 2]  # (n, nσ, 1)
        middle = x[:, None] + 0.5 * (t0 + t1) * d
        keep = (value(cf, middle) > 0.0)[..., None] & (t1 > t0)
        t = t0 + (t1 - t0) * tau
        s = x[:, None, None] + t[..., None] * d[:, :, None]
        w = jac[:, None, None] * ws[:, None] * (t1 - t0) * wt * t * keep
        q = t.shape[1] * t.shape[2]
        mask = w.ravel() > 0.0
        out.append(
            (
                np.repeat(face, q)[mask],
                np.repeat(piece, q)[mask],
                s.reshape(-1, 2)[mask],
                w.ravel()[mask],
            )
        )
    return tuple(np.concatenate(a) for a in zip(*out, strict=True))
