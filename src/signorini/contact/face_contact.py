"""The contact set on faces: the constraints of Γ_C at the P2 nodes of its faces in three
dimensions, their frames, the transformed face basis and the contact force and pressures
(docs/method.md, *Three dimensions: contact on faces*).

Every P2 node ``z`` (vertices and edge midpoints) of a contact part's faces carries a
constraint row ``u_h(z)·n_z ≤ ψ(z)`` for that part, unless the held Cartesian components at
``z`` fix ``u·n_z`` (a Dirichlet node, or a roller along ``n_z``). Directions: the obstacle's
at its closest point for a shape; for a gap function the part's given normal, the surface's
normal on a curved part, or else the body's normal, the normalised mean of the unit normals of
the part's faces at ``z``. A node of several parts carries one row per part, rows of one
direction (within :data:`SAME_DIRECTION`) merged into the first part's, as 2D corners do.
A node with rows takes the frame of its rows and held directions
(:func:`~.node_frames3d.row_frames`); condition (b) transforms the rows by the face basis of
:mod:`.face_basis` (condition (a): α = 0).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import scipy.sparse as sp

from ..fem.facet_element import FaceElement
from ..fem.quadrature import triangle_rule
from ..problem.conditions import Contact
from ..problem.fields import ProblemError, evaluate_field
from ..problem.normals import face_node_normals
from ..problem.rollers import HeldNodes
from ..problem.rollers3d import held_basis, span_residual
from .face_basis import DEFAULT_ALPHA, FaceEdges, change_of_variables, face_edges
from .face_checks import check_deep_overlap, given_directions
from .face_fields import FaceFields
from .face_friction import FaceFriction
from .node_frames3d import frame_operator, held_frames, to_frames_3d

if TYPE_CHECKING:
    from ..fem.space3d import P2TetSpace

__all__ = ["SAME_DIRECTION", "FaceContactSet", "face_contact_set", "row_weights"]

#: two rows at a node whose directions differ by less than this (max-norm) are one row
SAME_DIRECTION = 1e-8


@dataclass(frozen=True)
class FaceContactSet:
    """The constraints of Γ_C on P2 faces, one row per constraint (sorted by node, then part).

    Attributes
    ----------
    n_dofs : int
    node, part : (k,) int arrays
        Each row's node and contact part (index into ``parts``).
    parts : tuple of str
    direction : (k, 3) float array
        ``n_z``, unit.
    psi : (k,) float array
        ``ψ(z)``, the gap along ``n_z`` (the bounds of the solver's variables are
        :attr:`gap`).
    dof : (k,) int array
        The frame DOF the row bounds, ``3 z + j``.
    frame_nodes : (m,) int array
        The nodes with rows; ``frames (m, 3, 3)`` their ``Q_z`` (``u(z) = Q_z y_z``).
    frames : (m, 3, 3) float array
    held_dofs : (n_h,) int array
        The held DOFs in the frame variables; ``held_values (n_h,)`` their values.
    held_values : (n_h,) float array
    faces : (n_f, 6) int array
        The P2 nodes of the contact faces; ``face_part (n_f,)`` their parts.
    face_part : (n_f,) int array
    edges : FaceEdges
        The transformed basis on the rows (α = 0: condition (a)).
    basis_integral : (k,) float array
        ``w_z = ∫_{Γ_C} ψ_z`` over the row's part (zero at the vertices of flat faces).
    hat_integral : (k,) float array
        ``m_z = ∫ φ_z`` of the hats of the once-refined faces (the force density's (4.1)).
    facet : FaceElement
        The space's face element (its weights and nodal pressure).
    facet_local : (n_f, 6) int array
        The row of each contact face's nodes for the face's part, ``-1`` at a node without
        one (held); the node classes of Section 4 read it (:func:`~.contact_set.node_classes`).
    facet_gap : (n_f, 6) float array
        ψ at the contact faces' nodes (held nodes too); ``facet_direction (n_f, 6, 3)`` the
        directions there.
    facet_direction : (n_f, 6, 3) float array
    roller_dof : (r,) int array
        The frame DOF held by each oblique or curved roller row
        (:attr:`~signorini.problem.rollers.HeldNodes.roller_nodes`).
    """

    n_dofs: int
    node: np.ndarray
    part: np.ndarray
    parts: tuple[str, ...]
    direction: np.ndarray
    psi: np.ndarray
    dof: np.ndarray
    frame_nodes: np.ndarray
    frames: np.ndarray
    held_dofs: np.ndarray
    held_values: np.ndarray
    faces: np.ndarray
    face_part: np.ndarray
    edges: FaceEdges
    basis_integral: np.ndarray
    hat_integral: np.ndarray
    facet: FaceElement
    facet_local: np.ndarray
    facet_gap: np.ndarray
    facet_direction: np.ndarray
    roller_dof: np.ndarray
    #: with friction (:mod:`.face_friction`): the laws and the tangential DOFs of the rows
    friction: FaceFriction | None = None

    @property
    def has_friction(self) -> bool:
        """Whether some row has a friction law."""
        return self.friction is not None and self.friction.laws.any

    #: rigid obstacles only: no bodies coupled (:class:`~.mortar3d_set.MortarFaceSet`)
    couples_bodies = False

    @property
    def operator(self) -> sp.csr_matrix:
        """``Q P (n_dofs, n_dofs)``: ``u = Q P ỹ`` from the solver's variables (frames, then
        the transformed basis on the rows; with friction on their tangential DOFs too) to
        Cartesian DOFs."""
        Q = frame_operator(self.n_dofs, self.frame_nodes, self.frames)
        P = change_of_variables(self.n_dofs, self.dof, self.edges)
        if self.friction is not None:
            P = P @ self.friction.change_of_variables(self.n_dofs)
        return (Q @ P).tocsr()

    @property
    def gap(self) -> np.ndarray:
        """``(k,)`` ψ̃ = T^{-T} ψ: the bounds ``ỹ_dof ≤ ψ̃`` of the solver's variables (ψ
        itself for condition (a))."""
        return self.edges.coefficients(self.psi)

    def row_integrals(self, integral: np.ndarray) -> np.ndarray:
        """``(k,)`` ``∫ f φ̃_z`` at the rows of the face-node integrals ``∫_F f φ_a (n_f,
        6)``: summed per row (none at a held node), then in the transformed basis."""
        local = self.facet_local
        ok = local >= 0
        w = np.bincount(local[ok], weights=np.asarray(integral)[ok], minlength=self.n_rows)
        return self.edges.transformed(w)

    @property
    def transformed_integral(self) -> np.ndarray:
        """``(k,)`` ``w̃_z = ∫ φ̃_z = (T w)_z``: positive for 0 < α < 1/2."""
        return self.edges.transformed(self.basis_integral)

    def system(self, K: sp.spmatrix, F: np.ndarray) -> tuple[sp.csr_matrix, np.ndarray]:
        """``(Rᵀ K R, Rᵀ F)`` with ``R`` = :attr:`operator`: the bound-constrained system of
        :func:`~signorini.algebra.pdas.solve_pdas` (constrained ``dof``, bounds
        :attr:`gap`, Dirichlet ``held_dofs`` at ``held_values``)."""
        R = self.operator
        return (R.T @ K @ R).tocsr(), R.T @ np.asarray(F, dtype=np.float64)

    def displacement(self, x: np.ndarray) -> np.ndarray:
        """``(n_dofs,)`` Cartesian DOFs ``u = Q P x`` of the solver's solution ``x``."""
        return self.operator @ x

    def force(self, K: sp.spmatrix, F: np.ndarray, u: np.ndarray) -> np.ndarray:
        """``(k,)`` the discrete contact force (3.17) ``Λ_z = L(ψ_z n_z) − a(u_h, ψ_z n_z)``
        of each row, ``(Qᵀ (F − K u))_dof`` (positive where the obstacle pushes)."""
        Q = frame_operator(self.n_dofs, self.frame_nodes, self.frames)
        return (Q.T @ (np.asarray(F, dtype=np.float64) - K @ u))[self.dof]

    def pressure(self, force: np.ndarray) -> np.ndarray:
        """``(k,)`` the transformed basis's nodal pressure ``p̃_z = Λ̃_z / w̃_z``
        (``Λ̃ = T Λ``), exact for a constant pressure; refused for condition (a), where the
        vertex weights vanish (:meth:`~signorini.fem.facet_element.FaceElement.pressure`)."""
        return self.facet.pressure(self.edges.transformed(force), self.transformed_integral)

    def recovered_pressure(self, force: np.ndarray) -> np.ndarray:
        """``(k,)`` the P1-lumped recovered pressure of either condition: at a vertex the
        force on the P1 hat over its lumped face mass, ``(T_½ Λ)_v / (T_½ w)_v``, at a midpoint
        the mean of its edge's ends (a midpoint outside every transformed edge keeps
        ``Λ_e / w_e``); exact for a constant pressure."""
        half = FaceEdges(self.n_rows, 0.5, self.edges.mid, self.edges.start, self.edges.end)
        weight = half.transformed(self.basis_integral)
        p = np.divide(
            half.transformed(force), weight, out=np.full(self.n_rows, np.nan), where=weight > 0
        )
        p[half.mid] = 0.5 * (p[half.start] + p[half.end])
        return p

    def unknowns(self, u: np.ndarray) -> np.ndarray:
        """``(n_dofs,)`` the solver's variables ``ỹ = P⁻¹ Q⁻¹ u`` of Cartesian DOFs ``u``
        (the inverse of :meth:`displacement`: out of the frames, then ``T^{-T}`` on the
        rows' DOFs)."""
        y = to_frames_3d(u, self.frame_nodes, self.frames)
        y[self.dof] = self.edges.coefficients(y[self.dof])
        return y if self.friction is None else self.friction.coefficients(y)

    def normal_displacement(self, u: np.ndarray) -> np.ndarray:
        """``(k,)`` the rows' bounded variables ``ỹ_dof`` (:meth:`unknowns`) of nodal values
        ``u (n_nodes, 3)``: what :attr:`gap` bounds, so that a warm start's rows at their
        bound are read where the solver reads them (for condition (a) at a node of one row
        ``u(z)·n_z``; :func:`~.nested.warm_active_set`)."""
        return self.unknowns(np.asarray(u, dtype=np.float64).ravel())[self.dof]

    def facet_normal_gap(self, u: np.ndarray) -> np.ndarray:
        """``u(z)·n_z − ψ(z)`` at the nodes of each contact face ``(n_f, 6)``, for nodal
        values ``u (n_nodes, 3)``."""
        return np.einsum("fjc,fjc->fj", np.asarray(u)[self.faces], self.facet_direction) - (
            self.facet_gap
        )

    def fields(self, u: np.ndarray, force: np.ndarray, active: np.ndarray) -> FaceFields:
        """The rows' gap ``u(z)·n_z − ψ(z)``, force, pressures (:meth:`pressure` for
        condition (b), NaN for (a); :meth:`recovered_pressure`), flag and direction of a
        solution ``u (n_nodes, 3)`` with forces ``Λ (k,)`` and active set ``(k,)``."""
        force = np.asarray(force, dtype=np.float64)
        p = self.pressure(force) if self.edges.alpha > 0 else np.full(self.n_rows, np.nan)
        return FaceFields(
            node=self.node,
            part=self.part,
            normal=self.direction,
            gap=np.einsum("kc,kc->k", np.asarray(u)[self.node], self.direction) - self.psi,
            contact_force=force,
            pressure=p,
            recovered_pressure=self.recovered_pressure(force),
            active=np.asarray(active, dtype=bool),
        )

    @property
    def n_rows(self) -> int:
        """The number of rows ``k``."""
        return self.node.size

    # what the solve reads of a contact set (as of the 2D ContactSet)
    size = n_rows
    transfer = None

    @property
    def constrained_dofs(self) -> np.ndarray:
        """``(k,)`` the bounded DOFs of the solver's variables (``dof``)."""
        return self.dof


