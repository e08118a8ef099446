"""The algebraic problem of one tetrahedral mesh: 3D elasticity and contact on faces
(docs/method.md, *Three dimensions: solving elasticity*, *Three dimensions: rollers, force
control, regions*).

:func:`~.system.assemble` hands a mesh with ``dim = 3`` here. The stiffness matrix is
:func:`~signorini.fem.stiffness3d.assemble_stiffness_3d`'s, the load the body force and the
Neumann tractions of :mod:`signorini.fem.elasticity3d`; the held DOFs are the Dirichlet
parts' components and the axis rollers' (one Cartesian component each,
:func:`~signorini.problem.rollers.held_nodes`), interleaved ``3 node + c``, and the
oblique and curved rollers' normal components in node frames. Without contact parts the
system is ``K u = F`` with Cartesian unknowns but at the rollers' frame nodes. With
contact parts the contact set on faces (:func:`~.face_contact.face_contact_set`; condition
(b) with ``DEFAULT_ALPHA`` unless the parts give ``face_alpha``) gives the system
``Rᵀ K R ỹ = Rᵀ F``, ``u = R ỹ`` (node frames, then the transformed face basis), its bounds
and its held DOFs (docs/method.md, *Three dimensions: contact on faces*).

On ``ranks`` of several MPI processes the nodes are partitioned as in 2D
(:func:`~.partition.partition`) and this rank assembles the stiffness rows of its own nodes
(and, with contact, the rows its rows of ``Rᵀ K R`` read: the edge midpoints of Γ_C that the
transformed basis couples to its vertices), from the cells that touch them; its system's
``K`` is the serial one with the other ranks' rows emptied, bit for bit. ``F`` and everything
else are the same on every rank (docs/parallel.md, *A stiffness matrix split by rows*).
"""

from __future__ import annotations

import time
from dataclasses import replace

import numpy as np
import scipy.sparse as sp

from ..algebra.ranks import SERIAL, Ranks
from ..fem.elasticity3d import assemble_body_force_3d, assemble_face_load_3d
from ..fem.space3d import P2TetSpace
from ..fem.stiffness3d import assemble_stiffness_3d
from ..mesh.mesh import Mesh
from ..problem.conditions import Neumann, Roller
from ..problem.fields import ProblemError, evaluate_field
from ..problem.normals import straight_normal
from ..problem.problem import ContactProblem
from ..problem.rigid3d import motion_field_3d
from ..problem.rollers import held_nodes
from .admissible import check_load_size
from .contact_set import _empty
from .discrete_conditions import DiscreteConditions
from .face_basis import DEFAULT_ALPHA
from .face_contact import FaceContactSet, face_contact_set
from .face_friction import face_friction, pair_friction
from .mortar3d import mortar_coupling_3d
from .mortar3d_set import MortarFaceSet, mortar_face_set
from .node_frames3d import held_frames, rotate_frames_3d
from .ordering import Ordering
from .partition import Partition, partition
from .system import Assembled, RollerDofs

__all__ = ["assemble_3d", "LOAD_DEGREE_3D"]

#: quadrature degree on the tetrahedron and its faces for loads with smooth data (the rule
#: of degree 8 in 2D is for f·φ of high degree; degree 6 integrates a quartic load against
#: the quadratic basis exactly)
LOAD_DEGREE_3D = 6


