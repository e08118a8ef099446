"""The dual (biorthogonal) mortar coupling of one contact pair between two bodies.

The bodies are disjoint components of one :class:`~signorini.mesh.Mesh`, numbered by one
:class:`~signorini.fem.space.P2Space`. A pair joins a boundary part of one body (the *slave*)
to a part of the other (the *master*). Per slave edge the P2 trace basis φ_a (a = start, end,
midpoint) gets its dual ψ_a with ``∫_e ψ_a φ_b ds = δ_ab ∫_e φ_a ds``; the mortar matrix
``M_jk = ∫_Γs ψ_j (φ_k ∘ π) ds`` couples slave node j to master node k through the projection
π of the slave onto the master along the interpolated constraint directions, and
``D_jj = ∫_Γs φ_j ds``. Everything lives in the reference configuration (small sliding):
docs/method.md, *Two bodies: the dual mortar coupling*.

Arrays: an edge's nodes are ``[start, end, midpoint]`` (counter-clockwise around its cell) and
its map ``x(t) = Σ_a x_a φ_a(t)``, ``t ∈ [0, 1]`` (quadratic on a curved part, affine
otherwise, where the midpoint node is the chord's midpoint).

References
----------
B. I. Wohlmuth, *A mortar finite element method using dual spaces for the Lagrange
multiplier*, SIAM J. Numer. Anal. 38 (2000). S. Hüeber, B. I. Wohlmuth, *A primal-dual active
set strategy for non-linear multibody contact problems*, CMAME 194 (2005).
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import chain

import numpy as np
import scipy.sparse as sp
from scipy.spatial import cKDTree

from ..fem.quadrature import gauss_legendre
from ..fem.space import P2Space
from ..mesh.geometry import segment_normals
from ..problem.fields import ProblemError
from .constraint_data import part_normals
from .mortar_checks import check_coupling, check_pair, pair_size

__all__ = ["DIRECTIONS", "MortarCoupling", "mortar_coupling"]

#: Gauss points per segment (slave edge ∩ projected master edge) when both edges are
#: straight: on a flat interface the integrand ψ_j (φ_k ∘ π) is a polynomial of degree 4 in
#: the slave's parameter, so 3 points are exact; 4 are used
STRAIGHT_POINTS = 4
#: Gauss points per segment when either edge is curved: the integrand is analytic (the line
#: element and π are not polynomials); 10 points give the mortar matrix to about 1e-15 relative
#: on the test arcs (docs/method.md, *Two bodies: the dual mortar coupling*)
CURVED_POINTS = 10
#: a projected master vertex within ``SNAP · eps · max|x| / h`` of a slave edge's end (the
#: round-off of the projection) is put on the end
SNAP = 64
#: Gauss points of the slave edges' local mass matrices (exact on straight edges)
MASS_POINTS = 10
#: Newton steps of the projections (quadratic convergence; a straight master needs one),
#: stopped once every step in the edge parameter is at most ``NEWTON_TOL``: the error after
#: it is of its square, below round-off
NEWTON_STEPS = 30
NEWTON_TOL = 1e-10
#: fixed-point steps of the averaged normal (it contracts by about gap × curvature per step)
NORMAL_STEPS = 200


@dataclass(frozen=True)
class MortarCoupling:
    """The mortar data of one contact pair (docs/method.md, *Two bodies: the dual mortar
    coupling*).

    Attributes
    ----------
    slave, master : str
        The boundary parts.
    slave_nodes : (s,) int array
        Sorted global P2 nodes of the slave part's edges (vertices and midpoints, all of them).
    normal : (s, 2) float array
        The unit constraint direction n_j, pointing from the slave body towards the master:
        ``normalize(n_s(x_j) − n_m(π_j))``.
    D : (s,) float array
        ``D_jj = ∫_Γs φ_j ds`` (along the quadratic edge on curved parts).
    M : (s, n_nodes) scipy.sparse.csr_matrix
        ``M_jk = ∫_Γs ψ_j (φ_k ∘ π) ds``, columns the global master nodes.
    weighted_gap : (s,) float array
        ``g̃_j = n_j · (Σ_k M_jk x_k − D_jj x_j)``: ``≥ 0`` open, ``< 0`` overlapping.
    coverage : (s,) float array
        ``Σ_k M_jk / D_jj``: 1 where ψ_j's support lies wholly over the master.
    master_point : (s, 2) float array
        π_j, where the line ``x_j + t n_j`` meets the master (NaN where it misses it).
    """

    slave: str
    master: str
    slave_nodes: np.ndarray
    normal: np.ndarray
    D: np.ndarray
    M: sp.csr_matrix
    weighted_gap: np.ndarray
    coverage: np.ndarray
    master_point: np.ndarray


@dataclass(frozen=True)
class _Side:
    """One part's edges: ``nodes (e, 3)`` global, ``points (e, 3, 2)``, outward nodal
    ``normals (e, 3, 2)`` (:func:`~signorini.contact.constraint_data.part_normals`),
    ``curved (e,)``."""

    nodes: np.ndarray
    points: np.ndarray
    normals: np.ndarray
    curved: np.ndarray


def _side(space: P2Space, name: str) -> _Side:
    mesh = space.mesh
    edges = mesh.part_edges(name)
    nodes = space.edge_nodes(edges)
    points = space.node_points[nodes]
    _, chord = segment_normals(points[:, 0], points[:, 1])
    curve = mesh.curves[mesh.part_index(name)]
    curved = np.full(edges.size, curve is not None, dtype=bool)
    return _Side(nodes, points, part_normals(space, name, nodes, chord), curved)


# --------------------------------------------------------------------------- edge kernels


def _basis(t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """P2 edge basis ``[start, end, midpoint]`` and its derivative at ``t (...)``: ``(..., 3)``
    each."""
    phi = np.stack([(1 - t) * (1 - 2 * t), t * (2 * t - 1), 4 * t * (1 - t)], axis=-1)
    dphi = np.stack([4 * t - 3, 4 * t - 1, 4 - 8 * t], axis=-1)
    return phi, dphi


def _on_edge(X: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``Σ_a X_a φ_a(t)`` and its t-derivative for nodal values ``X (p, 3, 2)`` at ``t (p,)``
    or ``(p, q)``: ``(p, 2)`` or ``(p, q, 2)`` each. Written on ``X_a − X_0`` (``Σ_a φ_a = 1``,
    ``Σ_a φ_a' = 0``), so a short edge far from the origin keeps its digits."""
    phi, dphi = _basis(t)
    rel = X[:, 1:] - X[:, :1]
    if t.ndim == 1:
        x = X[:, 0] + np.einsum("pa,pai->pi", phi[..., 1:], rel)
        return x, np.einsum("pa,pai->pi", dphi[..., 1:], rel)
    x = X[:, None, 0] + np.einsum("pqa,pai->pqi", phi[..., 1:], rel)
    return x, np.einsum("pqa,pai->pqi", dphi[..., 1:], rel)


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.hypot(v[..., 0], v[..., 1])[..., None]


