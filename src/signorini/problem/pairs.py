"""Contact pairs between two deformable bodies: which slave part touches which master part
(docs/method.md, *Two bodies*)."""

from __future__ import annotations

from collections.abc import Mapping

from ..mesh.mesh import Mesh
from .conditions import Contact
from .fields import ProblemError

__all__ = ["contact_pairs"]


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
