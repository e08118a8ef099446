"""An independent solve of a 3D contact problem on the package's mesh (issue 38, "each built-in
problem's solution equals an independent computation on the same mesh to round-off").

It shares no code with the package's solver: no node frames, no change of variables, no
active-set iteration, no sparse factorization. From the package it reads only

- the Cartesian stiffness matrix K and load F of the problem with its contact parts made
  traction-free (``assemble`` of a problem without contact: ``K u = F`` in Cartesian DOFs
  ``3 z + c``) and its held DOFs and values;
- the raw rows of the face contact set: each row's node, direction n_r and gap ψ_r, and the
  triples (midpoint, start, end) of the edges the transformed face basis couples, with α.

It builds the constraint matrix itself, condition (a) ``B_r u = n_r · u(z_r) ≤ ψ_r`` and for
(b) the rows of the coefficients of the transformed basis, ``M B u ≤ M ψ`` with
``(M v)_e = (v_e − α (v_a + v_b)) / (1 − 2α)`` on each edge e = (a, b) and the identity
elsewhere, and solves the QP ``min ½ uᵀ K u − Fᵀ u, M B u ≤ M ψ, u_D fixed`` through its
dual: with the free DOFs f, ``S = B_f K_ff⁻¹ B_fᵀ`` (dense LAPACK Cholesky of K_ff) and
``c = g′ − B_f K_ff⁻¹ b``, the multipliers solve the LCP ``λ ≥ 0, w = c + S λ ≥ 0,
λ·w = 0``, i.e. ``min_{λ ≥ 0} ‖Lᵀ λ + L⁻¹ c‖`` with ``S = L Lᵀ`` (Lawson–Hanson NNLS,
``scipy.optimize.nnls``); the multipliers of the rows NNLS leaves positive are then solved
once more from ``S_AA λ_A = −c_A`` (dense Cholesky) for round-off accuracy.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import scipy.linalg as la
import scipy.sparse as sp
from scipy.optimize import nnls

from signorini.contact.system import assemble
from signorini.problem import Contact, Neumann

#: the largest number of free unknowns the dense solve takes (K_ff dense: 8 n² bytes)
MAX_DENSE = 4000


@dataclass(frozen=True)
class IndependentSolution:
    """The QP's solution: ``u (n_nodes, 3)``, the multipliers ``lam (k,)`` of the rows
    ``M B u ≤ M ψ`` (Λ̃ for (b), the P2 force for (a)), the P2 nodal force
    ``force = Mᵀ lam (k,)`` (3.17), the slack ``M ψ − M B u (k,)``, and the KKT residuals
    (relative) of the solution."""

    u: np.ndarray
    lam: np.ndarray
    force: np.ndarray
    slack: np.ndarray
    kkt: dict


@dataclass(frozen=True)
class CartesianQP:
    """The problem's QP in Cartesian DOFs: K, F, the constraint rows ``C = M B (k, n)``, their
    bounds ``g = M ψ``, ``M (k, k)``, and the held DOFs with their values."""

    K: sp.csr_matrix
    F: np.ndarray
    C: sp.csr_matrix
    g: np.ndarray
    M: sp.csr_matrix
    held: np.ndarray
    held_values: np.ndarray


def cartesian_qp(result) -> CartesianQP:
    """The QP of a 3D :class:`~signorini.ContactResult`'s problem on its mesh, from the
    Cartesian assembly of the problem without contact and the raw rows of ``result.contact``."""
    problem, mesh, cs = result.problem, result.mesh, result.contact
    free = {
        name: Neumann((0.0, 0.0, 0.0)) if isinstance(cond, Contact) else cond
        for name, cond in problem.conditions.items()
    }
    plain = assemble(replace(problem, conditions=free), mesh)
    assert plain.contact.size == 0 and plain.frames.shape[0] == 0  # Cartesian unknowns
    n, k = plain.K.shape[0], cs.node.size
    rows = np.repeat(np.arange(k), 3)
    cols = (3 * cs.node[:, None] + np.arange(3)).ravel()
    B = sp.csr_matrix((cs.direction.ravel(), (rows, cols)), shape=(k, n))
    e, a = cs.edges.mid, cs.edges.alpha
    diagonal = np.ones(k)
    diagonal[e] = 1.0 / (1.0 - 2.0 * a)
    M = sp.csr_matrix(
        (
            np.concatenate([diagonal, np.full(2 * e.size, -a / (1.0 - 2.0 * a))]),
            (
                np.concatenate([np.arange(k), e, e]),
                np.concatenate([np.arange(k), cs.edges.start, cs.edges.end]),
            ),
        ),
        shape=(k, k),
    )
    return CartesianQP(
        plain.K.tocsr(), plain.F, (M @ B).tocsr(), M @ cs.psi, M, plain.dirichlet,
        plain.dirichlet_values,
    )  # fmt: skip


def kkt_residuals(qp: CartesianQP, u: np.ndarray, lam: np.ndarray) -> dict:
    """Relative KKT residuals of ``(u (n,), lam (k,))``: stationarity at the free DOFs over
    the largest force, feasibility and complementarity over the displacement scale, the
    sign of the multipliers over the largest one, the held values' misfit."""
    free = np.setdiff1d(np.arange(qp.K.shape[0]), qp.held)
    r = (qp.K @ u - qp.F + qp.C.T @ lam)[free]
    force = max(
        np.abs(qp.F[free]).max(), np.abs((qp.K @ u)[free]).max(), np.abs(qp.C.T @ lam).max()
    )
    slack = qp.g - qp.C @ u
    disp = max(np.abs(u).max(), np.abs(qp.g).max())
    lam_scale = max(np.abs(lam).max(), 1e-300)
    return {
        "stationarity": float(np.abs(r).max() / force),
        "primal": float(np.maximum(-slack, 0.0).max(initial=0.0) / disp),
        "dual": float(np.maximum(-lam, 0.0).max(initial=0.0) / lam_scale),
        "complementarity": float(np.abs(lam * slack).max(initial=0.0) / (lam_scale * disp)),
        "dirichlet": float(np.abs(u[qp.held] - qp.held_values).max(initial=0.0) / disp),
    }


