"""SOLVE: the discrete Signorini problem (3.2) on one mesh, solved by PDAS.

The only module that joins the assembled system, the contact boundary and the algebraic
solver; :class:`ContactResult` carries the solution and everything derived from it.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass, field, replace
from functools import cached_property

import numpy as np

from ..algebra.backends import make_solver
from ..algebra.pdas import solve_pdas
from ..algebra.result import PDASResult
from ..fem.norms import energy_error2, h1_seminorm_error2
from ..fem.space import P2Space
from ..mesh.mesh import Mesh
from ..problem.fields import evaluate_field
from ..problem.problem import ContactProblem
from .contact_set import ContactSet, node_classes
from .node_frames import to_cartesian
from .system import Assembled, assemble

__all__ = ["ContactResult", "solve", "stiffness_unit"]

log = logging.getLogger(__name__)

#: quadrature degree for errors against a smooth exact solution
ERROR_DEGREE = 10
#: a stiffness matrix whose largest diagonal entry lies in this range is solved as it is;
#: outside it (E beyond about 1e±77) K and F are divided by a power of 2 first
STIFFNESS_RANGE = (2.0**-256, 2.0**256)


def stiffness_unit(K) -> float:
    """1 if ``max |diag K|`` lies in ``STIFFNESS_RANGE`` (or is 0), else the power of 2
    not above it. Dividing K and F by it is exact, so u_h is the same; it keeps sums over
    K (the active set rule's constant c = mean diag K, the force scales of the KKT check)
    and the factorization's products away from overflow and underflow when E is extreme."""
    d = float(np.abs(K.diagonal()).max(initial=0.0))
    lo, hi = STIFFNESS_RANGE
    if d == 0.0 or not np.isfinite(d) or lo <= d <= hi:
        return 1.0
    return float(np.ldexp(1.0, int(np.floor(np.log2(d)))))


@dataclass
class ContactResult:
    """The discrete solution of one mesh and everything derived from it.

    Attributes
    ----------
    problem : ContactProblem
    space : P2Space
    u : (n_nodes, 2) float array
        Nodal displacements (Cartesian).
    contact : ContactSet
    contact_force : (k,) float array
        Nodal contact forces Λ_z ≥ 0 (3.17).
    active : (k,) bool array
        Final active set of the PDAS iteration (``u(z)·n = ψ(z)`` imposed): the actual
        contact nodes.
    pdas : PDASResult
    timings : dict
        Seconds spent in ``assemble`` and ``solve``.
    """

    problem: ContactProblem
    space: P2Space
    u: np.ndarray
    contact: ContactSet
    contact_force: np.ndarray
    active: np.ndarray
    pdas: PDASResult
    dirichlet_nodes: np.ndarray
    timings: dict = field(default_factory=dict)

    @property
    def mesh(self) -> Mesh:
        return self.space.mesh

    @property
    def ndof(self) -> int:
        """Free scalar unknowns (the paper's Ndof): all DOFs minus the Dirichlet ones."""
        return self.space.n_dofs - 2 * self.dirichlet_nodes.size

    @property
    def density(self) -> np.ndarray:
        """The paper's discrete contact force density ``s_z = Λ_z / m_z`` (4.1)."""
        return self.contact_force / self.contact.hat_integral

    @property
    def pressure(self) -> np.ndarray:
        """Consistent nodal contact pressure ``p_z = Λ_z / w_z``, ``w_z = ∫ψ_z`` (docs/method.md,
        *Discrete problem*)."""
        return self.contact_force / self.contact.basis_integral

    @property
    def total_contact_force(self) -> float:
        """``Σ_z Λ_z`` (the resultant normal force on Γ_C)."""
        return float(self.contact_force.sum())

    @cached_property
    def classes(self) -> np.ndarray:
        """Full / semi / no contact class of every constrained node (paper, Section 4)."""
        cs = self.contact
        loc = cs.edge_local
        gap = cs.edge_normal_gap(self.u)
        scale = max(
            float(np.abs(cs.edge_gap).max(initial=0)), float(np.abs(self.u).max(initial=0)), 1e-300
        )
        dirichlet_touch = gap >= -1e-12 * scale
        edge_in = np.where(loc >= 0, self.active[np.maximum(loc, 0)], dirichlet_touch)
        return node_classes(cs, self.active, edge_in)

    def errors(self, degree: int = ERROR_DEGREE) -> dict[str, float]:
        """Energy-norm ``a(e,e)^{1/2}`` and H¹-seminorm errors against the exact solution."""
        exact = self.problem.exact
        if exact is None:
            raise ValueError(f"{self.problem.name} has no exact solution")
        u_cell = self.space.cell_values(self.u)

        def gradient(x: np.ndarray) -> np.ndarray:
            return evaluate_field(exact.gradient, x, "the exact gradient", shape=(2, 2))

        vertices, material = self.space.vertices, self.problem.material
        energy = energy_error2(vertices, u_cell, gradient, material, degree=degree)
        h1 = h1_seminorm_error2(vertices, u_cell, gradient, degree=degree)
        return {"error_energy": float(np.sqrt(energy.sum())), "error_h1": float(np.sqrt(h1.sum()))}


def solve(
    problem: ContactProblem,
    mesh: Mesh | None = None,
    *,
    u0: np.ndarray | None = None,
    backend: str = "auto",
    max_iter: int = 50,
    fallback: bool = False,
    assembled: Assembled | None = None,
) -> ContactResult:
    """Solve the discrete Signorini problem (3.2) on ``mesh`` by the primal-dual active set
    method (docs/method.md, *Solver*).

    Parameters
    ----------
    problem : ContactProblem
    mesh : Mesh, optional
        Defaults to the problem's initial mesh.
    u0 : (n_nodes, 2) array, optional
        Warm start (e.g. the previous level's solution prolongated to ``mesh``): its nodes in
        contact form the initial active set.
    backend : str
        Sparse solver backend, see :func:`signorini.algebra.make_solver`.
    max_iter : int
        Bound on PDAS iterations.
    fallback : bool
        On PDAS failure, fall back to a convergent method instead of raising.
    assembled : Assembled, optional
        Reuse an assembly of the same mesh.
    """
    mesh = problem.mesh if mesh is None else mesh
    if assembled is None:
        assembled = assemble(problem, mesh)
    space, cs = assembled.space, assembled.contact
    active0 = None
    if u0 is not None:
        u0 = np.asarray(u0, dtype=np.float64)
        if u0.shape != (space.n_nodes, 2):
            raise ValueError(f"u0 must have shape ({space.n_nodes}, 2), got {u0.shape}")
        if not np.isfinite(u0).all():
            raise ValueError("u0 contains NaN or inf")
        un = cs.normal_displacement(u0)
        scale = max(float(np.abs(cs.gap).max(initial=0)), float(np.abs(u0).max()), 1e-300)
        active0 = un - cs.gap >= -1e-10 * scale
    # K and F divided by a power of 2 when E is extreme (exact; 1 otherwise), so that no
    # product in the factorization overflows or underflows
    unit = stiffness_unit(assembled.K)
    K, F = (assembled.K, assembled.F) if unit == 1.0 else (assembled.K / unit, assembled.F / unit)
    t0 = time.perf_counter()
    # the assembled matrix is symmetric by construction: skip the solver's symmetry check
    with make_solver(backend, check_symmetry=False) as solver:
        res = solve_pdas(
            K,
            F,
            2 * cs.nodes,
            cs.gap,
            assembled.dirichlet,
            assembled.dirichlet_values,
            active0=active0,
            max_iter=max_iter,
            solver=solver,
            fallback=fallback,
        )
    seconds = time.perf_counter() - t0
    if unit != 1.0:
        res = replace(res, multiplier=res.multiplier * unit, c_scale=res.c_scale * unit)
    u = to_cartesian(res.x, cs.nodes, cs.normal).reshape(-1, 2)
    log.info(
        "solved %s: %d unknowns, %d PDAS iterations, %d active of %d",
        problem.name,
        space.n_dofs,
        res.iterations,
        int(res.active.sum()),
        cs.size,
    )
    return ContactResult(
        problem=problem,
        space=space,
        u=u,
        contact=cs,
        contact_force=res.multiplier,
        active=res.active,
        pdas=res,
        dirichlet_nodes=assembled.dirichlet[::2] // 2,
        timings={"assemble": assembled.seconds, "solve": seconds},
    )