def discrete_conditions_3d(problem: ContactProblem, space: P2TetSpace) -> DiscreteConditions:
    """The conditions of a 3D problem on the nodes of ``space``: the held components and
    their values ``(n_nodes, 3)``, the axis rollers' outward normals, and nothing of contact
    (:class:`~.discrete_conditions.DiscreteConditions` with ``d = 3`` columns)."""
    n = space.n_nodes
    held_parts = tuple(problem.dirichlet_parts)
    held_part = np.full(n, -1, dtype=np.int64)
    for i, name in enumerate(held_parts):  # a loop over parts: the later one wins
        held_part[space.part_nodes([name])] = i
    axis_normal = np.zeros((n, 3))
    for name in reversed(problem.held):  # a loop over parts: the first one wins
        if isinstance(problem.conditions[name], Roller):
            normal = straight_normal(space.mesh, name)
            c = int(np.argmax(np.abs(normal)))
            axis_normal[space.part_nodes([name])] = np.eye(3)[c] * np.sign(normal[c])
    none = np.zeros(0, dtype=np.int64)
    return DiscreteConditions(
        held=held_nodes(problem, space),
        held_parts=held_parts,
        held_part=held_part,
        axis_normal=axis_normal,
        contact_parts=(),
        straight_normal=np.zeros((0, 3)),
        obstacles=(),
        obstacle_motion=np.zeros((0, 3)),
        gap_nodes=none,
        gap_part=none,
        gap=np.zeros(0),
        obstacle_direction=np.zeros((0, 3)),
        friction=(),
        pairs={},
        rigid_motions=problem.rigid_motions,
        rigid_field=motion_field_3d(space.mesh, problem.rigid_motions, space.node_points),
    )


def _roller_dofs_3d(conditions: DiscreteConditions, roller_dof: np.ndarray) -> RollerDofs:
    """The held DOF of each node held along one roller's normal only, and that normal: an
    axis roller's node holding one Cartesian component (``3 z + c``), an oblique or curved
    roller's node with one roller row and nothing else held (its frame DOF in
    ``roller_dof``), sorted by node."""
    held = conditions.held
    axis = conditions.axis_normal
    partial = held.components.sum(axis=1) == 1
    rows = np.bincount(held.roller_nodes, minlength=axis.shape[0])
    z = np.flatnonzero(partial & axis.any(axis=1) & (rows == 0))
    c = np.argmax(np.abs(axis[z]), axis=1)
    alone = (rows[held.roller_nodes] == 1) & ~held.components[held.roller_nodes].any(axis=1)
    nodes = np.concatenate([z, held.roller_nodes[alone]])
    order = np.argsort(nodes, kind="stable")
    return RollerDofs(
        nodes[order],
        np.concatenate([3 * z + c, roller_dof[alone]])[order],
        np.concatenate([axis[z, c], np.ones(alone.sum())])[order],
        np.concatenate([axis[z], held.roller_normal[alone]])[order],
    )


def assemble_3d(problem: ContactProblem, mesh: Mesh, ranks: Ranks = SERIAL) -> Assembled:
    """Stiffness, load and held DOFs of a 3D ``problem`` on the tetrahedral ``mesh``; on
    ``ranks`` of several processes this rank's rows of the system (module docstring).

    ``K[3 z + i, 3 w + j] = a(φ_w e_j, φ_z e_i)``, ``F[3 z + i] = ∫_Ω f_i φ_z +
    Σ_Neumann ∫_Γ g_i φ_z`` (docs/method.md, *Three dimensions: P2 tetrahedra and 3D
    elasticity*), with the problem's data evaluated at points ``(n, 3)``.

    The held components, rollers and contact parts are resolved first (their user
    functions evaluated and checked: a refusal comes before any work on the system); an
    oblique or curved roller's nodes get the frames of :func:`~.node_frames3d.held_frames`
    (``Qᵀ K Q``, ``Qᵀ F``), contact parts the system in the solver's variables.

    Returns
    -------
    Assembled
        Without contact an empty contact set and the rollers' frames; ``dirichlet`` the held
        DOFs (sorted) and ``dirichlet_values`` their prescribed values.

    Raises
    ------
    ProblemError
        If the stiffness matrix overflows, a load, gap, normal or Dirichlet function does not
        give finite numbers of the right shape, an obstacle starts deep inside the body, or
        a load's displacement would overflow (naming it).
    """
    t0 = time.perf_counter()
    space = P2TetSpace(mesh)
    # the conditions and the contact set first: their user functions are evaluated and
    # checked before any work on the system
    conditions = discrete_conditions_3d(problem, space)
    cs = _face_contact(problem, space, conditions) if problem.contact_parts else None
    part, rows = None, None
    if ranks.size > 1 and isinstance(cs, MortarFaceSet):
        raise ValueError(
            f"contact pairs {sorted(problem.pairs)} on a tetrahedral mesh run on one process: "
            "the rows of the 3D mortar coupling are not split over MPI ranks yet"
        )
    if ranks.size > 1:  # this rank's rows, and with contact the rows they read
        part = partition(space, ranks)
        rows = part.owned_dofs
        if cs is not None:
            rows = np.repeat((abs(cs.operator) @ rows).reshape(-1, 3).any(axis=1), 3)
    K, F = _stiffness_and_load(problem, space, rows, ranks)
    if cs is not None:
        return _with_contact(space, cs, (K, F), conditions, part, time.perf_counter() - t0)
    held = conditions.held
    none = np.zeros(0, dtype=np.int64)
    frames = held_frames(space.node_points, none, np.zeros((0, 3)), none, held)
    if frames.frame_nodes.size:  # oblique and curved rollers: u = Q y at their nodes
        K, F = rotate_frames_3d(K, F, frames.frame_nodes, frames.frames)
    if part is not None:
        K = part.own_rows(K)
    order = np.argsort(frames.held_dofs)
    return Assembled(
        space,
        _empty(()),
        K,
        F,
        frames.held_dofs[order],
        frames.held_values[order],
        time.perf_counter() - t0,
        conditions.dirichlet_nodes,
        np.zeros((0, 3)),
        frames.frame_nodes,
        frames.frames,
        _roller_dofs_3d(conditions, frames.roller_dof),
        conditions,
        part,
        Ordering(space),
    )


