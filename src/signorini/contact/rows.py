"""The constraint rows of a contact set from its (node, part) candidates: candidates of one
node with the same direction merge into one constraint, two directions make a corner
(docs/method.md, *Contact directions*)."""

from __future__ import annotations

import numpy as np

from ..problem.fields import ProblemError

__all__ = ["MAX_CORNER_COS", "MIN_CORNER_ANGLE", "SAME_DIRECTION", "constraint_rows"]

#: two parts' constraint directions at a shared node closer than this (|n − m|) are one
#: constraint; their gaps must then agree
SAME_DIRECTION = 1e-8
#: a corner's two constraint directions must be at least this angle apart (radians): the
#: corner frame's condition number grows like 1 / sin² of the angle
MIN_CORNER_ANGLE = 1e-2
#: two directions at a node closer than MIN_CORNER_ANGLE to opposite are refused as well
MAX_CORNER_COS = float(np.cos(MIN_CORNER_ANGLE))


def constraint_rows(
    nodes: np.ndarray, direction: np.ndarray, gap: np.ndarray, points: np.ndarray, names: tuple
) -> tuple[np.ndarray, np.ndarray]:
    """Which constraint row each (node, part) candidate becomes, and whether it starts one.

    Candidates (sorted by node, then part) of the same node with directions closer than
    :data:`SAME_DIRECTION` are one constraint (their gaps must agree); a node with two
    distinct directions is a corner.
    """
    same_node = nodes[1:] == nodes[:-1]
    diff = np.abs(direction[1:] - direction[:-1]).max(axis=1, initial=0.0)
    merge = np.concatenate([[False], same_node & (diff <= SAME_DIRECTION)])
    scale = max(float(np.abs(gap).max(initial=0.0)), 1e-300)
    bad = np.flatnonzero(merge[1:] & (np.abs(gap[1:] - gap[:-1]) > 1e-12 * scale))
    if bad.size:
        raise ProblemError(
            f"node {nodes[bad[0]]} at {points[nodes[bad[0]]].tolist()} lies on contact parts "
            "whose gap functions disagree there; the obstacle must be continuous"
        )
    corner = np.concatenate([[False], same_node]) & ~merge
    cos = np.einsum("kc,kc->k", direction[1:], direction[:-1])
    _refuse_opposite(nodes, points, names, np.flatnonzero(corner[1:] & (cos < -MAX_CORNER_COS)))
    narrow = np.flatnonzero(corner[1:] & (np.arccos(np.clip(cos, -1, 1)) < MIN_CORNER_ANGLE))
    if narrow.size:
        raise ProblemError(
            f"node {nodes[narrow[0]]} at {points[nodes[narrow[0]]].tolist()} lies on two "
            "contact parts whose constraint directions "
            f"differ by less than {MIN_CORNER_ANGLE} rad but are not equal: two constraints "
            "there would be ill-conditioned; join the parts into one part (its normal at the "
            "node is then the mean of its edges') or give them the same obstacle"
        )
    starts = ~merge
    return np.cumsum(starts) - 1, starts


def _refuse_opposite(nodes: np.ndarray, points: np.ndarray, names: tuple, pair: np.ndarray):
    """Refuse a node whose two contact parts' directions are (nearly) opposite.

    Two opposite constraints ``u·n ≤ ψ_1`` and ``−u·n ≤ ψ_2`` bound the same displacement
    component from both sides: a box, not a corner. The corner frame gives each of a node's
    constraints its own DOF (``A_z = [n; m]`` must be invertible) and PDAS one bound per DOF,
    so the pair cannot be represented; and it arises where the body's boundary folds back on
    itself at the node (a slit, a cusp), or two obstacles pinch one point from both sides.
    ``pair`` indexes the first of each such pair of candidates.
    """
    if pair.size == 0:
        return
    i = pair[0]
    part_names, part = names
    x = points[nodes[i]]
    raise ProblemError(
        f"the node at ({x[0]:.12g}, {x[1]:.12g}) lies on contact parts "
        f"{part_names[part[i]]!r} and {part_names[part[i + 1]]!r}, whose constraint directions "
        f"there are opposite (within {MIN_CORNER_ANGLE} rad; {pair.size} such node(s)): the "
        "two constraints bound one displacement component from both sides, which a corner "
        "node's two constraints cannot represent. Let the obstacles meet the body on one side "
        "of the node, or make the node a Dirichlet node"
    )
