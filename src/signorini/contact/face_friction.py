"""Friction on the rows of a face contact set (docs/method.md, *Friction in three dimensions:
the disc law*): the tangential DOFs of each row in its node frame ``[n t_1 t_2]``, the
transformed face basis on them, and each row's law and nodal weight.

The tangential DOFs of a row are the two frame DOFs of its node other than the row's own
(``3 z + j``); one held by a roller through the node (a symmetry plane) is marked held and
the law acts on the other alone. The transformed basis of the rows (:mod:`.face_basis`)
acts on both tangential slots too, on the edges none of whose three nodes holds a slot, so
that ``Λ̃_t`` and ``Λ̃_n`` are forces on the same functions ``φ̃_z`` there. It mixes a slot's
values of an edge's nodes, so it needs the same directions at them: a held node's slots are
its roller normal and the completion of the pair, other directions than its neighbours'
(which, moreover, depend on how the roller plane lies against the axes), so the edges at a
held node keep the plain basis in both slots — one slot transformed there and not the
other would make the discrete space depend on the frames, and a problem turned about the
normal would not have the turned answer. The nodal weights are
the laws' :meth:`~signorini.algebra.friction.laws.FrictionLaw.nodal_weight` with
``integrate(f) = ∫ f φ̃_z`` (Tresca: ``s_z = ∫ s φ̃_z``; Coulomb: ``F``), by the degree-4
rule on the (flat or quadratic) faces of the row's part.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
import scipy.sparse as sp

from ..algebra.friction.laws import FrictionLaw, LawGroups
from ..fem.quadrature import triangle_rule
from ..problem.fields import ProblemError
from .face_basis import FaceEdges, change_of_variables

if TYPE_CHECKING:
    from ..fem.space3d import P2TetSpace
    from .face_contact import FaceContactSet
    from .mortar3d_set import MortarFaceSet

__all__ = ["FaceFriction", "face_friction", "pair_friction", "row_tangents"]


class FaceFriction:
    """The friction data of a face contact set's rows.

    Attributes
    ----------
    laws : LawGroups
        Each row's law and weight (``-1``: a frictionless part).
    tangent : (k, 2) int64 array
        The two tangential frame DOFs of each row.
    held : (k, 2) bool array
        Whether each is held (a roller through the node).
    edges : tuple of FaceEdges
        The transformed basis on each tangential slot (the same edges for both: those at no held
        node).
    """

    def __init__(self, laws: LawGroups, tangent: np.ndarray, held: np.ndarray, edges: tuple):
        self.laws, self.tangent, self.held, self.edges = laws, tangent, held, edges

    def change_of_variables(self, n_dofs: int) -> sp.csr_matrix:
        """``P_t (n_dofs, n_dofs)``: ``Tᵀ`` on each tangential slot (the identity elsewhere)."""
        P = change_of_variables(n_dofs, self.tangent[:, 0], self.edges[0])
        return (P @ change_of_variables(n_dofs, self.tangent[:, 1], self.edges[1])).tocsr()

    def coefficients(self, y: np.ndarray) -> np.ndarray:
        """``y`` with ``T^{-T}`` applied on each tangential slot (the inverse of
        :meth:`change_of_variables`)."""
        y = np.array(y, dtype=np.float64)
        for j in range(2):  # the two tangential slots
            y[self.tangent[:, j]] = self.edges[j].coefficients(y[self.tangent[:, j]])
        return y

    def solver_tangent(self) -> np.ndarray:
        """``(k, 2)`` the tangential DOFs for :func:`~signorini.algebra.friction.disc.check_disc`,
        ``-1`` where held."""
        return np.where(self.held, -1, self.tangent)


def face_friction(
    space: P2TetSpace, cs: FaceContactSet, laws: Sequence[FrictionLaw | None]
) -> FaceFriction:
    """The friction data of ``cs`` with ``laws[i]`` the law of its part ``i`` (module
    docstring).

    Raises
    ------
    ProblemError
        At a node with rows of two parts (a corner: friction there is not built), or if a
        law's nodal weights are not finite and ``≥ 0``.
    """
    node = cs.node
    shared = np.flatnonzero(np.r_[False, node[1:] == node[:-1]])
    if shared.size:
        raise ProblemError(
            f"node {node[shared[0]]} carries rows of two contact parts (a corner): friction "
            "at such a node is not built in 3D; join the parts or make one frictionless"
        )
    tangent, held = _tangential_dofs(cs)
    e = cs.edges
    # both slots on the same edges, those whose three nodes hold no tangential slot: the
    # slots of a held node are other directions than its neighbours' (docstring)
    free = ~held.any(axis=1)
    ok = free[e.mid] & free[e.start] & free[e.end]
    edges = (FaceEdges(cs.n_rows, e.alpha, e.mid[ok], e.start[ok], e.end[ok]),) * 2
    return FaceFriction(_law_groups(space, cs, laws), tangent, held, edges)


def pair_friction(
    space: P2TetSpace, cs: MortarFaceSet, laws: Sequence[FrictionLaw | None]
) -> FaceFriction:
    """The friction data of the rows of contact pairs ``cs`` with ``laws[i]`` the law of its
    pair ``i`` (docs/method.md, *Two bodies in three dimensions: friction*): the tangential
    unknowns are the frame's relative slip, already in the transformed basis on every
    component (:mod:`.mortar3d_set`), so no change of variables of their own; the weights
    ``∫ s φ̃_j`` as on one body.

    Raises
    ------
    ProblemError
        If a law's nodal weights are not finite and ``≥ 0``.
    """
    tangent, held = _tangential_dofs(cs)
    none = np.zeros(0, dtype=np.int64)
    edges = (FaceEdges(cs.n_rows, cs.alpha, none, none, none),) * 2
    return FaceFriction(_law_groups(space, cs, laws), tangent, held, edges)


def row_tangents(cs) -> np.ndarray:
    """``(k, 2, 3)`` the unit tangents ``t_1, t_2`` of the frictional contact set ``cs``'s
    rows: the columns of each row's node frame at its tangential slots
    (:attr:`FaceFriction.tangent`)."""
    frame = cs.frames[np.searchsorted(cs.frame_nodes, cs.node)]  # (k, 3, 3): columns
    return frame[np.arange(cs.n_rows)[:, None], :, cs.friction.tangent % 3]


def _tangential_dofs(cs) -> tuple[np.ndarray, np.ndarray]:
    """``(k, 2)`` the two frame DOFs of each row's node other than the row's own, and
    whether a roller through the node holds each."""
    tangent = 3 * cs.node[:, None] + (cs.dof[:, None] % 3 + np.array([1, 2])) % 3
    return tangent, np.isin(tangent, cs.held_dofs)


def _law_groups(space, cs, laws: Sequence[FrictionLaw | None]) -> LawGroups:
    """Each row's law (index into the used ones, ``-1`` frictionless) and nodal weight
    (:meth:`~signorini.algebra.friction.laws.FrictionLaw.nodal_weight`, checked)."""
    k = cs.n_rows
    index = np.full(k, -1, dtype=np.int64)
    weight = np.zeros(k)
    used = []
    for i, law in enumerate(laws):  # a loop over parts
        if law is None:
            continue
        what = f"the {type(law).__name__} bound of contact part {cs.parts[i]!r}"
        values = np.asarray(law.nodal_weight(_integrator(space, cs, i), k), dtype=np.float64)
        if values.shape != (k,) or not np.isfinite(values).all():
            raise ProblemError(f"{what}: its nodal weights must be {k} finite numbers >= 0")
        values = _vertex_zeros(values, what)
        mine = cs.part == i
        index[mine] = len(used)
        weight[mine] = values[mine]
        used.append(law)
    return LawGroups(tuple(used), index, weight)


#: a nodal weight ``∫ s φ_z`` within this many ulps of the largest weight of zero is the
#: round-off of an integral that vanishes (a vertex of a flat face under condition (a))
WEIGHT_ROUNDOFF = 64


def _vertex_zeros(values: np.ndarray, what: str) -> np.ndarray:
    """``values`` with those within round-off of zero set to zero (docs/method.md, *Tresca under
    condition (a)*): with the plain P2 face basis (``face_alpha=0``) the vertex weights
    ``∫ s φ_v`` vanish on flat faces and come out as ``±`` round-off.

    Raises
    ------
    ProblemError
        If a weight is negative beyond round-off: curved faces under condition (a), where
        ``∫ s φ_v`` is truly negative and the discrete friction functional not convex.
    """
    tol = WEIGHT_ROUNDOFF * np.finfo(float).eps * np.abs(values).max(initial=0.0)
    below = np.flatnonzero(values < -tol)
    if below.size:
        raise ProblemError(
            f"{what}: its nodal weights ∫ s φ_z are negative at {below.size} row(s) "
            f"(the most {values[below].min():.3g}): with face_alpha=0 (condition (a)) the "
            "vertex weights of curved faces are negative; use the transformed face basis "
            "(0 < face_alpha < 1/2, None for the default)"
        )
    return np.where(values <= tol, 0.0, values)


def _integrator(space: P2TetSpace, cs: FaceContactSet, i: int):
    """``integrate(f) = (T ∫ f ψ_z)`` over the faces of part ``i`` per row ``(k,)``."""
    parts = cs.parts
    facet_index = np.concatenate([space.mesh.part_facets(p) for p in parts])
    on = np.flatnonzero(cs.face_part == i)
    s, wq = triangle_rule(4)
    phi = space.element.facet.basis(s)  # (q, 6)

    def integrate(field) -> np.ndarray:
        integral = np.zeros((on.size, 6))
        for rows, group in space.boundary_facets(facet_index[on]):  # flat / quadratic
            x = group.points(s)  # (j, q, 3)
            f = np.asarray(field(x.reshape(-1, 3)), dtype=np.float64).reshape(x.shape[:2])
            integral[rows] = (group.speeds(s) * wq * f) @ phi
        full = np.zeros(cs.faces.shape)
        full[on] = integral
        return cs.row_integrals(full)

    return integrate
