"""The contact set of a 3D problem's contact pairs: the dual mortar constraints made nodal
by a change of basis, so that PDAS solves the pair as it solves one body against an obstacle
(docs/method.md, *Two bodies in three dimensions: the change of basis*).

A constrained slave node j (its normal component not held) bounds the weighted gap,
``n_j·(D_jj ũ_j − Σ_k M_jk u_k) ≤ g̃_j``, where ``ũ = T^{-T} u`` are the coefficients of the
slave's displacement in the transformed basis φ̃ (:mod:`.mortar3d`, ``∫ ψ_j u_s = D_jj ũ_j``)
and ``u_k`` the master's nodal displacements. With ``T_jk = M_jk / D_jj`` and the relative
unknown ``r_j = ũ_j − n_j n_jᵀ Σ_k T_jk u_k`` this is ``n_j·r_j ≤ g̃_j / D_jj``: one bound in
the node's frame. The solver's variables y give the Cartesian displacement through

    u = R y,   R = T_tᵀ (I + T_d) Q,

``Q`` the node frames (:func:`~.node_frames3d.held_frames`: the constraint direction, held
axes), ``T_d`` the blocks ``P_j T_jk`` from the master's DOFs to the constrained slave
rows (``T_d² = 0``: no master node is a slave node), ``T_tᵀ`` the transformed basis on every
side of the slave parts, all three components (``u_e = (1 − 2α) ũ_e + α (ũ_a + ũ_b)``). The
system ``Rᵀ K R``, ``Rᵀ F`` is symmetric positive definite and its multiplier at row j is
``Λ̃_j``, the force on ``φ̃_j n_j``; the pressure is its dual-basis coefficient
``p_j = Λ̃_j / D_jj``, exact for a uniform pressure.

``P_j`` is ``n_j n_jᵀ`` at a frictionless row: its tangential unknowns stay the slave's own.
At a row with a friction law (docs/method.md, *Two bodies in three dimensions: friction*)
``P_j = Q_j diag(1, f_1, f_2) Q_jᵀ`` keeps the relative displacement in every direction of
the frame ``Q_j = [n t_1 t_2]`` but a held one (``f = 0`` on an axis a roller holds, whose
slave component a roller holds as at an obstacle): the frame's tangential unknowns are the
relative slip ``t·(ũ_j − Σ_k T_jk u_k)`` the disc law acts on, and their multipliers
``Λ̃_t`` the friction forces on ``φ̃_j t``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ..fem.dofs import node_dofs
from ..problem.fields import ProblemError
from ..problem.rollers import HeldNodes
from .admissible import DEEP_OVERLAP
from .face_basis import FaceEdges
from .face_contact import SAME_DIRECTION, row_weights
from .face_fields import FaceFields
from .face_friction import FaceFriction, row_tangents
from .mortar3d import MortarCoupling3D
from .mortar_checks import COVERAGE_TOL
from .node_frames3d import frame_operator, held_frames, to_frames_3d

__all__ = ["MortarFaceSet", "face_sides", "mortar_face_set"]

_SIDES = np.array([[3, 0, 1], [4, 1, 2], [5, 2, 0]])


@dataclass(frozen=True)
class MortarFaceSet:
    """The constraints of a 3D problem's contact pairs, one row per constrained slave node
    (sorted by node).

    Attributes
    ----------
    n_dofs : int
    node, part : (k,) int arrays
        Each row's slave node and its pair (index into ``parts``, the slave parts).
    parts : tuple of str
    masters : tuple of str
    direction : (k, 3) float array
        ``n_j``, the slave's outward unit normal.
    psi : (k,) float array
        ``g̃_j / D_jj``: the bound of the row's frame unknown (:attr:`gap`).
    basis_integral : (k,) float array
        ``D_jj = ∫ φ̃_j``.
    dof : (k,) int array
        The frame DOF ``3 j`` the row bounds.
    frame_nodes, frames : (m,) int and (m, 3, 3) float arrays
        The nodes in a frame and their ``Q_z``.
    held_dofs, held_values : (n_h,) arrays
        The held DOFs in the solver's variables and their values.
    roller_dof : (r,) int array
        The frame DOF of each oblique or curved roller row (none on a slave node).
    operator : (n_dofs, n_dofs) scipy.sparse.csr_matrix
        ``R``: Cartesian DOFs of the solver's variables.
    node_transfer : (k, n_nodes) scipy.sparse.csr_matrix
        ``T_jk = M_jk / D_jj`` of the rows.
    faces, face_part : (n_f, 6) and (n_f,) int arrays
        The slave faces' nodes and pairs (the slave parts' faces in order, pair after pair).
    facet_local : (n_f, 6) int array
        The row of each face node, −1 at a node without one (its normal component held).
    facet_direction : (n_f, 6, 3) float array
        The slave's outward unit normal at each face node (the rows' ``direction``).
    hat_integral : (k,) float array
        ``m_j``: the integrals of the hats of the once-refined slave faces at the row's node
        (the estimator's η6, as :attr:`FaceContactSet.hat_integral`).
    edges : (n_e, 3) int array
        The slave sides' nodes (midpoint, start, end) of the transformed basis.
    alpha : float
    projection : (k, 3, 3) float array
        ``P_j`` (module docstring): ``n_j n_jᵀ``, or with friction the frame's free axes.
    friction : FaceFriction or None
        The rows' friction laws and tangential frame DOFs (:func:`~.face_friction.pair_friction`;
        its change of variables the identity: ``T_t`` already acts on every component).
    """

    n_dofs: int
    node: np.ndarray
    part: np.ndarray
    parts: tuple[str, ...]
    masters: tuple[str, ...]
    direction: np.ndarray
    psi: np.ndarray
    basis_integral: np.ndarray
    dof: np.ndarray
    frame_nodes: np.ndarray
    frames: np.ndarray
    held_dofs: np.ndarray
    held_values: np.ndarray
    roller_dof: np.ndarray
    operator: sp.csr_matrix
    node_transfer: sp.csr_matrix
    faces: np.ndarray
    face_part: np.ndarray
    facet_local: np.ndarray
    facet_direction: np.ndarray
    hat_integral: np.ndarray
    edges: np.ndarray
    alpha: float
    projection: np.ndarray
    friction: FaceFriction | None = None

    # what the solve reads of a contact set (``transfer``: the 2D pairs' change of basis)
    transfer = None
    couples_bodies = True  # the constraints couple the pair's bodies

    @property
    def has_friction(self) -> bool:
        """Whether some row has a friction law."""
        return self.friction is not None and self.friction.laws.any

    @property
    def n_rows(self) -> int:
        return self.node.size

    size = n_rows

    @property
    def sides(self) -> FaceEdges:
        """The transformed basis on the slave sides over node numbers (all three components:
        ``ũ``, ``T Λ``, nodal values of coefficients)."""
        return FaceEdges(self.n_dofs // 3, self.alpha, *self.edges.T)

    def row_integrals(self, integral: np.ndarray) -> np.ndarray:
        """``(k,)`` ``∫ f φ̃_j`` at the rows of the face-node integrals ``∫_F f φ_a (n_f, 6)``:
        summed per node, then in the transformed basis over the slave sides (whose midpoints
        and ends need not carry rows)."""
        w = np.bincount(self.faces.ravel(), weights=np.ravel(integral), minlength=self.n_dofs // 3)
        return self.sides.transformed(w)[self.node]

    @property
    def constrained_dofs(self) -> np.ndarray:
        """``(k,)`` the bounded DOFs of the solver's variables."""
        return self.dof

    @property
    def gap(self) -> np.ndarray:
        """``(k,)`` the bounds ``y_dof ≤ g̃_j / D_jj``."""
        return self.psi

    def system(self, K: sp.spmatrix, F: np.ndarray) -> tuple[sp.csr_matrix, np.ndarray]:
        """``(Rᵀ K R, Rᵀ F)``: the bound-constrained system of the solver's variables."""
        R = self.operator
        return (R.T @ K @ R).tocsr(), R.T @ np.asarray(F, dtype=np.float64)

    def displacement(self, x: np.ndarray) -> np.ndarray:
        """``(n_dofs,)`` Cartesian DOFs ``u = R x``."""
        return self.operator @ x

    def force(self, K: sp.spmatrix, F: np.ndarray, u: np.ndarray) -> np.ndarray:
        """``(k,)`` ``Λ̃_j = (Rᵀ (F − K u))_dof``: the force on ``φ̃_j n_j`` (positive where
        the master pushes the slave)."""
        return (self.operator.T @ (np.asarray(F, dtype=np.float64) - K @ u))[self.dof]

    def pressure(self, force: np.ndarray) -> np.ndarray:
        """``(k,)`` ``p_j = Λ̃_j / D_jj``, the multiplier's coefficient in the dual basis."""
        return np.asarray(force, dtype=np.float64) / self.basis_integral

    def coefficients(self, u: np.ndarray) -> np.ndarray:
        """``ũ (n_nodes, 3)``: nodal values ``u`` with the slave sides' midpoints as the
        transformed basis's coefficients, ``(u_e − α (u_a + u_b)) / (1 − 2α)``."""
        return self.sides.coefficients(u)

    def unknowns(self, u: np.ndarray) -> np.ndarray:
        """``(n_dofs,)`` the solver's variables ``y = R⁻¹ u`` of Cartesian DOFs ``u``: the
        transformed coefficients, minus ``T_d u`` at the rows (``T_d² = 0``), into the
        frames."""
        u = np.asarray(u, dtype=np.float64)
        r = self.coefficients(u.reshape(-1, 3))
        moved = self.node_transfer @ u.reshape(-1, 3)  # Σ_k T_jk u_k
        if self.friction is None:  # P_j = n_j n_jᵀ
            rel = np.einsum("kc,kc->k", moved, self.direction)
            r[self.node] -= rel[:, None] * self.direction
        else:
            r[self.node] -= np.einsum("kcd,kd->kc", self.projection, moved)
        return to_frames_3d(r.ravel(), self.frame_nodes, self.frames)

    def normal_displacement(self, u: np.ndarray) -> np.ndarray:
        """``(k,)`` the rows' bounded variables ``y_dof`` (:meth:`unknowns`) of nodal values
        ``u (n_nodes, 3)``: what :attr:`gap` bounds, read where the solver reads it (a
        warm start's first active set, :func:`~.nested.warm_active_set`)."""
        return self.unknowns(np.asarray(u, dtype=np.float64).ravel())[self.dof]

    def relative_gap(self, u: np.ndarray) -> np.ndarray:
        """``(k,)`` ``n_j·(ũ_j − Σ_k T_jk u_k) − g̃_j / D_jj`` of nodal values ``u (n_nodes,
        3)``: 0 in contact, negative where the bodies are apart."""
        u = np.asarray(u, dtype=np.float64)
        rel = self.coefficients(u)[self.node] - self.node_transfer @ u
        return np.einsum("kc,kc->k", rel, self.direction) - self.psi

    @property
    def facet_gap(self) -> np.ndarray:
        """``(n_f, 6)`` the rows' bounds ``g̃_j / D_jj`` at the face nodes, 0 without a row."""
        return np.where(self.facet_local >= 0, self.psi[np.maximum(self.facet_local, 0)], 0.0)

    def facet_normal_gap(self, u: np.ndarray) -> np.ndarray:
        """``(n_f, 6)`` the relative gap (:meth:`relative_gap`) at the face nodes of nodal
        values ``u``; 0 at a node without a row, whose normal displacement is held (taken in
        contact, as a Dirichlet end point in 2D)."""
        gap = self.relative_gap(np.asarray(u, dtype=np.float64).reshape(-1, 3))
        return np.where(self.facet_local >= 0, gap[np.maximum(self.facet_local, 0)], 0.0)

    def row_forces(self, force: np.ndarray, tangential: np.ndarray | None = None) -> np.ndarray:
        """``(k, 3)`` the Cartesian force of each row on the slave's ``φ̃_j``, ``Λ̃_j n_j``
        plus, with friction, ``Σ_i Λ̃_t,ij t_i`` over the row's free tangents (``tangential
        (k, 2)`` on :attr:`FaceFriction.tangent`), all as the solver's multipliers ``F − K u``
        (the master pushes the slave along ``−n_j``)."""
        f = np.asarray(force, dtype=np.float64)[:, None] * self.direction
        if tangential is not None and self.friction is not None:
            t, held = row_tangents(self), self.friction.held
            for i in range(2):  # the two tangential slots
                f = f + np.where(held[:, i], 0.0, tangential[:, i])[:, None] * t[:, i]
        return f

    def master_forces(
        self, force: np.ndarray, n_nodes: int, tangential: np.ndarray | None = None
    ) -> np.ndarray:
        """``(n_nodes, 3)`` the nodal forces the slave rows' ``Λ̃ (k,)`` (and friction forces
        ``tangential (k, 2)``) exert on the master, ``Σ_j T_jk f_j`` with ``f_j`` of
        :meth:`row_forces` (the slave receives ``−f_j`` on φ̃_j, n_j pointing towards the
        master): equal and opposite resultants where ``Σ_k M_jk = D_jj``."""
        f = self.row_forces(force, tangential)
        out = np.zeros((n_nodes, 3))
        out[: self.node_transfer.shape[1]] = self.node_transfer.T @ f
        return out

    def fields(self, u: np.ndarray, force: np.ndarray, active: np.ndarray) -> FaceFields:
        """The rows' relative gap, force, pressure (also as the recovered one), flag and
        direction (what a 3D run's VTU file and figures read)."""
        p = self.pressure(force)
        return FaceFields(
            node=self.node,
            part=self.part,
            normal=self.direction,
            gap=self.relative_gap(u),
            contact_force=np.asarray(force, dtype=np.float64),
            pressure=p,
            recovered_pressure=p,
            active=np.asarray(active, dtype=bool),
        )


