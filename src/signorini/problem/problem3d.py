"""The checks of a :class:`~signorini.problem.problem.ContactProblem` on a tetrahedral mesh
(docs/method.md, *Three dimensions: solving elasticity*): 3D elasticity without contact.

A 3D problem holds Dirichlet parts (all or some of ``(u_x, u_y, u_z)``), rollers on planar
parts normal to an axis (one Cartesian component held), Neumann parts and frictionless
contact parts against a gap function or a shape of space (docs/method.md, *Three
dimensions: contact on faces*); friction, contact pairs, plane shapes and oblique rollers are
refused here, before any work.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from ..mesh.mesh import Mesh
from .conditions import Condition, Contact, Dirichlet, Neumann
from .fields import ProblemError

__all__ = ["check_dimension", "check_problem_3d", "rigid_modes_3d"]

#: the relative size of a singular value of the held rigid motions' matrix below which a
#: rigid motion counts as free
RIGID_RTOL = 1e-8


def check_dimension(mesh: Mesh, conditions: Mapping[str, Condition]) -> None:
    """Refuse on a tetrahedral ``mesh`` what 3D contact does not build (friction, pairs,
    plane shapes), and constant data with another number of components than the mesh has
    dimensions.

    Raises
    ------
    ProblemError
        Naming the contact part and what it asks for, or the part whose data have the wrong
        number of components.
    """
    if mesh.dim == 3:
        _check_contact_3d(conditions)
    alpha = [
        n for n, c in conditions.items() if isinstance(c, Contact) and c.face_alpha is not None
    ]
    if mesh.dim == 2 and alpha:
        raise ProblemError(
            f"contact part(s) {alpha} give face_alpha on a 2D mesh: the transformed face basis "
            "is the 3D contact condition on P2 faces"
        )
    for name, cond in conditions.items():  # a loop over parts
        if not isinstance(cond, Dirichlet | Neumann):
            continue
        value = cond.value if isinstance(cond, Dirichlet) else cond.traction
        if not callable(value) and np.size(value) != mesh.dim:
            raise ProblemError(
                f"the condition of part {name!r} gives {np.size(value)} components "
                f"{value!r} on a {mesh.dim}D mesh: give {mesh.dim}, "
                f"{('(x, y)', '(x, y, z)')[mesh.dim - 2]} (None for a free Dirichlet component)"
            )


def _check_contact_3d(conditions: Mapping[str, Condition]) -> None:
    """Refuse what 3D contact on faces does not build yet: friction, contact pairs, a plane
    shape (dim 2) as the obstacle; and contact parts with different ``face_alpha``."""
    for name, cond in conditions.items():  # a loop over parts
        if not isinstance(cond, Contact):
            continue
        what = None
        if cond.friction is not None:
            what = "friction on faces is not built yet (frictionless contact only)"
        elif cond.master is not None:
            what = "contact pairs between bodies are not built in 3D yet"
        elif cond.obstacle is not None and cond.obstacle.dim != 3:
            what = (
                f"the obstacle {cond.obstacle!r} is a plane shape: use a shape of space "
                "(signorini.problem.obstacles3d: HalfSpace, Ball, Cylinder, SignedDistance3D)"
            )
        if what is not None:
            raise ProblemError(f"contact part {name!r} on a 3D (tetrahedral) mesh: {what}")
    alphas = {c.face_alpha for c in conditions.values() if isinstance(c, Contact)}
    if len(alphas) > 1:
        raise ProblemError(
            f"the contact parts give different face_alpha {sorted(alphas, key=str)}: one "
            "discrete contact condition on all of Γ_C"
        )


def rigid_modes_3d(x: np.ndarray) -> np.ndarray:
    """``(n, 3, 6)`` the rigid motions at points ``x (n, 3)``: the translations ``e_k`` and
    the rotations ``e_k × x`` (k = 0, 1, 2)."""
    n = x.shape[0]
    modes = np.zeros((n, 3, 6))
    modes[:, [0, 1, 2], [0, 1, 2]] = 1.0
    eye = np.eye(3)
    modes[:, :, 3:] = np.cross(eye[None, :, :], x[:, None, :]).transpose(0, 2, 1)
    return modes


def check_problem_3d(
    mesh: Mesh,
    held: Mapping[str, Dirichlet],
    rollers: Mapping[str, object],
) -> None:
    """The checks of a 3D problem beyond the 2D ones that hold as they are.

    Parameters
    ----------
    mesh : Mesh
        Tetrahedral.
    held : mapping part -> Dirichlet
        The Dirichlet parts and the axis rollers as Dirichlet conditions.
    rollers : mapping part -> Roller
        The rollers not along an axis (refused).

    Raises
    ------
    ProblemError
        For an oblique or non-planar roller, or rigid motions the held components leave
        free (the matrix would be singular).
    """
    if rollers:
        raise ProblemError(
            f"roller part(s) {list(rollers)} on a 3D mesh are not planar faces normal to the "
            "x, y or z axis: in 3D a Roller holds one Cartesian component of a plane "
            "x, y or z = const (oblique and curved rollers need the node frames of issue 38)"
        )
    # the held components at the held parts' vertices against the six rigid motions
    rows = []
    for name, cond in held.items():  # a loop over parts
        vertices = np.unique(mesh.facets[mesh.part_facets(name)])
        comp = np.resize(np.asarray(cond.components), 3)
        rows.append(rigid_modes_3d(mesh.points[vertices])[:, comp, :].reshape(-1, 6))
    if not rows:
        return
    scale = 1.0 + np.abs(mesh.points).max()
    s = np.linalg.svd(np.concatenate(rows) / scale, compute_uv=False)
    free = 6 - int((s > RIGID_RTOL * s.max(initial=0.0)).sum()) if s.size else 6
    if free > 0:
        raise ProblemError(
            f"the Dirichlet and Roller parts {list(held)} leave {free} rigid motion(s) of the "
            "body free: hold more components (e.g. one part with Dirichlet((0, 0, 0)))"
        )
