"""The first active set of a solve: from a warm start (:func:`warm_active_set`), or, for a
cold solve, by nested iteration from a coarse mesh.

A PDAS iteration started from the empty active set on a fine mesh moves the free boundary
by a few nodes per iteration, and every iteration costs a factorization. Started from the
active set of a coarse solve whose contact boundary has the fine mesh's resolution, it
needs one or two (docs/method.md, *Solver*). The coarse mesh is rebuilt from the problem's
initial mesh: cells that are not cells of the fine mesh are bisected, all of them while
the mesh stays below a tenth of the fine mesh's cells, then only those near Γ_C
(:func:`coarse_mesh`); for a fine mesh made by newest vertex bisection from the initial
mesh this reproduces the fine cells at Γ_C and one layer of cells around them and an
ancestor of the fine mesh elsewhere. The result is only the initial guess of PDAS, which
converges to the same discrete solution from any active set.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np
from scipy.spatial import cKDTree

from ..algebra.errors import PDASConvergenceError
from ..algebra.pdas import rule_active_set
from ..algebra.ranks import SERIAL, Ranks
from ..fem.space import LagrangeSpace
from ..mesh.mesh import Mesh
from ..mesh.refine import refine_nvb
from .contact_set import ContactSet
from .face_contact import FaceContactSet
from .mortar3d_set import MortarFaceSet

if TYPE_CHECKING:
    from .system import Assembled

__all__ = [
    "GLOBAL_SHARE",
    "NESTED_MAX_SHARE",
    "NESTED_MIN_NDOF",
    "coarse_mesh",
    "PAIR_WARM_START_RTOL",
    "WARM_START_RTOL",
    "nested_active_set",
    "round_off_scale",
    "transfer_active",
    "warm_active_set",
    "warm_rule_active_set",
    "WARM_SMOOTHING_SWEEPS",
]

#: a warm start's node starts in the active set where
#: ``u0·n − ψ ≥ −WARM_START_RTOL · max(max|u0|, |ψ|)``: the prolongated contact nodes
#: of the previous level, whose u0·n − ψ is round-off of the displacements
WARM_START_RTOL = 1e-10
#: the same with contact pairs between bodies: a new slave node's weighted gap is the dual
#: mortar projection of the gap on the refined interface, which the prolongated
#: displacement meets only to the projection's consistency error (measured on the two
#: cylinders: up to 1.6e-6 relative at the nodes in contact, against 2.6e-4 at the nearest
#: node out of contact; docs/method.md, *Two bodies*)
PAIR_WARM_START_RTOL = 1e-5
#: projected ℓ1-Jacobi sweeps on the prolongated solution before the active set rule of a 3D
#: warm start (:func:`warm_rule_active_set`; docs/method.md, *Three dimensions: warm starts
#: smoothed before the rule*). Measured on hertz-3d adaptive, levels 1–9 to 35k unknowns, rows of
#: the converged set the prediction misses: 4 8 0 5 6 2 12 7 2 with 0 sweeps, 0 4 0 2 2 2 2 2 0
#: with 20, 0 2 0 2 0 2 0 0 0 with 40 (``benchmarks/warm3d.py --adaptive``)
WARM_SMOOTHING_SWEEPS = 40


def round_off_scale(u: np.ndarray, gap: np.ndarray) -> np.ndarray:
    """``max(max|u|, |ψ(z)|)`` per node (the shape of ``gap``): the size of the two numbers
    ``u(z)·n − ψ(z)`` is the difference of, hence of its round-off. Relative to the
    displacements and to the gap at the node itself, not to the gap far away (a distant
    obstacle must not make the test lenient), and invariant under scaling of the problem."""
    return np.maximum(np.abs(u).max(initial=0.0), np.abs(gap))


def warm_active_set(
    contact: ContactSet | FaceContactSet,
    u0: np.ndarray,
    assembled: Assembled | None = None,
    system: tuple | None = None,
) -> np.ndarray:
    """``(m,) bool``: the constraints whose node meets its bound under the warm start
    ``u0 (n_nodes, d)`` to :data:`WARM_START_RTOL` (:data:`PAIR_WARM_START_RTOL` with
    contact pairs) relative to :func:`round_off_scale`: PDAS's first active set. On faces
    (a :class:`~.face_contact.FaceContactSet`) in the solver's variables, the transformed
    basis's ``ỹ_dof ≤ ψ̃`` (docs/method.md, *Three dimensions: warm starts*); given the
    ``assembled`` system and its ``system = (K̃, F̃)`` (as scaled for the solver), there the
    active set rule at ``u0`` instead (:func:`warm_rule_active_set`)."""
    if system is not None and isinstance(contact, FaceContactSet | MortarFaceSet):
        held = (assembled.dirichlet, assembled.dirichlet_values)
        return warm_rule_active_set(contact, u0, system, held, assembled.ranks)
    rtol = WARM_START_RTOL if contact.transfer is None else PAIR_WARM_START_RTOL
    gap = contact.gap
    return contact.normal_displacement(u0) - gap >= -rtol * round_off_scale(u0, gap)


def warm_rule_active_set(
    contact: FaceContactSet,
    u0: np.ndarray,
    system: tuple,
    held: tuple[np.ndarray, np.ndarray],
    ranks: Ranks = SERIAL,
) -> np.ndarray:
    """``(k,) bool``: PDAS's first active set of a 3D warm start ``u0 (n_nodes, 3)`` on faces,
    the active set rule at it (:func:`~signorini.algebra.pdas.rule_active_set`): a row is
    active where ``Λ0 + c (ỹ0 − ψ̃) > 0``, ``Λ0 = F̃ − K̃ ỹ0`` the residual of the warm start
    in the solver's variables ``ỹ0`` (:meth:`~.face_contact.FaceContactSet.unknowns`) with
    the held DOFs at their values ``held = (dofs, values)``, ``system = (K̃, F̃)``. Unlike
    :func:`warm_active_set` it reads the contact force the refined mesh puts on the rows
    where the prolongated solution is off its bound (a zone that grows between levels, new
    nodes of a curved surface off the coarse cells), and drops the rows at their bound
    that pull (docs/method.md, *Three dimensions: warm starts by the active set rule*).

    Before the rule, :data:`WARM_SMOOTHING_SWEEPS` projected ℓ1-Jacobi sweeps
    (:func:`projected_l1_jacobi`) carry the prolongated solution towards the refined mesh's
    solution near the zone's edge, where the new nodes reach the obstacle."""
    K, F = system
    x0 = contact.unknowns(np.asarray(u0, dtype=np.float64).ravel())
    x0[held[0]] = held[1]
    c, gap = contact.constrained_dofs, contact.gap
    x0 = projected_l1_jacobi(K, F, c, gap, x0, held[0], WARM_SMOOTHING_SWEEPS, ranks)
    return rule_active_set(K, F, c, gap, x0, held[0], ranks=ranks)


