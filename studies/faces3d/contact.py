"""The two discrete contact conditions on the P2 face z = 0 and their exact active-set solve.

(a) nodal: u_h(z)·n ≤ ψ(z) at every P2 node z of Γ_C (the paper's (3.6) carried to faces).
(b) transformed: on Γ_C the P2 basis is replaced by φ̃ = T φ,

    φ̃_v = φ_v + α Σ_{edges e ∋ v} φ_e,    φ̃_e = (1 − 2α) φ_e,

and the constraints are ũ_z·n ≤ ψ̃_z on the coefficients of u_h and ψ_h = I_h ψ in that basis
(ũ = T^{-T} u, ψ̃ = T^{-T} ψ on the normal components of Γ_C). The change of variables
u = P ũ (P the identity but for the block Tᵀ on the normal DOFs of Γ_C) turns both variants
into the same bound-constrained quadratic programme, min ½ xᵀ K̃ x − F̃ᵀ x with x_C ≥ ℓ, that
one primal–dual active set loop solves (docs/method.md, "Three dimensions").
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.optimize as so
import scipy.sparse as sp
import scipy.sparse.linalg as sla

from .elasticity import body_load, face_load, stiffness
from .manufactured import Manufactured
from .mesh import CubeMesh

try:  # the direct solver: PARDISO where installed, SuperLU otherwise
    from pypardiso import spsolve as _spsolve
except ImportError:  # pragma: no cover
    _spsolve = sla.spsolve


@dataclass(frozen=True)
class ContactProblem:
    """The assembled problem: K u = F + contact force, u = u_D on z = 1.

    Attributes
    ----------
    K : csr_matrix, shape (3 n_nodes, 3 n_nodes)
    F : ndarray, shape (3 n_nodes,)
        Body force, Neumann data on the side faces, tangential traction on Γ_C.
    fixed : ndarray of int, shape (n_fixed,)
        Dirichlet DOFs (all components at z = 1), values ``u_fixed``.
    faces : ndarray, shape (n_faces, 6)
        The 6-node faces of Γ_C.
    nodes : ndarray, shape (n_C,)
        The P2 nodes of Γ_C, vertices first (``n_cv`` of them), then midpoints.
    psi : ndarray, shape (n_C,)
        ψ at ``nodes``.
    """

    mesh: CubeMesh
    K: sp.csr_matrix
    F: np.ndarray
    fixed: np.ndarray
    u_fixed: np.ndarray
    faces: np.ndarray
    nodes: np.ndarray
    n_cv: int
    psi: np.ndarray


def assemble(mesh: CubeMesh, exact: Manufactured) -> ContactProblem:
    """Stiffness, loads and Dirichlet data of ``exact`` on ``mesh`` (contact face z = 0)."""
    K = stiffness(mesh, exact.lam, exact.mu)
    F = body_load(mesh, exact.f)
    for axis, value in [(0, 0.0), (0, 1.0), (1, 0.0), (1, 1.0)]:
        normal = np.zeros(3)
        normal[axis] = 1.0 if value else -1.0
        F += face_load(
            mesh, mesh.boundary_faces(axis, value), lambda p, nrm=normal: exact.stress(p) @ nrm
        )
    faces = mesh.boundary_faces(2, 0.0)
    tangential = np.array([1.0, 1.0, 0.0])
    F += face_load(mesh, faces, lambda p: -exact.stress(p)[..., :, 2] * tangential)
    top = np.flatnonzero(np.isclose(mesh.points[:, 2], 1.0))
    fixed = (3 * top[:, None] + np.arange(3)).ravel()
    nodes = np.unique(faces)
    return ContactProblem(
        mesh,
        K,
        F,
        fixed,
        exact.u(mesh.points[top]).ravel(),
        faces,
        nodes,
        int((nodes < mesh.n_vertices).sum()),
        exact.psi(mesh.points[nodes]),
    )


def face_transform(problem: ContactProblem, alpha: float) -> sp.csr_matrix:
    """T with φ̃ = T φ on the nodes of Γ_C, shape (n_C, n_C); α = 0 is the identity.

    Rows are the new functions, columns the P2 ones: T_vv = 1, T_ve = α for each edge e
    of Γ_C at vertex v, T_ee = 1 − 2α. Every column sums to 1 (partition of unity kept).
    """
    mesh, nodes = problem.mesh, problem.nodes
    index = np.full(mesh.n_nodes, -1)
    index[nodes] = np.arange(nodes.size)
    mids = nodes[problem.n_cv :]
    ends = mesh.edges[mids - mesh.n_vertices]  # (n_ce, 2) vertices of each Γ_C edge
    e = index[mids]
    rows = np.concatenate([np.arange(problem.n_cv), index[ends[:, 0]], index[ends[:, 1]], e])
    cols = np.concatenate([np.arange(problem.n_cv), e, e, e])
    vals = np.concatenate(
        [np.ones(problem.n_cv), np.full(2 * e.size, alpha), np.full(e.size, 1 - 2 * alpha)]
    )
    return sp.csr_matrix((vals, (rows, cols)), shape=(nodes.size,) * 2)


@dataclass(frozen=True)
class Solution:
    """The discrete solution of one variant.

    Attributes
    ----------
    u : ndarray, shape (n_nodes, 3)
        Nodal displacements.
    force : ndarray, shape (n_C,)
        Λ_z = (K u − F) at the normal DOFs of Γ_C: the discrete contact force (3.17) on the
        P2 basis, pushing the body in +z.
    multiplier : ndarray, shape (n_C,)
        The multiplier of the variant's constraints, T Λ (Λ̃_z = force on φ̃_z).
    active : ndarray of bool, shape (n_C,)
    gap : ndarray, shape (n_C,)
        ψ̃ − ũ·n ≥ 0, the constraint's slack.
    iterations : int
    kkt : dict of float
        Scaled residuals: stationarity, primal and dual feasibility, complementarity.
    """

    u: np.ndarray
    force: np.ndarray
    multiplier: np.ndarray
    active: np.ndarray
    gap: np.ndarray
    iterations: int
    kkt: dict


def solve_pdas(problem: ContactProblem, alpha: float = 0.0, max_iter: int = 50) -> Solution:
    """Solve variant (a) (α = 0) or (b) (α > 0) by a primal–dual active set loop.

    In the variables x = ũ the problem is min ½ xᵀ K̃ x − F̃ᵀ x, x_C ≥ ℓ = −ψ̃ (u·n = −u_z);
    the multiplier is λ = (K̃ x − F̃)_C. The active set of the next step is
    A = {i ∈ C : λ_i + c (ℓ_i − x_i) > −τ}, each step one direct sparse solve with x_A = ℓ_A
    (Hüeber–Wohlmuth); the loop stops when A repeats exactly. The tie level
    τ = 10⁻¹² c max|ℓ| keeps a node with λ = 0 = gap (a vertex of (a) on the patch test)
    from flipping on round-off; it changes no non-degenerate active set.
    """
    mesh, T = problem.mesh, face_transform(problem, alpha)
    n = 3 * mesh.n_nodes
    C = 3 * problem.nodes + 2
    P = sp.identity(n, format="lil")
    P[C[:, None], C[None, :]] = T.T
    P = P.tocsr()
    K = (P.T @ problem.K @ P).tocsr()
    F = P.T @ problem.F
    lower = -sla.spsolve(T.T.tocsc(), problem.psi)
    c = float(K.diagonal()[C].mean())
    tie = 1e-12 * c * np.abs(lower).max()  # a round-off tie (λ = 0 = gap) counts as active
    x = np.zeros(n)
    x[problem.fixed] = problem.u_fixed
    active = np.ones(C.size, bool)
    for it in range(1, max_iter + 1):  # noqa: B007 (the count is reported)
        x[C[active]] = lower[active]
        held = np.zeros(n, bool)
        held[problem.fixed] = True
        held[C[active]] = True
        free = np.flatnonzero(~held)
        rhs = F[free] - K[free][:, held] @ x[held]
        x[free] = _spsolve(K[free][:, free].tocsr(), rhs)
        lam = (K @ x - F)[C]
        new = lam + c * (lower - x[C]) > -tie
        if np.array_equal(new, active):
            break
        active = new
    else:
        raise RuntimeError(f"PDAS: no repeated active set in {max_iter} steps")
    lam[~active] = 0.0
    u = P @ x
    r = K @ x - F
    r[problem.fixed] = 0.0
    r[C] -= lam
    gap = x[C] - lower
    scale_f = max(np.abs(F).max(), abs(K).max() * np.abs(x).max())
    kkt = {
        "stationarity": np.abs(r).max() / scale_f,
        "primal": max(-gap.min(), 0.0) / np.abs(lower).max(),
        "dual": max(-lam.min(), 0.0) / max(np.abs(lam).max(), 1e-300),
        "complementarity": np.abs(lam * gap).max()
        / max(np.abs(lam).max() * np.abs(lower).max(), 1e-300),
    }
    force = (problem.K @ u - problem.F)[C]
    return Solution(u.reshape(-1, 3), force, lam, active, gap, it, kkt)


def solve_dual_nnls(problem: ContactProblem, alpha: float = 0.0) -> np.ndarray:
    """An independent exact solve for small meshes: Lawson–Hanson NNLS on the dual problem.

    Constraints B u ≤ b in the original variables (B = −T^{-T} E_C, b = T^{-T} ψ, with T^{-T}
    a dense inverse), Dirichlet DOFs eliminated, S = B K⁻¹ Bᵀ = L Lᵀ (dense Cholesky):
    min_{λ ≥ 0} ½ λᵀ S λ − λᵀ (B K⁻¹ F − b) = ½ ‖Lᵀ λ − L⁻¹ (B K⁻¹ F − b)‖² + const.

    Returns
    -------
    ndarray, shape (n_nodes, 3)
        The nodal displacements u = K⁻¹ (F − Bᵀ λ).
    """
    mesh = problem.mesh
    n = 3 * mesh.n_nodes
    K = problem.K.toarray()
    held = np.zeros(n, bool)
    held[problem.fixed] = True
    free = np.flatnonzero(~held)
    u = np.zeros(n)
    u[problem.fixed] = problem.u_fixed
    Kff = K[np.ix_(free, free)]
    Ff = problem.F[free] - K[np.ix_(free, problem.fixed)] @ problem.u_fixed
    Tinv_t = np.linalg.inv(face_transform(problem, alpha).toarray().T)
    position = np.searchsorted(free, 3 * problem.nodes + 2)
    B = np.zeros((problem.nodes.size, free.size))
    B[:, position] = -Tinv_t
    b = Tinv_t @ problem.psi
    KiBt = np.linalg.solve(Kff, B.T)
    L = np.linalg.cholesky(B @ KiBt)
    rhs = np.linalg.solve(L, B @ np.linalg.solve(Kff, Ff) - b)
    lam, _ = so.nnls(L.T, rhs, maxiter=50 * B.shape[0])
    u[free] = np.linalg.solve(Kff, Ff - B.T @ lam)
    return u.reshape(-1, 3)
