"""An independent solve of the 3D Tresca problem (the disc law with a given bound) on the
package's mesh, sharing no code with :mod:`signorini.algebra.friction.disc`.

It reads from the package only the Cartesian stiffness matrix K and load F of the problem
with its contact part made traction-free, the held DOFs, and the raw rows of the face
contact set (node, direction n, gap ψ; condition (a), α = 0). It builds its own tangent
basis (t_1 = n × e / ‖n × e‖ with e the axis least aligned with n, t_2 = n × t_1) and the
rows ``B = [n; t_1; t_2]`` per node, and solves the dual of

    min ½ uᵀ K u − Fᵀ u + Σ_i s_i ‖P_i u(z_i) − ρ_i‖  subject to  n_i · u(z_i) ≤ ψ_i,

(``P_i`` the tangential components, ``ρ_i`` the reference slip), that is, with
``S = B_f K_ff⁻¹ B_fᵀ`` (dense Cholesky) and ``q = B_f K_ff⁻¹ b − [ψ; ρ]``,

    min ½ Λᵀ S Λ − qᵀ Λ  over  Λ_n ≥ 0,  ‖(Λ_t1, Λ_t2)‖ ≤ s  (a box-in-a-disc, second-order
    cone constraint per node),

by the accelerated projected gradient method (FISTA with adaptive restart, O'Donoghue–
Candès 2015; linear convergence on a strongly convex S), and ``u_f = K_ff⁻¹ (b − B_fᵀ Λ)``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as la


@dataclass(frozen=True)
class TrescaSolution:
    """``u (n,)`` Cartesian, ``force (m, 3)`` the Cartesian contact force per node
    (``Λ_n n + Λ_t1 t_1 + Λ_t2 t_2``), ``iterations`` of the gradient method."""

    u: np.ndarray
    force: np.ndarray
    iterations: int


def tangent_basis(direction: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Orthonormal ``t_1, t_2 (m, 3)`` completing the unit ``direction (m, 3)``."""
    axis = np.eye(3)[np.argmin(np.abs(direction), axis=1)]
    t1 = np.cross(direction, axis)
    t1 /= np.linalg.norm(t1, axis=1)[:, None]
    return t1, np.cross(direction, t1)


def solve_tresca(K, F, held, held_values, node, direction, psi, bound, reference, *, tol=1e-15):
    """The Tresca problem's solution (module docstring): ``reference (m, 3)`` Cartesian
    tangential reference slips, ``bound (m,)`` the nodal bounds ``s_i``."""
    n, m = K.shape[0], node.size
    t1, t2 = tangent_basis(direction)
    basis = np.stack([direction, t1, t2], axis=1)  # (m, 3 rows, 3 Cartesian)
    B = np.zeros((3 * m, n))
    for k in range(3):  # the three rows of each node
        B[3 * np.arange(m)[:, None] + k, 3 * node[:, None] + np.arange(3)] = basis[:, k]
    offset = np.stack([psi, np.sum(t1 * reference, 1), np.sum(t2 * reference, 1)], 1).ravel()
    return solve_tresca_rows(K, F, held, held_values, B, offset, bound, basis, tol=tol)


def solve_tresca_rows(K, F, held, held_values, B, offset, bound, basis, *, tol=1e-15):
    """The Tresca problem of the module docstring with general rows: ``B (3m, n)`` the
    normal and two tangential rows of each of m nodes (node-major), ``B u ≤ offset`` on the
    normal rows, ``‖(B u − offset)_t‖`` weighted by ``bound (m,)`` on the tangential ones;
    ``basis (m, 3, 3)`` the rows' unit directions ``[n; t_1; t_2]`` for the Cartesian
    force."""
    n, m = K.shape[0], bound.size
    free = np.setdiff1d(np.arange(n), held)
    Kd = K.toarray()
    b = F[free] - Kd[np.ix_(free, held)] @ held_values
    factor = la.cho_factor(Kd[np.ix_(free, free)])
    Bf = B[:, free]
    S = Bf @ la.cho_solve(factor, Bf.T)
    S = 0.5 * (S + S.T)
    q = Bf @ la.cho_solve(factor, b) - (offset - B[:, held] @ held_values)
    step = 1.0 / np.linalg.eigvalsh(S)[-1]

    def project(lam):
        lam = lam.reshape(m, 3).copy()
        lam[:, 0] = np.maximum(lam[:, 0], 0.0)
        norm = np.linalg.norm(lam[:, 1:], axis=1)
        # ‖Λ_t‖ ≤ s; a bound of 0 (a vertex under condition (a)) projects to 0
        lam[:, 1:] *= (bound / np.maximum(norm, np.maximum(bound, np.finfo(float).tiny)))[:, None]
        return lam.ravel()

    lam = project(np.zeros(3 * m))
    y, theta = lam.copy(), 1.0
    it = 0
    while it < 200_000:
        it += 1
        new = project(y - step * (S @ y - q))
        if np.abs(new - lam).max() <= tol * max(np.abs(new).max(), 1e-300):
            lam = new
            break
        if (y - new) @ (new - lam) > 0:  # adaptive restart: the momentum points uphill
            theta = 1.0
        theta_next = 0.5 * (1 + np.sqrt(1 + 4 * theta**2))
        y = new + (theta - 1) / theta_next * (new - lam)
        lam, theta = new, theta_next
    u = np.zeros(n)
    u[held] = held_values
    u[free] = la.cho_solve(factor, b - Bf.T @ lam)
    force = np.einsum("mk,mkc->mc", lam.reshape(m, 3), basis)
    return TrescaSolution(u, force, it)