def _master_parameter(X: np.ndarray, x: np.ndarray, n: np.ndarray) -> tuple[np.ndarray, ...]:
    """η where the line ``x + t n`` meets the master edges ``X (p, 3, 2)`` (``x, n (p, 2)`` or
    ``(p, q, 2)``): Newton on ``(x_m(η) − x) × n = 0`` from the chord's intersection (exact
    for a straight edge). Returns ``η`` and whether it converged."""
    a, b = X[:, 0], X[:, 1]
    if x.ndim == 3:
        a, b = a[:, None], b[:, None]
    eta = _cross(x - a, n) / _cross(b - a, n)
    eta = np.clip(np.nan_to_num(eta, nan=0.5), -1.0, 2.0)
    scale = np.hypot(*(b - a).T).T * np.hypot(n[..., 0], n[..., 1])
    for _ in range(NEWTON_STEPS):
        xm, dxm = _on_edge(X, eta)
        g = _cross(xm - x, n)
        dg = _cross(dxm, n)
        step = np.divide(g, dg, out=np.zeros_like(g), where=dg != 0)
        eta = np.clip(eta - step, -1.0, 2.0)
        if np.all(np.abs(step) <= NEWTON_TOL):
            break
    xm, _ = _on_edge(X, eta)
    return eta, np.abs(_cross(xm - x, n)) <= 1e-12 * scale