def projected_l1_jacobi(
    K,
    F: np.ndarray,
    constrained: np.ndarray,
    gap: np.ndarray,
    x: np.ndarray,
    dirichlet: np.ndarray,
    sweeps: int,
    ranks: Ranks = SERIAL,
) -> np.ndarray:
    """``sweeps`` steps ``x ← min(x + M⁻¹(F − K x), g)`` on the DOFs not in ``dirichlet``
    (the bound on ``constrained`` only), ``M = diag(Σ_j |K_ij|)``: since ``M − K`` is
    positive semi-definite (diagonally dominant), each step minimises a quadratic majorant
    of the energy ``½ xᵀKx − Fᵀx`` over the bounds, so the energy never increases (the ℓ1
    smoother of algebraic multigrid with the box projection; docs/method.md, *Three
    dimensions: warm starts smoothed before the rule*). ``K``'s rows may be split over
    ``ranks``; the result is the same on every rank."""
    x = x.copy()
    step = ranks.sum(abs(K) @ np.ones(x.size))
    step[dirichlet] = np.inf  # held DOFs keep their values
    for _ in range(sweeps):  # a loop over sweeps, not over the mesh
        x += (F - ranks.sum(K @ x)) / step
        x[constrained] = np.minimum(x[constrained], gap)
    return x


log = logging.getLogger(__name__)

#: nested iteration is used on meshes with at least this many free unknowns (below it one
#: cold PDAS is cheap and the coarse solve would not pay for itself)
NESTED_MIN_NDOF = 20_000
#: the coarse mesh is used only if it has at most this share of the fine mesh's cells
NESTED_MAX_SHARE = 0.25
#: every cell that is not a fine cell is bisected while the coarse mesh would stay within
#: this share of the fine mesh's cells (measured on Example 6.2 at 1.2M unknowns: 0 gives 4
#: constraints of 1361 in the wrong state, 0.1 none)
GLOBAL_SHARE = 0.1
#: layers of cells around Γ_C (counted through shared vertices) that get the fine
#: mesh's cells on the coarse mesh
BAND = 1
#: bound on the bisection rounds (the fine mesh's depth of bisection near Γ_C)
MAX_ROUNDS = 200


def _row_keys(a: np.ndarray) -> np.ndarray:
    """One opaque, sortable key per row of a 2-D array (its bytes)."""
    a = np.ascontiguousarray(a)
    return a.view(np.dtype((np.void, a.dtype.itemsize * a.shape[1]))).ravel()


