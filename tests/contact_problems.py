"""Problems with known discrete solutions, and an independent assembly, for the solver tests.

- :class:`Quadratic`: a quadratic displacement ``u_i = c_i + G_ij x_j + H_ijk x_j x_k / 2`` with
  its gradient, Hessian, stress and ``div σ`` in closed form (Hooke's law written out here, not
  taken from the package), and its rotated copy.
- :func:`patch_problem`: a :class:`~signorini.problem.ContactProblem` whose exact solution is a
  given quadratic (the discrete solution must reproduce it at every node).
- :func:`contact_patch_field`: a random quadratic with zero tangential and compressive normal
  stress on the bottom edge ``y = 0`` (normal ``(0, −1)``), so that it solves a Signorini
  problem with the gap ``ψ = u·n`` and every contact node active.
- :func:`independent_system`: Cartesian ``K``, ``F`` and Dirichlet data assembled from the mesh
  with :mod:`signorini.fem.stiffness` and :mod:`signorini.fem.loads` only (no rotated frames,
  no :mod:`signorini.contact`).
- :func:`graded_half_disc`: a half-disc on its arc, its mesh graded towards the bottom point
  (the partial-slip problem).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from signorini.fem.loads import assemble_body_force, assemble_facet_load
from signorini.fem.material import Material
from signorini.fem.stiffness import assemble_stiffness
from signorini.mesh.builders import rectangle
from signorini.mesh.curves import Circle
from signorini.mesh.mesh import Mesh
from signorini.mesh.refine import refine_nvb
from signorini.problem import Contact, ContactProblem, Dirichlet, Neumann
from signorini.problem.obstacles import HalfPlane


def rotation(angle_deg: float) -> np.ndarray:
    """The 2 x 2 counter-clockwise rotation by ``angle_deg`` degrees."""
    a = np.deg2rad(angle_deg)
    return np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])


@dataclass(frozen=True)
class Quadratic:
    """``u_i(x) = c_i + G_ij x_j + 1/2 H_ijk x_j x_k`` (``H`` symmetric in ``j, k``)."""

    c: np.ndarray  # (2,)
    G: np.ndarray  # (2, 2)
    H: np.ndarray  # (2, 2, 2)

    def value(self, x: np.ndarray) -> np.ndarray:
        x = np.asarray(x, dtype=float)
        return (
            self.c
            + np.einsum("ij,...j->...i", self.G, x)
            + 0.5 * np.einsum("ijk,...j,...k->...i", self.H, x, x)
        )

    def gradient(self, x: np.ndarray) -> np.ndarray:
        x = np.asarray(x, dtype=float)
        return self.G + np.einsum("ijk,...k->...ij", self.H, x)

    def hessian(self) -> np.ndarray:
        """``∂²u_i / ∂x_j ∂x_k = H_ijk`` (constant)."""
        return self.H

    def stress(self, x: np.ndarray, material: Material) -> np.ndarray:
        """``σ(u) = λ tr ε I + 2 μ ε`` at ``x (..., 2)``, shape ``(..., 2, 2)``."""
        g = self.gradient(x)
        eps = 0.5 * (g + np.swapaxes(g, -1, -2))
        tr = eps[..., 0, 0] + eps[..., 1, 1]
        return material.lam * tr[..., None, None] * np.eye(2) + 2 * material.mu * eps

    def div_stress(self, material: Material) -> np.ndarray:
        """``(div σ(u))_i = (λ + μ) ∂_i div u + μ Δu_i`` (a constant vector)."""
        grad_div = np.einsum("kki->i", self.H)
        laplace = np.einsum("ikk->i", self.H)
        return (material.lam + material.mu) * grad_div + material.mu * laplace

    def rotated(self, R: np.ndarray) -> Quadratic:
        """The field ``x ↦ R u(Rᵀ x)``."""
        return Quadratic(
            R @ self.c, R @ self.G @ R.T, np.einsum("ia,abc,jb,kc->ijk", R, self.H, R, R)
        )


def random_quadratic(rng: np.random.Generator, scale: float = 1.0) -> Quadratic:
    H = rng.standard_normal((2, 2, 2))
    H = H + H.transpose(0, 2, 1)
    return Quadratic(scale * rng.standard_normal(2), scale * rng.standard_normal((2, 2)), scale * H)


def contact_patch_field(
    rng: np.random.Generator, material: Material, uniform: bool = False
) -> Quadratic:
    """A random quadratic with ``σ_12 = 0`` and ``σ_22 ≤ −1`` on the line ``y = 0``.

    On ``y = 0``: ``∂_j u_i = G_ij + H_ij0 x``, so ``σ_12 = μ (G_01 + G_10 + (H_010 + H_100) x)``
    and ``σ_22 = λ G_00 + (λ + 2μ) G_11 + (λ H_000 + (λ + 2μ) H_110) x``. With ``uniform`` the
    normal stress (and so the contact pressure ``p = −σ_22``) is constant along the line.
    """
    lam, mu = material.lam, material.mu
    q = random_quadratic(rng)
    c, G, H = q.c.copy(), q.G.copy(), q.H.copy()
    G[1, 0] = -G[0, 1]
    H[1, 0, 0] = -H[0, 1, 0]
    H[0, 0, 1] = H[0, 1, 0]  # keep H symmetric in its last two indices
    slope = 0.0 if uniform else rng.uniform(-1.0, 1.0)
    H[1, 1, 0] = H[1, 0, 1] = (slope - lam * H[0, 0, 0]) / (lam + 2 * mu)
    intercept = -1.0 - abs(slope) - rng.uniform(0.0, 1.0)
    G[1, 1] = (intercept - lam * G[0, 0]) / (lam + 2 * mu)
    return Quadratic(c, G, H)


def patch_problem(
    mesh: Mesh,
    material: Material,
    u: Quadratic,
    kinds: dict[str, str],
    normal: np.ndarray | None = None,
) -> ContactProblem:
    """The problem solved by the quadratic ``u``: ``f = −div σ(u)``, ``g = σ(u) n`` on the parts
    of kind ``"N"``, ``u_D = u`` on kind ``"D"``, and contact with ``ψ = u·n`` on kind ``"C"``.
    """
    f = -u.div_stress(material)

    def traction(x, normal):
        sig = u.stress(x, material)
        return np.einsum("...ij,...j->...i", sig, normal)

    conditions = {}
    for name, kind in kinds.items():
        if kind == "D":
            conditions[name] = Dirichlet(u.value)
        elif kind == "N":
            conditions[name] = Neumann(traction)
        else:
            n = np.asarray(normal, dtype=float)
            conditions[name] = Contact(gap=lambda x, n=n: u.value(x) @ n, normal=tuple(n))
    return ContactProblem(
        mesh=mesh,
        material=material,
        conditions=conditions,
        body_force=lambda x: np.broadcast_to(f, x.shape),
        name="patch",
    )


@dataclass
class System:
    """Cartesian algebraic problem: ``K (n_dofs, n_dofs)``, ``F (n_dofs,)``, Dirichlet DOFs and
    values, and the constrained nodes with their normals and gaps."""

    K: object
    F: np.ndarray
    dirichlet: np.ndarray
    dirichlet_values: np.ndarray
    nodes: np.ndarray
    normal: np.ndarray
    gap: np.ndarray
    node_points: np.ndarray


def independent_system(problem: ContactProblem, mesh: Mesh) -> System:
    """Assemble the discrete problem (3.2) in Cartesian DOFs from the mesh arrays alone."""
    n_points = mesh.n_points
    node_points = np.vstack([mesh.points, 0.5 * mesh.points[mesh.edges].sum(axis=1)])
    n_dofs = 2 * len(node_points)
    cell_nodes = np.hstack([mesh.cells, n_points + mesh.cell2edge])
    cell_dofs = (2 * cell_nodes[:, :, None] + np.arange(2)).reshape(-1, 12)
    vertices = mesh.points[mesh.cells]
    K = assemble_stiffness(vertices, cell_dofs, n_dofs, problem.material)
    F = np.zeros(n_dofs)
    if problem.body_force is not None:
        F += assemble_body_force(vertices, cell_dofs, n_dofs, problem.body_force, degree=8)

    def part_nodes(name):
        edges = mesh.part_facets(name)
        ab = mesh.oriented_boundary(edges)
        return edges, np.column_stack([ab, n_points + edges])

    for name in problem.neumann_parts:
        _, nodes = part_nodes(name)
        g = problem.conditions[name].field()
        dofs = (2 * nodes[:, :, None] + np.arange(2)).reshape(-1, 6)
        F += assemble_facet_load(mesh.points[nodes[:, :2]], dofs, n_dofs, g, degree=8)
    d_nodes = np.unique(np.concatenate([part_nodes(p)[1].ravel() for p in problem.dirichlet_parts]))
    d_vals = np.zeros((d_nodes.size, 2))
    for name in problem.dirichlet_parts:
        mine = np.isin(d_nodes, part_nodes(name)[1])
        d_vals[mine] = np.broadcast_to(
            problem.conditions[name].field()(node_points[d_nodes[mine]]), (int(mine.sum()), 2)
        )
    c_nodes, c_normal, c_gap = [], [], []
    for name in problem.contact_parts:
        edges, nodes = part_nodes(name)
        d = mesh.points[nodes[:, 1]] - mesh.points[nodes[:, 0]]
        n = np.array([d[0, 1], -d[0, 0]]) / np.hypot(*d[0])
        nodes = np.setdiff1d(np.unique(nodes), d_nodes)
        cond = problem.conditions[name]
        gap = cond.gap(node_points[nodes]) if callable(cond.gap) else np.full(nodes.size, cond.gap)
        c_nodes.append(nodes)
        c_normal.append(np.broadcast_to(n, (nodes.size, 2)))
        c_gap.append(np.broadcast_to(gap, nodes.shape))
    if c_nodes:
        nodes = np.concatenate(c_nodes)
        order = np.argsort(nodes)
        nodes, normal, gap = (
            nodes[order],
            np.concatenate(c_normal)[order],
            np.concatenate(c_gap)[order],
        )
    else:
        nodes, normal, gap = np.zeros(0, int), np.zeros((0, 2)), np.zeros(0)
    dirichlet = np.column_stack([2 * d_nodes, 2 * d_nodes + 1]).ravel()
    return System(K.tocsr(), F, dirichlet, d_vals.ravel(), nodes, normal, gap, node_points)


def corner_problem(angle: float = 0.0, shapes: bool = False) -> ContactProblem:
    """The unit square (rotated by ``angle``) pushed down by its top into a rigid corner: a floor
    under the bottom and a wall right of the right side, both at gap 0, with a body force."""
    c, s = np.cos(angle), np.sin(angle)
    R = np.array([[c, -s], [s, c]])
    base = rectangle(nx=4, ny=4)

    def on(coord, value):
        return lambda x: np.abs((x @ R)[:, coord] - value) < 1e-12

    mesh = Mesh.from_arrays(
        base.points @ R.T,
        base.cells,
        {"left": on(0, 0.0), "top": on(1, 1.0), "bottom": on(1, 0.0), "right": on(0, 1.0)},
    )
    if shapes:
        floor = Contact(obstacle=HalfPlane(R @ [0.0, 0.0], R @ [0.0, 1.0]))
        wall = Contact(obstacle=HalfPlane(R @ [1.0, 0.0], R @ [-1.0, 0.0]))
    else:
        floor, wall = Contact(), Contact()
    push = R @ [0.0, -0.03]
    force = R @ [0.5, -1.0]
    return ContactProblem(
        mesh,
        Material.from_young(10.0, 0.3),
        {"left": Neumann(), "top": Dirichlet(push), "bottom": floor, "right": wall},
        body_force=lambda x: np.broadcast_to(force, x.shape),
    )


@dataclass
class FrictionSystem:
    """A rotated contact system for the friction solver: ``K``, ``F``, Dirichlet data, and per
    contact node its normal DOF ``2 z``, tangential DOF ``2 z + 1`` and gap."""

    K: object
    F: np.ndarray
    dirichlet: np.ndarray
    dirichlet_values: np.ndarray
    normal: np.ndarray
    tangent: np.ndarray
    gap: np.ndarray
    x: np.ndarray  # (m,) abscissae of the contact nodes


def pressed_block(
    nx: int, ny: int, push: float = 0.02, shift: float = 0.01, curvature: float = 0.04
) -> FrictionSystem:
    """The block ``(0, 2) × (0, 1)`` (E = 1, ν = 0.3) pushed down by ``push`` and sideways by
    ``shift`` at its top onto the curved obstacle ``ψ(x) = curvature (x − 1)²`` below its
    bottom: contact in the middle, open ends, and a tangential load that makes stick and slip
    zones. Assembled by :func:`signorini.contact.system.assemble` (frames rotated)."""
    from signorini.contact.system import assemble
    from signorini.mesh.builders import rectangle

    mesh = rectangle(0.0, 2.0, 0.0, 1.0, nx=nx, ny=ny)
    problem = ContactProblem(
        mesh=mesh,
        material=Material.from_young(1.0, 0.3),
        conditions={
            "top": Dirichlet((shift, -push)),
            "left": Neumann(),
            "right": Neumann(),
            "bottom": Contact(gap=lambda x: curvature * (x[:, 0] - 1.0) ** 2),
        },
    )
    a = assemble(problem, mesh)
    nodes = a.contact.nodes
    return FrictionSystem(
        a.K,
        a.F,
        a.dirichlet,
        a.dirichlet_values,
        2 * nodes,
        2 * nodes + 1,
        a.contact.gap,
        a.space.node_points[nodes, 0],
    )


def graded_half_disc(radius: float, h_contact: float, zone: float, grading: float = 0.25) -> Mesh:
    """The lower half of the disc of ``radius`` centred at ``(0, radius)``: flat side ``top``
    (y = radius), arc ``arc`` carrying its :class:`Circle` (isoparametric cells), touching
    y = 0 at the origin. The union-jack rectangle [−1, 1] × [−1, 0] mapped by
    p ↦ p |p|_∞ / |p|_2 (squares to circles), then bisected (new arc vertices on the circle)
    until every cell within ``zone`` of the origin has ``h_T ≤ h_contact`` and every other
    ``h_T ≤ max(h_contact, grading · (distance − zone))``."""
    base = rectangle(-1.0, 1.0, -1.0, 0.0, nx=8, ny=4)
    p = base.points
    norm2 = np.hypot(p[:, 0], p[:, 1])
    scale = np.abs(p).max(axis=1) / np.where(norm2 > 0, norm2, 1.0)
    mesh = Mesh.from_arrays(
        radius * p * scale[:, None] + [0.0, radius],
        base.cells,
        {
            "top": lambda x: x[:, 1] > radius * (1 - 1e-12),
            "arc": lambda x: x[:, 1] < radius * (1 - 1e-12),
        },
    ).with_curve("arc", Circle((0.0, radius), radius))
    while True:
        corners = mesh.points[mesh.cells]
        distance = np.hypot(corners[..., 0], corners[..., 1]).min(axis=1)
        marked = mesh.h > np.maximum(h_contact, grading * (distance - zone))
        if not marked.any():
            return mesh
        mesh = refine_nvb(mesh, marked).mesh


def problem_contact_set(problem: ContactProblem, space):
    """The contact set of ``problem`` on ``space`` as the assembly builds it: the problem's
    conditions resolved on the space once, then the constraints from them."""
    from signorini.contact.contact_set import contact_set
    from signorini.contact.discrete_conditions import discrete_conditions

    return contact_set(discrete_conditions(problem, space), space)