def _part_rows(space, name: str, cond: Contact) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The nodes of part ``name``'s faces (sorted), their directions and gaps."""
    facets = space.mesh.part_facets(name)
    z = np.unique(space.facet_nodes(facets))
    x = space.node_points[z]
    if cond.obstacle is not None:
        if cond.obstacle.dim != 3:
            raise ProblemError(
                f"the obstacle {cond.obstacle!r} of contact part {name!r} is a plane shape "
                "(dim 2) on a 3D mesh: use a shape of signorini.problem.obstacles3d"
            )
        try:
            psi, n = cond.obstacle.gap_and_direction(x)
        except ValueError as err:
            raise ProblemError(f"the obstacle of contact part {name!r}: {err}") from err
        return z, n, psi
    what = f"the gap function of contact part {name!r}"
    psi = evaluate_field(cond.gap_field(), x, what, shape=(), bounded=True)
    body = face_node_normals(space, name, z)
    if cond.normal is None:
        return z, body, psi
    return z, given_directions(cond.normal, name, x, body), psi


def face_contact_set(
    space: P2TetSpace,
    contact: Mapping[str, Contact],
    held: np.ndarray | HeldNodes,
    held_values: np.ndarray | None = None,
    alpha: float = DEFAULT_ALPHA,
) -> FaceContactSet:
    """Resolve the contact parts of a 3D problem on a P2 tetrahedral space.

    Parameters
    ----------
    space : P2TetSpace
    contact : mapping part name -> Contact
        The contact parts, in order (gap function or shape of space; frictionless).
    held : (n_nodes, 3) bool array or HeldNodes
        The Cartesian components held at each node (Dirichlet, axis rollers); or all that
        the Dirichlet and Roller parts hold, oblique and curved rollers' rows among it
        (:func:`~signorini.problem.rollers3d.held_rows_3d`).
    held_values : (n_nodes, 3) float array
        The held components' values (with a bool ``held``).
    alpha : float
        The transformed basis's α (0: condition (a); default 1/5: condition (b)).

    Returns
    -------
    FaceContactSet

    Raises
    ------
    ProblemError
        Naming the part or the node: a plane obstacle, a gap function that is not finite, a
        node with more than three rows and held directions, a given normal of the wrong
        shape or length, an obstacle that starts deep inside the body.
    """
    if not isinstance(held, HeldNodes):
        none = np.zeros(0, dtype=np.int64)
        values = np.asarray(held_values, dtype=np.float64)
        held = HeldNodes(np.asarray(held, dtype=bool), values, none, np.zeros((0, 3)), none * 0.0)
    parts = tuple(contact)
    found = [_part_rows(space, name, contact[name]) for name in parts]  # a loop over parts
    node = np.concatenate([f[0] for f in found])
    part = np.repeat(np.arange(len(parts)), [f[0].size for f in found])
    direction = np.concatenate([f[1] for f in found])
    gap = np.concatenate([f[2] for f in found])
    check_deep_overlap(
        space, held, (node, part, direction, gap), [contact[p] for p in parts], parts
    )
    free_normal = _free_normal(held, node, direction)
    order = np.lexsort((part, node))
    order = order[free_normal[order]]
    # merge a later part's row into an earlier one at the same node with the same direction
    row_of_part = np.full((space.n_nodes, len(parts)), -1, dtype=np.int64)
    first = np.r_[True, node[order][1:] != node[order][:-1]]
    d = direction[order]
    same = ~first & (np.abs(d - np.roll(d, 1, axis=0)).max(axis=1) <= SAME_DIRECTION)
    keep = ~same
    row_of_part[node[order], part[order]] = np.cumsum(keep) - 1  # merged: the previous row
    rows = order[keep]
    face_data = _face_data(space, found, parts, row_of_part)
    return _assembled(space, parts, (node[rows], part[rows], direction[rows], gap[rows]),
                      row_of_part, held, alpha, face_data)  # fmt: skip


