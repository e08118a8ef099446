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
otherwise, where the midpoint node is the chord's midpoint). The geometry (projections,
directions, segments) is in :mod:`signorini.contact.mortar_pairing`, the refusals in
:mod:`signorini.contact.mortar_checks`.

References
----------
B. I. Wohlmuth, *A mortar finite element method using dual spaces for the Lagrange
multiplier*, SIAM J. Numer. Anal. 38 (2000). S. Hüeber, B. I. Wohlmuth, *A primal-dual active
set strategy for non-linear multibody contact problems*, CMAME 194 (2005).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ..fem.quadrature import gauss_legendre
from ..fem.space import P2Space
from ..problem.fields import ProblemError
from .mortar_checks import check_coupling, check_pair, pair_size
from .mortar_pairing import (
    Side,
    candidate_pairs,
    directions,
    facet_basis,
    master_parameter,
    on_facet,
    segments,
    side,
)

__all__ = ["DIRECTIONS", "MortarCoupling", "mortar_coupling"]

#: Gauss points per segment (slave edge ∩ projected master edge) when both edges are
#: straight: on a flat interface the integrand ψ_j (φ_k ∘ π) is a polynomial of degree 4 in
#: the slave's parameter, so 3 points are exact; 4 are used
STRAIGHT_POINTS = 4
#: Gauss points per segment when either edge is curved: the integrand is analytic (the line
#: element and π are not polynomials); 10 points give the mortar matrix to about 1e-15 relative
#: on the test arcs (docs/method.md, *Two bodies: the dual mortar coupling*)
CURVED_POINTS = 10
#: Gauss points of the slave edges' local mass matrices (exact on straight edges)
MASS_POINTS = 10


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


# --------------------------------------------------------------------------- integrals


def _dual_basis(slave: Side) -> tuple[np.ndarray, np.ndarray]:
    """Per slave edge the local mass ``M_e = ∫_e φ_a φ_b ds`` (along the quadratic edge), the
    weights ``D_e = ∫_e φ_a ds = Σ_b (M_e)_ab`` ``(e, 3)`` and the coefficients ``A_e = D_e
    M_e⁻¹`` ``(e, 3, 3)`` of the dual basis ``ψ_a = Σ_b (A_e)_ab φ_b``."""
    t, w = gauss_legendre(MASS_POINTS)
    phi, _ = facet_basis(t)
    _, dx = on_facet(slave.points, np.broadcast_to(t, (len(slave.points), t.size)))
    ws = w * np.hypot(dx[..., 0], dx[..., 1])  # (e, q)
    mass = np.einsum("eq,qa,qb->eab", ws, phi, phi)
    weight = mass.sum(axis=2)
    # A = D M⁻¹ with M symmetric: Aᵀ = M⁻¹ D
    coef = np.swapaxes(np.linalg.solve(mass, weight[:, :, None] * np.eye(3)), 1, 2)
    return weight, coef