def face_sides(faces: np.ndarray) -> np.ndarray:
    """The distinct sides ``(n_e, 3)`` (midpoint, start, end) of 6-node faces."""
    sides = faces[:, _SIDES].reshape(-1, 3)
    sides[:, 1:] = np.sort(sides[:, 1:], axis=1)
    return np.unique(sides, axis=0)


def _transformed_held(held: HeldNodes, edges: np.ndarray, alpha: float, points) -> HeldNodes:
    """The held values at the slave sides' midpoints as transformed coefficients (a held
    midpoint component needs both ends held in it, which a part's faces give)."""
    comp, values = held.components, np.array(held.values, dtype=np.float64)
    e, a, b = edges.T
    bad = comp[e] & ~(comp[a] & comp[b])
    if bad.any():
        z = int(e[np.argwhere(bad)[0, 0]])
        raise ProblemError(
            f"the slave node at {points[z].tolist()} holds a component that an end of its "
            "side leaves free: the transformed basis needs the held components of a side's "
            "midpoint held at its ends"
        )
    values[e] = np.where(
        comp[e], (values[e] - alpha * (values[a] + values[b])) / (1.0 - 2.0 * alpha), 0.0
    )
    return HeldNodes(comp, values, held.roller_nodes, held.roller_normal, held.roller_value)