def _stiffness_and_load(
    problem: ContactProblem, space: P2TetSpace, rows: np.ndarray | None, ranks: Ranks
) -> tuple:
    """``(K, F)`` Cartesian: the stiffness matrix (only the DOF ``rows`` when given: the
    rows this rank reads) and the load (body force, tractions), checked for overflow on every
    rank (:func:`~.admissible.check_load_size`)."""
    mesh, n_dofs = space.mesh, space.n_dofs
    material = problem.material_on(mesh)
    with np.errstate(over="ignore", invalid="ignore"):  # overflow is reported just below
        K = assemble_stiffness_3d(space.mapping, space.cell_dofs, n_dofs, material, rows)
    overflow = not np.isfinite(K.data).all()
    if ranks.size > 1:  # every rank raises, or none
        overflow = ranks.max(float(overflow)) > 0.0
    if overflow:
        raise ProblemError(
            f"material: the stiffness matrix overflows float64 (lam = {np.max(material.lam):.3g}"
            f", mu = {np.max(material.mu):.3g}); state E in larger units"
        )
    F = np.zeros(n_dofs)
    loads = {}
    if problem.body_force is not None:

        def force(x):
            return evaluate_field(problem.body_force, x, "body_force", shape=(3,))

        f = assemble_body_force_3d(space, force, degree=LOAD_DEGREE_3D)
        F += f
        loads["the body force"] = float(np.abs(f).max(initial=0.0))
    for name in problem.neumann_parts:  # a loop over parts
        cond: Neumann = problem.conditions[name]
        if cond.is_zero:
            continue
        g = cond.field()
        what = f"the traction of Neumann part {name!r}"

        def traction(x, n, g=g, what=what):
            return evaluate_field(g, x, what, shape=(3,), normal=n)

        t = assemble_face_load_3d(space, mesh.part_facets(name), traction, LOAD_DEGREE_3D)
        F += t
        loads[what] = float(np.abs(t).max(initial=0.0))
    check_load_size(K, F, loads, ranks)
    return K, F


