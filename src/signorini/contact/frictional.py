"""SOLVE with friction: the assembled system of a problem whose contact parts carry friction
laws (Tresca, Coulomb, or any :class:`~signorini.algebra.friction.laws.FrictionLaw`, mixed part by
part), handed to the semismooth Newton method of :mod:`signorini.algebra.friction.newton`
(docs/method.md, *Friction: the algebraic problem and its solver*).

Every constraint is one contact node with its normal DOF ``d z`` and tangential DOFs
``d z + j`` (``j = 1 … d − 1``, the frictional problem's ``tangent (m, d − 1)``; in 2D
``2z + 1``) in the node frame ``[n t_1 … t_{d−1}]``; each node has its part's law (the contact set's
:class:`~signorini.algebra.friction.laws.LawGroups`), frictionless parts none (no friction
force). The systems are symmetric (Cholesky) when every law in play is (Tresca), else LU.
Tresca is by default the classical problem, the bound acting on every node of Γ_C (the minimiser of
``½ a(u, u) − L(u) + Σ_z s_z |u_t(z)|`` subject to ``u(z)·n_z ≤ ψ(z)``).

A load step of a quasi-static path (docs/method.md, *Load paths*) gets the previous step's
result: its tangential displacements ``u(z)·t_z`` are the reference ``x_t,ref`` of the law (it
acts on the slip increment), and its node states warm-start the iteration.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..algebra.backends.solvers import SolverFactory, SPDSolver
from ..algebra.friction.kkt import check_friction
from ..algebra.friction.laws import LawGroups
from ..algebra.friction.newton import INACTIVE, SLIP, STICK, FrictionOptions, solve_friction
from ..algebra.result import SolveReport
from ..fem.space import LagrangeSpace, node_dofs
from ..problem.fields import ProblemError
from .contact_set import ContactSet
from .node_frames import to_frames
from .ordering import ordered_solver
from .rigid_modes import system_rigid_modes
from .system import Assembled

__all__ = [
    "Solved",
    "check_friction_set",
    "check_previous",
    "slip_reference",
    "solve_frictional",
    "states_from_displacement",
]


@dataclass(frozen=True)
class Solved:
    """What a solve of the algebraic problem gives per constraint (k of them), in the unit of
    the system it solved, and its report (frictionless or frictional alike).

    Attributes
    ----------
    x : (n,) float array
        The solution in node frames.
    normal_force, tangential_force : (k,) float arrays
        ``Λ_n`` and ``Λ_t`` (0 without friction).
    state : (k,) int array
        ``INACTIVE``, ``STICK`` or ``SLIP``; a frictionless node in contact slips.
    direction : (k,) int8 array
        The slip direction ``sign Λ_t`` where a friction force is at a positive bound, else 0.
    reference : (k,) float array
        The tangential displacement of no slip (0 for a single step and without friction).
    report : SolveReport
    """

    x: np.ndarray
    normal_force: np.ndarray
    tangential_force: np.ndarray
    state: np.ndarray
    direction: np.ndarray
    reference: np.ndarray
    report: SolveReport


def check_friction_set(cs: ContactSet) -> None:
    """Refuse friction at a node where two contact parts meet at an angle.

    Raises
    ------
    ProblemError
        If a node where two contact parts meet at an angle (two constraints) lies on a part
        with friction.
    """
    law = cs.friction
    friction_parts = np.unique(cs.part[law.index >= 0])
    corner = np.isin(cs.nodes, cs.nodes[cs.second])
    at_corner = corner & np.isin(cs.part, friction_parts)
    if at_corner.any():
        k = int(np.flatnonzero(at_corner)[0])
        raise ProblemError(
            f"node {cs.nodes[k]} is a corner of contact parts {cs.parts[cs.part[k]]!r} and "
            "another part (two constraint directions): friction at such a corner is not "
            "supported; end the frictional part before the corner (e.g. a frictionless part "
            "for the last edge) or join the parts"
        )


def same_law_kinds(a: LawGroups, b: LawGroups) -> bool:
    """Whether every node has a law of the same class in ``a`` and ``b`` (or none in both):
    then the node states of one are a warm start of the other."""
    if a.size != b.size:
        return False

    def kinds(groups: LawGroups) -> np.ndarray:
        names = np.array([type(law).__qualname__ for law in groups.laws] + [""], dtype=object)
        return names[groups.index]  # -1 picks ""

    return bool(np.array_equal(kinds(a), kinds(b)))


def check_previous(previous: object, space: LagrangeSpace, cs: ContactSet) -> None:
    """Check that ``previous`` is the result of a load step in ``space`` with the contact
    nodes of ``cs`` (docs/method.md, *Load paths*).

    Raises
    ------
    ValueError
        If ``previous`` is not a result, was solved on another mesh (other P2 nodes, curved
        midpoints included, or cells), or has other contact parts or nodes.
    """
    if not all(hasattr(previous, name) for name in ("u", "contact", "space", "report")):
        raise ValueError(
            f"previous must be the ContactResult of the previous load step, got "
            f"{type(previous).__name__}"
        )
    old = previous.space
    same_mesh = old is space or (
        old.node_points.shape == space.node_points.shape
        and old.cell_nodes.shape == space.cell_nodes.shape
        and np.array_equal(old.node_points, space.node_points)
        and np.array_equal(old.cell_nodes, space.cell_nodes)
    )
    if not same_mesh:
        raise ValueError(
            f"previous was solved on another mesh ({old.n_nodes} P2 nodes, "
            f"{old.cell_nodes.shape[0]} cells; this one has {space.n_nodes} and "
            f"{space.cell_nodes.shape[0]}): the steps of a load path share one mesh"
        )
    pc = previous.contact
    nodes = cs.nodes if hasattr(cs, "nodes") else cs.node  # 2D constraints, or faces' rows
    old = pc.nodes if hasattr(pc, "nodes") else pc.node
    if pc.parts != cs.parts or not np.array_equal(old, nodes):
        raise ValueError(
            f"previous has the contact parts {list(pc.parts)} with {pc.size} constraints, this "
            f"problem {list(cs.parts)} with {cs.size}: the steps of a load path share their "
            "contact parts"
        )


def slip_reference(previous: object, cs: ContactSet) -> np.ndarray:
    """``(k,)`` the tangential displacement of no slip per constraint: the previous step's
    ``u(z)·t_z`` in this step's frames (the DOF ``2z + 1`` of :func:`to_frames`)."""
    x = to_frames(cs.relative(previous.u).ravel(), cs.frame_nodes, cs.frames)
    return x[2 * cs.nodes + 1]