def _find(sorted_keys: np.ndarray, keys: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Positions of ``keys`` in ``sorted_keys`` and whether each was found."""
    pos = np.minimum(np.searchsorted(sorted_keys, keys), sorted_keys.size - 1)
    return pos, sorted_keys[pos] == keys


def coarse_mesh(initial: Mesh, fine: Mesh, contact_parts: list[str]) -> Mesh | None:
    """The coarse mesh of the nested iteration, or None where there is none.

    Starting from ``initial``, the cells that are not cells of ``fine`` are bisected
    (newest vertex bisection with closure): all of them while the mesh would stay within
    :data:`GLOBAL_SHARE` of ``fine``'s cells, then those with a vertex within :data:`BAND`
    layers of cells of a contact edge, until there is none. Points and cells are compared
    by their exact coordinates, so this works for a ``fine`` made from ``initial`` by
    :func:`~signorini.mesh.refine_nvb` (the adaptive loop's meshes and their uniform
    refinements); for any other mesh a new point that is not a point of ``fine`` ends the
    construction and the mesh so far is returned (``initial`` itself at worst).

    Parameters
    ----------
    initial : Mesh
        The problem's initial mesh.
    fine : Mesh
        The mesh to be solved on.
    contact_parts : list of str
        The names of the contact parts.

    Returns
    -------
    Mesh or None
        None if the coarse mesh has more than :data:`NESTED_MAX_SHARE` of ``fine``'s cells.
    """
    fine_points = _row_keys(fine.points)
    point_order = np.argsort(fine_points)
    fine_points = fine_points[point_order]
    fine_cells = np.sort(_row_keys(np.sort(fine.cells, axis=1)))
    parts = [initial.part_index(name) for name in contact_parts]
    coarse = initial
    everywhere = True
    for _ in range(MAX_ROUNDS):
        pos, found = _find(fine_points, _row_keys(coarse.points))
        if not found.all():
            break  # not a refinement of the initial mesh: keep what matches
        cells = np.sort(point_order[pos][coarse.cells], axis=1)
        is_fine = _find(fine_cells, _row_keys(cells))[1]
        near = np.zeros(coarse.n_points, dtype=bool)
        near[coarse.boundary[np.isin(coarse.boundary_part, parts)].ravel()] = True
        for _ in range(BAND):
            near[coarse.cells[near[coarse.cells].any(axis=1)].ravel()] = True
        # a bisected cell leaves at most 4 children
        everywhere &= coarse.n_cells + 3 * (~is_fine).sum() <= GLOBAL_SHARE * fine.n_cells
        marked = ~is_fine & (everywhere | near[coarse.cells].any(axis=1))
        if not marked.any():
            break
        coarse = refine_nvb(coarse, marked).mesh
    if coarse.n_cells > NESTED_MAX_SHARE * fine.n_cells:
        return None
    return coarse


def transfer_active(
    coarse_space: LagrangeSpace,
    coarse_contact: ContactSet,
    coarse_active: np.ndarray,
    space: LagrangeSpace,
    contact: ContactSet,
) -> np.ndarray:
    """The fine mesh's initial active set: each constraint takes the state of the coarse
    constraint at the nearest coarse contact node (the same node where the coarse mesh has
    the fine mesh's cells at Γ_C), the second one of a corner that of the corner's second.

    Returns
    -------
    (k,) bool array
        One entry per constraint of ``contact``.
    """
    if contact.size == 0 or coarse_contact.size == 0:
        return np.zeros(contact.size, dtype=bool)
    first = np.flatnonzero(~coarse_contact.second)
    coarse_points = coarse_space.node_points[coarse_contact.frame_nodes]
    nearest = cKDTree(coarse_points).query(space.node_points[contact.nodes])[1]
    row = first[nearest]
    # a fine corner's second constraint reads the coarse corner's second, if there is one
    following = np.minimum(row + 1, coarse_contact.size - 1)
    corner = contact.second & coarse_contact.second[following] & (following > row)
    return coarse_active[np.where(corner, following, row)]


def nested_active_set(
    initial: Mesh, space: LagrangeSpace, cs: ContactSet, solve_coarse: Callable[[Mesh], object]
) -> np.ndarray | None:
    """The initial active set of a cold solve on ``space`` (contact set ``cs``) of a problem
    posed on the mesh ``initial`` from the solve ``solve_coarse(mesh)`` (a
    :class:`~signorini.contact.ContactResult`) on the coarse mesh of :func:`coarse_mesh`,
    or None where there is no coarse mesh or its PDAS fails (the fine PDAS then starts
    empty)."""
    coarse = coarse_mesh(initial, space.mesh, list(cs.parts))
    if coarse is None:
        return None
    try:
        result = solve_coarse(coarse)
    except PDASConvergenceError:
        return None
    log.info(
        "nested iteration: coarse mesh of %d unknowns, %d PDAS iterations",
        result.ndof,
        result.report.iterations,
    )
    return transfer_active(result.space, result.contact, result.active, space, cs)
