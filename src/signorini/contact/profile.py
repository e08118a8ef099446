"""The contact quantities of one contact part, ordered along the boundary."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from .solution import ContactResult

__all__ = ["ContactProfile", "contact_profile"]


@dataclass(frozen=True)
class ContactProfile:
    """The nodes of one contact part in order along the boundary, with the contact quantities.

    Consistent units: if E is in MPa and lengths in mm, ``s``, ``points``, ``gap``,
    ``normal_displacement`` and ``normal_gap`` are in mm, ``pressure`` in MPa and
    ``contact_force`` in N per mm of thickness.

    Attributes
    ----------
    part : str
        The contact part.
    nodes : (m,) int array
        Global P2 nodes (vertices and edge midpoints) of the part, in the order of the
        counter-clockwise boundary.
    chain : (m,) int array
        Which connected piece of the part each node is on: 0, 1, … in the order of the pieces
        along the part's direction (a part made of disjoint segments has several chains).
    s : (m,) float array
        Distance from the part's first node: ``s_0 = 0``, ``s_{i+1} = s_i + |x_{i+1} − x_i|``.
        Within a chain this is the length of the polygon through the nodes (the arc length
        on a straight part); from one chain to the next it jumps by the straight distance
        between them.
    points : (m, 2) float array
        The nodes' coordinates.
    pressure : (m,) float array
        Consistent pressure ``p_z = Λ_z / w_z`` (docs/method.md, *Discrete problem*); NaN at
        Dirichlet nodes (no contact unknown there).
    contact_force : (m,) float array
        Nodal contact force ``Λ_z`` (3.17); NaN at Dirichlet nodes. A node shared with another
        contact part carries its whole ``Λ_z`` (and ``w_z`` counts both parts' edges).
    gap : (m,) float array
        The obstacle ψ(z).
    normal_displacement : (m,) float array
        ``u_h(z)·n_z``, n_z the part's constraint direction at the node.
    normal_gap : (m,) float array
        ``u_h(z)·n − ψ(z)``: 0 in contact, < 0 where the body is off the obstacle.
    """

    part: str
    nodes: np.ndarray
    chain: np.ndarray
    s: np.ndarray
    points: np.ndarray
    pressure: np.ndarray
    contact_force: np.ndarray
    gap: np.ndarray
    normal_displacement: np.ndarray
    normal_gap: np.ndarray


def contact_profile(result: ContactResult, part: str | None = None) -> ContactProfile:
    """The contact quantities of one contact part, ordered along the boundary.

    Parameters
    ----------
    result : ContactResult
    part : str, optional
        A contact part of the problem; may be omitted when there is only one.

    Returns
    -------
    ContactProfile
        Every P2 node of the part (Dirichlet end points included) in the order of the
        counter-clockwise boundary, with arc length, p_z, Λ_z, ψ, u·n and u·n − ψ. A part
        made of disjoint segments gives one ``chain`` per segment, in the order of the
        segments along the part's direction.

    Examples
    --------
    >>> prof = result.contact_profile("right")                    # doctest: +SKIP
    >>> plt.plot(prof.s, prof.pressure)                           # doctest: +SKIP
    """
    cs = result.contact
    if part is None:
        if len(cs.parts) != 1:
            raise ValueError(
                f"part: the problem has contact parts {list(cs.parts)}; name one of them"
            )
        part = cs.parts[0]
    if part not in cs.parts:
        raise ValueError(
            f"part: {part!r} is not a contact part of {result.problem.name!r}; its contact "
            f"parts are {list(cs.parts)}"
        )
    mine = np.flatnonzero(cs.facet_part == cs.parts.index(part))
    order, chain_end, chain = _walk(cs.facet_nodes[mine], result.space.node_points)
    edges = mine[order]
    # per ordered edge: start, midpoint (P2; P1 edges have none), and the end vertex where a
    # chain ends
    inner = [np.ones(edges.size, bool)] * (cs.facet_nodes.shape[1] - 1)
    take = np.column_stack([*inner, chain_end])
    order_of = np.array([0, 2, 1]) if cs.facet_nodes.shape[1] == 3 else np.array([0, 1])
    column = np.broadcast_to(order_of, take.shape)[take]
    row = np.broadcast_to(edges[:, None], take.shape)[take]
    nodes = cs.facet_nodes[row, column]
    points = result.space.node_points[nodes]
    step = np.sqrt((np.diff(points, axis=0) ** 2).sum(axis=1))
    loc = cs.facet_local[row, column]
    inside = loc >= 0
    force = np.where(inside, result.contact_force[np.maximum(loc, 0)], np.nan)
    gap = cs.facet_gap[row, column]
    un = np.einsum("kc,kc->k", result.u[nodes], cs.facet_direction[row, column])
    return ContactProfile(
        part=part,
        nodes=nodes,
        chain=np.broadcast_to(chain[:, None], take.shape)[take],
        s=np.concatenate([[0.0], np.cumsum(step)]),
        points=points,
        pressure=np.where(
            inside,
            result.space.element.facet.pressure(force, cs.basis_integral[np.maximum(loc, 0)]),
            np.nan,
        ),
        contact_force=force,
        gap=gap,
        normal_displacement=un,
        normal_gap=un - gap,
    )


def _walk(edge_nodes: np.ndarray, node_points: np.ndarray):
    """Order the oriented edges ``[start, end, midpoint]`` of one straight contact part into
    chains (each edge's end is the next edge's start), vectorized by pointer doubling.

    Returns
    -------
    order : (k,) int array
        The edges, chain after chain, each chain from its first edge.
    chain_end : (k,) bool array
        For the ordered edges: the last edge of its chain.
    chain : (k,) int array
        For the ordered edges: the chain number, chains ordered along the part's direction.
    """
    k = edge_nodes.shape[0]
    start, end = edge_nodes[:, 0], edge_nodes[:, 1]
    by_start = np.argsort(start, kind="stable")
    pos = np.minimum(np.searchsorted(start[by_start], end), k - 1)
    succ = np.where(start[by_start][pos] == end, by_start[pos], -1)
    pred = np.full(k, -1)
    pred[succ[succ >= 0]] = np.flatnonzero(succ >= 0)
    # pointer doubling: every edge finds its chain's first edge and its distance to it
    root = np.where(pred >= 0, pred, np.arange(k))
    rank = (pred >= 0).astype(np.int64)  # distance to ``root``
    for _ in range(int(np.ceil(np.log2(max(k, 2)))) + 1):
        rank, root = rank + rank[root], root[root]
    if np.any(pred[root] >= 0):  # a closed chain: impossible for a straight part
        raise ValueError("the contact part is a closed curve; it has no first node")
    # chains in the order of their first point along the (straight) part
    first = np.flatnonzero(pred < 0)
    direction = node_points[end[first[0]]] - node_points[start[first[0]]]
    along = node_points[start[first]] @ direction
    chain_of_root = np.empty(k, dtype=np.int64)
    chain_of_root[first[np.argsort(along, kind="stable")]] = np.arange(first.size)
    chain = chain_of_root[root]
    order = np.lexsort((rank, chain))
    return order, succ[order] < 0, chain[order]
