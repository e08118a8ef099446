"""A 3D contact level's contact surface as plain arrays, for the figures that draw it
(``plots.contact_map``, ``plots.body3d``): the P2 nodes of the contact parts' faces with the
solution's fields there (:meth:`FaceContactSet.fields
<signorini.contact.face_contact.FaceContactSet.fields>`), and the planes among the
obstacles (docs/method.md, *Three dimensions: contact on faces*, "What a 3D contact run
shows")."""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

import numpy as np

from ..problem.obstacle_base import MovedObstacle
from ..problem.obstacles3d import HalfSpace

if TYPE_CHECKING:
    from ..contact.solution import ContactResult

__all__ = ["obstacle_planes", "surface_arrays"]


def surface_arrays(result: ContactResult) -> dict[str, Any]:
    """The contact surface of a 3D contact solution.

    Returns
    -------
    dict
        ``points (m, 3)``, the P2 nodes of the contact parts' faces; ``faces (f, 6)``, each
        face's nodes as rows of ``points`` (three vertices in outward order, then the
        midpoints of ab, bc, ca); ``face_part (f,)``, an index into ``parts``, the contact
        parts' names; ``displacement (m, 3)``; at each node the fields of
        :meth:`FaceFields.at_nodes <signorini.contact.face_fields.FaceFields.at_nodes>`:
        ``recovered_pressure``, ``pressure``, ``gap``, ``contact_force`` ``(m,)``, ``active
        (m,)`` bool and ``normal (m, 3)``; ``planes``, the plane obstacles
        (:func:`obstacle_planes`).
    """
    cs = result.contact
    nodes, local = np.unique(cs.faces, return_inverse=True)
    rows = cs.fields(result.u, result.contact_force, result.active)
    nodal = rows.at_nodes(result.space.n_nodes)
    arrays = {
        "points": result.space.node_points[nodes],
        "faces": local.reshape(cs.faces.shape),
        "face_part": cs.face_part,
        "parts": cs.parts,
        "displacement": result.u[nodes],
        **{name: value[nodes] for name, value in nodal.items()},
        "planes": obstacle_planes(result.problem.conditions, cs.parts),
    }
    arrays["active"] = arrays["active"] > 0
    return arrays


def obstacle_planes(
    conditions: Mapping[str, Any], parts: tuple[str, ...]
) -> list[tuple[np.ndarray, np.ndarray]]:
    """``[(point (3,), normal (3,)), ...]``: the boundary plane of each contact part's
    obstacle that is a :class:`~signorini.problem.obstacles3d.HalfSpace` (also when moved),
    its normal the obstacle's outward one (towards the body), each plane once."""
    planes = []
    for name in parts:  # a loop over the contact parts
        shape, shift = conditions[name].obstacle, np.zeros(3)
        if isinstance(shape, MovedObstacle):
            shape, shift = shape.shape, shape.displacement
        if isinstance(shape, HalfSpace):
            plane = (shape.point + shift, shape.normal.copy())
            if not any(_same(plane, other) for other in planes):
                planes.append(plane)
    return planes


def _same(a: tuple[np.ndarray, np.ndarray], b: tuple[np.ndarray, np.ndarray]) -> bool:
    """Two planes ``(point, normal)`` are one."""
    return bool(np.allclose(a[1], b[1]) and abs((a[0] - b[0]) @ a[1]) <= 1e-12)
