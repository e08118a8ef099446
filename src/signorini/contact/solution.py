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

__all__ = ["ContactProfile", "ContactResult", "solve", "stiffness_unit"]

log = logging.getLogger(__name__)

#: quadrature degree for errors against a smooth exact solution
ERROR_DEGREE = 10
#: a stiffness matrix whose largest diagonal entry lies in this range is solved as it is;
#: outside it (E beyond about 1e±77) K and F are divided by a power of 2 first
STIFFNESS_RANGE = (2.0**-256, 2.0**256)


#: a Dirichlet end point of Γ_C touches the obstacle (for the node classes) where
#: ``u_D·n − ψ ≥ −TOUCH_RTOL · max(max|u_h|, |ψ|)``
TOUCH_RTOL = 1e-12
#: a warm start's node starts in the active set where
#: ``u0·n − ψ ≥ −WARM_START_RTOL · max(max|u0|, |ψ|)``: the prolongated contact nodes
#: of the previous level, whose u0·n − ψ is round-off of the displacements
WARM_START_RTOL = 1e-10


def _round_off_scale(u: np.ndarray, gap: np.ndarray) -> np.ndarray:
    """``max(max|u|, |ψ(z)|)`` per node (the shape of ``gap``): the size of the two numbers
    ``u(z)·n − ψ(z)`` is the difference of, hence of its round-off. Relative to the
    displacements and to the gap at the node itself, not to the gap far away (a distant
    obstacle must not make the test lenient), and invariant under scaling of the problem."""
    return np.maximum(np.abs(u).max(initial=0.0), np.abs(gap))


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


@dataclass(frozen=True)
class ContactProfile:
    """The nodes of one contact part in order along the boundary, with the contact quantities.

    Consistent units: if E is in MPa and lengths in mm, ``s``, ``points``, ``gap``,
    ``normal_displacement`` and ``normal_gap`` are in mm, ``pressure`` in MPa and
    ``contact_force`` in N per mm of thickness.

    Attributes
    ----------
    part : str
        The contact part.
    nodes : (m,) int array
        Global P2 nodes (vertices and edge midpoints) of the part, in the order of the
        counter-clockwise boundary.
    chain : (m,) int array
        Which connected piece of the part each node is on: 0, 1, … in the order of the pieces
        along the part's direction (a part made of disjoint segments has several chains).
    s : (m,) float array
        Distance from the part's first node: ``s_0 = 0``, ``s_{i+1} = s_i + |x_{i+1} − x_i|``.
        Within a chain this is the length of the polygon through the nodes (the arc length
        on a straight part); from one chain to the next it jumps by the straight distance
        between them.
    points : (m, 2) float array
        The nodes' coordinates.
    pressure : (m,) float array
        Consistent pressure ``p_z = Λ_z / w_z`` (docs/method.md, *Discrete problem*); NaN at
        Dirichlet nodes (no contact unknown there).
    contact_force : (m,) float array
        Nodal contact force ``Λ_z`` (3.17); NaN at Dirichlet nodes. A node shared with another
        contact part carries its whole ``Λ_z`` (and ``w_z`` counts both parts' edges).
    gap : (m,) float array
        The obstacle ψ(z).
    normal_displacement : (m,) float array
        ``u_h(z)·n_z``, n_z the part's constraint direction at the node.
    normal_gap : (m,) float array
        ``u_h(z)·n − ψ(z)``: 0 in contact, < 0 where the body is off the obstacle.
    """

    part: str
    nodes: np.ndarray
    chain: np.ndarray
    s: np.ndarray
    points: np.ndarray
    pressure: np.ndarray
    contact_force: np.ndarray
    gap: np.ndarray
    normal_displacement: np.ndarray
    normal_gap: np.ndarray


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
    space : P2Space
        The P2 space of the mesh (``space.mesh``; node numbering: vertices, then midpoints).
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
    pdas : PDASResult
        How the active set solver got there: iterations, KKT residuals (relative), timings.
        ``pdas.multiplier`` equals ``contact_force``; when E is extreme the system was
        solved divided by ``stiffness_unit(K)``, so ``pdas.kkt.force_scale`` is in that unit.
    dirichlet_nodes : (n_D,) int array
        The P2 nodes on the closure of Γ_D (both components prescribed).
    timings : dict
        Seconds spent in ``assemble`` and ``solve``.

    Derived: ``ndof``, ``density`` s_z, ``pressure`` p_z, ``total_contact_force``,
    ``classes``, :meth:`contact_profile` (the contact quantities of a part in boundary
    order), :meth:`errors`.
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
        """Free scalar unknowns (the paper's Ndof): ``2 n_nodes − 2 n_D``, all P2 DOFs minus
        both DOFs of every Dirichlet node; constrained contact DOFs are counted."""
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
        """``Σ_z Λ_z`` (the resultant normal force on Γ_C where all n_z agree)."""
        return float(self.contact_force.sum())

    @property
    def contact_force_vector(self) -> np.ndarray:
        """``(2,)`` the resultant force of the obstacles on the body, ``−Σ_z Λ_z n_z``
        (docs/method.md, *Contact directions*)."""
        return -(self.contact_force @ self.contact.normal)

    @cached_property
    def classes(self) -> np.ndarray:
        """Full / semi / no contact class of every constrained node (paper, Section 4)."""
        cs = self.contact
        loc = cs.edge_local
        gap = cs.edge_normal_gap(self.u)
        dirichlet_touch = gap >= -TOUCH_RTOL * _round_off_scale(self.u, cs.edge_gap)
        edge_in = np.where(loc >= 0, self.active[np.maximum(loc, 0)], dirichlet_touch)
        return node_classes(cs, self.active, edge_in)

    def contact_profile(self, part: str | None = None) -> ContactProfile:
        """The contact quantities of one contact part, ordered along the boundary.

        Parameters
        ----------
        part : str, optional
            A contact part of the problem; may be omitted when there is only one.

        Returns
        -------
        ContactProfile
            Every P2 node of the part (Dirichlet end points included) in the order of the
            counter-clockwise boundary, with arc length, p_z, Λ_z, ψ, u·n and u·n − ψ. A part
            made of disjoint segments gives one ``chain`` per segment, in the order of the
            segments along the part's direction.

        Examples
        --------
        >>> prof = result.contact_profile("right")                    # doctest: +SKIP
        >>> plt.plot(prof.s, prof.pressure)                           # doctest: +SKIP
        """
        cs = self.contact
        if part is None:
            if len(cs.parts) != 1:
                raise ValueError(
                    f"part: the problem has contact parts {list(cs.parts)}; name one of them"
                )
            part = cs.parts[0]
        if part not in cs.parts:
            raise ValueError(
                f"part: {part!r} is not a contact part of {self.problem.name!r}; its contact "
                f"parts are {list(cs.parts)}"
            )
        mine = np.flatnonzero(cs.edge_part == cs.parts.index(part))
        order, chain_end, chain = _walk(cs.edge_nodes[mine], self.space.node_points)
        edges = mine[order]
        # per ordered edge: start, midpoint, and the end vertex where a chain ends
        take = np.column_stack([np.ones(edges.size, bool), np.ones(edges.size, bool), chain_end])
        column = np.broadcast_to(np.array([0, 2, 1]), take.shape)[take]
        row = np.broadcast_to(edges[:, None], take.shape)[take]
        nodes = cs.edge_nodes[row, column]
        points = self.space.node_points[nodes]
        step = np.sqrt((np.diff(points, axis=0) ** 2).sum(axis=1))
        loc = cs.edge_local[row, column]
        inside = loc >= 0
        force = np.where(inside, self.contact_force[np.maximum(loc, 0)], np.nan)
        gap = cs.edge_gap[row, column]
        un = np.einsum("kc,kc->k", self.u[nodes], cs.edge_direction[row, column])
        return ContactProfile(
            part=part,
            nodes=nodes,
            chain=np.broadcast_to(chain[:, None], take.shape)[take],
            s=np.concatenate([[0.0], np.cumsum(step)]),
            points=points,
            pressure=np.where(inside, force / cs.basis_integral[np.maximum(loc, 0)], np.nan),
            contact_force=force,
            gap=gap,
            normal_displacement=un,
            normal_gap=un - gap,
        )

    def errors(self, degree: int = ERROR_DEGREE) -> dict[str, float]:
        """Energy-norm ``a(e,e)^{1/2}`` and H¹-seminorm errors against the exact solution."""
        exact = self.problem.exact
        if exact is None:
            raise ValueError(f"{self.problem.name} has no exact solution")
        u_cell = self.space.cell_values(self.u)

        def gradient(x: np.ndarray) -> np.ndarray:
            return evaluate_field(exact.gradient, x, "the exact gradient", shape=(2, 2))

        vertices, material = self.space.vertices, self.problem.material
        curved = self.space.curved
        energy = energy_error2(vertices, u_cell, gradient, material, degree=degree, curved=curved)
        h1 = h1_seminorm_error2(vertices, u_cell, gradient, degree=degree, curved=curved)
        return {"error_energy": float(np.sqrt(energy.sum())), "error_h1": float(np.sqrt(h1.sum()))}


