"""The rigid motions of a 3D body that its Dirichlet and Roller parts leave free, and whether
its contact parts can hold them (docs/method.md, *Force control*; *Three dimensions:
rollers, force control, regions*).

A rigid motion in space is ``r(x) = a + ω × (x − x_c) / L``: six coefficients ``(a, ω)`` in a
basis scaled by the body's centre ``x_c`` and size ``L`` (:func:`~.rigid.motion_field`'s frame),
so that the six columns are alike. A held Cartesian component ``u_c`` at a vertex and a
roller's ``u·n`` there are linear conditions on the coefficients; their null space is the
free motions (SVD, the rank tolerance of :data:`~.rigid.RANK_RTOL`). Frictionless contact
acts along the contact directions only, so a free motion tangential to every contact face
(zero ``r(x_F)·n_F`` at every contact face's centroid) is held by nothing and is refused,
named: ``translation along (…)``, ``rotation about the axis (…) through (…)``.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from ..mesh.geometry import facet_normals
from ..mesh.mesh import Mesh
from .fields import ProblemError
from .normals import face_node_normals
from .rigid import _frame, _null_space

__all__ = [
    "describe_motion_3d",
    "free_rigid_motions_3d",
    "motion_field_3d",
    "rigid_modes_3d",
]

#: a rotation whose size ``|ω|`` is below this times the motion's largest coefficient is a
#: translation; a screw's pitch below it is a rotation
MOTION_RTOL = 1e-8


def rigid_modes_3d(x: np.ndarray) -> np.ndarray:
    """``(n, 3, 6)`` the rigid motions at points ``x (n, 3)``: the translations ``e_k`` and
    the rotations ``e_k × x`` (k = 0, 1, 2)."""
    n = x.shape[0]
    modes = np.zeros((n, 3, 6))
    modes[:, [0, 1, 2], [0, 1, 2]] = 1.0
    eye = np.eye(3)
    modes[:, :, 3:] = np.cross(eye[None, :, :], x[:, None, :]).transpose(0, 2, 1)
    return modes


def motion_field_3d(mesh: Mesh, motions: np.ndarray, x: np.ndarray) -> np.ndarray:
    """The rigid motions ``motions (k, 6)`` of :func:`free_rigid_motions_3d` at the points
    ``x (n, 3)``: ``(k, n, 3)``."""
    centre, size = _frame(mesh)
    return np.einsum("nck,mk->mnc", rigid_modes_3d((x - centre) / size), motions)


def describe_motion_3d(mesh: Mesh, motion: np.ndarray) -> str:
    """A rigid motion of space in words: ``translation along (0, 0, 1)``, ``rotation about
    the axis (0, 0, 1) through (x, y, z)`` or a screw motion about such an axis."""
    centre, size = _frame(mesh)
    m = np.asarray(motion, dtype=np.float64) / np.abs(motion).max()
    a, omega = m[:3], m[3:] / size
    if np.linalg.norm(omega) * size <= MOTION_RTOL:
        d = a / np.linalg.norm(a)
        d = d if d[np.argmax(np.abs(d))] > 0 else -d
        return f"translation along {tuple((np.round(d, 6) + 0.0).tolist())}"
    w2 = float(omega @ omega)
    axis = omega / np.sqrt(w2)
    axis = axis if axis[np.argmax(np.abs(axis))] > 0 else -axis
    through = centre + np.cross(omega, a) / w2
    kind = (
        "rotation" if abs(a @ axis) <= MOTION_RTOL * np.linalg.norm(a) + 1e-15 else "screw motion"
    )
    return (
        f"{kind} about the axis {tuple((np.round(axis, 6) + 0.0).tolist())} through "
        f"{tuple((np.round(through, 6) + 0.0).tolist())}"
    )


def free_rigid_motions_3d(
    space, held: Mapping[str, object], rollers: Mapping[str, object], contact_parts: list[str]
) -> np.ndarray:
    """The rigid motions ``(k, 6)`` (orthonormal coefficients, ``k ≤ 6``) that the held
    components of ``held`` (part name → :class:`~.conditions.Dirichlet`, axis rollers among
    them) and the oblique and curved ``rollers`` (part name → :class:`~.conditions.Roller`:
    ``r·n = 0`` at the part's vertices, ``n`` of :func:`~.normals.face_node_normals`) leave
    free, on the P2 space ``space`` of a tetrahedral mesh.

    Raises
    ------
    ProblemError
        If a free motion is tangential to every contact part (or there is none): nothing
        holds it. The message names the motion.
    """
    mesh = space.mesh
    centre, size = _frame(mesh)
    rows = [np.zeros((0, 6))]
    for name, cond in held.items():  # a loop over parts
        v = np.unique(mesh.facets[mesh.part_facets(name)])
        comp = np.resize(np.asarray(cond.components), 3)
        rows.append(rigid_modes_3d((mesh.points[v] - centre) / size)[:, comp, :].reshape(-1, 6))
    for name in rollers:  # a loop over parts
        v = np.unique(mesh.facets[mesh.part_facets(name)])
        n = face_node_normals(space, name, v)  # vertices come first in the P2 numbering
        modes = rigid_modes_3d((mesh.points[v] - centre) / size)
        rows.append(np.einsum("nc,nck->nk", n, modes))
    free = _null_space(np.concatenate(rows), 6)
    if free.shape[0] == 0:
        return free
    if contact_parts:
        faces = np.concatenate([mesh.facets[mesh.part_facets(p)] for p in contact_parts])
        _, n = facet_normals(mesh.points[faces])
        r = motion_field_3d(mesh, free, mesh.points[faces].mean(axis=1))  # (k, n_f, 3)
        loose = _null_space(np.einsum("kfc,fc->fk", r, n), free.shape[0]) @ free
    else:
        loose = free
    if loose.shape[0]:
        motions = "; ".join(describe_motion_3d(mesh, m) for m in loose)
        held_by = (
            f"the contact parts {contact_parts} act only along their normals, to which it is "
            "tangential"
            if contact_parts
            else "there is no contact part"
        )
        raise ProblemError(
            f"the Dirichlet and Roller parts {list(held) + list(rollers)} leave {loose.shape[0]}"
            f" rigid motion(s) of the body free, held by nothing: {motions}; {held_by}. Hold "
            "more components (e.g. one part with Dirichlet((0, 0, 0)) or a Roller) or add a "
            "contact part that holds it (docs/method.md, *Force control*)"
        )
    return free
