"""The data of each constraint before the rows are formed: directions n_z and gaps ψ(z) at
the contact facets' nodes (edges in 2D), the weights m_z, w_z per facet, and the friction data
(docs/method.md, *Contact directions*, *Discrete problem*, *Friction in a ContactProblem*).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING

import numpy as np

from ..algebra.friction.laws import LawGroups
from ..fem import iso, p2
from ..fem.quadrature import gauss_legendre
from ..fem.space import LagrangeSpace
from ..problem.fields import ProblemError, evaluate_field
from ..problem.normals import node_normals

if TYPE_CHECKING:
    from .discrete_conditions import DiscreteConditions
    from .mortar import MortarCoupling

__all__ = [
    "body_normals",
    "directions_and_gaps",
    "facet_weights",
    "friction_data",
    "part_normals",
]


def body_normals(
    conditions: DiscreteConditions,
    space: LagrangeSpace,
    i: int,
    nodes: np.ndarray,
    chord: np.ndarray,
) -> np.ndarray:
    """The body's outward unit normal at the nodes ``[start, end, midpoint]`` of contact part
    ``i``'s facets (edges in 2D; ``nodes (e, 3)``, chord normals ``(e, 2)``), shape
    ``(e, 3, 2)``: the part's straight normal where it has one
    (:attr:`DiscreteConditions.straight_normal`), else
    :func:`signorini.problem.normals.node_normals` (docs/method.md, *Contact directions*)."""
    return node_normals(
        space.mesh,
        conditions.contact_parts[i],
        nodes,
        space.node_points[nodes],
        chord,
        straight=conditions.straight(i),
    )


def part_normals(
    space: LagrangeSpace, name: str, nodes: np.ndarray, chord: np.ndarray
) -> np.ndarray:
    """The outward unit normal of boundary part ``name`` at the nodes ``[start, end,
    midpoint]`` of its edges (``nodes (e, 3)``, chord normals ``(e, 2)``), shape ``(e, 3, 2)``,
    from the geometry alone (:func:`signorini.problem.normals.node_normals`)."""
    return node_normals(space.mesh, name, nodes, space.node_points[nodes], chord)


def directions_and_gaps(
    conditions: DiscreteConditions,
    space: LagrangeSpace,
    cs_facets: tuple,
    chord: np.ndarray,
    couplings: Mapping[str, MortarCoupling],
) -> tuple[np.ndarray, np.ndarray]:
    """n_z and ψ(z) at the nodes ``[start, end, midpoint]`` of the contact facets (edges in
    2D), part by part (each part has its own obstacle), shapes ``(n_cf, 3, 2)`` and
    ``(n_cf, 3)``: a shape's direction and ψ, or the body's normal and the gap function's ψ,
    from ``conditions``; on the slave part of a contact pair the mortar direction and
    weighted gap ``g̃_z / D_zz`` of its coupling (docs/method.md, *Two bodies*)."""
    parts, facet_part, facet_nodes = cs_facets
    direction = np.empty(facet_nodes.shape + (2,))
    gap = np.empty(facet_nodes.shape)
    for i, name in enumerate(parts):
        sel = facet_part == i
        nodes, inverse = np.unique(facet_nodes[sel], return_inverse=True)
        on_part = conditions.gap_part == i  # the same nodes, sorted
        if name in couplings:
            c = couplings[name]
            loc = np.searchsorted(c.slave_nodes, nodes)
            psi = c.weighted_gap[loc] / c.D[loc]
            direction[sel] = c.normal[loc][inverse].reshape(-1, 3, 2)
        elif conditions.is_shape[i]:
            psi, n = conditions.gap[on_part], conditions.obstacle_direction[on_part]
            direction[sel] = n[inverse].reshape(-1, facet_nodes.shape[1], 2)
        else:
            psi = conditions.gap[on_part]
            direction[sel] = body_normals(conditions, space, i, facet_nodes[sel], chord[sel])
        gap[sel] = psi[inverse].reshape(-1, facet_nodes.shape[1])
    return direction, gap


def facet_weights(space: LagrangeSpace, facets: np.ndarray, facet_nodes: np.ndarray):
    """``∫ φ_z ds`` and ``∫ ψ_z ds`` of ``[start, end, midpoint]`` (P1: ``[start, end]``) on
    each contact facet (an edge in 2D), ``(n_cf, 3)`` (``(n_cf, 2)``) each: closed forms on
    straight edges (the element's shares of the length), a Gauss rule along the quadratic
    edge on curved ones."""
    length = space.mesh.facet_measure[facets]
    hat = np.outer(length, space.element.facet.hat_share)
    basis = np.outer(length, space.element.facet.basis_share)
    curved = np.flatnonzero(np.isin(facets, space.curved_facets))
    if curved.size:
        t, w = gauss_legendre(6)
        halves = np.concatenate([t / 2, 0.5 + t / 2])  # φ_z is linear on each half-edge
        wh = np.concatenate([w, w]) / 2
        points = space.node_points[facet_nodes[curved]]
        _, speed, _ = iso.edge_geometry(points[:, :2], points[:, 2], halves)
        phi = np.column_stack(
            [
                np.maximum(1 - 2 * halves, 0),
                np.maximum(2 * halves - 1, 0),
                1 - np.abs(2 * halves - 1),
            ]
        )
        hat[curved] = (speed * wh) @ phi
        basis[curved] = (speed * wh) @ p2.edge_basis(halves)
    return hat, basis


def friction_data(
    conditions: DiscreteConditions,
    space: LagrangeSpace,
    facet_part: np.ndarray,
    facet_nodes: np.ndarray,
    facet_local: np.ndarray,
    part: np.ndarray,
    second: np.ndarray,
) -> LawGroups:
    """The friction laws per constraint: each frictional part's law, the law of each
    constraint and its nodal weight
    (:meth:`~signorini.algebra.friction.laws.FrictionLaw.nodal_weight`, e.g. Tresca's
    ``s_z = ∫ s ψ_z ds``, Coulomb's F); a corner node's constraints are frictionless."""
    k = part.size
    index = np.full(k, -1, dtype=np.int64)
    weight = np.zeros(k)
    laws = []
    corner = second | np.concatenate([second[1:], [False]])
    for i, name in enumerate(conditions.contact_parts):
        law = conditions.friction[i]
        if law is None:
            continue
        mine = (part == i) & ~corner
        what = f"the {type(law).__name__} bound of contact part {name!r}"
        values = np.asarray(
            law.nodal_weight(
                _integrator(space, facet_part == i, (facet_nodes, facet_local), what, k), k
            ),
            dtype=np.float64,
        )
        if values.shape != (k,) or not np.isfinite(values).all() or (values < 0).any():
            raise ProblemError(f"{what}: its nodal weights must be {k} finite numbers >= 0")
        index[mine] = len(laws)
        weight[mine] += values[mine]
        laws.append(law)
    return LawGroups(tuple(laws), index, weight)


def _integrator(space: LagrangeSpace, on_part: np.ndarray, facets: tuple, what: str, k: int):
    """``integrate(f)``: ``∫ f ψ_z ds`` over the facets ``on_part`` (of ``facets``, the contact
    facets' nodes and constraint rows; edges in 2D) per constraint ``(k,)``,
    by a 4-point Gauss rule along the (quadratic) edges; ``f`` must be ``≥ 0``."""
    facet_nodes, facet_local = facets
    t, w = gauss_legendre(4)
    sel = np.flatnonzero(on_part)

    def integrate(field) -> np.ndarray:
        points = space.node_points[facet_nodes[sel]]
        if points.shape[1] == 2:  # P1: straight edges [start, end]
            d = points[:, 1] - points[:, 0]
            x = points[:, None, 0] + t[None, :, None] * d[:, None]
            speed = np.broadcast_to(np.hypot(d[:, 0], d[:, 1])[:, None], x.shape[:2])
        else:
            x, speed, _ = iso.edge_geometry(points[:, :2], points[:, 2], t)
        s = evaluate_field(field, x.reshape(-1, 2), what, shape=())
        if (s < 0).any():
            raise ProblemError(f"{what} must be >= 0; it is {s.min():.6g} somewhere")
        # ∫ s ψ_j |x'(t)| dt on each edge, j = start, end, midpoint
        share = (s.reshape(-1, t.size) * speed * w) @ space.element.facet.basis(t)
        loc = facet_local[sel].ravel()
        inside = loc >= 0
        return np.bincount(loc[inside], weights=share.ravel()[inside], minlength=k)

    return integrate