def _mortar_entries(slave: Side, master: Side, seg: tuple, N: np.ndarray, coef: np.ndarray):
    """``(S, 3, 3)`` ``∫_seg ψ_a (φ_b ∘ π) ds`` of the segments ``seg = (e, f, lo, hi)``: a
    Gauss rule in ξ on ``[lo, hi]`` (:data:`STRAIGHT_POINTS` or :data:`CURVED_POINTS`), π(ξ)
    on master edge f along ``n(ξ)`` (:func:`.mortar_pairing.master_parameter`). Also
    whether each segment faces the master (``n(ξ) · n_m(π(ξ)) < 0`` at its middle Gauss point)."""
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
        xs, dxs = on_facet(slave.points[e[g]], xi)
        n, _ = on_facet(N[e[g]], xi)
        eta, _ = master_parameter(master.points[f[g]], xs, n)
        nm, _ = on_facet(master.normals[f[g]], eta[:, points // 2])
        faces[g] = np.einsum("pi,pi->p", n[:, points // 2], nm) < 0
        ws = length[:, None] * w * np.hypot(dxs[..., 0], dxs[..., 1])
        psi = np.einsum("sqb,sab->sqa", facet_basis(xi)[0], coef[e[g]])
        out[g] = np.einsum("sq,sqa,sqb->sab", ws, psi, facet_basis(eta)[0])
    return out, faces


def _node_list(nodes: object, n_nodes: int, pair: str) -> np.ndarray:
    """``nodes`` as a 1-D int64 array of node indices, or a ProblemError naming the fault."""
    array = np.asarray(nodes)
    if array.size == 0:
        return np.zeros(0, dtype=np.int64)
    if array.ndim != 1 or not np.issubdtype(array.dtype, np.integer):
        raise ProblemError(
            f"{pair}: constrained must be a 1-D array of node indices (int), got an array of "
            f"shape {array.shape} and dtype {array.dtype}"
        )
    if array.min() < 0 or array.max() >= n_nodes:
        raise ProblemError(
            f"{pair}: constrained holds node indices outside [0, {n_nodes}): "
            f"{array.min()} ... {array.max()}"
        )
    return array.astype(np.int64)


def _couple(sides: tuple, pairs: tuple, nodes: tuple, mix: tuple, coef: np.ndarray):
    """The directions, paired points, facing segments and their entries from the candidate
    edge pairs: ``(normal, point, (e, f, lo, hi), entries)``."""
    s_side, m_side = sides
    index, x, ns = nodes
    normal, point = directions(m_side, (*pairs, index), x, ns, mix)
    N = normal[index]
    seg = segments(s_side, m_side, pairs, N, point[index[:, :2]])
    entries, faces = _mortar_entries(s_side, m_side, seg, N, coef)
    return normal, point, tuple(a[faces] for a in seg), entries[faces]


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
        The nodes that carry a constraint (e.g. all but the Dirichlet nodes; nodes off the
        slave part are ignored); each slave node among them must lie wholly over the master
        (coverage 1) and not start deeper inside it than the small-deformation model covers.
        Default: every slave node.
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
        overlap of the slave with the master, a constrained slave node not wholly over the
        master (naming it), an initial overlap deeper than ``DEEP_OVERLAP`` times the bodies'
        size.
    """
    pair = f"contact pair (slave {slave!r}, master {master!r})"
    if direction not in DIRECTIONS:
        raise ProblemError(
            f"{pair}: direction must be one of {list(DIRECTIONS)}, got {direction!r}"
        )
    bodies = check_pair(space, slave, master, pair)
    if constrained is not None:
        constrained = _node_list(constrained, space.n_nodes, pair)
    s_side, m_side = side(space, slave), side(space, master)
    slave_nodes, index = np.unique(s_side.nodes, return_inverse=True)
    index = index.reshape(-1, 3)
    x = space.node_points[slave_nodes]
    ns = np.zeros_like(x)
    ns[index.ravel()] = s_side.normals.reshape(-1, 2)
    weight, coef = _dual_basis(s_side)
    D = np.bincount(index.ravel(), weights=weight.ravel(), minlength=slave_nodes.size)
    mix = DIRECTIONS[direction]
    pairs = candidate_pairs(s_side, m_side, mix)
    normal, point, seg, entries = _couple((s_side, m_side), pairs, (index, x, ns), mix, coef)
    covered = np.bincount(seg[0], weights=seg[3] - seg[2], minlength=len(index))
    wide = np.flatnonzero((np.abs(covered - 1) > 1e-12) | np.isnan(point[index, 0]).any(axis=1))
    if wide.size:  # search these slave edges' surroundings widely
        more = candidate_pairs(s_side, m_side, mix, wide)
        both = np.vstack([np.column_stack(pairs), np.column_stack(more)])
        pairs = tuple(np.unique(both, axis=0).T)
        normal, point, seg, entries = _couple((s_side, m_side), pairs, (index, x, ns), mix, coef)
    e, f = seg[0], seg[1]
    if e.size == 0:
        raise ProblemError(
            f"{pair}: no part of the slave lies over the master along the normals (the parts "
            "do not overlap): pair parts that face each other"
        )
    rows = np.broadcast_to(index[e][:, :, None], (e.size, 3, 3))
    cols = np.broadcast_to(m_side.nodes[f][:, None, :], (e.size, 3, 3))
    M = sp.coo_matrix(
        (entries.ravel(), (rows.ravel(), cols.ravel())),
        shape=(slave_nodes.size, space.n_nodes),
    ).tocsr()
    mx = M @ space.node_points
    gap = np.einsum("si,si->s", mx - D[:, None] * x, normal)
    coverage = np.asarray(M.sum(axis=1)).ravel() / D
    coupling = MortarCoupling(slave, master, slave_nodes, normal, D, M, gap, coverage, point)
    mine = np.ones(slave_nodes.size, dtype=bool)
    if constrained is not None:
        mine = np.isin(slave_nodes, constrained)
    check_coupling(coupling, (mine, pair_size(space, bodies), x), pair)
    return coupling
