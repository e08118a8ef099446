"""The rigid motions of the bodies in the unknowns of an assembled system: the near-nullspace
an algebraic multigrid builds its coarse spaces from (:mod:`signorini.algebra.backends.petsc_gamg`).

Each body (a connected component of the mesh, :func:`~signorini.mesh.bodies.body_of_cells`)
moves rigidly by ``u(x) = a + ω (−(y − y_b), x − x_b)``, ``(x_b, y_b)`` its centroid: two
translations and a rotation, three vectors per body, each zero off its body; in 3D by
``u(x) = a + ω × (x − x_b)``, three translations and three rotations, six vectors per body
(docs/method.md, *Three dimensions: the linear solver (measured)*). The assembled
stiffness matrix ``K`` annihilates them before the Dirichlet DOFs are fixed — in the
system's unknowns ``y``, which are the Cartesian displacement written in node frames at the
contact and roller nodes, ``u = Q y`` (:mod:`.node_frames`), and with contact pairs the
relative displacement ``ũ = (I − T_d) u`` (:mod:`.two_body`). So a motion ``u`` of the
bodies is ``y = Q⁻¹ (I − T_d) u`` there, and ``K y = 0`` holds to round-off (tested). In 3D
with contact the unknowns are those of the frames and the transformed face basis,
``ỹ = P⁻¹ Q⁻¹ u`` (:meth:`~.face_contact.FaceContactSet.unknowns`).
"""

from __future__ import annotations

import numpy as np

from ..fem.space import node_dofs
from ..mesh.bodies import body_of_cells
from ..problem.rigid3d import rigid_modes_3d
from .face_contact import FaceContactSet
from .mortar3d_set import MortarFaceSet
from .node_frames import to_frames
from .node_frames3d import to_frames_3d
from .system import Assembled

__all__ = ["system_rigid_modes"]


def system_rigid_modes(assembled: Assembled) -> np.ndarray:
    """The rigid motions of every body of ``assembled``'s mesh in its system's unknowns.

    Parameters
    ----------
    assembled : Assembled

    Returns
    -------
    (n_dofs, 3 n_bodies) float array in 2D, (n_dofs, 6 n_bodies) in 3D
        2D: columns ``3b, 3b + 1, 3b + 2``, body b's translations along x and y and its
        rotation about its centroid; 3D: columns ``6b + c`` the translations along ``e_c``
        and ``6b + 3 + a`` the rotations ``e_a × (x − x_b)`` about the centroid ``x_b``;
        written as the system's unknowns (module docstring).
    """
    return _in_system(_cartesian_modes(assembled), assembled)


def _cartesian_modes(assembled: Assembled) -> np.ndarray:
    """The rigid motions of every body as Cartesian DOFs (the columns of
    :func:`system_rigid_modes`, before the change of unknowns)."""
    space = assembled.space
    points = space.node_points
    cell_body = body_of_cells(space.mesh)
    body = np.zeros(space.n_nodes, dtype=np.int64)
    body[space.cell_nodes.ravel()] = np.repeat(cell_body, space.cell_nodes.shape[1])
    n_bodies = int(cell_body.max(initial=0)) + 1
    count = np.bincount(body, minlength=n_bodies)
    centre = (
        np.stack(
            [
                np.bincount(body, weights=points[:, k], minlength=n_bodies)
                for k in range(space.mesh.dim)
            ],
            axis=1,
        )
        / np.maximum(count, 1)[:, None]
    )
    local = points - centre[body]
    d = space.mesh.dim
    k = 3 if d == 2 else 6  # the rigid motions of one body: d translations, d(d-1)/2 rotations
    modes = np.zeros((space.n_dofs, k * n_bodies))
    dofs = node_dofs(np.arange(space.n_nodes), space.n_components).T  # (d, n_nodes)
    if d == 2:
        x, y = dofs
        modes[x, 3 * body] = 1.0
        modes[y, 3 * body + 1] = 1.0
        modes[x, 3 * body + 2] = -local[:, 1]
        modes[y, 3 * body + 2] = local[:, 0]
    else:  # translations e_c and rotations e_a × (x − x_b)
        motion = rigid_modes_3d(local)  # (n_nodes, 3, 6)
        for c in range(3):  # a loop over the three components
            modes[dofs[c][:, None], 6 * body[:, None] + np.arange(6)] = motion[:, c, :]
    return modes


def _in_system(modes: np.ndarray, assembled: Assembled) -> np.ndarray:
    """Cartesian ``modes`` as the unknowns of a 2D system (relative displacement, frames)
    or of a 3D system without contact (Cartesian itself)."""
    space = assembled.space
    transfer = assembled.contact.transfer
    if transfer is not None:  # the relative displacement of the contact pairs
        modes = modes - transfer.dofs @ modes
    if isinstance(assembled.contact, FaceContactSet | MortarFaceSet):  # ỹ = R⁻¹ u
        return np.column_stack([assembled.contact.unknowns(m) for m in modes.T])
    if space.mesh.dim == 3:  # the frames of the oblique and curved rollers
        return np.column_stack(
            [to_frames_3d(m, assembled.frame_nodes, assembled.frames) for m in modes.T]
        )
    return to_frames(modes, assembled.frame_nodes, assembled.frames)
