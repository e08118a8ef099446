"""SOLVE: the discrete Signorini problem (3.2) on one mesh, solved by PDAS, or with friction
by the semismooth Newton method of :mod:`.frictional`.

The only module that joins the assembled system, the contact boundary and the algebraic
solvers: both are behind one call (:func:`_solve_system`) that gives a
:class:`~.frictional.Solved`, from which :class:`ContactResult` is built once; it carries the
solution, the solver's report and everything derived from them.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
import scipy.sparse as sp

from ..algebra.backends.selection import takes_ordering
from ..algebra.backends.solvers import SolverFactory, SPDSolver
from ..algebra.friction.newton import INACTIVE, SLIP, STICK
from ..algebra.pdas import PDASOptions, solve_pdas
from ..algebra.ranks import solver_ranks
from ..algebra.result import SolveReport
from ..algebra.sparse import stiffness_unit
from ..fem.element import Element
from ..fem.norms import energy_error2, h1_seminorm_error2
from ..fem.postprocess import nodal_stress
from ..fem.space import LagrangeSpace
from ..mesh.mesh import Mesh
from ..problem.fields import evaluate_field
from ..problem.problem import ContactProblem
from ..problem.problem3d import check_mesh_dimension
from .contact_set import ContactSet, node_classes
from .face_contact import FaceContactSet
from .force_control import check_load_carried, initial_active_set
from .frictional3d import Solved, check_previous, solve_frictional
from .nested import (
    NESTED_MIN_NDOF,
    WARM_START_RTOL,
    nested_active_set,
    round_off_scale,
    warm_active_set,
)
from .ordering import SolverAhead, ordered_solver
from .partition import Partition
from .profile import ContactProfile, contact_profile
from .rigid_modes import system_rigid_modes
from .solution3d import cartesian_displacement, contact_force, errors_3d, nodal_pressure
from .system import Assembled, assemble
from .two_body import master_traction

__all__ = [
    "ContactProfile",
    "ContactResult",
    "INACTIVE",
    "SLIP",
    "STICK",
    "solve",
    "stiffness_unit",
]

log = logging.getLogger(__name__)

#: quadrature degree for errors against a smooth exact solution
ERROR_DEGREE = 10


#: a Dirichlet end point of Γ_C touches the obstacle (for the node classes) where
#: ``u_D·n − ψ ≥ −TOUCH_RTOL · max(max|u_h|, |ψ|)``
TOUCH_RTOL = 1e-12


@dataclass
class ContactResult:
    """The discrete solution of one mesh and everything derived from it.

    Consistent units: if E is in MPa and lengths in mm, ``u`` is in mm, ``contact_force``
    Λ_z in N per mm of thickness (plane strain: forces per unit thickness), ``density``
    s_z and ``pressure`` p_z in MPa.

    Attributes
    ----------
    problem : ContactProblem
        The problem that was solved.
    space : P2Space or P1Space
        The space of the mesh (``space.mesh``; P2 node numbering: vertices, then midpoints).
    u : (n_nodes, 2) float array
        Nodal displacements u_h(z) (Cartesian) at every P2 node.
    contact : ContactSet
        The constrained nodes (k of them) with normals, gaps ψ(z) and weights.
    contact_force : (k,) float array
        Nodal contact forces Λ_z ≥ 0 (3.17), ``L(ψ_z n) − a(u_h, ψ_z n)``; their sum is the
        resultant normal force on Γ_C.
    active : (k,) bool array
        Final active set of the PDAS iteration (``u(z)·n = ψ(z)`` imposed): the actual
        contact nodes.
    report : SolveReport
        How the solver got there (:class:`~signorini.algebra.SolveReport`): iterations,
        solver counters, KKT residuals (relative, ``report.kkt.columns()``), history,
        backend, timings. A :class:`~signorini.algebra.PDASResult` without friction
        (``report.multiplier`` equals ``contact_force``), a
        :class:`~signorini.algebra.FrictionResult` with it (KKT residuals of both laws).
        When E is extreme the system was solved divided by ``stiffness_unit(K)``, so
        ``report.kkt.force_scale`` is in that unit.
    dirichlet_nodes : (n_D,) int array
        The P2 nodes on the closure of Γ_D (both components prescribed).
    timings : dict
        Seconds spent in ``assemble`` and ``solve``.
    roller_nodes : (r,) int array
        The nodes of roller parts held along their normal only (not Dirichlet nodes, not
        constrained nodes; docs/method.md, *Rollers and components*).
    roller_force : (r,) float array
        The roller's nodal force on the body along ``−n_z`` at each,
        ``Λ_z = L(ψ_z n_z) − a(u_h, ψ_z n_z)`` as for a contact force (3.17): positive where
        the roller pushes the body; the roller acts on the body with ``−Λ_z n_z``.
    partition : Partition or None
        On a run of several MPI ranks, which rank owns which nodes and cells and the ranks
        themselves (:attr:`~.system.Assembled.partition`); None on one process. Everything
        else is the same on every rank.
    obstacle_motion : (k, 2) float array or None
        The prescribed displacement of the obstacle of each constraint
        (:attr:`~.system.Assembled.obstacle_motion`), which the next load step's slip is
        measured against (docs/method.md, *Obstacle motion*).
    tangential_force : (k,) float array
        Nodal friction forces Λ_t,z (along the constraint's tangent ``contact.tangent``,
        ``t = (−n_y, n_x)``; the obstacle acts on the body with ``−Λ_t t``); 0 without
        friction.
    state : (k,) int array
        ``INACTIVE`` (no contact), ``STICK`` or ``SLIP`` per constraint; a frictionless
        node in contact slips (its friction force, 0, is at its bound).
    direction : (k,) int8 array
        The slip direction ``sign Λ_t,z`` where the friction force is at a positive bound,
        else 0 (always 0 without friction).
    tangential_reference : (k,) float array
        The tangential displacement of no slip per constraint, which the friction law's slip
        ``u(z)·t_z − tangential_reference`` is measured from: the previous load step's
        ``u(z)·t_z`` (docs/method.md, *Load paths*), 0 for a single step and without
        friction; with a moved obstacle, relative to it (docs/method.md, *Obstacle motion*).

    Derived: ``ndof``, ``density`` s_z, ``pressure`` p_z, ``total_contact_force``,
    ``classes``, :meth:`contact_profile` (the contact quantities of a part in boundary
    order), :meth:`errors`.
    """

    problem: ContactProblem
    space: LagrangeSpace
    u: np.ndarray
    contact: ContactSet
    contact_force: np.ndarray
    active: np.ndarray
    report: SolveReport
    dirichlet_nodes: np.ndarray
    tangential_force: np.ndarray
    state: np.ndarray
    direction: np.ndarray
    tangential_reference: np.ndarray
    timings: dict = field(default_factory=dict)
    roller_nodes: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    roller_force: np.ndarray = field(default_factory=lambda: np.zeros(0))
    partition: Partition | None = None
    obstacle_motion: np.ndarray | None = None

    @property
    def mesh(self) -> Mesh:
        return self.space.mesh

    @property
    def ndof(self) -> int:
        """Free scalar unknowns, the paper's Ndof (:meth:`ContactProblem.free_ndof`)."""
        return self.problem.free_ndof(self.space)

    @property
    def density(self) -> np.ndarray:
        """The paper's discrete contact force density ``s_z = Λ_z / m_z`` (4.1)."""
        return self.contact_force / self.contact.hat_integral

    @property
    def pressure(self) -> np.ndarray:
        """Consistent nodal contact pressure ``p_z = Λ_z / w_z``, ``w_z = ∫ψ_z`` (docs/method.md,
        *Discrete problem*; on faces :func:`~.solution3d.nodal_pressure`)."""
        return nodal_pressure(self)

    @property
    def tangential_pressure(self) -> np.ndarray:
        """Consistent nodal friction stress ``p_t,z = Λ_t,z / w_z``."""
        weight = self.contact.basis_integral
        return self.space.element.facet.pressure(self.tangential_force, weight)

    @cached_property
    def master_side(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """With contact pairs, the master parts' P2 nodes ``(m,)``, the consistent traction
        the slaves exert there ``(m, 2)`` and the transferred pressure ``(m,)``
        (:func:`~signorini.contact.two_body.master_traction`; docs/method.md, *Two
        bodies*); empty arrays without pairs."""
        cs = self.contact
        if cs.transfer is None:
            return np.zeros(0, np.int64), np.zeros((0, 2)), np.zeros(0)
        f = -(
            self.contact_force[:, None] * cs.normal
            + self.tangential_force[:, None] * cs.tangent[:, 0]
        )
        force = np.column_stack([f, self.contact_force])
        return master_traction(self.space, cs.transfer, cs.nodes, force)

    @property
    def total_contact_force(self) -> float:
        """``Σ_z Λ_z`` (the resultant normal force on Γ_C where all n_z agree)."""
        return float(self.contact_force.sum())

    @property
    def contact_force_vector(self) -> np.ndarray:
        """``(2,)`` the resultant force of the obstacles on the body,
        ``−Σ_z (Λ_z n_z + Λ_t,z t_z)`` (docs/method.md, *Contact directions*)."""
        n, t = self.contact.normal, self.contact.tangent[:, 0]
        return -(self.contact_force @ n) - self.tangential_force @ t

    @cached_property
    def nodal_stress(self) -> np.ndarray:
        """``(n_nodes, 3, 3)`` σ(u_h) at the P2 nodes, each the mean of its cells' values, σ_zz
        from the material (:func:`signorini.fem.postprocess.nodal_stress`)."""
        return nodal_stress(self.space, self.u, self.problem.material_on(self.mesh))

    @cached_property
    def classes(self) -> np.ndarray:
        """Full / semi / no contact class of every constrained node (paper, Section 4)."""
        cs = self.contact
        loc = cs.facet_local
        gap = cs.facet_normal_gap(self.u)
        dirichlet_touch = gap >= -TOUCH_RTOL * round_off_scale(self.u, cs.facet_gap)
        edge_in = np.where(loc >= 0, self.active[np.maximum(loc, 0)], dirichlet_touch)
        return node_classes(cs, self.active, edge_in)

    def contact_profile(self, part: str | None = None) -> ContactProfile:
        """The contact quantities of one contact part, ordered along the boundary
        (:func:`signorini.contact.profile.contact_profile`)."""
        return contact_profile(self, part)

    def errors(self, degree: int = ERROR_DEGREE) -> dict[str, float]:
        """Energy-norm ``a(e,e)^{1/2}`` and H¹-seminorm errors against the exact solution
        (3D: also the L² error, :func:`~.solution3d.errors_3d`)."""
        exact = self.problem.exact
        if exact is None:
            raise ValueError(f"{self.problem.name} has no exact solution")
        if self.mesh.dim == 3:
            return errors_3d(self)
        u_cell = self.space.field_coefficients(self.u)

        def gradient(x: np.ndarray) -> np.ndarray:
            return evaluate_field(exact.gradient, x, "the exact gradient", shape=(2, 2))

        cells, material = self.space.mapping, self.problem.material_on(self.space.mesh)
        energy = energy_error2(cells, u_cell, gradient, material, degree=degree)
        h1 = h1_seminorm_error2(cells, u_cell, gradient, degree=degree)
        return {"error_energy": float(np.sqrt(energy.sum())), "error_h1": float(np.sqrt(h1.sum()))}


def solve(
    problem: ContactProblem,
    mesh: Mesh | None = None,
    *,
    u0: np.ndarray | None = None,
    solver: SPDSolver | SolverFactory | None = None,
    max_iter: int = 50,
    fallback: bool = False,
    assembled: Assembled | None = None,
    previous: ContactResult | None = None,
    nested: bool = True,
    element: str | Element = "P2",
) -> ContactResult:
    """Solve the discrete Signorini problem (3.2) on ``mesh`` by the primal-dual active set
    method (docs/method.md, *Solver*); with Tresca or Coulomb friction on a contact part, by
    the semismooth Newton method of docs/method.md, *Friction*.

    Parameters
    ----------
    problem : ContactProblem
    mesh : Mesh, optional
        Defaults to the problem's initial mesh.
    u0 : (n_nodes, 2) array, optional
        Warm start (e.g. the previous level's solution prolongated to ``mesh``): its nodes in
        contact form the initial active set.
    solver : SolverFactory or SPDSolver, optional
        The linear solver, and the processes it runs on
        (:func:`~signorini.algebra.ranks.solver_ranks`: on several MPI ranks each assembles
        the stiffness rows of its own nodes, :func:`~.system.assemble`). A factory
        (:class:`~signorini.algebra.SolverFactory`, default
        :func:`~signorini.algebra.auto_solver`: PARDISO, else SuperLU; a backend by name:
        :data:`signorini.algebra.SOLVERS`) is called once per sequence of systems (the
        solve, and the coarse solve of nested iteration) and its solvers are closed. An
        :class:`~signorini.algebra.SPDSolver` is used for every system as it is (no ordering
        set) and not closed; with Coulomb friction it must factorize non-symmetric matrices.
    max_iter : int
        Bound on PDAS iterations.
    fallback : bool
        On PDAS failure, fall back to a convergent method instead of raising.
    assembled : Assembled, optional
        Reuse an assembly of the same mesh: a whole matrix on every process, or a rank's
        rows for the solver's ranks.
    previous : ContactResult, optional
        The previous step of a quasi-static load path on the same mesh with the same contact
        parts (docs/method.md, *Load paths*): the friction law acts on the slip from its
        tangential displacements, and it is the warm start (its node states, or its
        displacement; ``u0`` replaces it). Without friction only the warm start.
    nested : bool
        With contact, without a warm start, without friction and on a mesh other than the
        problem's initial one with at least ``NESTED_MIN_NDOF`` free unknowns, start PDAS
        from the active set of a coarse solve (:mod:`signorini.contact.nested`;
        docs/method.md, *Solver*). The solution is the same; False starts from the empty
        active set.
    element : {"P2", "P1"}
        The finite element (docs/method.md, *P1 elements and their estimator*); ignored with
        ``assembled``, whose space has one.

    Raises
    ------
    TypeError
        For a ``mesh`` that is not a :class:`~signorini.mesh.mesh.Mesh`.
    ValueError
        For a malformed ``u0``, an unknown ``element``, a ``previous`` of another mesh or
        other contact parts, or an ``assembled`` shared by rows over other ranks than the
        solver's.
    """
    mesh = problem.mesh if mesh is None else mesh
    check_mesh_dimension(problem.name, problem.mesh, mesh)
    ahead = None
    if assembled is None:
        serial = not solver_ranks(solver).distributed
        ahead = SolverAhead(solver) if serial and takes_ordering(solver) and mesh.dim == 2 else None
        assembled = assemble(
            problem, mesh, element=element, ranks=solver_ranks(solver),
            prefetch_ordering=ahead is not None, on_pattern=ahead and ahead.start,
        )  # fmt: skip
    elif assembled.partition is not None:
        assembled.partition.check_ranks(solver_ranks(solver))
    ranks = assembled.ranks
    space, cs = assembled.space, assembled.contact
    if assembled.conditions.rigid_motions.size:
        check_load_carried(assembled)
    if previous is not None:
        check_previous(previous, space, cs)
        if u0 is None and not cs.has_friction:
            u0 = previous.u
    # K and F divided by a power of 2 when E is extreme (exact; 1 otherwise), so that no
    # product in the factorization overflows or underflows
    diagonal = assembled.K if ranks.size == 1 else sp.diags(ranks.sum(assembled.K.diagonal()))
    unit = stiffness_unit(diagonal)
    K, F = (assembled.K, assembled.F) if unit == 1.0 else (assembled.K / unit, assembled.F / unit)
    active0 = None
    if u0 is not None:
        u0 = np.asarray(u0, dtype=np.float64)
        if u0.shape != (space.n_nodes, mesh.dim):
            raise ValueError(f"u0 must have shape ({space.n_nodes}, {mesh.dim}), got {u0.shape}")
        if not np.isfinite(u0).all():
            raise ValueError("u0 contains NaN or inf")
        active0 = warm_active_set(cs, u0, assembled, (K, F)) if mesh.dim == 2 or cs.size else None
    t0 = time.perf_counter()
    timings = {"assemble": assembled.seconds}
    if (
        nested
        and active0 is None
        and mesh is not problem.mesh
        and mesh.dim == 2
        and cs.size > 0
        and not cs.has_friction
        and problem.free_ndof(space) >= NESTED_MIN_NDOF
    ):
        active0 = nested_active_set(
            problem.mesh, space, cs,
            lambda coarse: solve(
                problem, coarse, solver=solver, max_iter=max_iter, fallback=fallback,
                element=space.element,
            ),
        )  # fmt: skip
        timings["nested"] = time.perf_counter() - t0
    if active0 is None and assembled.conditions.rigid_motions.size:
        # semi-coercive: the empty active set leaves the free rigid motions singular; start
        # from the first points of contact (docs/method.md, *Force control*)
        active0 = initial_active_set(assembled)
    solved = _solve_system(
        assembled, (K, F), u0=u0, active0=active0, previous=previous,
        options=PDASOptions(max_iter=max_iter, fallback=fallback), solver=ahead or solver,
    )  # fmt: skip
    timings["solve"] = time.perf_counter() - t0
    report = solved.report.scaled(unit)
    log.info(
        "solved %s: %d unknowns, %d iterations, %d in contact of %d",
        problem.name,
        space.n_dofs,
        report.iterations,
        int((solved.state != INACTIVE).sum()),
        cs.size,
    )
    return ContactResult(
        problem=problem,
        space=space,
        u=cartesian_displacement(solved.x, assembled),
        contact=cs,
        contact_force=contact_force(cs, solved.normal_force * unit),
        active=solved.state != INACTIVE,
        report=report,
        dirichlet_nodes=assembled.dirichlet_nodes,
        tangential_force=solved.tangential_force * unit,
        state=solved.state,
        direction=solved.direction,
        tangential_reference=solved.reference,
        timings=timings,
        roller_nodes=assembled.rollers.nodes,
        roller_force=assembled.rollers.force(assembled.K, assembled.F, solved.x, ranks),
        partition=assembled.partition,
        obstacle_motion=assembled.obstacle_motion,
    )


def _solve_system(
    assembled: Assembled,
    system: tuple,
    *,
    u0: np.ndarray | None,
    active0: np.ndarray | None,
    previous: ContactResult | None,
    options: PDASOptions,
    solver: SPDSolver | SolverFactory | None,
) -> Solved:
    """The algebraic problem of ``assembled`` with the matrix and load ``system = (K, F)``:
    frictional (:func:`~.frictional.solve_frictional`) when a contact part has a friction
    law, else the bound-constrained QP by PDAS. Forces in the unit of ``system``."""
    K, F = system
    cs = assembled.contact
    if cs.has_friction:
        return solve_frictional(
            assembled, K, F, u0=u0, solver=solver, max_iter=options.max_iter,
            previous=previous, active0=active0, warm_rtol=WARM_START_RTOL,
        )  # fmt: skip
    # on faces a warm start is an iterative solver's first iterate (docs/method.md, *Three
    # dimensions: warm-started CG*) too
    x0 = cs.unknowns(u0.ravel()) if u0 is not None and isinstance(cs, FaceContactSet) else None
    # the assembled matrix is symmetric by construction: skip the solver's symmetry check
    with ordered_solver(
        assembled.space, solver, check_symmetry=False, ordering=assembled.ordering,
        rigid_modes=lambda: system_rigid_modes(assembled), coupled=cs.couples_bodies,
    ) as linear:  # fmt: skip
        res = solve_pdas(
            K, F, cs.constrained_dofs, cs.gap, assembled.dirichlet, assembled.dirichlet_values,
            x0=x0, active0=active0, options=options, solver=linear, ranks=assembled.ranks,
        )  # fmt: skip
    zero = np.zeros(cs.size)
    state = np.where(res.active, SLIP, INACTIVE)
    return Solved(res.x, res.multiplier, zero, state, zero.astype(np.int8), zero, res)
