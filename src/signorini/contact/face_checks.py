"""The refusals of a 3D contact part's data before any work (docs/method.md, *Three
dimensions: rollers, force control, regions*): a given direction field of the wrong shape
or length or pointing into the body, and an obstacle shape that starts deeper inside the body
than the linearised model covers (the rule of 2D's
:func:`~signorini.contact.admissible.check_initial_overlap`, on faces).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..problem.conditions import Contact
from ..problem.fields import ProblemError, evaluate_field
from ..problem.rollers import HeldNodes
from .admissible import DEEP_OVERLAP, deepest_overlap

__all__ = ["UNIT_RTOL", "check_deep_overlap", "given_directions"]

#: a direction ``Contact(normal=n(x))`` returns must have length 1 within this
UNIT_RTOL = 1e-8


def given_directions(normal, name: str, x: np.ndarray, body: np.ndarray) -> np.ndarray:
    """``(j, 3)`` the directions ``Contact(normal=...)`` gives contact part ``name`` at its
    nodes ``x (j, 3)``: three numbers (normalised), or a function ``n(x)`` of the points
    returning unit vectors ``(j, 3)``; each must point out of the body (``n·n_body > 0``
    with the body's outward normals ``body (j, 3)``; docs/method.md, *Three dimensions:
    rollers, force control, regions*).

    Raises
    ------
    ProblemError
        Naming the part and the first node where the direction has the wrong shape, is not
        of unit length (within :data:`UNIT_RTOL`) or does not point out of the body.
    """
    if callable(normal):
        what = f"the normal of contact part {name!r}"
        n = evaluate_field(normal, x, what, shape=(3,))
        length = np.linalg.norm(n, axis=1)
        bad = np.flatnonzero(np.abs(length - 1.0) > UNIT_RTOL)
        if bad.size:
            raise ProblemError(
                f"{what} has length {length[bad[0]]:.6g} at the node "
                f"{tuple(x[bad[0]].tolist())} ({bad.size} node(s)): it must return unit "
                "vectors (n, 3)"
            )
    else:
        given = np.asarray(normal, dtype=np.float64)
        if given.shape != (3,):
            raise ProblemError(
                f"contact part {name!r}: normal must be 3 numbers (or a function n(x) of "
                f"points (n, 3) returning unit vectors (n, 3)) on a 3D mesh, got {normal!r}"
            )
        n = np.broadcast_to(given / np.linalg.norm(given), x.shape).copy()
    along = np.einsum("jc,jc->j", n, body)
    bad = np.flatnonzero(along <= 0.0)
    if bad.size:
        raise ProblemError(
            f"the normal {tuple(n[bad[0]].tolist())} given for contact part {name!r} at the "
            f"node {tuple(x[bad[0]].tolist())} points into the body or along it (n·n_body = "
            f"{along[bad[0]]:.6g}; {bad.size} node(s)): a constraint direction must point "
            "out of the body, towards the obstacle"
        )
    return n


def check_deep_overlap(
    space, held: HeldNodes, rows: tuple, contact: Sequence[Contact], parts: Sequence[str]
) -> None:
    """Refuse an obstacle shape that starts deeper inside the body than its linearisation
    covers: at a node ``z`` of a contact part against a shape, ``need = −ψ(z) − max_y
    u_D(y)·(−n_z)`` over the Dirichlet nodes ``y`` (held in every component) beyond
    :data:`~.admissible.DEEP_OVERLAP` times the body's size (its bounding box's diagonal);
    gap functions are taken as given (docs/method.md, *Obstacles as shapes*, "Initial
    overlap").

    Parameters
    ----------
    space : P2TetSpace
    held : HeldNodes
    rows : tuple of (c,) int, (c,) int, (c, 3) float, (c,) float arrays
        The candidate rows' nodes, parts, directions and gaps.
    contact : sequence of Contact
        The parts' conditions; ``parts`` their names.
    parts : sequence of str

    Raises
    ------
    ProblemError
        Naming the part, the node, its depth, the Dirichlet data's share and the body's size.
    """
    node, part, direction, gap = rows
    shape = np.array([c.obstacle is not None for c in contact], dtype=bool)
    size = float(np.linalg.norm(np.ptp(space.mesh.points, axis=0)))
    deep = np.flatnonzero((-gap > DEEP_OVERLAP * size) & shape[part])
    if deep.size == 0:
        return
    full = held.components.all(axis=1)
    value = held.values[full] if held.values is not None else np.zeros((0, 3))
    found = deepest_overlap(gap, direction, deep, value, size)
    if found is None:
        return
    i, moved = found
    x = space.node_points[node[i]]
    raise ProblemError(
        f"the obstacle of contact part {parts[part[i]]!r} starts {-gap[i]:.6g} deep inside "
        f"the body at {tuple(x.tolist())} (ψ = {gap[i]:.6g}; the Dirichlet data move the "
        f"body out by at most {moved:.6g} along the constraint direction), more than "
        f"{DEEP_OVERLAP} times the body's size {size:.6g} (its bounding box's diagonal): the "
        "linearised, small-deformation contact model cannot represent an initial overlap that "
        "deep. Place the obstacle at the body's surface (ψ ≈ 0) and move it in by steps of a "
        "load path, or shift the obstacle out"
    )