def _walk(edge_nodes: np.ndarray, node_points: np.ndarray):
    """Order the oriented edges ``[start, end, midpoint]`` of one straight contact part into
    chains (each edge's end is the next edge's start), vectorized by pointer doubling.

    Returns
    -------
    order : (k,) int array
        The edges, chain after chain, each chain from its first edge.
    chain_end : (k,) bool array
        For the ordered edges: the last edge of its chain.
    chain : (k,) int array
        For the ordered edges: the chain number, chains ordered along the part's direction.
    """
    k = edge_nodes.shape[0]
    start, end = edge_nodes[:, 0], edge_nodes[:, 1]
    by_start = np.argsort(start, kind="stable")
    pos = np.minimum(np.searchsorted(start[by_start], end), k - 1)
    succ = np.where(start[by_start][pos] == end, by_start[pos], -1)
    pred = np.full(k, -1)
    pred[succ[succ >= 0]] = np.flatnonzero(succ >= 0)
    # pointer doubling: every edge finds its chain's first edge and its distance to it
    root = np.where(pred >= 0, pred, np.arange(k))
    rank = (pred >= 0).astype(np.int64)  # distance to ``root``
    for _ in range(int(np.ceil(np.log2(max(k, 2)))) + 1):
        rank, root = rank + rank[root], root[root]
    if np.any(pred[root] >= 0):  # a closed chain: impossible for a straight part
        raise ValueError("the contact part is a closed curve; it has no first node")
    # chains in the order of their first point along the (straight) part
    first = np.flatnonzero(pred < 0)
    direction = node_points[end[first[0]]] - node_points[start[first[0]]]
    along = node_points[start[first]] @ direction
    chain_of_root = np.empty(k, dtype=np.int64)
    chain_of_root[first[np.argsort(along, kind="stable")]] = np.arange(first.size)
    chain = chain_of_root[root]
    order = np.lexsort((rank, chain))
    return order, succ[order] < 0, chain[order]


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
        active0 = un - cs.gap >= -WARM_START_RTOL * _round_off_scale(u0, cs.gap)
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
            cs.constrained_dofs,
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
    u = to_cartesian(res.x, cs.frame_nodes, cs.frames).reshape(-1, 2)
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
