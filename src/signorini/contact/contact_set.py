"""The discrete contact boundary: constraints, weights, contact forces, node classes.

Constrained nodes are all P2 nodes (vertices and midpoints) on the closure of Γ_C that are
not Dirichlet nodes. Each carries a constraint ``u_h(z)·n_z ≤ ψ(z)`` (paper, the set K^h of
Section 3) with its own direction n_z and gap ψ(z) (docs/method.md, *Contact directions*): the
body's outward normal for a gap given along it, the obstacle's inward normal at the closest
point for a shape. A node where two contact parts meet at an angle (a corner) carries one
constraint per part. From the nodal contact force ``Λ_z = L(ψ_z n_z) − a(u_h, ψ_z n_z)``
(3.5), (3.9), (3.17) we derive (docs/method.md, *Discrete problem*)

- the paper's contact force density ``s_z = Λ_z / m_z`` (4.1), with ``m_z = ∫ φ_z ds`` the
  integral of the half-edge hat φ_z of Q^h (3.6) (:attr:`ContactSet.hat_integral`):
  ``|e|/4`` per edge at a vertex, ``|e|/2`` at a midpoint;
- the consistent pressure ``p_z = Λ_z / w_z`` with ``w_z = ∫_{Γ_C} ψ_z ds`` the integral of the
  P2 basis function (:attr:`ContactSet.basis_integral`): ``|e|/6`` per edge at a vertex,
  ``2|e|/3`` at a midpoint; exact for linear pressures.

On a curved edge both integrals are taken along the quadratic edge (docs/method.md, *Curved
boundaries*).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from ..algebra.friction.laws import LawGroups
from ..fem.space import LagrangeSpace
from ..mesh.geometry import facet_normals
from ..problem.fields import ProblemError
from .admissible import check_dirichlet_admissible, check_initial_overlap, check_obstacle_side
from .constraint_data import directions_and_gaps, facet_weights, friction_data
from .discrete_conditions import DiscreteConditions
from .mortar import mortar_coupling
from .rows import MIN_CORNER_ANGLE, SAME_DIRECTION, constraint_rows
from .two_body import PairTransfer, pair_transfer

__all__ = [
    "ContactSet",
    "contact_set",
    "NO_CONTACT",
    "SEMI_CONTACT",
    "FULL_CONTACT",
    "node_classes",
    "SAME_DIRECTION",
    "MIN_CORNER_ANGLE",
]

NO_CONTACT, SEMI_CONTACT, FULL_CONTACT = 0, 1, 2


@dataclass(frozen=True)
class ContactSet:
    """Discrete contact data of a P2 space: one row per constraint.

    Arrays of length k are indexed by constraint, sorted by node; a corner node (two contact
    parts meeting at an angle) has two rows, the first bounding the DOF ``2z`` and the second
    ``2z + 1`` of the node's frame. Arrays of length n_cf are indexed by contact facet (an
    edge in 2D).
    Consistent units: if lengths are in mm, gaps and weights are in mm (the weights are
    lengths: integrals of dimensionless basis functions along Γ_C).

    Attributes
    ----------
    nodes : (k,) int array
        Global P2 node of each constraint (sorted; a corner node twice).
    normal : (k, 2) float array
        The constraint direction n_z (unit): the body's outward normal for a gap function,
        the obstacle's normal pointing into it for a shape.
    gap : (k,) float array
        ψ(z), the admissible displacement along n_z (``u(z)·n_z ≤ ψ(z)``), in length units.
    part : (k,) int array
        Index into ``parts`` of the constraint's contact part (its zone).
    second : (k,) bool array
        Whether the row is the second constraint of a corner node.
    hat_integral : (k,) float array
        ``m_z = ∫ φ_z ds`` (length) over the constraint's part(s), the integral of the
        half-edge hat φ_z of Q^h (3.6); the contact force density is ``s_z = Λ_z / m_z``
        (4.1).
    basis_integral : (k,) float array
        ``w_z = ∫ ψ_z ds`` (length) over the constraint's part(s), the integral of the P2
        basis function; the consistent pressure is ``p_z = Λ_z / w_z``.
    is_vertex : (k,) bool array
        Whether the node is a mesh vertex (else an edge midpoint).
    facets : (n_cf,) int array
        Mesh facets of Γ_C (edges in 2D), part after part.
    facet_nodes : (n_cf, 3) int array
        Global nodes ``[start, end, midpoint]`` (P1: ``(n_cf, 2)``, ``[start, end]``; the
        other per-facet-node arrays likewise) of each contact facet, start to end in the
        counter-clockwise direction of the boundary (Dirichlet nodes included).
    facet_part : (n_cf,) int array
        Index into ``parts`` of each contact facet.
    parts : tuple of str
        The contact parts, in the problem's order.
    facet_gap : (n_cf, 3) float array
        ψ at ``[start, end, midpoint]`` for the facet's part (also at Dirichlet end points).
    facet_direction : (n_cf, 3, 2) float array
        The constraint direction at ``[start, end, midpoint]`` for the facet's part.
    facet_normal : (n_cf, 2) float array
        Outward unit normal of each contact facet's chord.
    facet_local : (n_cf, 3) int array
        Row of the constraint of each contact facet's nodes (for the facet's part), ``-1``
        at Dirichlet nodes.
    friction : LawGroups
        The friction laws of the frictional parts (:mod:`signorini.algebra.friction.laws`), the law
        of each constraint (``-1``: frictionless; a corner's constraints are frictionless)
        and its nodal weight (Tresca: ``s_z = ∫ s ψ_z ds`` over the constraint's part, force
        per unit thickness; Coulomb: its coefficient F); docs/method.md, *Friction*.
    transfer : PairTransfer or None
        With contact pairs between two bodies, the mortar transfer of
        :mod:`~signorini.contact.two_body`: the constraints bound the relative displacement
        ``ũ = u − T_d u`` (:meth:`relative`); ``None`` without pairs (``ũ = u``).

    Derived: ``tangent`` (the tangent space of each constraint as a basis beside its
    normal), ``facet_tangent``, ``frames``, ``has_friction``.
    """

    nodes: np.ndarray
    normal: np.ndarray
    gap: np.ndarray
    part: np.ndarray
    second: np.ndarray
    hat_integral: np.ndarray
    basis_integral: np.ndarray
    is_vertex: np.ndarray
    facets: np.ndarray
    facet_nodes: np.ndarray
    facet_part: np.ndarray
    parts: tuple[str, ...]
    facet_gap: np.ndarray
    facet_direction: np.ndarray
    facet_normal: np.ndarray
    facet_local: np.ndarray
    friction: LawGroups
    transfer: PairTransfer | None = None

    @property
    def size(self) -> int:
        return self.nodes.size

    @property
    def has_friction(self) -> bool:
        """Whether some constraint has a friction law."""
        return self.friction.any

    @property
    def couples_bodies(self) -> bool:
        """Whether the constraints couple bodies (contact pairs' mortar transfer)."""
        return self.transfer is not None

    @cached_property
    def tangent(self) -> np.ndarray:
        """``(k, 1, 2)`` an orthonormal basis of the tangent space of each constraint, beside
        its normal: ``t_z = (−n_y, n_x)`` (``[n_z t_z]`` is a rotation)."""
        return _tangents(self.normal)

    @cached_property
    def facet_tangent(self) -> np.ndarray:
        """``(n_cf, 3, 1, 2)`` the tangent basis beside :attr:`facet_direction` at
        ``[start, end, midpoint]`` of each contact facet."""
        return _tangents(self.facet_direction)

    @property
    def constrained_dofs(self) -> np.ndarray:
        """``(k,)`` the DOF each constraint bounds in the node frames: ``d z`` (``d z + 1``
        for a corner's second constraint), ``d = normal.shape[1]`` the components a node."""
        return self.normal.shape[1] * self.nodes + self.second

    @cached_property
    def frame_nodes(self) -> np.ndarray:
        """``(m,)`` the distinct constrained nodes (sorted)."""
        return self.nodes[~self.second]

    @cached_property
    def frames(self) -> np.ndarray:
        """``(m, 2, 2)`` the frame ``Q_z`` of each of :attr:`frame_nodes` (``u = Q_z y``):
        the rotation ``[n t]`` for one constraint, ``A_z^{-1}`` with rows ``n, m`` of ``A_z``
        for a corner's two (docs/method.md, *Contact directions*)."""
        first = np.flatnonzero(~self.second)
        Q = np.stack([self.normal[first], self.tangent[first, 0]], axis=-1)
        corner = np.flatnonzero(self.second)
        if corner.size:
            A = np.stack([self.normal[corner - 1], self.normal[corner]], axis=1)
            Q[np.searchsorted(self.frame_nodes, self.nodes[corner])] = np.linalg.inv(A)
        return Q

    def local(self, nodes: np.ndarray) -> np.ndarray:
        """Row of the (first) constraint of global nodes, ``-1`` for nodes that are not
        constrained."""
        return _locate(self.frame_nodes, np.asarray(nodes), np.flatnonzero(~self.second))

    def relative(self, u: np.ndarray) -> np.ndarray:
        """The displacement ``ũ = u − T_d u`` the constraints bound, for nodal values
        ``u (n_nodes, 2)``: ``u`` itself without contact pairs (docs/method.md, *Two
        bodies*)."""
        u = np.asarray(u)
        if self.transfer is None:
            return u
        return u - (self.transfer.dofs @ u.ravel()).reshape(u.shape)

    def normal_displacement(self, u: np.ndarray) -> np.ndarray:
        """``ũ(z)·n_z`` per constraint, for nodal values ``u (n_nodes, 2)``
        (:meth:`relative`)."""
        return np.einsum("kc,kc->k", self.relative(u)[self.nodes], self.normal)

    def facet_relative(self, u: np.ndarray) -> np.ndarray:
        """The relative displacement ``u − T u`` at ``[start, end, midpoint]`` of each contact
        facet ``(n_cf, 3, 2)``, Dirichlet end points of a pair's slave included (``u``
        itself without pairs)."""
        u = np.asarray(u)
        if self.transfer is not None:
            u = u - (self.transfer.every_slave @ u.ravel()).reshape(u.shape)
        return u[self.facet_nodes]

    def facet_normal_gap(self, u: np.ndarray) -> np.ndarray:
        """``ũ·n_z − ψ`` at ``[start, end, midpoint]`` of each contact facet, ``(n_cf, 3)``."""
        un = np.einsum("ejc,ejc->ej", self.facet_relative(u), self.facet_direction)
        return un - self.facet_gap


def _tangents(normal: np.ndarray) -> np.ndarray:
    """``(..., 1, 2)`` the tangent ``(−n_y, n_x)`` of unit normals ``(..., 2)``, as a basis."""
    return np.stack([-normal[..., 1], normal[..., 0]], axis=-1)[..., None, :]


def _locate(sorted_keys: np.ndarray, query: np.ndarray, rows: np.ndarray | None = None):
    """Position of ``query`` entries in the sorted array ``sorted_keys`` (mapped through
    ``rows`` if given), ``-1`` if absent."""
    if sorted_keys.size == 0:
        return np.full(query.shape, -1, dtype=np.int64)
    pos = np.minimum(np.searchsorted(sorted_keys, query), sorted_keys.size - 1)
    found = sorted_keys[pos] == query
    return np.where(found, pos if rows is None else rows[pos], -1)


def _empty(parts: tuple[str, ...]) -> ContactSet:
    """The contact set of a problem without contact parts."""
    no_int, no_facets = np.zeros(0, dtype=np.int64), np.zeros((0, 3), dtype=np.int64)
    return ContactSet(
        nodes=no_int,
        normal=np.zeros((0, 2)),
        gap=np.zeros(0),
        part=no_int,
        second=np.zeros(0, dtype=bool),
        hat_integral=np.zeros(0),
        basis_integral=np.zeros(0),
        is_vertex=np.zeros(0, dtype=bool),
        facets=no_int,
        facet_nodes=no_facets,
        facet_part=no_int,
        parts=parts,
        facet_gap=np.zeros((0, 3)),
        facet_direction=np.zeros((0, 3, 2)),
        facet_normal=np.zeros((0, 2)),
        facet_local=no_facets,
        friction=LawGroups((), no_int, np.zeros(0)),
    )


def contact_set(conditions: DiscreteConditions, space: LagrangeSpace) -> ContactSet:
    """Collect the constraints of ``space`` for a problem's ``conditions`` on it
    (:func:`~.discrete_conditions.discrete_conditions`; docs/method.md, *Discrete problem*
    and *Contact directions*).

    Raises
    ------
    ProblemError
        If every contact node is a Dirichlet node, a Dirichlet value violates the contact
        constraint at a node shared with a contact part
        (:func:`check_dirichlet_admissible`), an obstacle shape lies on the body's side of its
        contact part (:func:`check_obstacle_side`), an obstacle starts deeper inside the body than a
        quarter of its size (:func:`check_initial_overlap`), contact parts with the same
        direction at a shared node have different gaps, two directions at a corner are nearly
        parallel, a node lies on more than two contact parts, or a gap function or obstacle
        does not give finite numbers.
    """
    mesh = space.mesh
    d = space.n_components
    parts = conditions.contact_parts
    if not parts:
        return _empty(parts)
    facet_lists = [mesh.part_facets(p) for p in parts]
    facets = np.concatenate(facet_lists)
    facet_part = np.repeat(np.arange(len(parts)), [e.size for e in facet_lists])
    facet_nodes = space.facet_nodes(facets)
    _, chord = facet_normals(mesh.points[facet_nodes[:, :2]])
    for i in range(len(parts)):  # straight parts: exactly their normal
        if conditions.straight(i) is not None:
            chord[facet_part == i] = conditions.straight_normal[i]
    dirichlet = conditions.dirichlet_nodes
    couplings = {  # the slave's Dirichlet nodes carry no constraint
        s: mortar_coupling(space, s, m, constrained=np.setdiff1d(space.part_nodes([s]), dirichlet))
        for s, m in conditions.pairs.items()
    }
    direction, facet_gap = directions_and_gaps(
        conditions, space, (parts, facet_part, facet_nodes), chord, couplings
    )
    cs_facets = (parts, facet_part, facet_nodes)
    check_obstacle_side(conditions, space, cs_facets, chord, (direction, facet_gap))

    # candidates: one per (node, part), Dirichlet nodes left out
    n_parts = len(parts)
    key = (facet_nodes * n_parts + facet_part[:, None]).ravel()
    ukey, first, cand_of = np.unique(key, return_index=True, return_inverse=True)
    cand_node = ukey // n_parts
    free = ~np.isin(cand_node, dirichlet)
    if not free.any():
        raise ProblemError("every node of the contact boundary is a Dirichlet node")
    held = np.flatnonzero(~free)
    check_dirichlet_admissible(
        conditions,
        space,
        cand_node[held],
        (direction.reshape(-1, d)[first[held]], facet_gap.ravel()[first[held]]),
        (parts, ukey[held] % n_parts),
        couplings,
    )
    kept = np.flatnonzero(free)
    check_initial_overlap(
        conditions,
        space,
        cand_node[kept],
        (direction.reshape(-1, d)[first[kept]], facet_gap.ravel()[first[kept]]),
        (parts, ukey[kept] % n_parts),
    )
    row_of, starts = constraint_rows(
        cand_node[kept],
        direction.reshape(-1, d)[first[kept]],
        facet_gap.ravel()[first[kept]],
        space.node_points,
        (parts, ukey[kept] % n_parts),
    )
    cand_row = np.full(ukey.size, -1)
    cand_row[kept] = row_of
    facet_local = cand_row[cand_of].reshape(facet_nodes.shape)
    lead = kept[starts]
    nodes = cand_node[lead]
    if np.unique(nodes, return_counts=True)[1].max() > 2:
        raise ProblemError("a node lies on more than two contact parts with different directions")
    second = np.concatenate([[False], nodes[1:] == nodes[:-1]])

    hat, basis = facet_weights(space, facets, facet_nodes)
    loc = facet_local.ravel()
    inside = loc >= 0
    k = nodes.size
    part = ukey[lead] % n_parts
    normal = direction.reshape(-1, d)[first[lead]]
    friction = friction_data(conditions, space, facet_part, facet_nodes, facet_local, part, second)
    return ContactSet(
        nodes=nodes,
        normal=normal,
        gap=facet_gap.ravel()[first[lead]],
        part=part,
        second=second,
        hat_integral=np.bincount(loc[inside], weights=hat.ravel()[inside], minlength=k),
        basis_integral=np.bincount(loc[inside], weights=basis.ravel()[inside], minlength=k),
        is_vertex=nodes < mesh.n_points,
        facets=facets,
        facet_nodes=facet_nodes,
        facet_part=facet_part,
        parts=parts,
        facet_gap=facet_gap,
        facet_direction=direction,
        facet_normal=chord,
        facet_local=facet_local,
        friction=friction,
        transfer=pair_transfer(
            space,
            couplings,
            (nodes, part, second, normal, friction.index >= 0),
            parts,
            tuple(conditions.pairs[s] for s in couplings),
        ),
    )


def node_classes(
    cs: ContactSet, in_contact: np.ndarray, facet_in_contact: np.ndarray
) -> np.ndarray:
    """Full / semi / no contact class of each constrained node (paper, Section 4).

    Parameters
    ----------
    cs : ContactSet
    in_contact : (k,) bool array
        Actual contact nodes (``u_h(z)·n = ψ(z)``).
    facet_in_contact : (n_cf, 3) bool array
        Whether each node ``[start, end, midpoint]`` of each contact facet (an edge in 2D)
        is in contact
        (for Dirichlet end points: whether ``u_D·n = ψ`` there).

    Returns
    -------
    (k,) int array of ``NO_CONTACT``, ``SEMI_CONTACT``, ``FULL_CONTACT``.
    """
    facet_full = facet_in_contact.all(axis=1)
    loc = cs.facet_local.ravel()
    touching = loc >= 0
    broken = np.bincount(
        loc[touching],
        weights=np.repeat(~facet_full, cs.facet_local.shape[1])[touching],
        minlength=cs.size,
    )
    classes = np.full(cs.size, NO_CONTACT, dtype=np.int64)
    classes[in_contact] = SEMI_CONTACT
    classes[in_contact & (broken == 0)] = FULL_CONTACT
    return classes
