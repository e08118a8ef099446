"""Contact pairs between two deformable bodies: which slave part touches which master part
(docs/method.md, *Two bodies*)."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from ..mesh.bodies import body_of_cells
from ..mesh.mesh import Mesh
from .conditions import Contact
from .fields import ProblemError
from .rigid import free_rigid_motions

__all__ = ["contact_pairs", "pair_rigid_motions"]


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


def pair_rigid_motions(
    mesh: Mesh,
    held: Mapping[str, object],
    pairs: Mapping[str, str],
    contact_parts: list[str],
    rollers: Mapping[str, tuple[np.ndarray, np.ndarray]] | None = None,
) -> tuple[np.ndarray, tuple[str, ...]]:
    """The rigid motions of the bodies of a union with contact pairs that their own
    Dirichlet and Roller parts leave free (docs/method.md, *Force control*, "In a contact
    pair"): a body may be under force control where the bodies across its pairs are held by
    their own parts in all 3 rigid motions (a loaded part on a deformable support). ``held``:
    the parts holding Cartesian components; ``rollers``: the oblique and curved roller parts,
    each part's vertices and normals there; ``contact_parts``: every part with a
    :class:`Contact` condition (the slaves and the parts on rigid obstacles).

    Returns
    -------
    motions : (k, 3) float array
        The free motions, each of one body, as :func:`~.rigid.free_rigid_motions` gives them
        (coefficients in the frame of the whole mesh).
    parts : tuple of k str
        For each motion, a boundary part of its body (the body is found from it on any
        refinement of the mesh).

    Raises
    ------
    ProblemError
        Naming the body (by its parts), if a free body touches across a pair another body
        that is not held in all its rigid motions by its own parts (two bodies held only by
        each other), or if a free motion is tangential to every contact part of its body.
    """
    body = body_of_cells(mesh)
    facet_body = np.full(mesh.n_facets, -1)
    facet_body[mesh.facet_part >= 0] = body[mesh.facet2cell[mesh.facet_part >= 0, 0]]
    part_body = {p: int(facet_body[mesh.part_facets(p)[0]]) for p in mesh.part_names}
    masters = set(pairs.values())

    def parts_of(b: int) -> list[str]:
        return [p for p in mesh.part_names if part_body[p] == b]

    free = {}
    for b in range(int(body.max(initial=-1)) + 1):  # a loop over bodies
        own = [p for p in parts_of(b) if p in contact_parts or p in masters]
        free[b] = free_rigid_motions(mesh, held, own, rollers, on_facets=facet_body == b)
    for slave, master in pairs.items():  # a loop over pairs
        a, b = part_body[slave], part_body[master]
        for loose, other in ((a, b), (b, a)):
            if free[loose].shape[0] and free[other].shape[0]:
                raise ProblemError(
                    f"the bodies with the parts {parts_of(loose)} and {parts_of(other)} "
                    f"touch in the contact pair {slave!r} / {master!r}, and neither is held "
                    f"in all its rigid motions by its own Dirichlet and Roller parts: a body "
                    "under force control needs the body across its pairs held (add a "
                    "Dirichlet or Roller part to one of them)"
                )
    motions = [free[b] for b in free if free[b].shape[0]]
    if not motions:
        return np.zeros((0, 3)), ()
    names = tuple(parts_of(b)[0] for b in free for _ in range(free[b].shape[0]))
    return np.concatenate(motions), names
