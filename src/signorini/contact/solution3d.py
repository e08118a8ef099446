"""What a 3D solution derives (docs/method.md, *Three dimensions: solving elasticity*): the
Cartesian displacement of the system's unknowns and the errors against an exact solution
(energy, H¹ seminorm, L²) of :mod:`signorini.fem.elasticity3d`; beside
:mod:`.solution`, which calls them where the mesh is tetrahedral.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..fem.elasticity3d import energy_error2_3d, h1_seminorm_error2_3d, l2_error2_3d
from ..problem.fields import evaluate_field
from .face_contact import FaceContactSet
from .mortar3d_set import MortarFaceSet
from .node_frames import to_cartesian
from .node_frames3d import to_cartesian_3d
from .system import Assembled
from .two_body import physical

if TYPE_CHECKING:
    from .contact_set import ContactSet
    from .solution import ContactResult

__all__ = [
    "ERROR_DEGREE_3D",
    "cartesian_displacement",
    "contact_force",
    "errors_3d",
    "nodal_pressure",
]

#: the rule's degree for errors against a smooth exact solution on the tetrahedron (5³
#: points)
ERROR_DEGREE_3D = 8


def cartesian_displacement(x: np.ndarray, assembled: Assembled) -> np.ndarray:
    """``(n_nodes, d)`` the Cartesian nodal displacements of the system's unknowns ``x
    (n_dofs,)``: out of the node frames (:func:`~.node_frames.to_cartesian`) and, with
    contact pairs, back from the relative displacement (:func:`~.two_body.physical`); in
    3D ``x`` out of the rollers' frames, or with contact ``R x`` out of the frames and the
    transformed face basis (:meth:`~.face_contact.FaceContactSet.displacement`)."""
    if isinstance(assembled.contact, FaceContactSet | MortarFaceSet):
        return assembled.contact.displacement(x).reshape(-1, 3)
    if assembled.space.mesh.dim == 3:  # out of the oblique and curved rollers' frames
        return to_cartesian_3d(x, assembled.frame_nodes, assembled.frames).reshape(-1, 3)
    y = to_cartesian(x, assembled.frame_nodes, assembled.frames).reshape(-1, 2)
    return physical(y, assembled.contact.transfer)


def contact_force(contact: ContactSet | FaceContactSet, multiplier: np.ndarray) -> np.ndarray:
    """``(k,)`` the contact force Λ_z (3.17) of the solver's multiplier: the multiplier itself,
    or on faces ``T^{-1} Λ̃`` back from the transformed basis
    (:meth:`~.face_basis.FaceEdges.untransformed`)."""
    if isinstance(contact, FaceContactSet):
        return contact.edges.untransformed(multiplier)
    return multiplier


def nodal_pressure(result: ContactResult) -> np.ndarray:
    """``(k,)`` the consistent nodal pressure: ``Λ_z / w_z`` by the facet element, or on faces
    the transformed basis's ``Λ̃_z / w̃_z`` (:meth:`~.face_contact.FaceContactSet.pressure`),
    of contact pairs the dual basis's ``Λ̃_j / D_jj``."""
    cs = result.contact
    if isinstance(cs, FaceContactSet | MortarFaceSet):
        return cs.pressure(result.contact_force)
    return result.space.element.facet.pressure(result.contact_force, cs.basis_integral)


def errors_3d(result: ContactResult, degree: int = ERROR_DEGREE_3D) -> dict[str, float]:
    """``error_energy`` ``a(e, e)^{1/2}``, ``error_h1`` ``|e|_{H¹}`` and ``error_l2``
    ``‖e‖_{L²}`` of ``e = u − u_h`` on a tetrahedral mesh, with the rule of ``degree`` on
    the tetrahedron; the exact solution's functions take points ``(n, 3)``."""
    exact = result.problem.exact
    material = result.problem.material_on(result.mesh)

    def gradient(x: np.ndarray) -> np.ndarray:
        return evaluate_field(exact.gradient, x, "the exact gradient", shape=(3, 3))

    def displacement(x: np.ndarray) -> np.ndarray:
        return evaluate_field(exact.displacement, x, "the exact displacement", shape=(3,))

    space, u = result.space, result.u
    energy = energy_error2_3d(space, u, gradient, material, degree=degree)
    h1 = h1_seminorm_error2_3d(space, u, gradient, degree=degree)
    l2 = l2_error2_3d(space, u, displacement, degree=degree)
    return {
        "error_energy": float(np.sqrt(energy)),
        "error_h1": float(np.sqrt(h1)),
        "error_l2": float(np.sqrt(l2)),
    }
