"""Contact pairs between two deformable bodies: which slave part touches which master part
(docs/method.md, *Two bodies*)."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from ..mesh.bodies import body_of_cells
from ..mesh.mesh import Mesh
from .conditions import Contact
from .fields import ProblemError
from .rigid import motion_conditions, null_motions

__all__ = ["check_bodies_held", "contact_pairs"]


def contact_pairs(mesh: Mesh, conditions: Mapping[str, object]) -> dict[str, str]:
    """``{slave part: master part}`` of the conditions ``Contact(master=...)``.

    Raises
    ------
    ProblemError
        If a master is not a boundary part of the mesh, is the slave itself, has a condition
        of its own, is a slave of another pair, or is the master of two slaves.
    """
    pairs = {
        name: cond.master
        for name, cond in conditions.items()
        if isinstance(cond, Contact) and cond.master is not None
    }
    for slave, master in pairs.items():
        if master not in mesh.part_names:
            raise ProblemError(
                f"contact part {slave!r}: its master {master!r} is not a boundary part of the "
                f"mesh; its parts are {list(mesh.part_names)}"
            )
        if master == slave:
            raise ProblemError(f"contact part {slave!r} names itself as its master")
        if master in pairs:
            raise ProblemError(
                f"part {master!r} is the master of contact part {slave!r} and the slave of "
                f"{pairs[master]!r}: a part is one side of one pair"
            )
        if master in conditions:
            raise ProblemError(
                f"part {master!r} is the master of contact part {slave!r}: the pair gives it "
                f"its traction, so it takes no condition of its own (remove "
                f"{type(conditions[master]).__name__}(...) from conditions)"
            )
    seen: dict[str, str] = {}
    for slave, master in pairs.items():
        if master in seen:
            raise ProblemError(
                f"part {master!r} is the master of both {seen[master]!r} and {slave!r}; join "
                "the two slave parts into one part"
            )
        seen[master] = slave
    return pairs


def check_bodies_held(
    mesh: Mesh,
    held: Mapping[str, object],
    pairs: Mapping[str, str],
    rollers: Mapping[str, tuple[np.ndarray, np.ndarray]] | None = None,
) -> None:
    """Each body with a part in a contact pair must have its rigid motions held by its own
    Dirichlet and Roller parts (a body held only through a pair, under force control, is not
    supported; docs/method.md, *Two bodies*). ``held``: the parts holding Cartesian
    components; ``rollers``: the oblique and curved roller parts, each part's vertices and
    normals there.

    Raises
    ------
    ProblemError
        Naming the body (by its parts) and how many rigid motions its own parts leave free.
    """
    if not pairs:
        return
    body = body_of_cells(mesh)
    edge_body = np.full(mesh.n_edges, -1)
    edge_body[mesh.edge_part >= 0] = body[mesh.edge2cell[mesh.edge_part >= 0, 0]]
    paired = np.concatenate([mesh.part_edges(p) for p in (*pairs, *pairs.values())])
    for b in np.unique(edge_body[paired]):  # a loop over bodies
        rank = 3 - null_motions(motion_conditions(mesh, held, rollers, edge_body == b)).shape[0]
        if rank < 3:
            parts = [p for p in mesh.part_names if (edge_body[mesh.part_edges(p)] == b).any()]
            raise ProblemError(
                f"the body with the parts {parts} is held by its own Dirichlet and Roller "
                f"parts in {rank} of its 3 rigid motions; a body in a contact pair must be "
                "held by its own parts (a body held only through its contact with another, "
                "under force control, is not supported yet): add a Dirichlet or Roller part"
            )