def _slave_parameter(X: np.ndarray, N: np.ndarray, y: np.ndarray) -> np.ndarray:
    """ξ where the slave edge ``X (p, 3, 2)`` with the normal field ``n(ξ) = Σ N_a φ_a(ξ)``
    projects onto the points ``y (p, 2)``: ``(x_s(ξ) − y) × n(ξ) = 0``, Newton from the
    projection onto the chord, kept within ``[−1, 2]``."""
    a, b = X[:, 0], X[:, 1]
    d = b - a
    xi = np.clip(np.einsum("pi,pi->p", y - a, d) / np.einsum("pi,pi->p", d, d), -1.0, 2.0)
    for _ in range(NEWTON_STEPS):
        xs, dxs = _on_edge(X, xi)
        n, dn = _on_edge(N, xi)
        f = _cross(xs - y, n)
        df = _cross(dxs, n) + _cross(xs - y, dn)
        step = np.divide(f, df, out=np.zeros_like(f), where=df != 0)
        xi = np.clip(xi - step, -1.0, 2.0)
        if np.all(np.abs(step) <= NEWTON_TOL):
            break
    return xi


# --------------------------------------------------------------------------- pairing


def _candidate_pairs(slave: _Side, master: _Side) -> tuple[np.ndarray, np.ndarray]:
    """Slave and master edges ``(e, f)`` that may face each other: the master edge's centre
    within ``3 r_e + r_f + 2 d_e`` of the slave edge's, ``r`` the edges' radii about their
    centres and ``d_e`` the largest distance from a node of e to the nearest master node. A
    master point reached from a point of e (within ``d_e + r_e`` of the master) along a
    direction within 60° of the master's normal (:data:`FACING`) lies within twice that."""
    cs, cm = slave.points.mean(axis=1), master.points.mean(axis=1)
    rs = np.hypot(*(slave.points - cs[:, None]).transpose(2, 0, 1)).max(axis=1)
    rm = np.hypot(*(master.points - cm[:, None]).transpose(2, 0, 1)).max(axis=1)
    d, _ = cKDTree(master.points.reshape(-1, 2)).query(slave.points.reshape(-1, 2))
    radius = 3 * rs + 2 * d.reshape(-1, 3).max(axis=1)  # a point of e: within d + rs
    radius = radius * (1 + 1e-9) + 1e-12 * float(np.abs(cs).max())
    tree = cKDTree(cm)
    reach = radius + rm.max()
    counts = tree.query_ball_point(cs, reach, return_length=True)
    f = np.fromiter(chain.from_iterable(tree.query_ball_point(cs, reach)), np.int64, counts.sum())
    e = np.repeat(np.arange(len(cs)), counts)
    near = np.hypot(*(cm[f] - cs[e]).T) <= radius[e] + rm[f] * (1 + 1e-9)
    return e[near], f[near]


def _nearest_hits(master: _Side, j: np.ndarray, f: np.ndarray, x: np.ndarray, n: np.ndarray):
    """For the candidates ``(node j, master edge f)``: per node the nearest point where the
    line ``x_j + t n_j`` meets a candidate edge, preferring points on an edge to points on
    an edge's extension (up to half its parameter range beyond an end: a node just beyond
    the master's end steers by it). Returns the nodes hit, their candidate, η there, the
    point and how far off its edge it lies (in η)."""
    eta, ok = _master_parameter(master.points[f], x[j], n[j])
    off = np.maximum(np.maximum(-eta, eta - 1), 0.0)
    ok &= off <= 0.5
    xm, _ = _on_edge(master.points[f], eta)
    t = np.einsum("pi,pi->p", xm - x[j], n[j])
    order = np.lexsort((np.abs(t), off > 1e-12, j))
    order = order[ok[order]]
    hit, first = np.unique(j[order], return_index=True)
    best = order[first]
    return hit, best, eta[best], xm[best], off[best]


