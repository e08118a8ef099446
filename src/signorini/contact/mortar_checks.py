"""The refusals of a mortar contact pair (:func:`signorini.contact.mortar.mortar_coupling`):
parts that cannot be coupled, a master too short for the slave, an initial overlap beyond
the small-deformation model (docs/method.md, *Two bodies: the dual mortar coupling*)."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from ..fem.space import P2Space
from ..mesh.validation import MeshError
from ..problem.fields import ProblemError
from .admissible import DEEP_OVERLAP

__all__ = ["COVERAGE_TOL", "check_coupling", "check_pair", "pair_size"]

#: a constrained slave node's ψ_j must lie wholly over the master: ``|coverage − 1| ≤
#: COVERAGE_TOL`` (ψ_j changes sign, so a partly covered node may have a coverage above 1)
COVERAGE_TOL = 1e-12


def _bodies(space: P2Space) -> np.ndarray:
    """``(n_cells,)`` the body of each cell: components of the cells joined through interior
    facets (as :class:`~signorini.problem.ContactProblem` finds them)."""
    mesh = space.mesh
    f2c = mesh.facet2cell
    inner = f2c[:, 1] >= 0
    graph = sp.coo_matrix(
        (np.ones(int(inner.sum()), dtype=np.int8), (f2c[inner, 0], f2c[inner, 1])),
        shape=(mesh.n_cells, mesh.n_cells),
    )
    return connected_components(graph, directed=False)[1]


def check_pair(space: P2Space, slave: str, master: str, pair: str) -> tuple:
    """Refuse a pair that cannot be coupled, before any work: see :func:`mortar_coupling`.
    Returns the cells' bodies and the two parts' bodies."""
    mesh = space.mesh
    for role, name in (("slave", slave), ("master", master)):
        if not isinstance(name, str):
            raise ProblemError(f"{pair}: the {role} must be a boundary part's name (a str)")
        try:
            mesh.part_index(name)
        except MeshError as err:
            raise ProblemError(f"{pair}: {err}") from None
    if slave == master:
        raise ProblemError(f"{pair}: the slave and the master must be two different parts")
    common = np.intersect1d(space.part_nodes([slave]), space.part_nodes([master]))
    if common.size:
        x = space.node_points[common[0]]
        raise ProblemError(
            f"{pair}: the node at ({x[0]:.12g}, {x[1]:.12g}) lies on both parts ({common.size} "
            "node(s)): a pair joins parts of two bodies, which share no node"
        )
    label = _bodies(space)
    found = []
    for role, name in (("slave", slave), ("master", master)):
        owner = np.unique(label[mesh.facet2cell[mesh.part_facets(name), 0]])
        if owner.size > 1:
            raise ProblemError(
                f"{pair}: the {role} part {name!r} runs over {owner.size} bodies (components "
                "of the mesh); a contact part must lie on one body: split it"
            )
        found.append(int(owner[0]))
    if found[0] == found[1]:
        raise ProblemError(
            f"{pair}: both parts lie on one body (a connected component of the mesh), where "
            "they cannot meet: in small deformation a body does not reach its own boundary "
            "(self-contact is not modelled); a pair joins parts of two bodies"
        )
    return label, found


def pair_size(space: P2Space, bodies: tuple) -> float:
    """The diagonal of the bounding box of the pair's two bodies."""
    label, found = bodies
    cells = space.mesh.cells[np.isin(label, found)]
    return float(np.hypot(*np.ptp(space.mesh.points[cells.ravel()], axis=0)))


def check_coupling(c, data: tuple, pair: str) -> None:
    """Refuse a constrained slave node not wholly over the master, and an initial overlap
    beyond the small-deformation model
    (docs/method.md, *Two bodies: the dual mortar coupling*)."""
    mine, size, x = data
    bad = np.flatnonzero(mine & (np.abs(c.coverage - 1) > COVERAGE_TOL))
    if bad.size:
        i = bad[np.argmax(np.abs(c.coverage[bad] - 1))]
        raise ProblemError(
            f"{pair}: the master is too short for the slave: the slave node at "
            f"({x[i, 0]:.12g}, {x[i, 1]:.12g}) has only {c.coverage[i]:.6g} of its "
            f"multiplier's support over the master ({bad.size} such node(s)); shorten the "
            "slave part to where the master lies opposite, or swap the roles (the shorter "
            "part as slave)"
        )
    depth = -c.weighted_gap / c.D
    bad = np.flatnonzero(mine & (depth > DEEP_OVERLAP * size))
    if bad.size:
        i = bad[np.argmax(depth[bad])]
        raise ProblemError(
            f"{pair}: the bodies overlap by {depth[i]:.6g} at the slave node ({x[i, 0]:.12g}, "
            f"{x[i, 1]:.12g}), more than {DEEP_OVERLAP} times their size {size:.6g}: beyond "
            "the small-deformation model; move the bodies apart"
        )
