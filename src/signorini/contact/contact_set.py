"""The discrete contact boundary: constrained nodes, weights, contact forces, node classes.

Constrained nodes are all P2 nodes (vertices and midpoints) on the closure of Γ_C that are
not Dirichlet nodes; the discrete constraint is ``u_h(z)·n ≤ ψ(z)`` (paper, the set K^h of
Section 3). From the nodal contact force ``Λ_z = L(ψ_z n) − a(u_h, ψ_z n)`` (3.5), (3.9),
(3.17) we derive (docs/method.md, *Discrete problem*)

- the paper's contact force density ``s_z = Λ_z / m_z`` (4.1), with the lumped weights
  ``m_z = ∫ φ_z`` of the half-edge hats of Q^h (3.6): ``|e|/4`` per edge at a vertex,
  ``|e|/2`` at a midpoint;
- the consistent pressure ``p_z = Λ_z / w_z`` with ``w_z = ∫ ψ_z`` (Simpson weights
  ``|e|/6`` per edge at a vertex, ``2|e|/3`` at a midpoint), exact for linear pressures.
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
    """Discrete contact data of a P2 space (all arrays indexed by constrained node).

    Attributes
    ----------
    nodes : (k,) int array
        Global P2 node of each constrained node (sorted).
    normal : (k, 2) float array
        Outward unit normal of the node's contact part.
    gap : (k,) float array
        ψ(z).
    lumped : (k,) float array
        ``m_z``, the integral of the half-edge hat φ_z of Q^h (3.6).
    simpson : (k,) float array
        ``w_z = ∫_{Γ_C} ψ_z ds``, the integral of the P2 basis function.
    is_vertex : (k,) bool array
    edges : (n_ce,) int array
        Mesh edges of Γ_C.
    edge_nodes : (n_ce, 3) int array
        Global nodes ``[start, end, midpoint]`` of each contact edge (counter-clockwise).
    edge_part : (n_ce,) int array
        Index into ``parts`` of each contact edge.
    parts : tuple of str
    edge_gap : (n_ce, 3) float array
        ψ at ``[start, end, midpoint]`` (also at Dirichlet end points).
    edge_normal : (n_ce, 2) float array
    """

    nodes: np.ndarray
    normal: np.ndarray
    gap: np.ndarray
    lumped: np.ndarray
    simpson: np.ndarray
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


def contact_set(problem: ContactProblem, space: P2Space) -> ContactSet:
    """Collect the constrained nodes of ``space`` for ``problem`` (docs/method.md, *Discrete
    problem*).

    Raises
    ------
    ProblemError
        If a node is shared by contact parts with different normals.
    """
    mesh = space.mesh
    parts = tuple(problem.contact_parts)
    empty_i = np.zeros(0, dtype=np.int64)
    if not parts:
        z2 = np.zeros((0, 2))
        return ContactSet(
            empty_i,
            z2,
            np.zeros(0),
            np.zeros(0),
            np.zeros(0),
            np.zeros(0, bool),
            empty_i,
            np.zeros((0, 3), np.int64),
            empty_i,
            parts,
            np.zeros((0, 3)),
            z2,
        )
    edge_lists = [mesh.part_edges(p) for p in parts]
    edges = np.concatenate(edge_lists)
    edge_part = np.repeat(np.arange(len(parts)), [e.size for e in edge_lists])
    edge_nodes = space.edge_nodes(edges)
    edge_normal = np.stack([problem.contact_normals[p] for p in parts])[edge_part]
    length = mesh.edge_length[edges]

    # ψ at the edge nodes, part by part (each part has its own gap function)
    x = space.node_points[edge_nodes]  # (n_ce, 3, 2)
    edge_gap = np.empty(edge_nodes.shape)
    for i, p in enumerate(parts):
        sel = edge_part == i
        cond: Contact = problem.conditions[p]
        edge_gap[sel] = evaluate_field(
            cond.gap_field(), x[sel], f"the gap function of contact part {p!r}", shape=()
        )

    dirichlet = problem.dirichlet_nodes(space)
    nodes = np.setdiff1d(np.unique(edge_nodes), dirichlet)
    if nodes.size == 0:
        raise ProblemError("every node of the contact boundary is a Dirichlet node")

    # per-node normal; a node on two contact parts needs equal normals
    flat_nodes = edge_nodes.ravel()
    flat_normal = np.repeat(edge_normal, 3, axis=0)
    pos = _locate(nodes, flat_nodes)
    inside = pos >= 0
    normal = np.zeros((nodes.size, 2))
    normal[pos[inside]] = flat_normal[inside]
    if np.abs(normal[pos[inside]] - flat_normal[inside]).max(initial=0) > 1e-12:
        bad = nodes[
            pos[inside][np.abs(normal[pos[inside]] - flat_normal[inside]).max(1) > 1e-12][0]
        ]
        raise ProblemError(
            f"node {bad} at {space.node_points[bad].tolist()} lies on contact "
            "parts with different normals; this corner is not supported"
        )
    gap = np.zeros(nodes.size)
    gap[pos[inside]] = edge_gap.ravel()[inside]
    mismatch = np.abs(gap[pos[inside]] - edge_gap.ravel()[inside])
    scale = max(float(np.abs(edge_gap).max()), 1e-300)
    if mismatch.max(initial=0) > 1e-12 * scale:
        bad = nodes[pos[inside][np.argmax(mismatch)]]
        raise ProblemError(
            f"node {bad} at {space.node_points[bad].tolist()} lies on contact "
            "parts whose gap functions disagree there; the obstacle must be "
            "continuous"
        )

    weights = np.column_stack([length / 4, length / 4, length / 2]).ravel()
    simpson = np.column_stack([length / 6, length / 6, 2 * length / 3]).ravel()
    lumped = np.bincount(pos[inside], weights=weights[inside], minlength=nodes.size)
    w = np.bincount(pos[inside], weights=simpson[inside], minlength=nodes.size)
    return ContactSet(
        nodes=nodes,
        normal=normal,
        gap=gap,
        lumped=lumped,
        simpson=w,
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
