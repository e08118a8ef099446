"""The geometry of a mortar contact pair (:mod:`signorini.contact.mortar`): the parts' facets
(edges in 2D: the pairing projects along curves, a 2D kernel; 3D faces get their own)
and normals, the P2 facet maps, the projections between slave and master, the candidate
facet pairs, the constraint directions and the slave facets' segments over the master
(docs/method.md, *Two bodies: the dual mortar coupling*). Vectorized over facets and pairs; the
loops are over Newton steps.

Arrays: a facet's nodes are ``[start, end, midpoint]`` (counter-clockwise around its cell)
and its map ``x(t) = Σ_a x_a φ_a(t)``, ``t ∈ [0, 1]``.
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import chain

import numpy as np
from scipy.spatial import cKDTree

from ..fem.space import P2Space
from ..mesh.geometry import facet_normals
from .constraint_data import part_normals

__all__ = [
    "Side",
    "candidate_pairs",
    "cross",
    "directions",
    "facet_basis",
    "master_parameter",
    "on_facet",
    "segments",
    "side",
]

#: a projected master vertex within ``SNAP · eps · max|x| / h`` of a slave facet's end (the
#: round-off of the projection) is put on the end
SNAP = 64
#: Newton steps of the projections (quadratic convergence; a straight master needs one),
#: stopped once every step in the facet parameter is at most ``NEWTON_TOL``: the error after
#: it is of its square, below round-off
NEWTON_STEPS = 30
NEWTON_TOL = 1e-13


@dataclass(frozen=True)
class Side:
    """One part's facets: ``nodes (e, 3)`` global, ``points (e, 3, 2)``, outward nodal
    ``normals (e, 3, 2)`` (:func:`~signorini.contact.constraint_data.part_normals`),
    ``curved (e,)``."""

    nodes: np.ndarray
    points: np.ndarray
    normals: np.ndarray
    curved: np.ndarray


def side(space: P2Space, name: str) -> Side:
    """The facets of boundary part ``name``, their node points and the body's outward normals
    at their nodes (as contact parts compute them: the curve's, else the mean of the part's
    facets' normals at a vertex); curved where the part carries a curve."""
    mesh = space.mesh
    facets = mesh.part_facets(name)
    nodes = space.facet_nodes(facets)
    points = space.node_points[nodes]
    _, chord = facet_normals(points[:, :2])
    curve = mesh.curves[mesh.part_index(name)]
    curved = np.full(facets.size, curve is not None, dtype=bool)
    return Side(nodes, points, part_normals(space, name, nodes, chord), curved)


# --------------------------------------------------------------------------- facet kernels


def facet_basis(t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """P2 facet basis ``[start, end, midpoint]`` and its derivative at ``t (...)``: ``(..., 3)``
    each."""
    phi = np.stack([(1 - t) * (1 - 2 * t), t * (2 * t - 1), 4 * t * (1 - t)], axis=-1)
    dphi = np.stack([4 * t - 3, 4 * t - 1, 4 - 8 * t], axis=-1)
    return phi, dphi


def on_facet(X: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``Σ_a X_a φ_a(t)`` and its t-derivative for nodal values ``X (p, 3, 2)`` at ``t (p,)``
    or ``(p, q)``: ``(p, 2)`` or ``(p, q, 2)`` each. Written on ``X_a − X_0`` (``Σ_a φ_a = 1``,
    ``Σ_a φ_a' = 0``), so a short facet far from the origin keeps its digits."""
    phi, dphi = facet_basis(t)
    rel = X[:, 1:] - X[:, :1]
    if t.ndim == 1:
        x = X[:, 0] + np.einsum("pa,pai->pi", phi[..., 1:], rel)
        return x, np.einsum("pa,pai->pi", dphi[..., 1:], rel)
    x = X[:, None, 0] + np.einsum("pqa,pai->pqi", phi[..., 1:], rel)
    return x, np.einsum("pqa,pai->pqi", dphi[..., 1:], rel)


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def unit(v: np.ndarray) -> np.ndarray:
    return v / np.hypot(v[..., 0], v[..., 1])[..., None]


def newton(residual, t: np.ndarray, lo: float, hi: float) -> np.ndarray:
    """Newton's method on each entry of ``t (p,)`` (changed in place and returned):
    ``residual(t[live], live) -> (g, g')`` for the entries still iterating, each kept within
    ``[lo, hi]``; an entry stops once its step is at most :data:`NEWTON_TOL` or it stays at
    a bound (its root lies beyond)."""
    live = np.arange(t.size)
    for _ in range(NEWTON_STEPS):
        g, dg = residual(t[live], live)
        step = np.divide(g, dg, out=np.zeros_like(g), where=dg != 0)
        old = t[live]
        new = np.clip(old - step, lo, hi)
        t[live] = new
        stuck = (new == old) & ((new == lo) | (new == hi))
        live = live[(np.abs(step) > NEWTON_TOL) & ~stuck]
        if live.size == 0:
            break
    return t


def master_parameter(X: np.ndarray, x: np.ndarray, n: np.ndarray) -> tuple[np.ndarray, ...]:
    """η where the line ``x + t n`` meets the master facets ``X (p, 3, 2)`` (``x, n (p, 2)`` or
    ``(p, q, 2)``): Newton on ``(x_m(η) − x) × n = 0`` from the chord's intersection (exact
    for a straight facet), kept within ``[−1, 2]``. Returns ``η`` and whether it converged."""
    shape = x.shape[:-1]
    rows = np.repeat(np.arange(len(X)), x[0, ..., 0].size)
    x, n = x.reshape(-1, 2), n.reshape(-1, 2)
    a, b = X[rows, 0], X[rows, 1]
    with np.errstate(divide="ignore", invalid="ignore"):
        eta = cross(x - a, n) / cross(b - a, n)
    eta = np.clip(np.nan_to_num(eta, nan=0.5), -1.0, 2.0)

    def residual(t, live):
        xm, dxm = on_facet(X[rows[live]], t)
        return cross(xm - x[live], n[live]), cross(dxm, n[live])

    eta = newton(residual, eta, -1.0, 2.0)
    xm, _ = on_facet(X[rows], eta)
    scale = np.hypot(*(b - a).T) * np.hypot(n[:, 0], n[:, 1])
    ok = np.abs(cross(xm - x, n)) <= 1e-12 * scale
    return eta.reshape(shape), ok.reshape(shape)


def slave_parameter(X: np.ndarray, N: np.ndarray, y: np.ndarray) -> np.ndarray:
    """ξ where the slave facet ``X (p, 3, 2)`` with the normal field ``n(ξ) = Σ N_a φ_a(ξ)``
    projects onto the points ``y (p, 2)``: ``(x_s(ξ) − y) × n(ξ) = 0``, Newton from the
    projection onto the chord, kept within ``[−1, 2]``."""
    a, b = X[:, 0], X[:, 1]
    d = b - a
    xi = np.clip(np.einsum("pi,pi->p", y - a, d) / np.einsum("pi,pi->p", d, d), -1.0, 2.0)

    def residual(t, live):
        xs, dxs = on_facet(X[live], t)
        n, dn = on_facet(N[live], t)
        return cross(xs - y[live], n), cross(dxs, n) + cross(xs - y[live], dn)

    return newton(residual, xi, -1.0, 2.0)


# --------------------------------------------------------------------------- pairing


def candidate_pairs(
    slave: Side, master: Side, mix: tuple, wide: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Slave and master facets ``(e, f)`` that may face each other, by a k-d tree of the
    master facets' centres: f is a candidate of e if its centre is within ``ρ_e + r_f`` of a
    centre ``c_e`` (``r`` a facet's radius about its centre).

    By default (*near*): each node x of e is sent along the direction estimated from the
    master's normal ``n_q`` at its nearest master node q (:func:`direction`) to the master's
    tangent line at q, at p; ``c_e`` is the mean of its nodes' p and ``ρ_e = r_e + max |p −
    c_e| + 2 max |p − q|``: a few master facets per slave facet, whatever the gap. For the
    slave facets ``wide`` (where the near search left a node unpaired or the facet not
    covered, :func:`~signorini.contact.mortar.mortar_coupling`): ``c_e`` the facet's centre
    and ``ρ_e = 3 r_e + 2 d_e``, ``d_e`` the largest distance from a node of e to the nearest
    master node: a master point reached from a point of e (within ``d_e + r_e`` of the
    master) along a direction within 60° of the master's normal lies within twice that."""
    cs, cm = slave.points.mean(axis=1), master.points.mean(axis=1)
    rs = np.hypot(*(slave.points - cs[:, None]).transpose(2, 0, 1)).max(axis=1)
    rm = np.hypot(*(master.points - cm[:, None]).transpose(2, 0, 1)).max(axis=1)
    x = slave.points.reshape(-1, 2)
    d, k = cKDTree(master.points.reshape(-1, 2)).query(x)
    if wide is None:
        q, nq = master.points.reshape(-1, 2)[k], master.normals.reshape(-1, 2)[k]
        n0 = direction(slave.normals.reshape(-1, 2), nq, q - x, mix)
        with np.errstate(divide="ignore", invalid="ignore"):
            t = np.einsum("pi,pi->p", q - x, nq) / np.einsum("pi,pi->p", n0, nq)
        p = (x + t[:, None] * n0).reshape(-1, 3, 2)
        centre = p.mean(axis=1)
        spread = np.hypot(*(p - centre[:, None]).transpose(2, 0, 1)).max(axis=1)
        off = np.hypot(*(p.reshape(-1, 2) - q).T).reshape(-1, 3).max(axis=1)
        radius = rs + spread + 2 * off
        rows = np.flatnonzero(np.isfinite(radius))
        centre = centre[rows]
    else:
        rows = np.asarray(wide, dtype=np.int64)
        radius = 3 * rs + 2 * d.reshape(-1, 3).max(axis=1)  # a point of e: within d + rs
        centre = cs[rows]
    radius = radius[rows] * (1 + 1e-9) + 1e-12 * float(np.abs(cs).max())
    tree = cKDTree(cm)
    reach = radius + rm.max()
    counts = tree.query_ball_point(centre, reach, return_length=True)
    found = chain.from_iterable(tree.query_ball_point(centre, reach))
    f = np.fromiter(found, np.int64, counts.sum())
    e = np.repeat(np.arange(rows.size), counts)
    near = np.hypot(*(cm[f] - centre[e]).T) <= radius[e] + rm[f] * (1 + 1e-9)
    return rows[e[near]], f[near]


def direction(ns: np.ndarray, nm: np.ndarray, r: np.ndarray, mix: tuple) -> np.ndarray:
    """``normalize(a n_s − b n_m)`` ``(p, 2)`` for unit normals ``ns, nm (p, 2)``; for the
    averaged one (``a = b = 1``) written as ``n_s`` turned by half the angle φ from n_s to
    −n_m, which stays a unit vector where the two normals nearly coincide (the ends of two
    half-discs, where ``n_s − n_m`` vanishes): there φ is taken on the branch near twice the
    angle from n_s to ``r`` (towards the master point), so the direction turns towards it."""
    a, b = mix
    if a != b:
        return unit(a * ns - b * nm)
    phi = angle(ns, -nm)
    psi = angle(ns, r)
    far = (np.abs(phi) > 2 * np.pi / 3) & (np.hypot(r[:, 0], r[:, 1]) > 0)
    phi = np.where(far, 2 * psi + np.mod(phi - 2 * psi + np.pi, 2 * np.pi) - np.pi, phi)
    c, s = np.cos(phi / 2), np.sin(phi / 2)
    turned = np.column_stack([c * ns[:, 0] - s * ns[:, 1], s * ns[:, 0] + c * ns[:, 1]])
    diff = ns - nm
    size = np.hypot(diff[:, 0], diff[:, 1])
    # where defined, the difference itself: exact on a mirror-symmetric pair
    return np.where((size > 0.5)[:, None], diff / np.maximum(size, 0.5)[:, None], turned)


def angle(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The angle from ``a`` to ``b`` ``(p, 2)``, in ``(−π, π]``."""
    return np.arctan2(cross(a, b), np.einsum("pi,pi->p", a, b))


def paired_points(
    master: Side, f: np.ndarray, x: np.ndarray, ns: np.ndarray, mix: tuple
) -> tuple[np.ndarray, np.ndarray]:
    """η on master facets ``f (p,)`` where ``x_m(η) − x`` is along ``d(η)``, the direction of
    :func:`direction` from n_s and ``n_m(η)`` (the normalised interpolant of the master's
    nodal normals): Newton on ``(x_m(η) − x) × d(η) = 0`` from the chord's intersection along
    ``d(1/2)``, kept within ``[−1/2, 3/2]``; ``d'`` by the chain rule through the angle of
    n_m. Returns η and whether it converged."""
    X, N = master.points[f], master.normals[f]
    A, B = X[:, 0], X[:, 1]
    d = direction(ns, unit(N[:, 2]), X[:, 2] - x, mix)
    with np.errstate(divide="ignore", invalid="ignore"):
        eta = cross(x - A, d) / cross(B - A, d)
    eta = np.clip(np.nan_to_num(eta, nan=0.5), -0.5, 1.5)
    # d turns with n_m: fully for the master's normal, by half for the averaged one
    share = mix[1] / (mix[0] + mix[1])

    def residual(t, live):
        xm, dxm = on_facet(X[live], t)
        m, dm = on_facet(N[live], t)
        size = np.hypot(m[:, 0], m[:, 1])
        nm = m / size[:, None]
        turn = cross(nm, dm) / size  # d(angle of n_m)/dη
        r = xm - x[live]
        d = direction(ns[live], nm, r, mix)
        dd = share * turn[:, None] * np.column_stack([-d[:, 1], d[:, 0]])
        return cross(r, d), cross(dxm, d) + cross(r, dd)

    eta = newton(residual, eta, -0.5, 1.5)
    xm, _ = on_facet(X, eta)
    d = direction(ns, unit(on_facet(N, eta)[0]), xm - x, mix)
    scale = np.hypot(*(B - A).T) + np.hypot(*(xm - x).T)
    return eta, np.abs(cross(xm - x, d)) <= 1e-12 * scale


def directions(master: Side, pairs: tuple, x: np.ndarray, ns: np.ndarray, mix: tuple):
    """The constraint directions ``n_j = normalize(a n_s(x_j) − b n_m(π_j))`` at the slave
    nodes ``x (s, 2)`` with outward normals ``ns (s, 2)`` (``mix = (a, b)``: ``(1, 1)`` the
    averaged normal, ``(1, 0)`` the slave's, ``(0, 1)`` the master's), π_j the point where
    the line ``x_j + t n_j`` meets the master: n_j and π_j depend on each other, so π_j is
    sought on the master, as the point η of a candidate facet (the node's index ``pairs[2]
    (e, 3)``) with ``x_m(η) − x_j`` along ``a n_s − b n_m(η)`` (:func:`paired_points`), the
    nearest one where several facets have one. A node whose line meets no candidate takes
    the master's normal at its nearest node. Returns ``n (s, 2)``, ``π (s, 2)`` (NaN where
    none)."""
    e, f, index = pairs
    key = np.unique(np.column_stack([index[e].ravel(), np.repeat(f, 3)]), axis=0)
    j, f = key[:, 0], key[:, 1]
    eta, ok = paired_points(master, f, x[j], ns[j], mix)
    ok &= (eta >= -1e-12) & (eta <= 1 + 1e-12)
    eta = np.clip(eta, 0.0, 1.0)
    xm, _ = on_facet(master.points[f], eta)
    order = np.lexsort((np.hypot(*(xm - x[j]).T), j))
    order = order[ok[order]]
    node, first = np.unique(j[order], return_index=True)
    best = order[first]
    _, k = cKDTree(master.points.reshape(-1, 2)).query(x)
    nm = master.normals.reshape(-1, 2)[k]
    nm[node] = unit(on_facet(master.normals[f[best]], eta[best])[0])
    toward = master.points.reshape(-1, 2)[k] - x
    toward[node] = xm[best] - x[node]
    point = np.full_like(x, np.nan)
    point[node] = xm[best]
    return direction(ns, nm, toward, mix), point


def segments(slave: Side, master: Side, pairs: tuple, N: np.ndarray, paired: np.ndarray):
    """The pieces ``[lo, hi] ⊂ [0, 1]`` of slave facets ``e`` over master facets ``f``: the
    master facet's ends projected onto the slave facet along ``n(ξ) = Σ N_a φ_a(ξ)`` (``N (e_s,
    3, 2)`` the slave facets' nodal directions). Returns ``e, f, lo, hi`` of non-empty ones.

    Each (slave facet, master vertex) is projected once, so the pieces of a slave facet tile
    it exactly. A cut within round-off of the facet's end (:data:`SNAP` times the ratio of
    the coordinates to the facet's length) is put on it, and so is the cut of a master vertex
    that is the paired point π_j of the facet's end node (``paired (e_s, 2, 2)``, NaN where
    none; within :data:`SNAP` eps times the coordinates): matching ends leave no sliver, even
    where the direction grazes the surfaces (the ends of two half-discs)."""
    e, f = pairs
    vertex = master.nodes[f, :2]  # (p, 2) global nodes
    key, inverse = np.unique(
        np.column_stack([np.repeat(e, 2), vertex.ravel()]), axis=0, return_inverse=True
    )
    which = np.column_stack([np.repeat(f, 2), np.tile([0, 1], f.size)])[
        np.unique(inverse.ravel(), return_index=True)[1]
    ]
    facet = key[:, 0]
    X = slave.points[facet]
    xi = slave_parameter(X, N[facet], master.points[which[:, 0], which[:, 1]])
    length = np.hypot(*(X[:, 1] - X[:, 0]).T)
    tol = SNAP * np.finfo(float).eps * np.abs(X).max(axis=(1, 2)) / length
    xi = np.where(np.abs(xi) <= tol, 0.0, np.where(np.abs(xi - 1) <= tol, 1.0, xi))
    y = master.points[which[:, 0], which[:, 1]]
    near = SNAP * np.finfo(float).eps * np.abs(X).max(axis=(1, 2))
    for end in (0, 1):
        at = np.hypot(*(paired[facet, end] - y).T) <= near  # NaN compares False
        xi[at] = float(end)
    xi0, xi1 = xi[inverse.reshape(-1, 2)].T
    lo = np.clip(np.minimum(xi0, xi1), 0.0, 1.0)
    hi = np.clip(np.maximum(xi0, xi1), 0.0, 1.0)
    keep = hi > lo
    return e[keep], f[keep], lo[keep], hi[keep]