def _rows(c: MortarCoupling3D, held: HeldNodes, points, size: float) -> np.ndarray:
    """The positions in ``c.slave_nodes`` of the constrained nodes (normal component free),
    checked: wholly over the master, not deeply overlapping it, held axes tangential."""
    pair = f"contact pair (slave {c.slave!r}, master {c.master!r})"
    comp = held.components[c.slave_nodes]
    free = np.abs(np.where(comp, 0.0, c.normal)).max(axis=1) > SAME_DIRECTION
    rows = np.flatnonzero(free)
    if np.isin(c.slave_nodes, held.roller_nodes).any():
        raise ProblemError(f"{pair}: an oblique or curved roller holds slave nodes (not built)")
    tilted = comp[rows] & (np.abs(c.normal[rows]) > SAME_DIRECTION)
    if tilted.any():
        z = c.slave_nodes[rows[np.argwhere(tilted)[0, 0]]]
        raise ProblemError(
            f"{pair}: the slave node at {points[z].tolist()} holds a Cartesian component "
            "along which its normal has a share: a held component at a constrained slave "
            "node must be tangential"
        )
    off = rows[np.abs(c.coverage[rows] - 1) > COVERAGE_TOL]
    if off.size:
        z = c.slave_nodes[off[np.argmax(np.abs(c.coverage[off] - 1))]]
        raise ProblemError(
            f"{pair}: the slave node at {points[z].tolist()} is not wholly over the master "
            f"({off.size} such node(s)): the coupling is computed once, in the reference "
            "configuration (small sliding; large sliding is not modelled); shorten the "
            "slave part to where the master lies opposite, or swap the roles"
        )
    depth = -c.weighted_gap[rows] / c.D[rows]
    if (depth > DEEP_OVERLAP * size).any():
        raise ProblemError(
            f"{pair}: the bodies overlap by {depth.max():.6g}, more than {DEEP_OVERLAP} times "
            f"their size {size:.6g}: beyond the small-deformation model"
        )
    return rows


