"""The contact terms of the 3D estimator on the faces of Γ_C: η4, η5, η6 and η7
(docs/method.md, *Three dimensions: the estimator on tetrahedra and faces*).

- **η4, η5** split the traction σ(u_h)n along the constraint direction field d (the
  normalised P2 interpolant of the nodal directions n_z, :func:`.faces3d.direction_field_3d`):
  ``σ_nn = d·σn`` and the tangent vector ``σ_t = σn − σ_nn d``; the consistent η5 is
  ``‖σ_nn + p_h‖²``, p_h the P2 interpolant on the face of the nodal pressure of
  :data:`PRESSURE_3D` (``transformed``: ``p̃_z = Λ̃_z / w̃_z`` of condition (b); ``recovered``:
  the P1-lumped pressure of either condition; held nodes 0, as Dirichlet end points in 2D).
- **η6** ``= s_p d_p`` at the semi-contact rows, ``d_p = ∫_{γ̃_p} (ψ_h − u_h·n)⁺ φ_p``: φ_p
  the P1 hat of the once-refined face (its support γ̃_p: a vertex's corner triangle, a
  midpoint's three triangles), ``ψ_h − u_h·n`` the P2 interpolant on the face of the nodal
  gaps ``ψ(z) − u_h(z)·n_z`` (the obstacle the constraints see), integrated over its positive
  set by :func:`~.surface.positive_part.positive_region_rule`; ``s_p = Λ̃_p / m_p``, the
  solver's multiplier (``Λ̃ = T Λ``, the force on the transformed functions; Λ itself for
  condition (a)) over ``m_p = ∫ φ_p``.
- **η7** is the guaranteed localised bound ``G`` of ``‖(u_h·n − ψ_h)⁺‖_{H^{1/2}(Γ_C)}``
  (:func:`~.surface.penetration.surface_penetration`; docs/method.md, *Three dimensions:
  positive parts on faces and η7 on surfaces*): the 3D replacement of the exact norm.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..contact.contact_set import SEMI_CONTACT
from ..contact.mortar3d_set import MortarFaceSet
from ..contact.solution import ContactResult
from ..fem.p2 import REFERENCE_NODES, grad_basis
from ..fem.p2 import basis as face_basis_at
from ..fem.p2_tet import face_basis
from ..fem.quadrature import triangle_rule
from ..problem.fields import evaluate_field
from .faces3d import TetStress, direction_field_3d, face_geometry
from .friction_faces3d import consistent_pressure, eta8_parts, friction_faces
from .surface.penetration import surface_penetration
from .surface.positive_part import PIECE_NODES, positive_region_rule, refined_face_hats
from .terms import FacetSet, normal_stress, tangential_stress

__all__ = [
    "PRESSURES_3D",
    "PRESSURE_3D",
    "ContactTerms",
    "contact_terms",
    "eta5_pressure",
    "obstacle_oscillation",
]

#: the nodal pressures the consistent η5 may balance σ_nn with
PRESSURES_3D = ("transformed", "recovered")
#: the default: (b)'s own p̃ (docs/method.md, *Three dimensions: the estimator on
#: tetrahedra and faces*, the measured comparison); condition (a) has none and takes the
#: recovered one
PRESSURE_3D = "transformed"
#: polynomial degree of η6's rule on the positive sets: ``v φ_p`` is cubic on a flat face;
#: two more for the area element of a quadratic face (measured on a strongly curved face:
#: 7·10⁻⁵ relative at degree 3, below the reference's 3·10⁻⁵ at 5)
ETA6_DEGREE = 5


class ContactTerms(NamedTuple):
    """The contact faces and the contact terms' integrals on them.

    Attributes
    ----------
    faces : FacetSet
        The contact faces (nodes ``(n_f, 6)``, :attr:`FaceContactSet.faces`).
    J4, J5 : (n_f,) float arrays
        ``‖σ_t‖²_F`` and ``‖σ_nn [+ p_h]‖²_F``.
    parts6 : (n_f, 6) float array
        η6's ``s_p d_p`` share of each face node.
    eta7 : (n_f,) float array
        Each face's share of η7² (the guaranteed bound G).
    oscillation : (n_f,) float array
        Each face's ``|∫_F λ̃_h (ψ − ψ_h)|`` (:func:`obstacle_oscillation`), in the unit of
        η6²; reported beside η_h, not a part of it.
    parts8 : (n_f, 6) float array or None
        η8's share of each face node with friction (:func:`.friction_faces3d.eta8_parts`);
        None without.
    """

    faces: FacetSet
    J4: np.ndarray
    J5: np.ndarray
    parts6: np.ndarray
    eta7: np.ndarray
    oscillation: np.ndarray
    parts8: np.ndarray | None = None


def contact_terms(
    result: ContactResult,
    stresses: TetStress,
    eta5_variant: str,
    s: np.ndarray,
    w: np.ndarray,
    pressure: str = PRESSURE_3D,
) -> ContactTerms | None:
    """η4 … η7 on the contact faces of a 3D solution (None without contact).

    Parameters
    ----------
    result : ContactResult
    stresses : TetStress
        σ(u_h) in the stress unit.
    eta5_variant : {"consistent", "paper"}
    s, w : triangle rule
        Points ``(q, 2)`` and weights (summing to 1/2) for η4, η5.
    pressure : {"transformed", "recovered"}
        The nodal pressure of the consistent η5 (:func:`eta5_pressure`).
    """
    cs, space, mesh = result.contact, result.space, result.mesh
    if not cs.size:
        return None
    e = np.concatenate([mesh.part_facets(p) for p in cs.parts])
    faces = FacetSet(e, cs.faces, mesh.facet2cell[e], mesh.facet_measure[e])
    rows = cs.facet_local
    on_faces = np.where(rows >= 0, 1.0, 0.0)
    p_face = None
    if eta5_variant == "consistent":
        p = eta5_pressure(result, pressure) / stresses.unit
        p_face = on_faces * p[np.maximum(rows, 0)]
    d = direction_field_3d(cs.facet_direction, s)
    friction = friction_faces(result, stresses.unit)
    p_t = None if friction is None else np.einsum("qa,fac->fqc", face_basis(s), friction.friction)
    J4, J5 = np.zeros(e.size), np.zeros(e.size)
    for sel, geometry in face_geometry(space, cs.faces):
        sigma = stresses.at_faces(faces.cells[sel, 0], cs.faces[sel, :3], s)
        n = np.broadcast_to(geometry.normals(s), sigma.shape[:2] + (3,))
        sn = (sigma @ n[..., None])[..., 0]
        if p_face is not None:  # σn + p_h d: its d-part is σ_nn + p_h, its tangent part σ_t
            sn = sn + (p_face[sel] @ face_basis(s).T)[..., None] * d[sel]
        speeds = geometry.speeds(s)
        # with friction η4 balances σ_t by the friction stress: the tangent part of σn + p_t,h
        sn4 = sn if p_t is None else sn + p_t[sel]
        J4[sel] = tangential_stress(sn4, d[sel], w, speeds)
        J5[sel] = normal_stress(sn, d[sel], None, w, speeds)
    gap = cs.facet_normal_gap(result.u)  # u_h·n − ψ_h at the face nodes
    points = space.node_points[cs.faces]
    density = _semi_contact_density(result) / stresses.unit
    parts6 = on_faces * density[np.maximum(rows, 0)] * _hat_integrals(-gap, points)
    force = np.maximum(transformed_force(result) / cs.hat_integral, 0.0)
    s_face = on_faces * (force / stresses.unit)[np.maximum(rows, 0)]
    oscillation = obstacle_oscillation(result, s_face)
    parts8 = None if friction is None else eta8_parts(result, friction)
    eta7 = surface_penetration(points, gap)
    return ContactTerms(faces, J4, J5, parts6, eta7, oscillation, parts8)


def obstacle_oscillation(result: ContactResult, density: np.ndarray) -> np.ndarray:
    """``(n_f,)`` ``|∫_F λ̃_h (ψ − ψ_h)|`` on each contact face: the obstacle's interpolation
    term of the reliability bound (docs/method.md, *Three dimensions: the estimator on
    tetrahedra and faces*, "η6 and the obstacle").

    ``λ̃_h = Σ_p s_p φ_p`` with the refined-face hats and the nodal densities ``density (n_f,
    6)`` (``s_p = Λ̃_p / m_p`` at every row, in the stress unit), ψ the part's obstacle or gap
    function at the points of a degree-6 rule in each of the four triangles of the once-refined
    face, ψ_h its P2 interpolant through the nodal ψ. Zero where ψ is piecewise quadratic on
    the faces (ψ = ψ_h) or nothing pushes, and on the slave faces of pairs, whose constraints
    read the weighted gap itself (no interpolated obstacle)."""
    cs, space = result.contact, result.space
    if isinstance(cs, MortarFaceSet):
        return np.zeros(len(cs.faces))
    xi, w = triangle_rule(6)
    corners = REFERENCE_NODES[PIECE_NODES]  # (4, 3, 2)
    s = np.concatenate([c[0] + xi @ np.stack([c[1] - c[0], c[2] - c[0]]) for c in corners])
    piece = np.repeat(np.arange(4), len(xi))
    weight = np.tile(w / 4.0, 4)  # each piece is a quarter of the reference triangle
    lam = density @ refined_face_hats(s, piece).T  # (n_f, 4q)
    psi_h = cs.facet_gap @ face_basis(s).T
    out = np.zeros(len(cs.faces))
    for sel, geometry in face_geometry(space, cs.faces):
        x = np.broadcast_to(geometry.points(s), (len(geometry), len(s), 3))
        psi = np.empty(x.shape[:2])
        part = cs.face_part[sel]
        for i, name in enumerate(cs.parts):  # a loop over parts
            mine = part == i
            cond = result.problem.conditions[name]
            y = x[mine].reshape(-1, 3)
            if cond.obstacle is not None:
                value = cond.obstacle.gap_and_direction(y)[0]
            else:
                value = evaluate_field(cond.gap_field(), y, f"the gap of {name!r}", shape=())
            psi[mine] = value.reshape(-1, len(s))
        area = np.broadcast_to(geometry.speeds(s), psi.shape) * weight
        out[sel] = np.abs((area * lam[sel] * (psi - psi_h[sel])).sum(axis=1))
    return out


def eta5_pressure(result: ContactResult, which: str = PRESSURE_3D) -> np.ndarray:
    """``(k,)`` the nodal pressure of the consistent η5: ``transformed`` (p̃ = Λ̃ / w̃ of
    condition (b); the recovered one for condition (a), whose vertex weights vanish) or
    ``recovered`` (:meth:`~signorini.contact.face_contact.FaceContactSet.recovered_pressure`).

    Raises
    ------
    ValueError
        For another ``which``.
    """
    if which not in PRESSURES_3D:
        raise ValueError(f"the 3D eta5 pressure must be one of {PRESSURES_3D}, got {which!r}")
    if isinstance(result.contact, MortarFaceSet):  # pairs: the dual basis's p_j = Λ̃_j / D_jj
        return result.contact.pressure(result.contact_force)
    if which == "transformed":
        return consistent_pressure(result, result.contact_force)
    return result.contact.recovered_pressure(result.contact_force)


def _semi_contact_density(result: ContactResult) -> np.ndarray:
    """``(k,)`` ``s_p = Λ̃_p / m_p`` at the semi-contact rows, else 0; a negative Λ̃_p is
    round-off (the KKT check bounds it) and counts as 0, so that η6² stays ≥ 0."""
    cs = result.contact
    semi = result.classes == SEMI_CONTACT
    return np.where(semi, np.maximum(transformed_force(result) / cs.hat_integral, 0.0), 0.0)


def transformed_force(result: ContactResult) -> np.ndarray:
    """``(k,)`` the solver's multiplier Λ̃: ``T Λ`` of a rigid obstacle's rows (the force on
    the transformed functions; Λ itself for condition (a)), the contact force itself for the
    rows of pairs (already on ``φ̃_j n_j``)."""
    cs = result.contact
    if isinstance(cs, MortarFaceSet):
        return np.asarray(result.contact_force, dtype=np.float64)
    return cs.edges.transformed(result.contact_force)


def _tangents(points: np.ndarray, face: np.ndarray, s: np.ndarray) -> np.ndarray:
    """``(m, 2, 3)`` ``∂x/∂s₁, ∂x/∂s₂`` of the P2 face maps of faces ``face (m,)`` (node
    points ``points (n_f, 6, 3)``) at one point ``s (m, 2)`` each (flat faces: constant)."""
    return np.swapaxes(grad_basis(s), 1, 2) @ points[face]  # (m, 2, 6) × (m, 6, 3)


def _hat_integrals(v: np.ndarray, points: np.ndarray) -> np.ndarray:
    """``(n_f, 6)`` ``∫_F v⁺ φ_a`` over each face for the refined-face hats φ_a, v the P2
    function of the nodal values ``v (n_f, 6)``, through each face's area element."""
    rule = positive_region_rule(v, ETA6_DEGREE)
    out = np.zeros(v.shape)
    if rule.face.size == 0:
        return out
    t = _tangents(points, rule.face, rule.s)
    area = np.linalg.norm(np.cross(t[:, 0], t[:, 1]), axis=1)
    value = np.einsum("ma,ma->m", face_basis_at(rule.s), v[rule.face])
    weight = rule.w * area * np.maximum(value, 0.0)
    hats = refined_face_hats(rule.s, rule.piece)
    for a in range(v.shape[1]):  # a loop over the six face nodes
        out[:, a] = np.bincount(rule.face, weights=weight * hats[:, a], minlength=len(v))
    return out
