"""η4 and η8 with friction on the faces of Γ_C in 3D (docs/method.md, *Three dimensions:
the frictional estimator terms on faces*): the 2D terms of *Estimator*, "With friction",
with the tangential quantities 2-vectors of each row's node frame ``[n t_1 t_2]`` and the
disc ``‖p_t‖ ≤ b`` in place of the interval.

At the six nodes of every contact face (0 at held nodes, as at Dirichlet end points in 2D):

- ``p_t,z = Σ_j p_j t_j``, ``p_j`` the nodal stress of the friction force ``Λ̃_t,j`` (the
  solver's, on the transformed functions φ̃_z) by the same pressure as the consistent η5
  (:func:`~.contact_faces3d.eta5_pressure`: ``Λ̃ / w̃`` for condition (b), the recovered one
  for (a)); the obstacle acts on the body with ``−Λ_t``, so ``σ_t(u_h) + p_t,h ≈ 0``;
- ``b_z``, the slip bound ``s_z`` of the node's law at its contact force (Tresca ``∫ s φ̃_z``,
  Coulomb ``F Λ̃_n``) by the same pressure;
- ``u_t(z) = u_h(z) − (u_h(z)·n_z) n_z − Σ_j r_j t_j``, the slip from the law's reference
  ``r`` (a load step's previous tangential displacement, in nodal values).

p_t,h, b_h and u_t^h are the P2 interpolants on the face; η8's integrand
``max(b_h, ‖p_t,h‖) ‖u_t^h‖ − p_t,h·u_t^h ≥ 0`` is integrated by a composite rule
(:data:`ETA8_SPLIT`² triangles, degree :data:`ETA8_DEGREE`: it has kinks on the curves
``‖p_t,h‖ = b_h`` and at the zeros of u_t^h) and given to the face nodes by the hats of the
once-refined face (as η6), a held node's part to the face's other nodes equally.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..contact.face_friction import row_tangents
from ..contact.mortar3d_set import MortarFaceSet
from ..contact.solution import ContactResult
from ..fem.p2_tet import face_basis
from ..fem.quadrature import triangle_rule
from .faces3d import face_geometry
from .surface.positive_part import refined_face_hats

__all__ = [
    "ETA8_DEGREE",
    "ETA8_SPLIT",
    "FrictionFaces",
    "consistent_pressure",
    "eta8_parts",
    "friction_faces",
]

#: sub-triangles per side of the composite rule of η8 (even: each lies in one piece of the
#: once-refined face)
ETA8_SPLIT = 4
#: degree of the rule on each sub-triangle
ETA8_DEGREE = 4
#: faces per block of η8's integrand (its temporaries are ``BLOCK × 96 × 3`` floats)
BLOCK = 4096


class FrictionFaces(NamedTuple):
    """The frictional quantities at the six nodes of each contact face: ``friction`` p_t,z
    ``(n_f, 6, 3)`` and ``bound`` b_z ``(n_f, 6)`` (stresses in the estimator's unit),
    ``slip`` u_t ``(n_f, 6, 3)`` (displacement)."""

    friction: np.ndarray
    bound: np.ndarray
    slip: np.ndarray


def friction_faces(result: ContactResult, unit: float = 1.0) -> FrictionFaces | None:
    """The nodal inputs of η4 and η8 on the contact faces of a 3D frictional result
    (module docstring; :func:`_pair_inputs` for the rows of pairs), stresses divided by
    ``unit``; ``None`` without friction."""
    cs = result.contact
    if not cs.has_friction:
        return None
    fr = cs.friction
    rows = cs.facet_local
    inside = rows >= 0
    row = np.maximum(rows, 0)
    t = row_tangents(cs)  # (k, 2, 3)
    free = ~fr.held
    force_t = np.where(free, result.tangential_force, 0.0)
    if isinstance(cs, MortarFaceSet):
        p, bound, slip = _pair_inputs(result, force_t, t)
    else:

        def stress(force: np.ndarray) -> np.ndarray:  # Λ̃ (k,) to a nodal stress
            return np.nan_to_num(consistent_pressure(result, cs.edges.untransformed(force)))

        p = sum(stress(force_t[:, j])[:, None] * t[:, j] for j in range(2))  # (k, 3)
        normal = cs.edges.transformed(result.contact_force)  # Λ̃_n, the solver's
        bound = stress(fr.laws.slip_bound(normal, result.active))
        n_dofs = result.u.size
        z = np.zeros(n_dofs)
        z[fr.tangent[free]] = result.tangential_reference[free]
        reference = (fr.change_of_variables(n_dofs) @ z)[fr.tangent] * free  # nodal values
        ref = np.einsum("kj,kjc->kc", reference, t)
        u = np.asarray(result.u, dtype=np.float64)[cs.faces]  # (n_f, 6, 3)
        n = cs.facet_direction
        slip = u - np.einsum("fjc,fjc->fj", u, n)[..., None] * n
        slip = slip - np.where(inside[..., None], ref[row], 0.0)
    return FrictionFaces(
        friction=np.where(inside[..., None], p[row], 0.0) / unit,
        bound=np.where(inside, np.maximum(bound, 0.0)[row], 0.0) / unit,
        slip=slip,
    )


def _pair_inputs(result: ContactResult, force_t: np.ndarray, t: np.ndarray):
    """``p_t (k, 3)``, ``b (k,)`` and the slip ``(n_f, 6, 3)`` of the rows of pairs
    (docs/method.md, *Two bodies in three dimensions: friction*): the dual basis's
    coefficients ``p_j = Λ̃_t,j / D_jj`` along the tangents ``t (k, 2, 3)`` and ``b_j =
    s_j / D_jj`` (Tresca ``s``, Coulomb ``F p_j``); the slip the relative one, the rows'
    unknowns ``t·(ũ_j − Σ_k T_jk u_k)`` less the reference as coefficients of the
    transformed basis, at the slave faces' nodes (0 at nodes without rows)."""
    cs = result.contact
    fr = cs.friction
    p = np.einsum("kj,kjc->kc", force_t / cs.basis_integral[:, None], t)
    bound = cs.pressure(fr.laws.slip_bound(result.contact_force, result.active))
    y = cs.unknowns(np.asarray(result.u, dtype=np.float64).ravel())
    relative = np.where(fr.held, 0.0, y[fr.tangent] - result.tangential_reference)
    coefficients = np.zeros((result.u.size // 3, 3))
    coefficients[cs.node] = np.einsum("kj,kjc->kc", relative, t)
    return p, bound, cs.sides.nodal(coefficients)[cs.faces]


def consistent_pressure(result: ContactResult, force: np.ndarray) -> np.ndarray:
    """The consistent η5's nodal stress of a force ``Λ (k,)`` on the rows: ``Λ̃ / w̃`` for
    condition (b) (α > 0), the recovered one for condition (a), whose vertex weights
    vanish (:func:`~.contact_faces3d.eta5_pressure` of the contact force)."""
    cs = result.contact
    if cs.edges.alpha > 0:
        return cs.pressure(force)
    return cs.recovered_pressure(force)


def composite_rule(split: int = ETA8_SPLIT, degree: int = ETA8_DEGREE):
    """Points ``(q, 2)``, weights (summing to 1/2) and the piece of the once-refined face
    ``(q,)`` of the composite rule on ``split``² sub-triangles of the reference triangle."""
    xi, w = triangle_rule(degree)
    h = 1.0 / split
    corners = []
    for i in range(split):  # a loop over the rule's rows of sub-triangles (fixed size)
        for j in range(split - i):
            corners.append([(i, j), (i + 1, j), (i, j + 1)])
            if j < split - i - 1:
                corners.append([(i + 1, j), (i + 1, j + 1), (i, j + 1)])
    c = np.array(corners, dtype=np.float64) * h  # (m, 3, 2)
    s = (c[:, :1] + xi[None] @ (c[:, 1:] - c[:, :1])).reshape(-1, 2)  # affine maps
    weight = np.tile(w * h * h, len(c))
    centre = c.mean(axis=1)
    lam = np.column_stack([1.0 - centre.sum(axis=1), centre])
    piece = np.where(lam.max(axis=1) > 0.5, lam.argmax(axis=1), 3)
    return s, weight, np.repeat(piece, len(xi))


def eta8_parts(result: ContactResult, data: FrictionFaces) -> np.ndarray:
    """``(n_f, 6)`` η8's part of each face node: ``∫_F (max(b_h, ‖p_t,h‖) ‖u_t^h‖ −
    p_t,h·u_t^h) φ_a`` by :func:`composite_rule`, a held node's part spread over the face's
    other nodes (module docstring); the parts of a face sum to its integral."""
    cs = result.contact
    s, w, piece = composite_rule()
    phi = face_basis(s)  # (q, 6)
    f = np.empty((len(cs.faces), len(w)))
    for start in range(0, len(f), BLOCK):  # blocks of faces: bounded temporaries
        at = slice(start, start + BLOCK)
        p = np.einsum("qa,fac->fqc", phi, data.friction[at])
        u = np.einsum("qa,fac->fqc", phi, data.slip[at])
        bound = np.maximum(data.bound[at] @ phi.T, np.linalg.norm(p, axis=-1))
        f[at] = bound * np.linalg.norm(u, axis=-1) - np.einsum("fqc,fqc->fq", p, u)
    f = np.maximum(f, 0.0)  # ≥ 0 pointwise (Cauchy–Schwarz); round-off below
    hats = refined_face_hats(s, piece)  # (q, 6)
    parts = np.zeros(data.bound.shape)
    for sel, geometry in face_geometry(result.space, cs.faces):
        area = np.broadcast_to(geometry.speeds(s), f[sel].shape) * w
        parts[sel] = (area * f[sel]) @ hats
    held = cs.facet_local < 0
    free = (~held).sum(axis=1)
    moved = np.where(held, parts, 0.0).sum(axis=1)
    share = np.divide(moved, free, out=np.zeros_like(moved), where=free > 0)
    return np.where(held, 0.0, parts + share[:, None]) + np.where((free == 0)[:, None], parts, 0.0)