def mortar_face_set(
    space, couplings: Sequence[MortarCoupling3D], held: HeldNodes, frictional: Sequence[bool] = ()
) -> MortarFaceSet:
    """The contact set of the pairs ``couplings`` (one α) with the held nodes ``held``, the
    rows of the pairs ``frictional[i]`` (none by default) with the relative displacement in
    every free direction (module docstring; the laws themselves:
    :func:`~.face_friction.pair_friction`).

    Raises
    ------
    ProblemError
        Naming the pair or node: a slave node on two pairs or on a master part, a
        constrained node not wholly over the master (large sliding), a deep initial overlap,
        a held component at a constrained slave node that is not tangential, an oblique
        roller on a slave node.
    """
    points, n_dofs = space.node_points, space.n_dofs
    size = float(np.linalg.norm(np.ptp(points, axis=0)))
    alpha = couplings[0].alpha
    faces = np.vstack([c.slave_faces for c in couplings])
    face_part = np.repeat(np.arange(len(couplings)), [len(c.slave_faces) for c in couplings])
    slaves = np.concatenate([c.slave_nodes for c in couplings])
    masters = np.concatenate([np.unique(c.M.indices) for c in couplings])
    if np.unique(slaves).size < slaves.size or np.isin(slaves, masters).any():
        raise ProblemError(
            "a slave node lies on two contact pairs or on a master part: give the pairs' parts "
            "no common node"
        )
    edges = face_sides(faces)
    held = _transformed_held(held, edges, alpha, points)
    found = [_rows(c, held, points, size) for c in couplings]  # a loop over pairs
    node = np.concatenate([c.slave_nodes[r] for c, r in zip(couplings, found, strict=True)])
    part = np.repeat(np.arange(len(couplings)), [r.size for r in found])
    direction = np.concatenate([c.normal[r] for c, r in zip(couplings, found, strict=True)])
    D = np.concatenate([c.D[r] for c, r in zip(couplings, found, strict=True)])
    gap = np.concatenate([c.weighted_gap[r] for c, r in zip(couplings, found, strict=True)])
    T = sp.vstack([sp.diags(1.0 / c.D[r]) @ c.M[r] for c, r in zip(couplings, found, strict=True)])
    order = np.argsort(node, kind="stable")
    node, part, direction, D, gap = node[order], part[order], direction[order], D[order], gap[order]
    T = sp.csr_matrix(T)[order]
    pole = np.argmax(np.abs(direction), axis=1)
    frames = held_frames(points, node, direction, pole, held)
    projection = _projections(node, direction, np.isin(part, np.flatnonzero(frictional)), frames)
    R = _operator(n_dofs, (node, projection, T), edges, alpha, frames)
    row_of = np.full(space.n_nodes, -1)
    row_of[node] = np.arange(node.size)
    normal = np.zeros((space.n_nodes, 3))
    for c in couplings:  # a loop over pairs
        normal[c.slave_nodes] = c.normal
    facet_index = np.concatenate([space.mesh.part_facets(c.slave) for c in couplings])
    hat = row_weights(space, facet_index, faces, face_part, lambda z, _: row_of[z], node.size)[1]
    return MortarFaceSet(
        n_dofs=n_dofs, node=node, part=part, parts=tuple(c.slave for c in couplings),
        masters=tuple(c.master for c in couplings), direction=direction, psi=gap / D,
        basis_integral=D, dof=frames.row_dof, frame_nodes=frames.frame_nodes,
        frames=frames.frames, held_dofs=frames.held_dofs, held_values=frames.held_values,
        roller_dof=frames.roller_dof, operator=R, node_transfer=T, faces=faces,
        face_part=face_part, facet_local=row_of[faces], facet_direction=normal[faces],
        hat_integral=hat, edges=edges, alpha=alpha, projection=projection,
    )  # fmt: skip