def states_from_displacement(
    u0: np.ndarray, cs: ContactSet, reference: np.ndarray, active0: np.ndarray, rtol: float
) -> tuple[np.ndarray, np.ndarray]:
    """Initial node states read off a displacement (the previous level's solution
    prolongated): in contact where ``active0``; there STICK where the slip
    ``u0(z)·t_z − reference`` is zero (below ``rtol · max|u0|``: a stick zone prolongates to
    exact zeros), else SLIP in the slip's direction (the friction force ``Λ_t`` has the sign
    of the slip). Out of contact the direction is kept too (classical Tresca acts there;
    the caller drops it where the node's law acts only in contact).

    Returns
    -------
    state0, direction0 : (k,) int arrays
        ``INACTIVE``/``STICK``/``SLIP`` and ``−1, 0, 1``.
    """
    slip = np.einsum("kc,kc->k", u0[cs.nodes], cs.tangent[:, 0])
    slip = slip - reference
    moving = np.abs(slip) > rtol * np.abs(u0).max(initial=0.0)
    direction = np.where(moving, np.sign(slip), 0.0).astype(np.int64)
    state = np.where(active0, np.where(moving, SLIP, STICK), INACTIVE)
    return state, direction


def solve_frictional(
    assembled: Assembled,
    K,
    F: np.ndarray,
    *,
    u0: np.ndarray | None,
    solver: SPDSolver | SolverFactory | None,
    max_iter: int,
    previous: object = None,
    active0: np.ndarray | None = None,
    warm_rtol: float = 0.0,
) -> Solved:
    """Solve the frictional contact problem of an assembled system (``K``, ``F`` possibly
    divided by the stiffness unit: the forces returned are in that unit).

    Parameters
    ----------
    assembled : Assembled
    K, F : the system to solve, in node frames
    u0 : (n_nodes, 2) float array or None
        Warm start (e.g. the previous level's solution prolongated): with ``active0`` the
        initial states are read off it (:func:`states_from_displacement`), else the update
        rule is evaluated at it.
    solver : SolverFactory or SPDSolver or None
        As in :func:`~signorini.contact.solve`.
    max_iter : int
    previous : ContactResult, optional
        The previous load step (checked by :func:`check_previous`): the law acts on the slip
        from its tangential displacements (:func:`slip_reference`) relative to its obstacles,
        moved by this step's obstacle motion (``assembled.obstacle_motion``;
        docs/method.md, *Obstacle motion*); without ``u0`` its states
        (laws of the same classes node by node) or its displacement (else) are the warm start.
    active0 : (k,) bool array, optional
        The nodes in contact in ``u0`` (the frictionless warm-start rule of ``solve``);
        without ``u0`` and ``previous``, the first active set (those nodes stick).
    warm_rtol : float
        The relative size below which a tangential displacement of ``u0`` counts as zero.
    """
    cs = assembled.contact
    check_friction_set(cs)
    law = cs.friction
    warm = {}
    # slip relative to the obstacle: its prescribed displacement counts (docs/method.md,
    # *Obstacle motion*)
    tangent = cs.tangent[:, 0]
    reference = np.einsum("kc,kc->k", assembled.obstacle_motion, tangent) + 0.0
    if previous is not None:
        moved = previous.obstacle_motion
        reference += slip_reference(previous, cs)
        if moved.any():
            reference -= np.einsum("kc,kc->k", moved, tangent)
        if u0 is None and same_law_kinds(previous.contact.friction, law):
            warm = {"state0": previous.state, "direction0": previous.direction}
        elif u0 is None:
            u0 = previous.u
    if u0 is not None:  # the unknowns bound by the constraints (docs/method.md, *Two bodies*)
        u0 = cs.relative(u0)
    if u0 is not None and active0 is not None:
        state0, direction0 = states_from_displacement(u0, cs, reference, active0, warm_rtol)
        # no friction force out of contact where the law acts only in contact: no direction
        direction0[(state0 == INACTIVE) & ~law.everywhere] = 0
        warm = {"state0": state0, "direction0": direction0}
    elif u0 is not None:
        warm = {"x0": to_frames(u0.ravel(), assembled.frame_nodes, assembled.frames)}
    elif active0 is not None and not warm:
        # a first active set without a displacement (a semi-coercive body: docs/method.md,
        # *Force control*): those nodes stick, the others are out of contact
        state0 = np.where(active0, STICK, INACTIVE).astype(np.int64)
        warm = {"state0": state0, "direction0": np.zeros(cs.size, dtype=np.int64)}
    # the frame [n t_1 … t_{d−1}] of each node: its normal DOF, then its d − 1 tangential DOFs
    frame_dofs = node_dofs(cs.nodes, assembled.space.n_components)
    problem = check_friction(
        K, F, frame_dofs[:, 0], frame_dofs[:, 1:], cs.gap,
        assembled.dirichlet, assembled.dirichlet_values,
        laws=law.laws, weight=law.weight, law_index=law.index, reference=reference,
    ).on_ranks(assembled.ranks)  # fmt: skip
    options = FrictionOptions(max_iter=max_iter)
    # symmetric laws only (Tresca): symmetric systems (Cholesky); else non-symmetric ones (LU)
    with ordered_solver(
        assembled.space, solver, symmetric=problem.symmetric, ordering=assembled.ordering,
        rigid_modes=lambda: system_rigid_modes(assembled),
    ) as linear:  # fmt: skip
        res = solve_friction(problem, options=options, solver=linear, **warm)
    state = res.state.astype(np.int64)
    # a frictionless node in contact slides freely: its friction force (0) is at its bound
    state[(state != INACTIVE) & (law.index < 0)] = SLIP
    return Solved(res.x, res.multiplier_n, res.multiplier_t, state, res.direction, reference, res)