def _angle(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The angle from unit vectors ``a`` to ``b`` ``(s, 2)``, in ``(−π, π]``."""
    return np.arctan2(_cross(a, b), np.einsum("si,si->s", a, b))


def _averaged_normals(master: _Side, pairs: tuple, x: np.ndarray, ns: np.ndarray, mix: tuple):
    """The fixed point ``n_j = normalize(n_s(x_j) − n_m(π_j))`` at the slave nodes ``x (s,
    2)`` with outward normals ``ns (s, 2)``, the node's index ``pairs[2] (e, 3)``; π_j the
    nearest point where ``x_j + t n_j`` meets a candidate master edge.

    Solved for the angle θ_j of n_j from n_s by the secant method on ``g(θ) − θ``, ``g(θ)``
    the angle of ``n_s − n_m(π(θ))`` (the plain iteration contracts only by about gap ×
    curvature per step), from the master's normal at its nearest node; the last step is a
    plain one, so the result is ``normalize(n_s − n_m(π_j))`` itself. Returns ``n (s, 2)``,
    ``π (s, 2)`` (NaN where the line misses the master) and ``n_s · n_m (s,)``.
    ``mix = (a, b)`` weighs the two normals, ``normalize(a n_s − b n_m)``: ``(1, 1)`` the
    averaged normal, ``(1, 0)`` the slave's, ``(0, 1)`` the master's (for comparisons)."""
    e, f, index = pairs
    a, b = mix
    key = np.unique(np.column_stack([index[e].ravel(), np.repeat(f, 3)]), axis=0)
    j, f = key[:, 0], key[:, 1]
    _, k = cKDTree(master.points.reshape(-1, 2)).query(x)
    theta = _angle(ns, _unit(a * ns - b * master.normals.reshape(-1, 2)[k]))
    previous = None
    for _ in range(NORMAL_STEPS):
        c, s = np.cos(theta), np.sin(theta)
        n = np.column_stack([c * ns[:, 0] - s * ns[:, 1], s * ns[:, 0] + c * ns[:, 1]])
        hit, best, eta, xm, off = _nearest_hits(master, j, f, x, n)
        nm = _unit(_on_edge(master.normals[f[best]], eta)[0])
        new = n.copy()
        new[hit] = _unit(a * ns[hit] - b * nm)
        residual = _angle(ns, new) - theta
        if np.abs(residual).max(initial=0.0) <= 1e-15:
            break
        step = residual.copy()  # plain: θ ← g(θ)
        if previous is not None:
            slope = residual - previous[1]
            run = theta - previous[0]
            secant = (slope != 0) & (run != 0)
            step[secant] = -residual[secant] * run[secant] / slope[secant]
        previous = (theta, residual)
        theta = theta + step
    on = off <= 1e-12
    point = np.full_like(x, np.nan)
    point[hit[on]] = xm[on]
    facing = np.full(len(x), -1.0)
    facing[hit[on]] = np.einsum("pi,pi->p", ns[hit[on]], nm[on])
    return new, point, facing


def _segments(slave: _Side, master: _Side, e: np.ndarray, f: np.ndarray, N: np.ndarray):
    """The pieces ``[lo, hi] ⊂ [0, 1]`` of slave edges ``e`` over master edges ``f``: the
    master edge's ends projected onto the slave edge along ``n(ξ) = Σ N_a φ_a(ξ)`` (``N (e_s,
    3, 2)`` the slave edges' nodal directions). Returns ``e, f, lo, hi`` of non-empty ones.

    Each (slave edge, master vertex) is projected once, so the pieces of a slave edge tile
    it exactly; a cut within round-off of the edge's end (:data:`SNAP` times the ratio of
    the coordinates to the edge's length) is put on it, so matching ends leave no sliver."""
    vertex = master.nodes[f, :2]  # (p, 2) global nodes
    key, inverse = np.unique(
        np.column_stack([np.repeat(e, 2), vertex.ravel()]), axis=0, return_inverse=True
    )
    which = np.column_stack([np.repeat(f, 2), np.tile([0, 1], f.size)])[
        np.unique(inverse.ravel(), return_index=True)[1]
    ]
    edge = key[:, 0]
    X = slave.points[edge]
    xi = _slave_parameter(X, N[edge], master.points[which[:, 0], which[:, 1]])
    length = np.hypot(*(X[:, 1] - X[:, 0]).T)
    tol = SNAP * np.finfo(float).eps * np.abs(X).max(axis=(1, 2)) / length
    xi = np.where(np.abs(xi) <= tol, 0.0, np.where(np.abs(xi - 1) <= tol, 1.0, xi))
    xi0, xi1 = xi[inverse.reshape(-1, 2)].T
    lo = np.clip(np.minimum(xi0, xi1), 0.0, 1.0)
    hi = np.clip(np.maximum(xi0, xi1), 0.0, 1.0)
    keep = hi > lo
    return e[keep], f[keep], lo[keep], hi[keep]


