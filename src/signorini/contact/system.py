"""The algebraic contact problem of one mesh (paper, Section 3): stiffness, load, Dirichlet
data and the constrained nodes, with the contact nodes rotated into (normal, tangential)
frames.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ..fem.element import Element
from ..fem.loads import assemble_body_force, assemble_edge_load
from ..fem.space import LagrangeSpace, space_of
from ..fem.stiffness import assemble_stiffness
from ..mesh.mesh import Mesh
from ..problem.conditions import Neumann
from ..problem.fields import ProblemError, evaluate_field
from ..problem.problem import ContactProblem
from .contact_set import ContactSet, contact_set
from .node_frames import rotate_frames

__all__ = ["Assembled", "assemble", "obstacle_displacement", "LOAD_DEGREE"]

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
        Dirichlet DOFs are fixed), rotated in place at the constrained nodes.
    F : (n_dofs,) float array
        The load ``L(ψ_i)``: body force and Neumann tractions, rotated like K.
    dirichlet : (n_held,) int array
        The held DOFs (sorted): both DOFs of every Dirichlet node, one DOF of a node on a
        roller or a one-component Dirichlet part (docs/method.md, *Rollers and components*).
    dirichlet_values : (n_held,) float array
        The prescribed displacements of those DOFs: Cartesian, except the frame DOF held at
        a constrained node on a roller (its tangential component).
    seconds : float
        Wall-clock time of the assembly.
    dirichlet_nodes : (n_D,) int array
        The nodes whose both DOFs are held.
    obstacle_motion : (k, 2) float array
        The prescribed rigid displacement of the obstacle of each constraint's part
        (:meth:`~signorini.problem.obstacle_base.Obstacle.moved`; 0 for a gap function or
        an obstacle in place): the friction law's slip is relative to it.
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


def assemble(problem: ContactProblem, mesh: Mesh, *, element: str | Element = "P2") -> Assembled:
    """Stiffness, load and constraints of ``problem`` on ``mesh`` (paper, Section 3).

    The two DOFs of every constrained node are transformed into its frame (normal and
    tangential components; a corner's two constraint directions) so that each constraint
    ``u(z)·n_z ≤ ψ(z)`` becomes a bound on one unknown. ``element``: ``"P2"`` (the paper's,
    default) or ``"P1"`` (docs/method.md, *P1 elements and their estimator*); a ValueError
    names it otherwise.
    """
    t0 = time.perf_counter()
    space = space_of(mesh, element)
    n_dofs = space.n_dofs
    # the space of a validated mesh and problem: no need to re-check the arrays
    with np.errstate(over="ignore", invalid="ignore"):  # overflow is reported just below
        K = assemble_stiffness(
            space.mapping,
            space.cell_dofs,
            n_dofs,
            problem.material_on(mesh),
            validate=False,
            element=space.element,
        )
    if not np.isfinite(K.data).all():
        m = problem.material_on(mesh)
        raise ProblemError(
            f"material: the stiffness matrix overflows float64 (lam = {np.max(m.lam):.3g}, "
            f"mu = {np.max(m.mu):.3g}); state E in larger units (e.g. GPa instead of Pa)"
        )
    F = np.zeros(n_dofs)
    if problem.body_force is not None:
        F += assemble_body_force(
            space.mapping,
            space.cell_dofs,
            n_dofs,
            lambda x: evaluate_field(problem.body_force, x, "body_force"),
            degree=LOAD_DEGREE,
            element=space.element,
        )
    for name in problem.neumann_parts:
        cond: Neumann = problem.conditions[name]
        if cond.is_zero:
            continue
        edges = mesh.part_edges(name)
        nodes = space.edge_nodes(edges)
        dofs = np.stack([2 * nodes, 2 * nodes + 1], axis=-1).reshape(len(nodes), -1)
        g = cond.field()

        def traction(x, n, g=g, name=name):
            return evaluate_field(g, x, f"the traction of Neumann part {name!r}", normal=n)

        for rows, geometry in space.boundary_edges(edges):
            F += assemble_edge_load(
                geometry, dofs[rows], n_dofs, traction, degree=LOAD_DEGREE, element=space.element
            )
    cs = contact_set(problem, space)
    K, F = rotate_frames(K, F, cs.frame_nodes, cs.frames, copy=False, validate=False)
    dirichlet, d_values = _dirichlet_dofs(problem, space, cs)
    return Assembled(
        space,
        cs,
        K,
        F,
        dirichlet,
        d_values,
        time.perf_counter() - t0,
        problem.dirichlet_nodes(space),
        obstacle_displacement(problem, cs),
    )


def obstacle_displacement(problem: ContactProblem, cs: ContactSet) -> np.ndarray:
    """``(k, 2)`` the prescribed displacement of the obstacle of each constraint of ``cs``
    (docs/method.md, *Obstacle motion*): ``Obstacle.displacement`` of its part's obstacle,
    0 for a part with a gap function."""
    by_part = np.zeros((len(cs.parts), 2))
    for i, name in enumerate(cs.parts):  # a loop over contact parts
        obstacle = problem.conditions[name].obstacle
        if obstacle is not None:
            by_part[i] = obstacle.displacement
    return by_part[cs.part] if cs.size else np.zeros((0, 2))


def _dirichlet_dofs(
    problem: ContactProblem, space: LagrangeSpace, cs: ContactSet
) -> tuple[np.ndarray, np.ndarray]:
    """The held DOFs (sorted) and their values (docs/method.md, *Rollers and components*).

    A node on two Dirichlet parts takes the later part's value in each component that part
    holds. At a constrained node (in its contact frame ``u = Q y``) a held Cartesian
    component ``u_c = Q[c] y`` must be one frame DOF: ``Q[c, j] = 0`` for the other ``j``
    (a roller along the contact direction's tangent, as where a symmetry axis meets a
    symmetric contact arc), and not a constrained one; that frame DOF is held at
    ``u_c / Q[c, j]``.

    Raises
    ------
    ProblemError
        If a component held at a constrained node is not one free frame DOF (a roller that
        holds the contact direction, or part of it), or the node has friction, naming the
        node and the contact part.
    """
    held = problem.held_components(space)
    values = np.zeros((space.n_nodes, 2))
    for name, cond in problem.held.items():
        nodes = space.part_nodes([name])
        v = evaluate_field(
            cond.field(), space.node_points[nodes], f"the Dirichlet value of part {name!r}"
        )
        comp = np.asarray(cond.components)
        values[nodes[:, None], np.flatnonzero(comp)[None, :]] = v[:, comp]
    where = cs.local(np.arange(space.n_nodes))
    partial = held.any(axis=1) & ~held.all(axis=1) & (where >= 0)
    if partial.any():
        nodes = np.flatnonzero(partial)
        Q = cs.frames[np.searchsorted(cs.frame_nodes, nodes)]  # (m, 2, 2): u = Q y
        comp = held[nodes, 1].astype(np.int64)  # the one held component
        row = Q[np.arange(nodes.size), comp]  # (m, 2): u_c = row · y
        j = np.argmax(np.abs(row), axis=1)
        other = np.abs(row[np.arange(nodes.size), 1 - j])
        bad = (other > 1e-9 * np.abs(row).max(axis=1)) | np.isin(2 * nodes + j, cs.constrained_dofs)
        bad = np.flatnonzero(bad)
        if bad.size:
            z = nodes[bad[0]]
            raise ProblemError(
                f"the node at {tuple(np.round(space.node_points[z], 12).tolist())} is held in "
                f"u_{'xy'[comp[bad[0]]]} by a Dirichlet or Roller part and lies on contact "
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
        held[nodes] = False
        held[nodes, j] = True
        values[nodes, j] = values[nodes, comp] / row[np.arange(nodes.size), j]
        values[nodes, 1 - j] = 0.0
    dofs = np.flatnonzero(held.ravel())
    return dofs, values.ravel()[dofs]
