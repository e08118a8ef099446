"""The linear system of one iteration of the frictional active set method.

Given the node states (docs/method.md, *Friction: the algebraic problem and its solver*), the
iterate solves ``K x = F`` on the free rows with

- ``x_n = g`` on nodes in contact and ``x_t = x_ref`` on sticking nodes, imposed by
  eliminating the DOF (Dirichlet-like, rows and columns zeroed in place, diagonal kept);
- ``Λ_t = F_t − (K x)_t = σ s`` on slipping nodes (``σ`` the slip direction).

Tresca's ``s`` is data, so that row is ``(K x)_t = F_t − σ s``: a change of the load, and the
system stays symmetric (:class:`TrescaSystem`, on :class:`~.active_system.ActiveSetSystem`
and an SPD solver). Coulomb's ``s = F Λ_n`` is the residual of another row, so the row
becomes ``(K_t − σ F K_n) x = F_t − σ F F_n``: the matrix is not symmetric
(:class:`CoulombSystem`, on a sparse LU). Both keep one sparsity pattern per call, so the
solver analyses it once.
"""

from __future__ import annotations

import time

import numpy as np
import scipy.sparse as sp

from .active_system import ActiveSetSystem, check_residual
from .friction_kkt import FrictionProblem, slip_bound
from .solvers import SPDSolver
from .sparse import csr_row_indices, diagonal_positions

__all__ = ["CoulombSystem", "TrescaSystem"]


class TrescaSystem:
    """The symmetric systems of the Tresca law: held DOFs eliminated, slip forces in the load.

    Parameters
    ----------
    problem : FrictionProblem
        With ``law == "tresca"``.
    solver : SPDSolver
        A symmetric positive definite solver.
    max_update : int
        Largest change of the held DOFs solved by a low-rank update
        (:class:`~.active_system.ActiveSetSystem`).
    """

    symmetric = True

    def __init__(self, problem: FrictionProblem, solver: SPDSolver, max_update: int = 4) -> None:
        self.problem = problem
        self.solver = solver
        self.inner = ActiveSetSystem(problem.qp, solver, max_update=max_update)

    @property
    def time_assembly(self) -> float:
        """Seconds spent forming right-hand sides."""
        return self.inner.time_elimination

    def solve(self, active: np.ndarray, stick: np.ndarray, direction: np.ndarray) -> np.ndarray:
        """The iterate of the states ``active``, ``stick`` (m,) bool and ``direction`` (m,)
        (±1 on slipping nodes): ``x (n,)``."""
        p = self.problem
        load = p.qp.F.copy()
        load[p.tangent] -= direction * slip_bound(p, np.zeros(p.m), active)
        x, _ = self.inner.solve(np.concatenate([active, stick]), load)
        return x


class CoulombSystem:
    """The non-symmetric systems of the Coulomb law on a fixed pattern.

    The pattern is that of ``K`` with every tangential row widened by the columns of its
    node's normal row (in a node-blocked ``K`` both rows have the same columns, so this adds
    nothing). The positions of ``K``'s entries and of the copies of the normal rows in it are
    found once; each solve writes the values, zeroes the held rows and columns (diagonal kept)
    and refactorizes.

    Parameters
    ----------
    problem : FrictionProblem
        With ``law == "coulomb"``.
    solver : SPDSolver
        A general sparse LU (a factory's solver for ``symmetric=False``).
    """

    symmetric = False

    def __init__(self, problem: FrictionProblem, solver: SPDSolver) -> None:
        self.problem = problem
        self.solver = solver
        qp = problem.qp
        K = qp.K
        n = K.shape[0]
        rows_K = csr_row_indices(K)
        # the entries of the normal rows, and where their copies go in the tangential rows
        row_node = np.full(n, -1)
        row_node[problem.normal] = np.arange(problem.m)
        self.copy_src = np.flatnonzero(row_node[rows_K] >= 0)
        self.copy_node = row_node[rows_K[self.copy_src]]
        copy_rows = problem.tangent[self.copy_node]
        copy_cols = K.indices[self.copy_src]
        rows = np.concatenate([rows_K, copy_rows])
        cols = np.concatenate([K.indices, copy_cols])
        pattern = sp.csr_matrix((np.ones(rows.size), (rows, cols)), shape=(n, n))
        pattern.sum_duplicates()
        pattern.sort_indices()
        self.rows = csr_row_indices(pattern)

        def key(r: np.ndarray, c: np.ndarray) -> np.ndarray:  # 64-bit: n² overflows int32
            return r.astype(np.int64) * n + c

        keys = key(self.rows, pattern.indices)
        self.pos_K = np.searchsorted(keys, key(rows_K, K.indices))
        self.pos_copy = np.searchsorted(keys, key(copy_rows, copy_cols))
        self.indptr, self.indices = pattern.indptr, pattern.indices
        self.diagonal = diagonal_positions(pattern, self.rows)
        self.is_diagonal = self.indices == self.rows
        self.fixed = np.zeros(n, dtype=bool)
        self.fixed[qp.dirichlet] = True
        self.values = np.zeros(n)
        self.values[qp.dirichlet] = qp.dirichlet_values
        self.time_assembly = 0.0

    def solve(self, active: np.ndarray, stick: np.ndarray, direction: np.ndarray) -> np.ndarray:
        """The iterate of the states ``active``, ``stick`` (m,) bool and ``direction`` (m,)
        (±1 on slipping nodes, 0 elsewhere): ``x (n,)``."""
        t0 = time.perf_counter()
        p, qp = self.problem, self.problem.qp
        n = qp.n
        factor = np.where(active & ~stick, direction * p.weight, 0.0)  # σ F on slip rows
        data = np.zeros(self.indices.size)
        data[self.pos_K] = qp.K.data
        data[self.pos_copy] -= factor[self.copy_node] * qp.K.data[self.copy_src]
        A = sp.csr_matrix((data, self.indices, self.indptr), shape=(n, n))
        rhs = qp.F.copy()
        rhs[p.tangent] -= factor * qp.F[p.normal]
        fixed, values = self.fixed, self.values
        fixed[p.normal] = active
        values[p.normal] = np.where(active, p.gap, 0.0)
        fixed[p.tangent] = stick
        values[p.tangent] = np.where(stick, p.reference, 0.0)
        b = rhs - A @ np.where(fixed, values, 0.0)
        b[fixed] = data[self.diagonal[fixed]] * values[fixed]
        keep = ~(fixed[self.rows] | fixed[self.indices]) | self.is_diagonal
        A.data *= keep
        self.time_assembly += time.perf_counter() - t0
        self.solver.factorize(A)  # the pattern is compared, and analysed only the first time
        x = self.solver.solve(b)
        check_residual(A @ x - b, b, self.solver.backend)
        x[fixed] = values[fixed]
        return x
