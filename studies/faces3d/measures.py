"""What is measured on Γ_C: lift-off, active shares, forces, η6 and a recovered pressure.

Weights on Γ_C (each computed here once): ``w_z = ∫_{Γ_C} φ_z`` of the P2 basis
(vertices 0, midpoints Σ |F|/3), and ``T_β w`` the integrals of the transformed basis
φ̃ = T_β φ (β = α of variant (b); β = ½ gives the P1 hats, φ_v + ½ Σ_e φ_e).
"""

from __future__ import annotations

import numpy as np

from .contact import ContactProblem, Solution, face_transform
from .elasticity import FACE_EDGES, face_areas, face_points, p2_values, tri_rule
from .manufactured import Manufactured

#: The 4 sub-triangles of the once-refined 6-node face (local nodes), 3 corners and middle.
SUB_TRIANGLES = np.array([[0, 3, 5], [1, 4, 3], [2, 5, 4], [3, 4, 5]])
#: Barycentric coordinates of the face's 6 local nodes.
NODE_BARY = np.array([[1, 0, 0], [0, 1, 0], [0, 0, 1], [0.5, 0.5, 0], [0, 0.5, 0.5], [0.5, 0, 0.5]])


def local_index(problem: ContactProblem) -> np.ndarray:
    """Map from mesh nodes to positions in ``problem.nodes`` (−1 off Γ_C), shape (n_nodes,)."""
    index = np.full(problem.mesh.n_nodes, -1)
    index[problem.nodes] = np.arange(problem.nodes.size)
    return index


def p2_weights(problem: ContactProblem) -> np.ndarray:
    """w_z = ∫_{Γ_C} φ_z ds = Σ_F |F| (0, 0, 0, ⅓, ⅓, ⅓), shape (n_C,)."""
    per_face = face_areas(problem.mesh, problem.faces)[:, None] * np.array([0, 0, 0, 1, 1, 1]) / 3
    return np.bincount(
        local_index(problem)[problem.faces].ravel(), per_face.ravel(), problem.nodes.size
    )


def recovered_pressure(problem: ContactProblem, force: np.ndarray, beta: float) -> np.ndarray:
    """p_z = (T_β Λ)_z / (T_β w)_z, exact for a constant pressure, shape (n_C,).

    β = ½: the force restricted to the P1 hats over the lumped P1 face mass (vertices only;
    NaN at midpoints). β = α: the weights of the transformed basis, p_z = Λ̃_z / ∫ φ̃_z.
    """
    T = face_transform(problem, beta)
    weight = T @ p2_weights(problem)
    with np.errstate(invalid="ignore", divide="ignore"):
        p = (T @ force) / weight
    p[weight <= 0] = np.nan
    return p


def pressure_error(
    problem: ContactProblem, p_h: np.ndarray, exact: Manufactured, beta: float
) -> float:
    """Relative discrete L² error of ``p_h`` at the interior nodes of Γ_C where it is defined.

    Σ w̃_z (p_z − p(z))² / Σ w̃_z p(z)², w̃ = T_β w, over nodes off the face's boundary.
    """
    x = problem.mesh.points[problem.nodes]
    inner = np.all((x[:, :2] > 1e-9) & (x[:, :2] < 1 - 1e-9), axis=1) & np.isfinite(p_h)
    w = (face_transform(problem, beta) @ p2_weights(problem))[inner]
    p = exact.pressure(x[inner])
    return float(np.sqrt((w * (p_h[inner] - p) ** 2).sum() / (w * p**2).sum()))


def nodal_gap(problem: ContactProblem, sol: Solution) -> np.ndarray:
    """ψ(z) − u_h(z)·n = ψ(z) + u_z(z) at the nodes of Γ_C, shape (n_C,)."""
    return problem.psi + sol.u[problem.nodes, 2]


def liftoff(problem: ContactProblem, sol: Solution, exact: Manufactured) -> tuple[float, float]:
    """Largest nodal gap at vertices and at midpoints of Γ_C where the exact pressure is > 0."""
    gap = nodal_gap(problem, sol)
    touching = exact.pressure(problem.mesh.points[problem.nodes]) > 0
    vertex = np.arange(problem.nodes.size) < problem.n_cv
    return float(gap[touching & vertex].max()), float(gap[touching & ~vertex].max())


def shares(problem: ContactProblem, sol: Solution) -> dict:
    """Active shares of vertices and midpoints; the vertices' share of the total force."""
    vertex = np.arange(problem.nodes.size) < problem.n_cv
    return {
        "active_v": float(sol.active[vertex].mean()),
        "active_e": float(sol.active[~vertex].mean()),
        "force_v": float(sol.force[vertex].sum() / sol.force.sum()),
        "mult_v": float(sol.multiplier[vertex].sum() / sol.multiplier.sum()),
    }


def eta6(
    problem: ContactProblem,
    sol: Solution,
    exact: Manufactured,
    interpolated: bool = False,
    m: int = 10,
) -> float:
    """η6 = (Σ_p s_p d_p)^{1/2}, the paper's (5.1) complementarity term carried to faces.

    d_p = ∫_{γ̃_p} (ψ − u_h·n)⁺ φ_p ds with φ_p the P1 hat of the once-refined face and γ̃_p
    its support (the sub-triangles at p); s_p = (λ_p / m_p)⁺, m_p = ∫ φ_p, λ_p the variant's
    multiplier. With ``interpolated`` the obstacle is its P2 interpolant ψ_h = I_h ψ (the
    gap of the discrete constraints) instead of ψ. The positive part is integrated by an
    m²-point rule per sub-triangle (a measurement, not exact where the sign changes).

    Returns
    -------
    float
    """
    mesh, faces = problem.mesh, problem.faces
    bary, w = tri_rule(m)
    index = local_index(problem)[faces]  # (n_faces, 6)
    area = face_areas(mesh, faces) / 4  # each sub-triangle
    uz = sol.u[faces, 2]  # (n_faces, 6)
    psi_h = np.zeros(mesh.n_nodes)
    psi_h[problem.nodes] = problem.psi
    d = np.zeros(problem.nodes.size)
    for sub in SUB_TRIANGLES:
        fb = bary @ NODE_BARY[sub]  # (q, 3) face barycentrics
        phi = p2_values(fb, FACE_EDGES).T  # (6, q)
        obstacle = psi_h[faces] @ phi if interpolated else exact.psi(face_points(mesh, faces, fb))
        gap = obstacle + uz @ phi
        hat = np.einsum("f,q,fq,qj->fj", 2 * area, w, np.maximum(gap, 0.0), bary)
        d += np.bincount(index[:, sub].ravel(), hat.ravel(), d.size)
    mass = np.bincount(index[:, SUB_TRIANGLES].ravel(), np.repeat(area / 3, 12), d.size)
    s = np.maximum(sol.multiplier / mass, 0.0)
    return float(np.sqrt((s * d).sum()))