def _face_contact(
    problem: ContactProblem, space: P2TetSpace, conditions: DiscreteConditions
) -> FaceContactSet | MortarFaceSet:
    """The contact set on faces of the problem's contact parts (one α for all): against
    obstacles, or the dual mortar constraints of its contact pairs (problem3d: not both)."""
    contact = {name: problem.conditions[name] for name in problem.contact_parts}
    alpha = next(iter(contact.values())).face_alpha  # one for all parts (problem3d)
    alpha = DEFAULT_ALPHA if alpha is None else alpha
    if problem.pairs:  # docs/method.md, *Two bodies in three dimensions*
        couplings = [
            mortar_coupling_3d(space, slave, master, alpha=alpha)
            for slave, master in problem.pairs.items()
        ]  # a loop over pairs
        laws = [contact[slave].friction for slave in problem.pairs]
        frictional = [law is not None for law in laws]
        ms = mortar_face_set(space, couplings, conditions.held, frictional)
        return replace(ms, friction=pair_friction(space, ms, laws)) if any(frictional) else ms
    cs = face_contact_set(space, contact, conditions.held, alpha=alpha)
    laws = [contact[name].friction for name in contact]
    if any(law is not None for law in laws):  # docs/method.md, *Friction in three dimensions*
        cs = replace(cs, friction=face_friction(space, cs, laws))
    return cs


def _with_contact(
    space: P2TetSpace,
    cs: FaceContactSet | MortarFaceSet,
    system: tuple[sp.csr_matrix, np.ndarray],
    conditions: DiscreteConditions,
    part: Partition | None,
    seconds: float,
) -> Assembled:
    """The :class:`Assembled` of a 3D problem with contact parts: the system ``system = (K,
    F)`` in the solver's variables (:meth:`~.face_contact.FaceContactSet.system`; this rank's
    rows of it on several), its held DOFs sorted, the rollers off the contact nodes."""
    t0 = time.perf_counter()
    K, F = system
    K_rot, F_rot = cs.system(K, F)
    if part is not None:
        K_rot = part.own_rows(K_rot)
    order = np.argsort(cs.held_dofs)
    rollers = _roller_dofs_3d(conditions, cs.roller_dof)
    off = ~np.isin(rollers.nodes, cs.node)
    return Assembled(
        space,
        cs,
        K_rot,
        F_rot,
        cs.held_dofs[order],
        cs.held_values[order],
        seconds + time.perf_counter() - t0,
        conditions.dirichlet_nodes,
        np.zeros((cs.n_rows, 3)),
        cs.frame_nodes,
        cs.frames,
        RollerDofs(rollers.nodes[off], rollers.dofs[off], rollers.sign[off], rollers.normal[off]),
        conditions,
        part,
        Ordering(space, _pair_coupling(space, cs)),
    )


def _pair_coupling(space: P2TetSpace, cs: FaceContactSet | MortarFaceSet) -> sp.csr_matrix | None:
    """``(n_nodes, n_nodes)`` the node pairs that the pair system ``Rᵀ K R`` joins beyond the
    mesh's own cells, for the fill-reducing ordering; None against obstacles.

    ``R`` carries a constrained slave node's displacement to the master nodes of its mortar
    transfer ``T_jk``, so a cell touching slave rows couples every node of the cell and every
    master node of those rows: the pattern of ``Bᵀ B``, ``B`` the incidence of those cells
    and nodes. Ordering the vertex graph without it (METIS sees two bodies apart) filled the
    factor: on two-spheres at 53 623 unknowns PARDISO took 38 s a factorization, against
    1.4 s with its own analysis of the whole matrix. In 2D the transfer alone suffices
    (docs/method.md, *Two bodies*)."""
    if not isinstance(cs, MortarFaceSet):
        return None
    n = space.n_nodes
    coo = sp.coo_matrix(cs.node_transfer)
    T = sp.csr_matrix((np.ones(coo.nnz), (cs.node[coo.row], coo.col)), shape=(n, n))
    cells = space.cell_nodes[np.isin(space.cell_nodes, cs.node).any(axis=1)]
    m, k = cells.shape
    C = sp.csr_matrix((np.ones(m * k), (np.repeat(np.arange(m), k), cells.ravel())), shape=(m, n))
    B = (C + C @ T).tocsr()
    B.data[:] = 1.0
    return (B.T @ B).tocsr()