def _free_normal(held: HeldNodes, node: np.ndarray, direction: np.ndarray) -> np.ndarray:
    """``(c,)`` whether a candidate row's direction is free of the directions held at its
    node (else the held components fix ``u·n_z`` and the row is left out)."""
    free = np.abs(np.where(held.components[node], 0.0, direction)).max(axis=1) > SAME_DIRECTION
    if held.roller_nodes.size == 0:
        return free
    nodes, basis, count = held_basis(held.components, held.roller_nodes, held.roller_normal)
    at = np.flatnonzero(np.isin(node, nodes))
    i = np.searchsorted(nodes, node[at])
    residual = span_residual(basis[i], count[i], direction[at])
    free[at] = np.abs(residual).max(axis=1) > SAME_DIRECTION
    return free


def _face_data(space, found, parts, row_of_part) -> tuple[np.ndarray, ...]:
    """The contact faces' nodes ``(n_f, 6)``, parts, and at their nodes the row (``-1`` at a
    held node), ψ and the direction of the face's part."""
    facet_index = np.concatenate([space.mesh.part_facets(p) for p in parts])
    faces = space.facet_nodes(facet_index)
    face_part = np.repeat(np.arange(len(parts)), [space.mesh.part_facets(p).size for p in parts])
    gap = np.zeros(faces.shape)
    direction = np.zeros(faces.shape + (3,))
    for i, (z, n, psi) in enumerate(found):  # a loop over parts
        on = face_part == i
        at = np.searchsorted(z, faces[on])
        gap[on], direction[on] = psi[at], n[at]
    local = row_of_part[faces, face_part[:, None]]
    return facet_index, faces, face_part, local, gap, direction


