"""The refusals of a contact set's data before the solve: Dirichlet values that violate the
contact constraint at a node they share with a contact part, an obstacle shape on the body's
side of its contact part, and one that starts deeper inside the body than the model covers
(docs/method.md, *Obstacles as shapes*; docs/reliability.md).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING

import numpy as np

from ..algebra.ranks import Ranks
from ..fem.space import LagrangeSpace
from ..problem.fields import DATA_MAX, ProblemError
from .constraint_data import body_normals

if TYPE_CHECKING:
    from .discrete_conditions import DiscreteConditions
    from .mortar import MortarCoupling

__all__ = [
    "DEEP_OVERLAP",
    "DIRICHLET_GAP_RTOL",
    "DIRICHLET_POINT_TOL",
    "SIDE_TOL",
    "check_dirichlet_admissible",
    "check_initial_overlap",
    "check_load_size",
    "check_obstacle_side",
    "deepest_overlap",
]


#: a node inside an obstacle shape is refused when its constraint direction points into the
#: body by more than this: ``n_z·n < −SIDE_TOL`` with the body's outward unit normal ``n``.
#: Both are unit vectors computed from coordinates, exact to about 1e-15 (measured: −1.2e-16
#: at the equator of hertz's arc, where the exact value is 0); the margin lets a direction
#: along the boundary (a node beside a punch's side wall, pushed out sideways) pass however
#: it is rounded, and refuses every direction that pulls the body outward by more than
#: 1e-8 of its penetration (docs/method.md, *Obstacles as shapes*, "Obstacle on the body's
#: side")
SIDE_TOL = 1e-8


def check_obstacle_side(
    conditions: DiscreteConditions,
    space: LagrangeSpace,
    cs_facets: tuple,
    chord: np.ndarray,
    constraint: tuple,
) -> None:
    """Refuse an obstacle shape that lies on the body's side of its contact part.

    A node ``z`` with ``ψ(z) < 0`` is inside the obstacle, and the constraint
    ``u(z)·n_z ≤ ψ(z)`` moves it by at least ``|ψ(z)|`` along ``−n_z`` to the obstacle's
    surface point closest to it. Pressed by an obstacle outside it, the body is pushed in:
    ``n_z`` (into the obstacle) points out of the body, ``n_z·n > 0`` with the body's
    outward normal ``n``, or along its boundary (``n_z·n = 0``, beside a punch's side wall).
    Where ``n_z·n < 0`` the closest surface lies on the body's inner side (a :class:`Disc`
    centred inside the body, a :class:`HalfPlane` whose normal points away from the body):
    the constraint pulls the contact side outward through the obstacle, however shallow the
    overlap, and the "solution" is that of another problem. Refused beyond round-off,
    ``ψ(z) < −DIRICHLET_POINT_TOL · extent`` and ``n_z·n < −SIDE_TOL``; gap functions (the
    direction is the body's normal) and the slaves of contact pairs are not concerned.

    Parameters
    ----------
    conditions : DiscreteConditions
        The problem's conditions on ``space`` (:mod:`~.discrete_conditions`).
    space : LagrangeSpace
    cs_facets : tuple of (tuple of str, (n_cf,) int array, (n_cf, m) int array)
        The contact parts, the part of each contact facet (an edge in 2D) and its nodes
        ``[start, end, midpoint]`` (P1: ``[start, end]``).
    chord : (n_cf, 2) float array
        The outward unit normal of each facet (the part's own on a straight part).
    constraint : tuple of (n_cf, m, 2) and (n_cf, m) float arrays
        The direction n_z and the gap ψ(z) at those nodes.

    Raises
    ------
    ProblemError
        Naming the part, its obstacle, the node, ψ, n_z, the body's normal and their product.
    """
    parts, facet_part, facet_nodes = cs_facets
    direction, gap = constraint
    pts = space.mesh.points
    depth_tol = DIRICHLET_POINT_TOL * float(np.abs(pts).max() + np.ptp(pts, axis=0).max())
    for i, name in enumerate(parts):  # a loop over parts
        if not conditions.is_shape[i] or name in conditions.pairs:
            continue
        sel = np.flatnonzero(facet_part == i)
        normal = body_normals(conditions, space, i, facet_nodes[sel], chord[sel])
        along = np.einsum("ejc,ejc->ej", direction[sel], normal).ravel()
        inside = gap[sel].ravel() < -depth_tol
        bad = np.flatnonzero(inside & (along < -SIDE_TOL))
        if bad.size == 0:
            continue
        k = bad[np.argmin(along[bad])]
        x = space.node_points[facet_nodes[sel].ravel()[k]]
        n_z, n = direction[sel].reshape(-1, 2)[k] + 0.0, normal.reshape(-1, 2)[k] + 0.0
        count = np.unique(facet_nodes[sel].ravel()[bad]).size
        raise ProblemError(
            f"the obstacle {conditions.obstacles[i]!r} of contact part {name!r} lies on the "
            f"body's side of it: the node at ({x[0]:.12g}, {x[1]:.12g}) starts inside it (ψ = "
            f"{gap[sel].ravel()[k]:.6g}), and its constraint direction n_z = ({n_z[0]:.6g}, "
            f"{n_z[1]:.6g}) (the obstacle's normal into it at its surface point nearest the node) "
            f"points into the "
            f"body, n_z·n = {along[k]:.6g} with the body's outward normal n = ({n[0]:.6g}, "
            f"{n[1]:.6g}) ({count} such node(s)): the constraint would pull the contact side "
            "outward through the obstacle instead of pushing it back. Place the obstacle "
            "outside the body, against the contact part (a Disc's centre outside the body; a "
            "HalfPlane's normal pointing from the obstacle towards the body)"
        )


#: a Dirichlet value may exceed the gap at a node it shares with a contact part by round-off:
#: this fraction of the larger of max|u_D| and max|ψ| there, plus
#: :data:`DIRICHLET_POINT_TOL` times the extent of the mesh (round-off of a distance
#: computed from coordinates)
DIRICHLET_GAP_RTOL = 1e-9
DIRICHLET_POINT_TOL = 1e-12


def check_dirichlet_admissible(
    conditions: DiscreteConditions,
    space: LagrangeSpace,
    nodes: np.ndarray,
    constraint: tuple,
    parts: tuple,
    couplings: Mapping[str, MortarCoupling] | None = None,
) -> None:
    """Refuse Dirichlet data that violate the contact constraint at a node of a contact part.

    At a node on the closure of both Γ_D and Γ_C the displacement is prescribed, so the
    constraint ``u(z)·n_z ≤ ψ(z)`` of the contact part holds only if ``u_D(z)·n_z ≤ ψ(z)``:
    otherwise the admissible set K of the continuous problem is empty (no displacement with
    these boundary values keeps the body out of the obstacle) and the discrete solutions
    converge to nothing; the estimator's η7 sees the violation at that node on every level
    (docs/method.md, *The continuous problem*).

    On the slave of a contact pair the constraint is on the displacement relative to the
    master's at the node's point π(z) on it, ``(u(z) − u(π(z)))·n_z ≤ ψ(z)`` with the
    pointwise gap ``ψ(z) = (π(z) − z)·n_z``: the same check where the master's displacement
    there is prescribed too (π(z) is a Dirichlet node of the master: the end of the master
    part beside its Dirichlet part), and none where the master is free to move there
    (docs/method.md, *Two bodies*).

    Parameters
    ----------
    conditions : DiscreteConditions
        The problem's conditions on ``space`` (:mod:`~.discrete_conditions`).
    space : P2Space
    nodes : (j,) int array
        Dirichlet nodes on contact facets, one entry per (node, contact part).
    constraint : tuple of (j, 2) and (j,) float arrays
        The constraint direction n_z and the gap ψ(z) of each entry.
    parts : tuple of (tuple of str, (j,) int array)
        The contact parts' names and the part of each entry.
    couplings : mapping slave part -> MortarCoupling, optional
        The contact pairs' couplings; without them the slaves' entries are not checked.

    Raises
    ------
    ProblemError
        Naming the node's coordinates, the Dirichlet and the contact part, u_D·n and ψ
        (on a slave: the master's node and its u_D as well).
    """
    names, part = parts
    value, owner = _dirichlet_values(conditions, nodes)
    direction, gap = (np.array(a, dtype=np.float64) for a in constraint)
    master = np.full(nodes.size, -1)  # the master's Dirichlet node at π(z), on a slave
    entry_part = np.asarray(names, dtype=object)[part]
    keep = ~np.isin(entry_part, list(conditions.pairs))
    held = conditions.held.values if couplings else None
    for slave, c in (couplings or {}).items():  # a loop over pairs
        on = np.flatnonzero(entry_part == slave)
        row = np.searchsorted(c.slave_nodes, nodes[on])
        k, gap_z = _held_master_node(conditions, space, c, row)
        on, k, gap_z = on[k >= 0], k[k >= 0], gap_z[k >= 0]
        master[on], gap[on], keep[on] = k, gap_z, True
        value[on] -= held[k]
    nodes, part, owner, master = nodes[keep], part[keep], owner[keep], master[keep]
    value, direction, gap = value[keep], direction[keep], gap[keep]
    parts = (names, part)
    if nodes.size == 0:
        return
    x = space.node_points[nodes]
    normal_value = np.einsum("kc,kc->k", value, direction)
    excess = normal_value - gap
    pts = space.mesh.points
    extent = float(np.abs(pts).max() + np.ptp(pts, axis=0).max())
    scale = max(float(np.abs(value).max()), float(np.abs(gap).max()))
    bad = np.flatnonzero(excess > DIRICHLET_GAP_RTOL * scale + DIRICHLET_POINT_TOL * extent)
    if bad.size == 0:
        return
    i = bad[np.argmax(excess[bad])]
    more = f" (and {bad.size - 1} more such node(s))" if bad.size > 1 else ""
    relative = ""
    if master[i] >= 0:
        slave = parts[0][parts[1][i]]
        y, u_m = space.node_points[master[i]], held[master[i]]
        relative = (
            f" relative to the node of master part {conditions.pairs[slave]!r} facing it at "
            f"({y[0]:.12g}, {y[1]:.12g}), held at u_D = ({u_m[0]:.6g}, {u_m[1]:.6g}),"
        )
    raise ProblemError(
        f"the node at ({x[i, 0]:.12g}, {x[i, 1]:.12g}) lies on Dirichlet part {owner[i]!r} and "
        f"contact part {parts[0][parts[1][i]]!r}{more}: its prescribed displacement{relative} "
        f"u_D = ({value[i, 0]:.6g}, {value[i, 1]:.6g}) moves it by u_D·n = {normal_value[i]:.6g} "
        f"along the constraint direction n = ({direction[i, 0]:.6g}, {direction[i, 1]:.6g}), "
        f"beyond the gap ψ = {gap[i]:.6g} by {excess[i]:.6g}: the Dirichlet data violate the "
        "contact constraint, so no admissible displacement exists. Make u_D·n ≤ ψ at the "
        "parts' common nodes (e.g. move the obstacle or change u_D)"
    )


def _held_master_node(
    conditions: DiscreteConditions,
    space: LagrangeSpace,
    coupling: MortarCoupling,
    row: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """For the slave nodes ``coupling.slave_nodes[row]``: the master's Dirichlet node (held
    in both components) at their point π(z) on the master, within the round-off of a
    coordinate, or −1; and the pointwise gap ``(π(z) − z)·n_z``."""
    x = space.node_points[coupling.slave_nodes[row]]
    pi, n = coupling.master_point[row], coupling.normal[row]
    master_nodes = space.part_nodes([coupling.master])
    held = conditions.dirichlet_nodes
    candidates = master_nodes[np.isin(master_nodes, held)]
    k = np.full(row.size, -1)
    if candidates.size and row.size:
        y = space.node_points[candidates]
        distance = np.hypot(*(pi[:, None, :] - y[None, :, :]).transpose(2, 0, 1))
        nearest = np.argmin(np.where(np.isnan(distance), np.inf, distance), axis=1)
        pts = space.mesh.points
        tol = DIRICHLET_POINT_TOL * float(np.abs(pts).max() + np.ptp(pts, axis=0).max())
        close = distance[np.arange(row.size), nearest] <= tol
        k[close] = candidates[nearest[close]]
    return k, np.einsum("kc,kc->k", pi - x, n)


#: the deepest initial penetration accepted beyond what the Dirichlet data move the body, as
#: a fraction of the body's size (the diagonal of its bounding box); docs/method.md,
#: *Obstacles as shapes*, "Initial overlap"
DEEP_OVERLAP = 0.25


def _dirichlet_values(conditions: DiscreteConditions, nodes: np.ndarray):
    """``u_D`` at the Dirichlet nodes ``nodes (j,)`` (held in both components, from one part
    or two, a roller's among them: :func:`~signorini.problem.rollers.held_nodes`) and the
    Dirichlet or Roller part of each (the later one at a node on two)."""
    value = conditions.held.values[nodes]
    names = np.asarray(("",) + conditions.held_parts, dtype=object)
    return value, names[conditions.held_part[nodes] + 1]


def check_initial_overlap(
    conditions: DiscreteConditions,
    space: LagrangeSpace,
    nodes: np.ndarray,
    constraint: tuple,
    parts: tuple,
) -> None:
    """Refuse an obstacle shape that starts deeper inside the body than its linearisation
    covers.

    Only shapes (``Contact(obstacle=...)``) are checked: their constraint is linearised at the
    point of the obstacle closest to the node, which for a node deep inside may lie on the far
    side of the obstacle (the body is pulled through it). A gap function ``ψ`` states the
    linear model's data directly and is taken as given at any size (a manufactured solution
    may have a large one).
    A node ``z`` with ``ψ(z) < 0`` starts inside the obstacle: ``u(z)·(−n_z) ≥ |ψ(z)|``. At a
    Dirichlet node ``y`` the displacement is ``u_D(y)``, so ``u`` changes by at least
    ``need = |ψ(z)| − max_y u_D(y)·(−n_z)`` between the two, within the body's size ``d`` (the
    diagonal of its bounding box): the displacement gradient is at least ``need / d``
    somewhere. Small-deformation elasticity and the linearised constraint are first-order
    models in that gradient; beyond ``need > DEEP_OVERLAP · d`` (a gradient of 1/4, where the
    neglected quadratic terms are an eighth of the linear ones) the solution is not a
    small-deformation one: refused. An overlap that the Dirichlet data themselves move the
    body out of (a translation) needs no strain and stays accepted; so does the paper's
    Example 6.2 (``ψ = −0.2`` on the unit square, u_D = 0: 0.14 d). docs/method.md,
    *Obstacles as shapes*.

    Parameters
    ----------
    conditions : DiscreteConditions
        The problem's conditions on ``space`` (:mod:`~.discrete_conditions`).
    space : P2Space
    nodes : (k,) int array
        The constrained nodes (not Dirichlet nodes), one entry per (node, contact part).
    constraint : tuple of (k, 2) and (k,) float arrays
        The direction n_z and the gap ψ(z) of each entry.
    parts : tuple of (tuple of str, (k,) int array)
        The contact parts' names and the part of each entry.

    Raises
    ------
    ProblemError
        Naming the part, the node, its depth, the Dirichlet data's share and the body's size.
    """
    direction, gap = constraint
    pts = space.mesh.points
    size = float(np.hypot(*np.ptp(pts, axis=0)))
    deep = np.flatnonzero((-gap > DEEP_OVERLAP * size) & conditions.is_shape[parts[1]])
    if deep.size == 0:
        return
    value, _ = _dirichlet_values(conditions, conditions.dirichlet_nodes)
    # (deep,) max_y u_D(y)·(−n_z); with no Dirichlet node (a body under force control) the
    # Dirichlet data move the body out by nothing
    found = deepest_overlap(gap, direction, deep, value, size)
    if found is None:
        return
    i, moved = found
    x, name = space.node_points[nodes[i]], parts[0][parts[1][i]]
    raise ProblemError(
        f"the obstacle of contact part {name!r} starts {-gap[i]:.6g} deep inside the body at "
        f"({x[0]:.12g}, {x[1]:.12g}) (ψ = {gap[i]:.6g}; the Dirichlet data move the body out "
        f"by at most {moved:.6g} along the constraint direction), more than "
        f"{DEEP_OVERLAP} times the body's size {size:.6g} (its bounding box's diagonal): the "
        "linearised, small-deformation contact model cannot represent an initial overlap that "
        "deep (it would pull the body through the obstacle with strains of order one). Place "
        "the obstacle at the body's surface (ψ ≈ 0) and move it in by steps of a load path, or "
        "shift the obstacle out"
    )


def check_load_size(K, F: np.ndarray, loads: Mapping[str, float], ranks: Ranks) -> None:
    """Refuse loads whose displacement would overflow: ``F = K u`` on the free rows gives
    ``max |u| ≥ max |F| / ‖K‖∞``, and beyond :data:`~signorini.problem.fields.DATA_MAX` the
    squares of such displacements (norms, energies, η7²) overflow double precision. Loads
    scale with the stiffness (E = 1e300 with loads to match is solved), so they are bounded
    through the displacement, not by their own size.

    Parameters
    ----------
    K : (n, n) or a rank's rows, sparse
        The assembled stiffness matrix.
    F : (n,) float array
        The assembled load vector.
    loads : mapping name -> float
        The largest entry of each load's own vector, e.g. ``{"the traction of Neumann part
        'top'": 0.5}``, to name the largest.
    ranks : Ranks

    Raises
    ------
    ProblemError
        Naming the largest load, the displacement bound and the limit.
    """
    row_sum = float(np.asarray(abs(K).sum(axis=1)).max(initial=0.0))
    if ranks.size > 1:
        row_sum = ranks.max(row_sum)
    force = float(np.abs(F).max(initial=0.0))
    if not loads or (np.isfinite(force) and force <= DATA_MAX * row_sum):
        return
    name = max(loads, key=loads.get)
    with np.errstate(over="ignore", divide="ignore"):
        moved = force / row_sum if row_sum > 0 else np.inf
    raise ProblemError(
        f"{name} is too large for the body's stiffness: the load vector reaches "
        f"{force:.3g} (largest of {name}: {loads[name]:.3g}) against the stiffness matrix's "
        f"largest row sum {row_sum:.3g}, so the displacement reaches at least {moved:.3g} "
        f"(F = K u), beyond ±{DATA_MAX:.3g}, where its squares overflow double precision. "
        "State the loads in the units of E (a load 1e300 times the modulus moves nothing "
        "like a small-deformation body), or check their size"
    )


def deepest_overlap(
    gap: np.ndarray, direction: np.ndarray, deep: np.ndarray, value: np.ndarray, size: float
) -> tuple[int, float] | None:
    """The entry of ``deep`` (rows with ``−ψ > DEEP_OVERLAP · size`` against a shape) that the
    Dirichlet values ``value (m, d)`` move out least, ``need = −ψ − max_y u_D(y)·(−n_z)``, as
    ``(row, moved)`` when its need still exceeds ``DEEP_OVERLAP · size``; None when the data
    move every such row out (:func:`check_initial_overlap`, docs/method.md, *Obstacles as
    shapes*, "Initial overlap"). With no Dirichlet value (a body under force control) the
    data move the body out by nothing."""
    moved = (value @ -direction[deep].T).max(axis=0) if len(value) else np.zeros(deep.size)
    need = -gap[deep] - moved
    worst = int(np.argmax(need))
    if need[worst] <= DEEP_OVERLAP * size:
        return None
    return int(deep[worst]), float(moved[worst])
