"""The master side of 3D contact pairs in the estimator: η3 on the master faces with the
consistent master traction (docs/method.md, *Two bodies in three dimensions: the
estimator*).

A master part has no condition of its own: its traction is the one the slave exerts through
the pair. The slave rows' multipliers reach the master nodes as forces on the master's P2
functions, ``f_k = Σ_j T_jk Λ̃_j n_j`` (with friction ``+ Σ_j T_jk Λ̃_t,j``, the friction
forces along the rows' tangents: *Two bodies in three dimensions: friction*)
(:meth:`~signorini.contact.mortar3d_set.MortarFaceSet.master_forces`). In 2D the master
traction is ``g_k = f_k / ∫ φ_k`` (:mod:`.pairs`); on faces the P2 vertex functions integrate
to zero, so the division is made in the transformed basis of the slave's condition (b) on the
master faces, whose integrals are positive:

- ``f̃_a = f_a + α Σ_{e ∋ a} f_e``, ``f̃_e = (1 − 2α) f_e`` (the forces on ``φ̃``), likewise
  ``w̃`` from ``w_k = ∫ φ_k``, and ``g̃_k = f̃_k / w̃_k``;
- ``g_h = Σ_k g̃_k φ̃_k``: its P2 nodal values ``g̃_a`` at vertices and ``(1 − 2α) g̃_e +
  α (g̃_a + g̃_b)`` at side midpoints.

For a uniform traction ``t`` (``f_k = t w_k``) this gives ``g_h = t`` exactly, since the
``φ̃_k`` sum to one: the contact patch test has a zero master residual. The master faces then
enter η3 as Neumann faces with data ``g_h``: ``h_p ‖σ(u_h) n − g_h‖²_F``.
"""

from __future__ import annotations

import numpy as np

from ..contact.face_basis import FaceEdges
from ..contact.mortar3d_set import MortarFaceSet, face_sides
from ..contact.solution import ContactResult
from ..fem.p2_tet import face_basis
from .faces3d import TetStress, face_geometry
from .terms import FacetSet, neumann_residual

__all__ = ["master_faces", "master_tractions"]


def master_faces(result: ContactResult) -> FacetSet:
    """The master parts' faces of a 3D result's pairs (pair after pair), with their six nodes
    in their cell's face order."""
    mesh, space, cs = result.mesh, result.space, result.contact
    e = np.concatenate([mesh.part_facets(m) for m in cs.masters])
    return FacetSet(e, space.facet_nodes(e), mesh.facet2cell[e], mesh.facet_measure[e])


def master_traction(result: ContactResult, faces: FacetSet, s: np.ndarray, w: np.ndarray):
    """``(n_m, q, 3)`` the consistent master traction ``g_h`` (module notes) at the points
    ``s`` of the master faces ``faces``."""
    cs, space = result.contact, result.space
    friction = result.tangential_force if cs.has_friction else None
    f = cs.master_forces(result.contact_force, space.n_nodes, friction)  # (n_nodes, 3)
    integral = np.zeros(faces.nodes.shape)
    for rows, geometry in face_geometry(space, faces.nodes):  # flat, then quadratic
        integral[rows] = (geometry.speeds(s) * w) @ face_basis(s)
    weight = np.bincount(faces.nodes.ravel(), integral.ravel(), minlength=space.n_nodes)
    # the transformed basis on the master faces, the slave's α, over node numbers
    edges = FaceEdges(space.n_nodes, cs.alpha, *face_sides(faces.nodes).T)
    on = np.unique(faces.nodes)
    g = np.zeros_like(f)
    g[on] = edges.transformed(f)[on] / edges.transformed(weight)[on, None]  # f̃ / w̃
    nodal = edges.nodal(g)  # the P2 values of Σ g̃_k φ̃_k
    return np.einsum("qa,kac->kqc", face_basis(s), nodal[faces.nodes])


def master_tractions(
    result: ContactResult, stresses: TetStress, s: np.ndarray, w: np.ndarray
) -> tuple[FacetSet, np.ndarray] | None:
    """η3's master faces and ``‖σ(u_h) n − g_h‖²_F`` on each (in the stress unit), ``g_h``
    the consistent master traction; None without pairs."""
    if not isinstance(result.contact, MortarFaceSet):
        return None
    faces = master_faces(result)
    g = master_traction(result, faces, s, w) / stresses.unit
    J = np.zeros(faces.index.size)
    for rows, geometry in face_geometry(stresses.space, faces.nodes):
        sigma = stresses.at_faces(faces.cells[rows, 0], faces.nodes[rows, :3], s)
        n = np.broadcast_to(geometry.normals(s), sigma.shape[:2] + (3,))
        sn = (sigma @ n[..., None])[..., 0]
        J[rows] = neumann_residual(sn - g[rows], w, geometry.speeds(s))
    return faces, J