def _projections(node, direction, frictional, frames) -> np.ndarray:
    """``P_j (k, 3, 3)`` (module docstring): ``n_j n_jᵀ``, or at a ``frictional (k,)`` row
    ``Q_j diag(1, f_1, f_2) Q_jᵀ`` with ``f = 0`` on the axes the frame holds."""
    plain = direction[:, :, None] * direction[:, None, :]
    if not frictional.any():
        return plain
    Q = frames.frames[np.searchsorted(frames.frame_nodes, node)]  # (k, 3, 3) columns
    dofs = 3 * node[:, None] + np.arange(3)
    keep = ~np.isin(dofs, frames.held_dofs)
    full = np.einsum("kci,ki,kdi->kcd", Q, keep.astype(np.float64), Q)
    return np.where(frictional[:, None, None], full, plain)


def _operator(n_dofs: int, rows: tuple, edges: np.ndarray, alpha: float, frames) -> sp.csr_matrix:
    """``R = T_tᵀ (I + T_d) Q`` (module docstring) of the rows ``(node, projection, T)``."""
    node, projection, T = rows
    coo = sp.coo_matrix(T)
    block = coo.data[:, None, None] * projection[coo.row]  # (nnz, 3, 3)
    r = node_dofs(node[coo.row], 3)[:, :, None]
    c = node_dofs(coo.col, 3)[:, None, :]
    r, c = np.broadcast_arrays(r, c)
    Td = sp.csr_matrix((block.ravel(), (r.ravel(), c.ravel())), shape=(n_dofs, n_dofs))
    e, a, b = (node_dofs(edges[:, i], 3).ravel() for i in range(3))
    other = np.setdiff1d(np.arange(n_dofs), e)
    Tt = sp.csr_matrix(
        (
            np.concatenate([np.ones(other.size), np.full(e.size, 1 - 2 * alpha),
                            np.full(2 * e.size, alpha)]),
            (np.concatenate([other, e, e, e]), np.concatenate([other, e, a, b])),
        ),
        shape=(n_dofs, n_dofs),
    )  # fmt: skip
    Q = frame_operator(n_dofs, frames.frame_nodes, frames.frames)
    return (Tt @ (sp.identity(n_dofs, format="csr") + Td) @ Q).tocsr()
