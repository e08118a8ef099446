"""Friction at a corner of two contact parts, refused when the problem is built
(docs/method.md, *Friction in a ContactProblem*)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..mesh.geometry import facet_normals
from .conditions import Contact
from .fields import ProblemError

if TYPE_CHECKING:
    from .problem import ContactProblem

__all__ = ["check_corner_friction"]


#: two contact parts' directions at a shared vertex closer than this are one constraint (as
#: ``contact.contact_set.SAME_DIRECTION``); farther apart the vertex is a corner
_SAME_DIRECTION = 1e-8


def _part_direction(problem: ContactProblem, name: str, vertex: np.ndarray) -> np.ndarray:
    """The constraint direction of contact part ``name`` at its vertices ``vertex (j,)``
    (docs/method.md, *Contact directions*): the obstacle's for a shape, else the part's given
    or straight normal, its curve's normal, or the normal of its edge there."""
    cond: Contact = problem.conditions[name]
    x = problem.mesh.points[vertex]
    if cond.obstacle is not None:
        return cond.obstacle.gap_and_direction(x)[1]
    if name in problem.contact_normals:
        return np.broadcast_to(problem.contact_normals[name], x.shape)
    mesh = problem.mesh
    ab = mesh.oriented_boundary(mesh.part_facets(name))
    _, chord = facet_normals(mesh.points[ab])
    total = np.zeros((mesh.n_points, 2))
    np.add.at(total, ab.ravel(), np.repeat(chord, 2, axis=0))
    n = total[vertex] / np.hypot(*total[vertex].T)[:, None]
    curve = mesh.curves[mesh.part_index(name)]
    if curve is not None and curve.has_normal:
        m = curve.normal(x)
        return m * np.where(np.einsum("jc,jc->j", m, n) < 0, -1.0, 1.0)[:, None]
    return n


def check_corner_friction(problem: ContactProblem) -> None:
    """Refuse friction at a vertex where two contact parts meet at an angle.

    Such a vertex carries one constraint per part, and the frame of those two constraints
    leaves no tangential direction for a friction law (docs/method.md, *Friction in a
    ContactProblem*); the solve refused it, after the assembly. Checked here on the initial
    mesh: refinement keeps its vertices and their directions.

    Raises
    ------
    ProblemError
        Naming both parts and the vertex.
    """
    mesh = problem.mesh
    parts = problem.contact_parts
    ends = {p: np.unique(mesh.facets[mesh.part_facets(p)]) for p in parts}
    for i, a in enumerate(parts):
        for b in parts[i + 1 :]:
            fa, fb = problem.conditions[a].friction, problem.conditions[b].friction
            if fa is None and fb is None:
                continue
            shared = np.intersect1d(ends[a], ends[b])
            if shared.size == 0:
                continue
            x = mesh.points[shared]
            na, nb = _part_direction(problem, a, shared), _part_direction(problem, b, shared)
            corner = np.flatnonzero(np.abs(na - nb).max(axis=1) > _SAME_DIRECTION)
            if corner.size:
                z = x[corner[0]]
                frictional = [p for p, f in ((a, fa), (b, fb)) if f is not None]
                raise ProblemError(
                    f"the vertex ({z[0]:.12g}, {z[1]:.12g}) is a corner of contact parts {a!r} "
                    f"and {b!r} (two constraint directions), and {frictional} have friction: "
                    "friction at such a corner is not supported; end the frictional part "
                    "before the corner (e.g. a frictionless part for the last edge) or join "
                    "the parts"
                )