def _assembled(space, parts, rows, row_of_part, held, alpha, face_data):
    """The frames, held DOFs, face basis and weights of the rows (:func:`face_contact_set`)."""
    node, part, direction, gap = rows
    k = node.size
    mean = np.array([np.abs(direction[part == i].sum(axis=0)) for i in range(len(parts))])
    pole = np.argmax(mean, axis=1)[part] if k else np.zeros(0, np.int64)
    frames = held_frames(space.node_points, node, direction, pole, held)
    facet_index, faces, face_part, local, face_gap, face_direction = face_data

    def row_of(nodes, which):
        return row_of_part[nodes, which]

    edges = face_edges(faces, face_part, row_of, k, alpha)
    w, m = row_weights(space, facet_index, faces, face_part, row_of, k)
    return FaceContactSet(
        n_dofs=space.n_dofs,
        node=node,
        part=part,
        parts=parts,
        direction=direction,
        psi=gap,
        dof=frames.row_dof,
        frame_nodes=frames.frame_nodes,
        frames=frames.frames,
        held_dofs=frames.held_dofs,
        held_values=frames.held_values,
        faces=faces,
        face_part=face_part,
        edges=edges,
        basis_integral=w,
        hat_integral=m,
        facet=space.element.facet,
        facet_local=local,
        facet_gap=face_gap,
        facet_direction=face_direction,
        roller_dof=frames.roller_dof,
    )


def row_weights(space, facet_index, faces, face_part, row_of, k):
    """``w (k,)`` the integrals of the P2 functions over the rows' faces (by quadrature, on
    flat and quadratic faces alike) and ``m (k,)`` those of the hats of the once-refined faces
    (the face element's hat shares times the face areas); ``row_of(nodes, which)`` the rows
    of the faces' nodes (−1: none), ``which`` their faces' parts ``face_part[:, None]``."""
    element = space.element.facet
    s, wq = triangle_rule(4)
    phi = element.basis(s)  # (q, 6)
    integral = np.zeros(faces.shape)
    area = np.zeros(faces.shape[0])
    for rows, group in space.boundary_facets(facet_index):  # a loop over flat / quadratic
        weight = group.speeds(s) * wq  # (j, q)
        integral[rows] = weight @ phi
        area[rows] = weight.sum(axis=1)
    rows = row_of(faces, face_part[:, None])
    ok = rows >= 0
    w = np.bincount(rows[ok], weights=integral[ok], minlength=k)
    hat = area[:, None] * np.asarray(element.hat_share)[None, :]
    m = np.bincount(rows[ok], weights=hat[ok], minlength=k)
    return w, m
