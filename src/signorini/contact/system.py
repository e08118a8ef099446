"""The algebraic contact problem of one mesh (paper, Section 3): stiffness, load, Dirichlet
data and the constrained nodes, with the contact nodes rotated into (normal, tangential)
frames.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ..fem.loads import assemble_body_force, assemble_edge_load
from ..fem.space import P2Space
from ..fem.stiffness import assemble_stiffness
from ..mesh.mesh import Mesh
from ..problem.conditions import Dirichlet, Neumann
from ..problem.fields import ProblemError, evaluate_field
from ..problem.problem import ContactProblem
from .contact_set import ContactSet, contact_set
from .node_frames import rotate_frames

__all__ = ["Assembled", "assemble", "LOAD_DEGREE"]

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
    space : P2Space
        The P2 space of the mesh (node numbering: vertices, then edge midpoints).
    contact : ContactSet
        The constrained nodes, their normals, gaps and weights.
    K : (n_dofs, n_dofs) scipy.sparse CSR matrix
        The stiffness matrix ``a(ψ_j, ψ_i)`` (symmetric positive semi-definite before the
        Dirichlet DOFs are fixed), rotated in place at the constrained nodes.
    F : (n_dofs,) float array
        The load ``L(ψ_i)``: body force and Neumann tractions, rotated like K.
    dirichlet : (2 n_D,) int array
        Both DOFs of every Dirichlet node, node after node (sorted by node).
    dirichlet_values : (2 n_D,) float array
        The prescribed displacements of those DOFs (Cartesian: Dirichlet nodes are never
        rotated).
    seconds : float
        Wall-clock time of the assembly.
    """

    space: P2Space
    contact: ContactSet
    K: sp.csr_matrix
    F: np.ndarray
    dirichlet: np.ndarray
    dirichlet_values: np.ndarray
    seconds: float


def assemble(problem: ContactProblem, mesh: Mesh) -> Assembled:
    """Stiffness, load and constraints of ``problem`` on ``mesh`` (paper, Section 3).

    The two DOFs of every constrained node are transformed into its frame (normal and
    tangential components; a corner's two constraint directions) so that each constraint
    ``u(z)·n_z ≤ ψ(z)`` becomes a bound on one unknown.
    """
    t0 = time.perf_counter()
    space = P2Space(mesh)
    n_dofs = space.n_dofs
    # the space of a validated mesh and problem: no need to re-check the arrays
    with np.errstate(over="ignore", invalid="ignore"):  # overflow is reported just below
        K = assemble_stiffness(
            space.mapping, space.cell_dofs, n_dofs, problem.material_on(mesh), validate=False
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
        )
    for name in problem.neumann_parts:
        cond: Neumann = problem.conditions[name]
        if cond.is_zero:
            continue
        edges = mesh.part_edges(name)
        nodes = space.edge_nodes(edges)
        dofs = np.stack([2 * nodes, 2 * nodes + 1], axis=-1).reshape(-1, 6)
        g = cond.field()

        def traction(x, n, g=g, name=name):
            return evaluate_field(g, x, f"the traction of Neumann part {name!r}", normal=n)

        for rows, geometry in space.boundary_edges(edges):
            F += assemble_edge_load(geometry, dofs[rows], n_dofs, traction, degree=LOAD_DEGREE)
    # Dirichlet values (a node on two Dirichlet parts takes the later part's value)
    d_nodes = problem.dirichlet_nodes(space)
    d_values = np.empty((d_nodes.size, 2))
    for name in problem.dirichlet_parts:
        cond: Dirichlet = problem.conditions[name]
        nodes = space.part_nodes([name])
        d_values[np.searchsorted(d_nodes, nodes)] = evaluate_field(
            cond.field(), space.node_points[nodes], f"the Dirichlet value of part {name!r}"
        )
    dirichlet = np.column_stack([2 * d_nodes, 2 * d_nodes + 1]).ravel()

    cs = contact_set(problem, space)
    K, F = rotate_frames(K, F, cs.frame_nodes, cs.frames, copy=False, validate=False)
    return Assembled(space, cs, K, F, dirichlet, d_values.ravel(), time.perf_counter() - t0)
