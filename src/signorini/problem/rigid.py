"""The rigid motions of a body that its Dirichlet and Roller parts leave free, and whether
its contact parts can hold them (docs/method.md, *Force control*).

A plane rigid motion is ``r(x) = (a − c (y − y_c) / L, b + c (x − x_c) / L)``: coefficients
``(a, b, c)`` in a basis scaled by the body's centre ``(x_c, y_c)`` and size ``L`` so that the
three columns are alike. A held component ``u_c`` at a vertex is a linear condition on
``(a, b, c)``; the null space of all of them is the free motions. Frictionless contact acts
along the contact directions only, so a free motion tangential to every contact facet (zero
``r(x_e)·n_e`` at every contact facet's midpoint ``x_e``; facets are edges in 2D) is held by
nothing.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from ..mesh.geometry import facet_normals
from ..mesh.mesh import Mesh
from .fields import ProblemError

__all__ = [
    "describe_motion",
    "free_rigid_motions",
    "motion_conditions",
    "motion_field",
    "null_motions",
]

#: a singular value below this times the largest is zero (the conditions are O(1) numbers)
RANK_RTOL = 1e-9


def _frame(mesh: Mesh) -> tuple[np.ndarray, float]:
    centre = 0.5 * (mesh.points.min(axis=0) + mesh.points.max(axis=0))
    size = float(np.ptp(mesh.points, axis=0).max())
    return centre, size


def motion_field(mesh: Mesh, motions: np.ndarray, x: np.ndarray) -> np.ndarray:
    """The rigid motions ``motions (k, 3)`` of :func:`free_rigid_motions` at the points
    ``x (n, 2)``: ``(k, n, 2)``."""
    centre, size = _frame(mesh)
    d = (x - centre) / size
    a, b, c = (motions[:, i, None] for i in range(3))
    return np.stack([a - c * d[None, :, 1], b + c * d[None, :, 0]], axis=-1)


def describe_motion(mesh: Mesh, motion: np.ndarray) -> str:
    """A rigid motion in words: ``translation along (0, 1)`` or ``rotation about (x, y)``
    (on a tetrahedral mesh :func:`~.rigid3d.describe_motion_3d`'s words)."""
    if mesh.dim == 3:
        from .rigid3d import describe_motion_3d  # (which builds on this module's frame)

        return describe_motion_3d(mesh, motion)
    centre, size = _frame(mesh)
    a, b, c = np.asarray(motion, dtype=np.float64) / np.abs(motion).max()
    if abs(c) <= 1e-8:
        d = np.array([a, b]) / np.hypot(a, b)
        d = d if (d[np.argmax(np.abs(d))] > 0) else -d
        return f"translation along {tuple(np.round(d, 6).tolist())}"
    p = centre + size * np.array([-b, a]) / c
    return f"rotation about {tuple(np.round(p, 6).tolist())}"


def _null_space(rows: np.ndarray, k: int) -> np.ndarray:
    """Orthonormal basis ``(m, k)`` of the null space of ``rows (n, k)``."""
    if rows.shape[0] == 0:
        return np.eye(k)
    _, s, vt = np.linalg.svd(rows, full_matrices=True)
    rank = int((s > RANK_RTOL * s.max()).sum()) if s.size and s.max() > 0 else 0
    return vt[rank:]


def motion_conditions(
    mesh: Mesh,
    held: Mapping[str, object],
    rollers: Mapping[str, tuple[np.ndarray, np.ndarray]] | None = None,
    on_facets: np.ndarray | None = None,
) -> np.ndarray:
    """The linear conditions ``(n, 3)`` on a rigid motion's coefficients ``(a, b, c)`` that
    the held components of ``held`` and the roller normals of ``rollers`` (as in
    :func:`free_rigid_motions`) impose at their parts' vertices; with ``on_facets`` (a bool
    mask of the mesh's facets) only the held parts' facets in it and the roller parts that
    start in it (one body of a union)."""
    centre, size = _frame(mesh)
    rows = [np.zeros((0, 3))]
    for name, cond in held.items():  # a loop over parts
        e = mesh.part_facets(name)
        v = np.unique(mesh.facets[e if on_facets is None else e[on_facets[e]]])
        d = (mesh.points[v] - centre) / size
        one, zero = np.ones(v.size), np.zeros(v.size)
        by_component = (
            np.column_stack([one, zero, -d[:, 1]]),
            np.column_stack([zero, one, d[:, 0]]),
        )
        rows += [by_component[c] for c in range(2) if cond.components[c]]
    for name, (x, n) in (rollers or {}).items():  # a loop over parts
        if on_facets is None or on_facets[mesh.part_facets(name)[0]]:
            d = (x - centre) / size  # r·n = a n_x + b n_y + c (d_x n_y − d_y n_x)
            rows.append(np.column_stack([n[:, 0], n[:, 1], d[:, 0] * n[:, 1] - d[:, 1] * n[:, 0]]))
    return np.concatenate(rows)


def null_motions(conditions: np.ndarray) -> np.ndarray:
    """The rigid motions ``(k, 3)`` (orthonormal coefficients) that ``conditions (n, 3)``
    leave free."""
    return _null_space(conditions, 3)


def free_rigid_motions(
    mesh: Mesh,
    held: Mapping[str, object],
    contact_parts: list[str],
    rollers: Mapping[str, tuple[np.ndarray, np.ndarray]] | None = None,
    on_facets: np.ndarray | None = None,
) -> np.ndarray:
    """The rigid motions ``(k, 3)`` (orthonormal coefficients, ``k ≤ 3``) that the held
    components of ``held`` (part name → :class:`~.conditions.Dirichlet`) and the normal
    components held by ``rollers`` (part name → its vertices ``(m, 2)`` and the normals
    ``n (m, 2)`` there: ``r·n = 0``) leave free. A roller on an oblique straight part holds
    the translation along its normal; on a circular arc it leaves the rotation about the
    centre free. With ``on_facets`` (a bool mask of the facets), the motions of one body
    of a union: only its held parts' facets and rollers count (:func:`motion_conditions`).

    Raises
    ------
    ProblemError
        If a free motion is tangential to every contact part (or there is none): nothing
        holds it. The message names the motion.
    """
    free = null_motions(motion_conditions(mesh, held, rollers, on_facets))
    if free.shape[0] == 0:
        return free
    normals, mids = [], []
    for name in contact_parts:  # a loop over parts
        ab = mesh.oriented_boundary(mesh.part_facets(name))
        _, n = facet_normals(mesh.points[ab])
        normals.append(n)
        mids.append(0.5 * (mesh.points[ab[:, 0]] + mesh.points[ab[:, 1]]))
    if normals:
        r = motion_field(mesh, free, np.concatenate(mids))  # (k, n_e, 2)
        along = np.einsum("kec,ec->ek", r, np.concatenate(normals))
        loose = _null_space(along, free.shape[0]) @ free
    else:
        loose = free
    if loose.shape[0]:
        motions = "; ".join(describe_motion(mesh, m) for m in loose)
        held_by = (
            f"the contact parts {contact_parts} act only along their normals, to which it is "
            "tangential"
            if contact_parts
            else "there is no contact part"
        )
        raise ProblemError(
            f"the problem needs a Dirichlet part (meas Γ_D > 0), a Roller or a contact part "
            f"to hold the rigid motion {motions}: the Dirichlet and Roller parts "
            f"{list(held) + list(rollers or {})} leave it free and {held_by} (docs/method.md, "
            "*Force control*)"
        )
    return free
