"""The discrete contact boundary: constrained nodes, weights, contact forces, node classes.

Constrained nodes are all P2 nodes (vertices and midpoints) on the closure of Γ_C that are
not Dirichlet nodes; the discrete constraint is ``u_h(z)·n ≤ ψ(z)`` (paper, the set K^h of
Section 3). From the nodal contact force ``Λ_z = L(ψ_z n) − a(u_h, ψ_z n)`` (3.5), (3.9),
(3.17) we derive (docs/method.md, *Discrete problem*)

- the paper's contact force density ``s_z = Λ_z / m_z`` (4.1), with ``m_z = ∫ φ_z ds`` the
  integral of the half-edge hat φ_z of Q^h (3.6) (:attr:`ContactSet.hat_integral`):
  ``|e|/4`` per edge at a vertex, ``|e|/2`` at a midpoint;
- the consistent pressure ``p_z = Λ_z / w_z`` with ``w_z = ∫_{Γ_C} ψ_z ds`` the integral of the
  P2 basis function (:attr:`ContactSet.basis_integral`): ``|e|/6`` per edge at a vertex,
  ``2|e|/3`` at a midpoint; exact for linear pressures.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from ..fem.space import P2Space
from ..problem.conditions import Contact
from ..problem.fields import ProblemError, evaluate_field
from ..problem.problem import ContactProblem

__all__ = [
    "ContactSet",
    "contact_set",
    "NO_CONTACT",
    "SEMI_CONTACT",
    "FULL_CONTACT",
    "node_classes",
]

NO_CONTACT, SEMI_CONTACT, FULL_CONTACT = 0, 1, 2


@dataclass(frozen=True)
class ContactSet:
    """Discrete contact data of a P2 space.

    Arrays of length k are indexed by constrained node (all P2 nodes on the closure of Γ_C
    that are not Dirichlet nodes), arrays of length n_ce by contact edge. Consistent units:
    if lengths are in mm, gaps and weights are in mm (the weights are lengths: integrals of
    dimensionless basis functions along Γ_C).

    Attributes
    ----------
    nodes : (k,) int array
        Global P2 node of each constrained node (sorted).
    normal : (k, 2) float array
        Outward unit normal of the node's contact part.
    gap : (k,) float array
        ψ(z), the admissible normal displacement (``u(z)·n ≤ ψ(z)``), in length units.
    hat_integral : (k,) float array
        ``m_z = ∫_{Γ_C} φ_z ds`` (length), the integral of the half-edge hat φ_z of Q^h
        (3.6): ``|e|/4`` per edge at a vertex, ``|e|/2`` at a midpoint; the contact force
        density is ``s_z = Λ_z / m_z`` (4.1).
    basis_integral : (k,) float array
        ``w_z = ∫_{Γ_C} ψ_z ds`` (length), the integral of the P2 basis function: ``|e|/6``
        per edge at a vertex, ``2|e|/3`` at a midpoint; the consistent pressure is
        ``p_z = Λ_z / w_z``.
    is_vertex : (k,) bool array
        Whether the node is a mesh vertex (else an edge midpoint).
    edges : (n_ce,) int array
        Mesh edges of Γ_C, part after part.
    edge_nodes : (n_ce, 3) int array
        Global nodes ``[start, end, midpoint]`` of each contact edge, start to end in the
        counter-clockwise direction of the boundary (Dirichlet nodes included).
    edge_part : (n_ce,) int array
        Index into ``parts`` of each contact edge.
    parts : tuple of str
        The contact parts, in the problem's order.
    edge_gap : (n_ce, 3) float array
        ψ at ``[start, end, midpoint]`` (also at Dirichlet end points).
    edge_normal : (n_ce, 2) float array
        Outward unit normal of each contact edge (its part's).
    """

    nodes: np.ndarray
    normal: np.ndarray
    gap: np.ndarray
    hat_integral: np.ndarray
    basis_integral: np.ndarray
    is_vertex: np.ndarray
    edges: np.ndarray
    edge_nodes: np.ndarray
    edge_part: np.ndarray
    parts: tuple[str, ...]
    edge_gap: np.ndarray
    edge_normal: np.ndarray

    @property
    def size(self) -> int:
        return self.nodes.size

    @property
    def dofs(self) -> np.ndarray:
        """Interleaved DOFs ``(k, 2)`` of the constrained nodes."""
        return np.column_stack([2 * self.nodes, 2 * self.nodes + 1])

    @cached_property
    def edge_local(self) -> np.ndarray:
        """``(n_ce, 3)`` position in this set of each contact edge's nodes, ``-1`` for
        Dirichlet nodes."""
        return self.local(self.edge_nodes.ravel()).reshape(-1, 3)

    def local(self, nodes: np.ndarray) -> np.ndarray:
        """Position in this set of global nodes, ``-1`` for nodes that are not constrained."""
        return _locate(self.nodes, np.asarray(nodes))

    def normal_displacement(self, u: np.ndarray) -> np.ndarray:
        """``u(z)·n`` at the constrained nodes, for nodal values ``u (n_nodes, 2)``."""
        return np.einsum("kc,kc->k", u[self.nodes], self.normal)

    def edge_normal_gap(self, u: np.ndarray) -> np.ndarray:
        """``u·n − ψ`` at ``[start, end, midpoint]`` of each contact edge, ``(n_ce, 3)``."""
        un = np.einsum("ejc,ec->ej", u[self.edge_nodes], self.edge_normal)
        return un - self.edge_gap


def _locate(sorted_nodes: np.ndarray, query: np.ndarray) -> np.ndarray:
    """Position of ``query`` entries in the sorted array ``sorted_nodes``, ``-1`` if absent."""
    if sorted_nodes.size == 0:
        return np.full(query.shape, -1, dtype=np.int64)
    pos = np.minimum(np.searchsorted(sorted_nodes, query), sorted_nodes.size - 1)
    return np.where(sorted_nodes[pos] == query, pos, -1)


def _empty(parts: tuple[str, ...]) -> ContactSet:
    """The contact set of a problem without contact parts."""
    no_int, no_edges = np.zeros(0, dtype=np.int64), np.zeros((0, 3), dtype=np.int64)
    return ContactSet(
        nodes=no_int,
        normal=np.zeros((0, 2)),
        gap=np.zeros(0),
        hat_integral=np.zeros(0),
        basis_integral=np.zeros(0),
        is_vertex=np.zeros(0, dtype=bool),
        edges=no_int,
        edge_nodes=no_edges,
        edge_part=no_int,
        parts=parts,
        edge_gap=np.zeros((0, 3)),
        edge_normal=np.zeros((0, 2)),
    )


def _edge_gaps(
    problem: ContactProblem, parts: tuple[str, ...], edge_part: np.ndarray, x: np.ndarray
) -> np.ndarray:
    """ψ at the nodes ``x (n_ce, 3, 2)`` of the contact edges, part by part (each part has its
    own gap function), shape ``(n_ce, 3)``."""
    edge_gap = np.empty(x.shape[:-1])
    for i, p in enumerate(parts):
        sel = edge_part == i
        cond: Contact = problem.conditions[p]
        edge_gap[sel] = evaluate_field(
            cond.gap_field(), x[sel], f"the gap function of contact part {p!r}", shape=()
        )
    return edge_gap


def _to_nodes(pos: np.ndarray, values: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Values per constrained node from values per edge node (``pos`` its position in the set,
    ``-1`` for Dirichlet nodes), and how far each edge node's value is from its node's."""
    inside = pos >= 0
    out = np.zeros((n,) + values.shape[1:])
    out[pos[inside]] = values[inside]
    diff = np.abs(out[pos[inside]] - values[inside])
    return out, diff.reshape(diff.shape[0], -1).max(axis=1, initial=0.0)


def contact_set(problem: ContactProblem, space: P2Space) -> ContactSet:
    """Collect the constrained nodes of ``space`` for ``problem`` (docs/method.md, *Discrete
    problem*).

    Raises
    ------
    ProblemError
        If every contact node is a Dirichlet node, a node is shared by contact parts with
        different normals or gaps, or a gap function does not return finite numbers.
    """
    mesh = space.mesh
    parts = tuple(problem.contact_parts)
    if not parts:
        return _empty(parts)
    edge_lists = [mesh.part_edges(p) for p in parts]
    edges = np.concatenate(edge_lists)
    edge_part = np.repeat(np.arange(len(parts)), [e.size for e in edge_lists])
    edge_nodes = space.edge_nodes(edges)
    edge_normal = np.stack([problem.contact_normals[p] for p in parts])[edge_part]
    edge_gap = _edge_gaps(problem, parts, edge_part, space.node_points[edge_nodes])

    nodes = np.setdiff1d(np.unique(edge_nodes), problem.dirichlet_nodes(space))
    if nodes.size == 0:
        raise ProblemError("every node of the contact boundary is a Dirichlet node")
    # a node on two contact parts needs equal normals and equal gaps
    pos = _locate(nodes, edge_nodes.ravel())
    inside = pos >= 0
    normal, off = _to_nodes(pos, np.repeat(edge_normal, 3, axis=0), nodes.size)
    if off.max(initial=0.0) > 1e-12:
        bad = nodes[pos[inside][np.flatnonzero(off > 1e-12)[0]]]
        raise ProblemError(
            f"node {bad} at {space.node_points[bad].tolist()} lies on contact "
            "parts with different normals; this corner is not supported"
        )
    gap, off = _to_nodes(pos, edge_gap.ravel(), nodes.size)
    if off.max(initial=0.0) > 1e-12 * max(float(np.abs(edge_gap).max()), 1e-300):
        bad = nodes[pos[inside][np.argmax(off)]]
        raise ProblemError(
            f"node {bad} at {space.node_points[bad].tolist()} lies on contact "
            "parts whose gap functions disagree there; the obstacle must be "
            "continuous"
        )

    # per edge [start, end, midpoint]: ∫ φ_z (half-edge hats) and ∫ ψ_z (P2 basis)
    length = mesh.edge_length[edges]
    hat = np.column_stack([length / 4, length / 4, length / 2]).ravel()
    basis = np.column_stack([length / 6, length / 6, 2 * length / 3]).ravel()
    return ContactSet(
        nodes=nodes,
        normal=normal,
        gap=gap,
        hat_integral=np.bincount(pos[inside], weights=hat[inside], minlength=nodes.size),
        basis_integral=np.bincount(pos[inside], weights=basis[inside], minlength=nodes.size),
        is_vertex=nodes < mesh.n_points,
        edges=edges,
        edge_nodes=edge_nodes,
        edge_part=edge_part,
        parts=parts,
        edge_gap=edge_gap,
        edge_normal=edge_normal,
    )


def node_classes(cs: ContactSet, in_contact: np.ndarray, edge_in_contact: np.ndarray) -> np.ndarray:
    """Full / semi / no contact class of each constrained node (paper, Section 4).

    Parameters
    ----------
    cs : ContactSet
    in_contact : (k,) bool array
        Actual contact nodes (``u_h(z)·n = ψ(z)``).
    edge_in_contact : (n_ce, 3) bool array
        Whether each node ``[start, end, midpoint]`` of each contact edge is in contact
        (for Dirichlet end points: whether ``u_D·n = ψ`` there).

    Returns
    -------
    (k,) int array of ``NO_CONTACT``, ``SEMI_CONTACT``, ``FULL_CONTACT``.
    """
    edge_full = edge_in_contact.all(axis=1)
    loc = cs.edge_local.ravel()
    touching = loc >= 0
    broken = np.bincount(
        loc[touching], weights=np.repeat(~edge_full, 3)[touching], minlength=cs.size
    )
    classes = np.full(cs.size, NO_CONTACT, dtype=np.int64)
    classes[in_contact] = SEMI_CONTACT
    classes[in_contact & (broken == 0)] = FULL_CONTACT
    return classes