def solve_independent(result) -> tuple[CartesianQP, IndependentSolution]:
    """Solve the QP of ``result``'s problem and mesh by the dual NNLS (module docstring)."""
    qp = cartesian_qp(result)
    n = qp.K.shape[0]
    free = np.setdiff1d(np.arange(n), qp.held)
    if free.size > MAX_DENSE:
        raise ValueError(f"{free.size} free unknowns: too many for the dense solve")
    u_held = np.zeros(n)
    u_held[qp.held] = qp.held_values
    Kff = qp.K[free][:, free].toarray()
    b = qp.F[free] - qp.K[free] @ u_held
    Cf = qp.C[:, free].toarray()
    g = qp.g - qp.C @ u_held
    factor = la.cho_factor(Kff, lower=True)
    KinvCt = la.cho_solve(factor, Cf.T)
    S = Cf @ KinvCt
    S = 0.5 * (S + S.T)
    c = g - Cf @ la.cho_solve(factor, b)
    L = la.cholesky(S, lower=True)
    lam, _ = nnls(L.T, -la.solve_triangular(L, c, lower=True), maxiter=50 * S.shape[0])
    active = lam > 0
    lam = np.zeros_like(lam)
    if active.any():
        lam[active] = la.solve(S[np.ix_(active, active)], -c[active], assume_a="pos")
    u = u_held.copy()
    u[free] = la.cho_solve(factor, b - Cf.T @ lam)
    solution = IndependentSolution(
        u=u.reshape(-1, 3),
        lam=lam,
        force=qp.M.T @ lam,
        slack=qp.g - qp.C @ u,
        kkt=kkt_residuals(qp, u, lam),
    )
    return qp, solution