# --------------------------------------------------------------------------- integrals


def _dual_basis(slave: _Side) -> tuple[np.ndarray, np.ndarray]:
    """Per slave edge the local mass ``M_e = ∫_e φ_a φ_b ds`` (along the quadratic edge), the
    weights ``D_e = ∫_e φ_a ds = Σ_b (M_e)_ab`` ``(e, 3)`` and the coefficients ``A_e = D_e
    M_e⁻¹`` ``(e, 3, 3)`` of the dual basis ``ψ_a = Σ_b (A_e)_ab φ_b``."""
    t, w = gauss_legendre(MASS_POINTS)
    phi, _ = _basis(t)
    _, dx = _on_edge(slave.points, np.broadcast_to(t, (len(slave.points), t.size)))
    ws = w * np.hypot(dx[..., 0], dx[..., 1])  # (e, q)
    mass = np.einsum("eq,qa,qb->eab", ws, phi, phi)
    weight = mass.sum(axis=2)
    # A = D M⁻¹ with M symmetric: Aᵀ = M⁻¹ D
    coef = np.swapaxes(np.linalg.solve(mass, weight[:, :, None] * np.eye(3)), 1, 2)
    return weight, coef


def _mortar_entries(slave: _Side, master: _Side, seg: tuple, N: np.ndarray, coef: np.ndarray):
    """``(S, 3, 3)`` ``∫_seg ψ_a (φ_b ∘ π) ds`` of the segments ``seg = (e, f, lo, hi)``: a
    Gauss rule in ξ on ``[lo, hi]`` (:data:`STRAIGHT_POINTS` or :data:`CURVED_POINTS`), π(ξ)
    on master edge f along ``n(ξ)`` (:func:`_master_parameter`). Also whether each segment
    faces the master (``n(ξ) · n_m(π(ξ)) < 0`` at its middle Gauss point)."""
    e, f, lo, hi = seg
    out = np.zeros((e.size, 3, 3))
    faces = np.zeros(e.size, dtype=bool)
    curved = slave.curved[e] | master.curved[f]
    for group, points in ((~curved, STRAIGHT_POINTS), (curved, CURVED_POINTS)):
        g = np.flatnonzero(group)
        if g.size == 0:
            continue
        t, w = gauss_legendre(points)
        length = hi[g] - lo[g]
        xi = lo[g, None] + length[:, None] * t  # (S, q)
        xs, dxs = _on_edge(slave.points[e[g]], xi)
        n, _ = _on_edge(N[e[g]], xi)
        eta, _ = _master_parameter(master.points[f[g]], xs, n)
        nm, _ = _on_edge(master.normals[f[g]], eta[:, points // 2])
        faces[g] = np.einsum("pi,pi->p", n[:, points // 2], nm) < 0
        ws = length[:, None] * w * np.hypot(dxs[..., 0], dxs[..., 1])
        psi = np.einsum("sqb,sab->sqa", _basis(xi)[0], coef[e[g]])
        out[g] = np.einsum("sq,sqa,sqb->sab", ws, psi, _basis(eta)[0])
    return out, faces


#: the constraint directions :func:`mortar_coupling` offers, as weights ``(a, b)`` of
#: ``normalize(a n_s − b n_m)``
DIRECTIONS = {"averaged": (1.0, 1.0), "slave": (1.0, 0.0), "master": (0.0, 1.0)}


def mortar_coupling(
    space: P2Space,
    slave: str,
    master: str,
    *,
    constrained: np.ndarray | None = None,
    direction: str = "averaged",
) -> MortarCoupling:
    """The dual mortar coupling of the contact pair ``slave`` → ``master``.

    Parameters
    ----------
    space : P2Space
        The P2 space of the mesh holding both bodies (disjoint components).
    slave, master : str
        Boundary parts of two different bodies, sharing no node.
    constrained : (c,) int array, optional
        The slave nodes that carry a constraint (e.g. all but the Dirichlet nodes); each must
        lie wholly over the master (coverage 1) and not start deeper inside it than the
        small-deformation model covers. Default: every slave node.
    direction : {"averaged", "slave", "master"}
        The constraint direction n_j: ``normalize(n_s − n_m(π_j))`` (the default; the
        symmetry plane's normal on a mirror-symmetric pair), the slave's outward normal
        ``n_s(x_j)``, or the reverse of the master's ``−n_m(π_j)`` (one-sided normals, for
        comparison: they put a spurious shear on a symmetric pair, docs/method.md).

    Returns
    -------
    MortarCoupling

    Raises
    ------
    ProblemError
        Naming the parts: an unknown part, both names the same, a node on both parts, parts
        on one body (self-contact is not modelled) or a part across several bodies, no
        overlap of the slave with the master, surfaces that do not face each other, a
        constrained slave node not wholly over the master (naming it), an initial overlap
        deeper than ``DEEP_OVERLAP`` times the bodies' size.
    """
    pair = f"contact pair (slave {slave!r}, master {master!r})"
    if direction not in DIRECTIONS:
        raise ProblemError(
            f"{pair}: direction must be one of {list(DIRECTIONS)}, got {direction!r}"
        )
    bodies = check_pair(space, slave, master, pair)
    s_side, m_side = _side(space, slave), _side(space, master)
    slave_nodes, index = np.unique(s_side.nodes, return_inverse=True)
    index = index.reshape(-1, 3)
    x = space.node_points[slave_nodes]
    ns = np.zeros_like(x)
    ns[index.ravel()] = s_side.normals.reshape(-1, 2)
    e, f = _candidate_pairs(s_side, m_side)
    normal, point, facing = _averaged_normals(m_side, (e, f, index), x, ns, DIRECTIONS[direction])
    weight, coef = _dual_basis(s_side)
    D = np.bincount(index.ravel(), weights=weight.ravel(), minlength=slave_nodes.size)
    N = normal[index]
    seg = _segments(s_side, m_side, e, f, N)
    entries, faces = _mortar_entries(s_side, m_side, seg, N, coef)
    e, f = seg[0][faces], seg[1][faces]
    if e.size == 0:
        raise ProblemError(
            f"{pair}: no part of the slave lies over the master along the normals (the parts "
            "do not overlap): pair parts that face each other"
        )
    rows = np.broadcast_to(index[e][:, :, None], (e.size, 3, 3))
    cols = np.broadcast_to(m_side.nodes[f][:, None, :], (e.size, 3, 3))
    M = sp.coo_matrix(
        (entries[faces].ravel(), (rows.ravel(), cols.ravel())),
        shape=(slave_nodes.size, space.n_nodes),
    ).tocsr()
    mx = M @ space.node_points
    gap = np.einsum("si,si->s", mx - D[:, None] * x, normal)
    coverage = np.asarray(M.sum(axis=1)).ravel() / D
    coupling = MortarCoupling(slave, master, slave_nodes, normal, D, M, gap, coverage, point)
    mine = np.ones(slave_nodes.size, dtype=bool)
    if constrained is not None:
        mine = np.isin(slave_nodes, np.asarray(constrained, dtype=np.int64))
    check_coupling(coupling, (facing, mine, pair_size(space, bodies), x), pair)
    return coupling
