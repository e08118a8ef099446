"""The algebraic contact problem of one mesh (paper, Section 3): stiffness, load, Dirichlet
data and the constrained nodes, with the contact nodes rotated into (normal, tangential)
frames and the nodes of oblique and curved rollers into ``[n t]`` frames (docs/method.md,
*Rollers and components*).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ..algebra.ranks import SERIAL, Ranks
from ..fem.element import Element
from ..fem.loads import assemble_body_force, assemble_facet_load
from ..fem.space import LagrangeSpace, space_of
from ..fem.stiffness import assemble_stiffness
from ..mesh.mesh import Mesh
from ..problem.conditions import Neumann
from ..problem.fields import ProblemError, evaluate_field
from ..problem.problem import ContactProblem
from ..problem.problem3d import check_mesh_dimension
from ..problem.rollers import HeldNodes
from .admissible import check_load_size
from .contact_set import ContactSet, contact_set
from .discrete_conditions import DiscreteConditions, discrete_conditions
from .node_frames import frame_matrices, rotate_frames
from .ordering import Ordering
from .partition import Partition, partition
from .two_body import rows_read, two_body_system

__all__ = [
    "Assembled",
    "RollerDofs",
    "assemble",
    "obstacle_displacement",
    "roller_dofs",
    "system_frames",
    "LOAD_DEGREE",
]

#: quadrature degree for loads with smooth data
LOAD_DEGREE = 8


@dataclass
class Assembled:
    """The algebraic problem of one mesh, in rotated (normal, tangential) contact frames.

    DOFs are interleaved, ``2 node + component`` (docs/method.md, *Data conventions*); at a
    constrained node z the two DOFs are ``(u·n, u·t)`` with ``t = (−n_y, n_x)``, elsewhere
    ``(u_x, u_y)``. Consistent units: if E is in MPa and lengths in mm, entries of K are in
    N/mm per mm of thickness (MPa), F and Λ_z in N per mm of thickness, displacements in mm.

    Attributes
    ----------
    space : P2Space or P1Space
        The space of the mesh (P2 node numbering: vertices, then edge midpoints; P1: the
        vertices).
    contact : ContactSet
        The constrained nodes, their normals, gaps and weights.
    K : (n_dofs, n_dofs) scipy.sparse CSR matrix
        The stiffness matrix ``a(ψ_j, ψ_i)`` (symmetric positive semi-definite before the
        Dirichlet DOFs are fixed), rotated in place at the constrained nodes; with contact
        pairs, in the basis of the relative displacement (``(I + T)ᵀ K (I + T)``). On a rank
        of several (:attr:`partition`), the rows of this rank's DOFs only, each the serial
        matrix's bit for bit, the others empty: the matrix is the sum over the ranks, and a
        product ``K x`` is ``partition.ranks.sum(K @ x)``.
    F : (n_dofs,) float array
        The load ``L(ψ_i)``: body force and Neumann tractions, rotated like K.
    dirichlet : (n_held,) int array
        The held DOFs (sorted): both DOFs of every Dirichlet node, one DOF of a node on a
        roller or a one-component Dirichlet part (docs/method.md, *Rollers and components*).
    dirichlet_values : (n_held,) float array
        The prescribed displacements of those DOFs: Cartesian, except the frame DOF held at
        a roller node (``u·n``) and at a constrained node on a roller (its tangential
        component).
    seconds : float
        Wall-clock time of the assembly.
    dirichlet_nodes : (n_D,) int array
        The nodes whose both DOFs are held.
    obstacle_motion : (k, 2) float array
        The prescribed rigid displacement of the obstacle of each constraint's part
        (:meth:`~signorini.problem.obstacle_base.Obstacle.moved`; 0 for a gap function or
        an obstacle in place): the friction law's slip is relative to it.
    frame_nodes : (m,) int array
        The nodes whose DOFs are in a frame ``u = Q_z y`` (sorted): the constrained nodes
        and the roller nodes (:func:`system_frames`).
    frames : (m, 2, 2) float array
        Their frames ``Q_z``: ``contact.frames`` at a constrained node, ``[n t]`` at a
        roller node (``y_0 = u·n`` held). Every reader of the solution in Cartesian
        components goes through them (:func:`~.node_frames.to_cartesian`).
    rollers : RollerDofs
        The held DOF of each roller node off the contact boundary and its roller's normal
        there, to recover the roller's force (:func:`roller_dofs`).
    conditions : DiscreteConditions
        The problem's conditions resolved on :attr:`space`, once
        (:func:`~.discrete_conditions.discrete_conditions`): what every helper below the
        assembly reads instead of the problem (force control among them).
    partition : Partition or None
        On a run of several MPI ranks, which rank owns which nodes and cells
        (:func:`~.partition.partition`) and the ranks (``partition.ranks``); None on one.
    ordering : Ordering or None
        The fill-reducing ordering of the unknowns offered to the solver
        (:func:`~.ordering.dof_ordering`, with a contact pair's coupling), computed once;
        started in the background during the assembly with ``prefetch_ordering``. None for
        an Assembled built by hand: the solver is then offered the space's.
    """

    space: LagrangeSpace
    contact: ContactSet
    K: sp.csr_matrix
    F: np.ndarray
    dirichlet: np.ndarray
    dirichlet_values: np.ndarray
    seconds: float
    dirichlet_nodes: np.ndarray
    obstacle_motion: np.ndarray
    frame_nodes: np.ndarray
    frames: np.ndarray
    rollers: RollerDofs
    conditions: DiscreteConditions
    partition: Partition | None = None
    ordering: Ordering | None = None

    @property
    def ranks(self) -> Ranks:
        """The ranks that share :attr:`K` by rows (:data:`~signorini.algebra.ranks.SERIAL`
        for a whole matrix)."""
        return SERIAL if self.partition is None else self.partition.ranks


def assemble(
    problem: ContactProblem,
    mesh: Mesh,
    *,
    element: str | Element = "P2",
    ranks: Ranks = SERIAL,
    prefetch_ordering: bool = False,
    on_pattern: Callable[[sp.csr_matrix, ContactSet, Ordering], None] | None = None,
) -> Assembled:
    """Stiffness, load and constraints of ``problem`` on ``mesh`` (paper, Section 3).

    The problem's boundary conditions are resolved once on the nodes of the space
    (:class:`~.discrete_conditions.DiscreteConditions`, :attr:`Assembled.conditions`); the
    contact set, the held DOFs and the rollers' DOFs are built from that record.

    The two DOFs of every constrained node are transformed into its frame (normal and
    tangential components; a corner's two constraint directions) so that each constraint
    ``u(z)·n_z ≤ ψ(z)`` becomes a bound on one unknown. With contact pairs between bodies
    the unknowns are first the relative displacement ``ũ = u − T u``
    (:mod:`~signorini.contact.two_body`; docs/method.md, *Two bodies*). ``element``:
    ``"P2"`` (the paper's, default) or ``"P1"`` (docs/method.md, *P1 elements and their
    estimator*; not with contact pairs); a ValueError names it otherwise.

    On ``ranks`` of several MPI processes (docs/parallel.md, *What is distributed*) the
    nodes are partitioned (:func:`~.partition.partition`, a contact pair's slave and master
    nodes on one rank) and this rank assembles the rows of its own DOFs only, from the cells
    that touch them: its ``K`` is the serial one with the other ranks' rows emptied, bit for
    bit, also after the change of basis of two bodies and the rotation into frames. F and
    everything else are the same on every rank. On one process nothing changes.

    With ``prefetch_ordering`` (on one process; :func:`~.solution.solve` asks for it when its
    solver takes an ordering, :func:`~signorini.algebra.backends.selection.takes_ordering`) the
    fill-reducing ordering of the unknowns (:attr:`Assembled.ordering`) is started in a
    background thread before the stiffness matrix is assembled, and runs beside it.
    ``on_pattern(K, contact, ordering)`` is called as soon as ``K``'s pattern is final (its
    values are not: the rotation into frames writes them afterwards, in place):
    :func:`~.solution.solve` starts the linear solver's symbolic analysis there, beside the
    rest of the assembly (docs/method.md, *Ordering of the unknowns*).
    """
    t0 = time.perf_counter()
    if not isinstance(ranks, Ranks):
        raise ValueError(
            f"ranks must be a signorini.algebra.ranks.Ranks, got {type(ranks).__name__}"
        )
    check_mesh_dimension(problem.name, problem.mesh, mesh)
    if mesh.dim == 3:  # 3D elasticity and contact on faces: its own assembly, beside this one
        from .system3d import assemble_3d  # (which builds on this module's Assembled)

        space_of(mesh, element)  # refuses an element the tetrahedron does not have
        if ranks.size > 1:
            raise ValueError("a 3D problem is assembled on one process (no MPI partition yet)")
        return assemble_3d(problem, mesh)
    space = space_of(mesh, element)
    if problem.pairs and space.element.name != "P2":
        raise ValueError(
            f"element={space.element.name!r}: contact pairs between bodies (the dual mortar "
            "coupling of docs/method.md, *Two bodies*) are built for P2 only"
        )
    n_dofs = space.n_dofs
    conditions = discrete_conditions(problem, space)
    cs = contact_set(conditions, space)
    coupling = None if cs.transfer is None else cs.transfer.nodes
    ordering = Ordering(space, coupling, prefetch=prefetch_ordering and ranks.size == 1)
    part, rows = None, None
    if ranks.size > 1:  # this rank's rows, and with contact pairs the rows they read
        part = partition(space, ranks, coupling)
        rows = part.owned_nodes
        if cs.transfer is not None:
            rows = rows_read(space.cell_nodes, cs.transfer.dofs, rows)
        rows = np.repeat(rows, 2)
    # the space of a validated mesh and problem: no need to re-check the arrays
    with np.errstate(over="ignore", invalid="ignore"):  # overflow is reported just below
        K = assemble_stiffness(
            space.mapping,
            space.cell_dofs,
            n_dofs,
            problem.material_on(mesh),
            validate=False,
            element=space.element,
            rows=rows,
        )
    overflow = not np.isfinite(K.data).all()
    if ranks.size > 1:  # every rank raises, or none
        overflow = ranks.max(float(overflow)) > 0.0
    if overflow:
        m = problem.material_on(mesh)
        raise ProblemError(
            f"material: the stiffness matrix overflows float64 (lam = {np.max(m.lam):.3g}, "
            f"mu = {np.max(m.mu):.3g}); state E in larger units (e.g. GPa instead of Pa)"
        )
    F = np.zeros(n_dofs)
    loads = {}  # the largest entry of each load's vector, by its name in messages
    if problem.body_force is not None:
        f = assemble_body_force(
            space.mapping,
            space.cell_dofs,
            n_dofs,
            lambda x: evaluate_field(problem.body_force, x, "body_force"),
            degree=LOAD_DEGREE,
            element=space.element,
        )
        F += f
        loads["the body force"] = float(np.abs(f).max(initial=0.0))
    for name in problem.neumann_parts:
        cond: Neumann = problem.conditions[name]
        if cond.is_zero:
            continue
        facets = mesh.part_facets(name)
        nodes = space.facet_nodes(facets)
        dofs = np.stack([2 * nodes, 2 * nodes + 1], axis=-1).reshape(len(nodes), -1)
        g = cond.field()

        def traction(x, n, g=g, name=name):
            return evaluate_field(g, x, f"the traction of Neumann part {name!r}", normal=n)

        for rows, geometry in space.boundary_facets(facets):
            g = assemble_facet_load(
                geometry, dofs[rows], n_dofs, traction, degree=LOAD_DEGREE, element=space.element
            )
            F += g
            what = f"the traction of Neumann part {name!r}"
            loads[what] = max(loads.get(what, 0.0), float(np.abs(g).max(initial=0.0)))
    check_load_size(K, F, loads, ranks)
    if cs.transfer is not None:  # contact pairs: the relative displacement's basis
        K, F = two_body_system(K, F, cs.transfer.dofs)
        if part is not None:
            K = part.own_rows(K)
    if on_pattern is not None:
        on_pattern(K, cs, ordering)
    held = conditions.held
    frame_nodes, frames = system_frames(cs, held)
    K, F = rotate_frames(K, F, frame_nodes, frames, copy=False, validate=False)
    dirichlet, d_values = _dirichlet_dofs(held, space, cs)
    return Assembled(
        space,
        cs,
        K,
        F,
        dirichlet,
        d_values,
        time.perf_counter() - t0,
        np.flatnonzero(held.components.all(axis=1)),
        obstacle_displacement(conditions, cs),
        frame_nodes,
        frames,
        roller_dofs(conditions, cs),
        conditions,
        part,
        ordering,
    )


@dataclass(frozen=True)
class RollerDofs:
    """The roller nodes of a space whose one held DOF is along the roller's normal: every
    node of a roller part that is neither a Dirichlet node nor a constrained node.

    Attributes
    ----------
    nodes : (r,) int array
        The nodes (sorted).
    dofs : (r,) int array
        The held DOF of each in the system's frames: ``2z`` (``y_0 = u·n``) at a roller
        node in a frame, ``2z + c`` at a node of a roller along an axis.
    sign : (r,) float array
        ``u·n = sign · y[dofs]`` (±1: the outward normal of an axis roller may point along
        −x or −y).
    normal : (r, 2) float array
        The roller's outward unit normal at each node.
    """

    nodes: np.ndarray
    dofs: np.ndarray
    sign: np.ndarray
    normal: np.ndarray

    def force(
        self, K: sp.csr_matrix, F: np.ndarray, y: np.ndarray, ranks: Ranks = SERIAL
    ) -> np.ndarray:
        """``(r,)`` the nodal force of the roller on the body along ``−n``,
        ``Λ_z = L(ψ_z n_z) − a(u_h, ψ_z n_z)`` (the contact force's formula, (3.17)):
        positive where the roller pushes the body, for the frame system ``K y = F``
        (``K`` shared by rows over ``ranks``: the product summed over them)."""
        return self.sign * (F[self.dofs] - ranks.sum(K[self.dofs] @ y))


def roller_dofs(conditions: DiscreteConditions, cs: ContactSet) -> RollerDofs:
    """The :class:`RollerDofs` of a problem's ``conditions`` on a space: the roller nodes in
    frames (``held.roller_nodes`` off the contact boundary) and the nodes of rollers along an
    axis (:attr:`~.discrete_conditions.DiscreteConditions.axis_normal`) that hold one
    Cartesian component there."""
    held = conditions.held
    off = cs.local(held.roller_nodes) < 0
    partial = held.components.sum(axis=1) == 1
    axis = conditions.axis_normal
    z = np.flatnonzero(partial & axis.any(axis=1))
    z = z[cs.local(z) < 0]
    c = np.argmax(np.abs(axis[z]), axis=1)
    nodes = np.concatenate([held.roller_nodes[off], z])
    order = np.argsort(nodes)  # the two sets are apart: an axis roller holds a component
    return RollerDofs(
        nodes[order],
        np.concatenate([2 * held.roller_nodes[off], 2 * z + c])[order],
        np.concatenate([np.ones(int(off.sum())), axis[z, c]])[order],
        np.concatenate([held.roller_normal[off], axis[z]])[order],
    )


def system_frames(cs: ContactSet, held: HeldNodes) -> tuple[np.ndarray, np.ndarray]:
    """The nodes of a space whose DOFs are in a frame ``u = Q_z y`` (sorted) and their
    frames ``(m, 2, 2)``: the constrained nodes with ``cs.frames``, and the roller nodes off
    the contact boundary with ``[n t]``, ``t = (−n_y, n_x)``, so that ``y_0 = u·n`` is the
    held DOF (docs/method.md, *Rollers and components*). A roller node on a contact part
    keeps its contact frame (:func:`_dirichlet_dofs` checks that the roller holds a free
    DOF of it)."""
    off = cs.local(held.roller_nodes) < 0
    nodes = np.concatenate([cs.frame_nodes, held.roller_nodes[off]])
    if nodes.size == cs.frame_nodes.size:
        return cs.frame_nodes, cs.frames
    frames = np.concatenate([cs.frames, frame_matrices(held.roller_normal[off])])
    order = np.argsort(nodes)
    return nodes[order], frames[order]


def obstacle_displacement(conditions: DiscreteConditions, cs: ContactSet) -> np.ndarray:
    """``(k, 2)`` the prescribed displacement of the obstacle of each constraint of ``cs``
    (docs/method.md, *Obstacle motion*): ``Obstacle.displacement`` of its part's obstacle
    (:attr:`~.discrete_conditions.DiscreteConditions.obstacle_motion`), 0 for a part with a
    gap function."""
    return conditions.obstacle_motion[cs.part] if cs.size else np.zeros((0, 2))


def _dirichlet_dofs(
    held: HeldNodes, space: LagrangeSpace, cs: ContactSet
) -> tuple[np.ndarray, np.ndarray]:
    """The held DOFs (sorted) and their values (docs/method.md, *Rollers and components*).

    A node held along one direction ``d`` (a Cartesian component ``e_c``, or a roller's
    normal) off the contact boundary holds ``u_c``, or the DOF ``y_0 = u·n`` of its roller
    frame. At a constrained node (in its contact frame ``u = Q y``) the held ``d·u =
    (Qᵀd)·y`` must be one frame DOF: ``(Qᵀd)_i = 0`` for the other ``i`` (a roller along
    the contact direction's tangent, as where a symmetry axis meets a symmetric contact
    arc), and not a constrained one; that frame DOF is held at ``value / (Qᵀd)_j``.

    Raises
    ------
    ProblemError
        If a direction held at a constrained node is not one free frame DOF (a roller that
        holds the contact direction, or part of it), or the node has friction, naming the
        node and the contact part.
    """
    comp = held.components.copy()
    values = held.values.copy()
    partial = comp.any(axis=1) & ~comp.all(axis=1)
    on_contact = np.flatnonzero(partial & (cs.local(np.arange(space.n_nodes)) >= 0))
    c = comp[on_contact, 1].astype(np.int64)  # the one held component
    rollers = held.roller_nodes
    at_contact = cs.local(rollers) >= 0
    # roller nodes off the contact boundary: the frame's first DOF, u·n
    comp[rollers[~at_contact], 0] = True
    values[rollers[~at_contact], 0] = held.roller_value[~at_contact]
    nodes = np.concatenate([on_contact, rollers[at_contact]])
    if nodes.size:
        direction = np.concatenate([np.eye(2)[c], held.roller_normal[at_contact]])
        value = np.concatenate([values[on_contact, c], held.roller_value[at_contact]])
        name = [f"u_{'xy'[i]}" for i in c] + [
            f"u·n along n = {tuple(np.round(n, 6).tolist())}" for n in direction[c.size :]
        ]
        j = _check_held_at_contact(space, cs, nodes, direction, name)
        Q = cs.frames[np.searchsorted(cs.frame_nodes, nodes)]  # (m, 2, 2): u = Q y
        row = np.einsum("mci,mc->mi", Q, direction)  # (m, 2): d·u = row · y
        comp[nodes] = False
        comp[nodes, j] = True
        values[nodes, j] = value / row[np.arange(nodes.size), j]
        values[nodes, 1 - j] = 0.0
    dofs = np.flatnonzero(comp.ravel())
    return dofs, values.ravel()[dofs]


def _check_held_at_contact(
    space: LagrangeSpace, cs: ContactSet, nodes: np.ndarray, direction: np.ndarray, name: list
) -> np.ndarray:
    """The frame DOF ``j`` each constrained node ``nodes`` holds along ``direction (m, 2)``
    (named ``name``); refuses a direction that is not one free frame DOF, or friction at
    the node (see :func:`_dirichlet_dofs`)."""
    Q = cs.frames[np.searchsorted(cs.frame_nodes, nodes)]
    row = np.einsum("mci,mc->mi", Q, direction)
    j = np.argmax(np.abs(row), axis=1)
    other = np.abs(row[np.arange(nodes.size), 1 - j])
    bad = (other > 1e-9 * np.abs(row).max(axis=1)) | np.isin(2 * nodes + j, cs.constrained_dofs)
    bad = np.flatnonzero(bad)
    if bad.size:
        z = nodes[bad[0]]
        raise ProblemError(
            f"the node at {tuple(np.round(space.node_points[z], 12).tolist())} is held in "
            f"{name[bad[0]]} by a Dirichlet or Roller part and lies on contact "
            f"part {cs.parts[cs.part[cs.local(np.array([z]))[0]]]!r}, whose direction "
            "there is not perpendicular to the held component: the two conditions "
            "conflict (end the roller before the contact part, or make the contact "
            "direction at the shared node perpendicular to it)"
        )
    rows = cs.local(nodes)
    if cs.has_friction and (cs.friction.index[rows] >= 0).any():
        k = int(np.flatnonzero(cs.friction.index[rows] >= 0)[0])
        raise ProblemError(
            f"contact part {cs.parts[cs.part[rows[k]]]!r} has friction at the node "
            f"{tuple(np.round(space.node_points[nodes[k]], 12).tolist())}, whose "
            "tangential displacement a Dirichlet or Roller part holds: the friction law "
            "has no slip to act on there. Give the contact part no friction, or end the "
            "roller before it (a symmetry plane through a frictional contact: model the "
            "whole body)"
        )
    return j
