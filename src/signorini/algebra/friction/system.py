"""The linear system of one iteration of the frictional active set method.

Given the node states (docs/method.md, *Friction: the algebraic problem and its solver*), the
iterate solves ``K x = F`` on the free rows with

- ``x_n = g`` on nodes in contact and ``x_t = x_ref`` on sticking nodes, imposed by
  eliminating the DOF (Dirichlet-like, rows and columns zeroed in place, diagonal kept);
- ``Λ_t = F_t − (K x)_t = σ s`` on slipping nodes (``σ`` the slip direction), with the
  node's law's bound ``s = s0 + s' Λ_n`` (:mod:`.laws`: ``s0`` its bound at ``Λ_n = 0``,
  ``s'`` its derivative).

Where ``s' = 0`` (Tresca) ``s`` is data, so that row is ``(K x)_t = F_t − σ s0``: a change of
the load. When every law in play has ``s' = 0`` the system stays symmetric
(:class:`SymmetricSystem`, on :class:`~.active_system.ActiveSetSystem` and an SPD solver).
Where ``s' ≠ 0`` (Coulomb: ``s = F Λ_n``) ``Λ_n`` is the residual of another row, so the row
becomes ``(K_t − σ s' K_n) x = F_t − σ s' F_n − σ s0``: the matrix is not symmetric
(:class:`CoupledSystem`, on a sparse LU), and nodes of both kinds may be mixed. Both keep one
sparsity pattern per call, so the solver analyses it once.
"""

from __future__ import annotations

import time
from dataclasses import replace

import numpy as np
import scipy.sparse as sp

from ..active_system import ActiveSetSystem, refine, update_accepted
from ..backends.solvers import SPDSolver
from ..ranks import stored_values
from ..sparse import abs_matvec, concatenated_ranges, csr_row_indices, diagonal_positions
from .kkt import FrictionProblem

__all__ = ["CoupledSystem", "SymmetricSystem", "friction_system"]


def friction_system(problem: FrictionProblem, solver: SPDSolver):
    """The system of ``problem``: :class:`SymmetricSystem` when every law in play is
    symmetric (``solver`` SPD), else :class:`CoupledSystem` (``solver`` an LU)."""
    if problem.symmetric:
        return SymmetricSystem(problem, solver)
    return CoupledSystem(problem, solver)


class SymmetricSystem:
    """The symmetric systems of laws with ``s' = 0`` (Tresca): held DOFs eliminated, slip
    forces in the load.

    Parameters
    ----------
    problem : FrictionProblem
        Whose laws are all symmetric.
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
        load[p.tangent_2d] -= direction * p.slip_bound(np.zeros(p.m), active)
        x, _ = self.inner.solve(np.concatenate([active, stick]), load)
        return x


class CoupledSystem:
    """The non-symmetric systems of laws with ``s' ≠ 0`` (Coulomb), on a fixed pattern.

    The pattern is that of ``K`` with the tangential row of every node whose law has
    ``s' ≠ 0`` widened by the columns of its normal row (in a node-blocked ``K`` both rows
    have the same columns, so this adds nothing, and ``K``'s own arrays are taken). The
    positions of ``K``'s entries and of the copies of the normal rows in it are found once;
    each solve writes the values, zeroes the held rows and columns (diagonal kept) and
    refactorizes.

    Where the states differ from those of the factorization in at most ``max_update`` DOFs
    (a held DOF released or held, or a slipping row's factor ``σ s'`` changed), the system
    is solved with the existing LU and a low-rank correction instead (:meth:`_solve_updated`,
    docs/method.md, *Friction*, "Low-rank updates of Coulomb's systems"), checked by its
    residual; with a direct solver (on several ranks the rows and products of ``K`` it
    reads are summed over them, as the symmetric updates do).

    Parameters
    ----------
    problem : FrictionProblem
    solver : SPDSolver
        A general sparse LU (a factory's solver for ``symmetric=False``).
    max_update : int
        Largest number of changed DOFs solved by a low-rank update (0: never).
    """

    symmetric = False

    def __init__(self, problem: FrictionProblem, solver: SPDSolver, max_update: int = 8) -> None:
        self.problem = problem
        self.solver = solver
        qp = problem.qp
        K = qp.K
        n = K.shape[0]
        self.max_update = max_update if solver.rtol is None else 0  # exact solves only
        self.factored: tuple[np.ndarray, np.ndarray] | None = None  # held DOFs, row factors
        self.normal_of = np.full(n, -1)  # the normal DOF of each tangential one
        self.normal_of[problem.tangent_2d] = problem.normal
        self._diagonal: np.ndarray | None = None  # K's, for the updates
        rows_K = csr_row_indices(K)
        contact = np.ones(problem.m, dtype=bool)
        self.derivative = problem.friction.bound_derivative(contact)  # s' in contact
        self.offset = problem.slip_bound(np.zeros(problem.m), contact)  # s0 in contact
        coupled = np.flatnonzero(self.derivative != 0)
        # the entries of the coupled normal rows, and where their copies go in the tangential
        row_node = np.full(n, -1)
        row_node[problem.normal[coupled]] = coupled
        self.copy_src = np.flatnonzero(row_node[rows_K] >= 0)
        self.copy_node = row_node[rows_K[self.copy_src]]
        copy_rows = problem.tangent_2d[self.copy_node]
        copy_cols = K.indices[self.copy_src]
        within = _same_columns(K, problem.normal[coupled], problem.tangent_2d[coupled])
        if within is not None:  # node blocks: the tangential rows store the normal's columns
            pattern, self.rows, self.pos_K = K, rows_K, None
            self.pos_copy = self.copy_src + within[np.searchsorted(coupled, self.copy_node)]
            self.indptr, self.indices = K.indptr, K.indices
        else:
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
        factor = np.where(active & ~stick, direction * self.derivative, 0.0)  # σ s' on slip rows
        row_factor = np.zeros(n)
        row_factor[p.tangent_2d] = factor
        fixed, values = self.fixed, self.values
        fixed[p.normal] = active
        values[p.normal] = np.where(active, p.gap, 0.0)
        fixed[p.tangent_2d] = stick
        values[p.tangent_2d] = np.where(stick, p.reference, 0.0)
        rhs = qp.F.copy()
        rhs[p.tangent_2d] -= factor * qp.F[p.normal]
        if self.offset.any():  # σ s0 on slip rows (direction is 0 elsewhere)
            rhs[p.tangent_2d] -= direction * p.slip_bound(np.zeros(p.m), active)
        if self.factored is not None and self.max_update > 0:
            held, factored = self.factored
            changed = np.flatnonzero((held != fixed) | (factored != row_factor))
            if changed.size <= self.max_update:
                solving = self.solver.time_solve  # counted by the solver, not here
                x = self._solve_updated(rhs, row_factor, changed)
                self.time_assembly += time.perf_counter() - t0 - (self.solver.time_solve - solving)
                if x is not None:
                    return x
                t0 = time.perf_counter()
        if self.pos_K is None:  # K's own pattern
            data = qp.K.data.copy()
        else:
            data = np.zeros(self.indices.size)
            data[self.pos_K] = qp.K.data
        data[self.pos_copy] -= factor[self.copy_node] * qp.K.data[self.copy_src]
        A = sp.csr_matrix((data, self.indices, self.indptr), shape=(n, n))
        total = qp.ranks.sum  # of the products with A's rows: each row is on one rank
        b = rhs - total(A @ np.where(fixed, values, 0.0))
        b[fixed] = stored_values(data, self.diagonal[fixed], qp.ranks) * values[fixed]
        keep = ~(fixed[self.rows] | fixed[self.indices]) | self.is_diagonal
        A.data *= keep
        self.time_assembly += time.perf_counter() - t0
        self.solver.factorize(A)  # the pattern is compared, and analysed only the first time
        x = self.solver.solve(b)
        norm = lambda: qp.ranks.max(float(abs_matvec(A, np.ones(n)).max(initial=0.0)))  # noqa: E731
        x = refine(self.solver.solve, lambda y: b - total(A @ y), b, x, norm, self.solver.backend)
        x[fixed] = values[fixed]
        self.factored = (fixed.copy(), row_factor)
        return x

    def rebound(self, bound: np.ndarray) -> None:
        """Make the slip bounds of a system whose laws all have ``s' = 0`` the weights
        ``bound (m,)`` of its laws (:class:`~.friction.fixed_point.GivenBound`): only the
        loads of later solves change, the factorization and the pattern are kept."""
        if self.derivative.any():
            raise ValueError("rebound needs laws with s' = 0 at every node")
        friction = replace(self.problem.friction, weight=np.asarray(bound, dtype=np.float64))
        self.problem = replace(self.problem, friction=friction)
        m = self.problem.m
        self.offset = self.problem.slip_bound(np.zeros(m), np.ones(m, dtype=bool))

    def _solve_updated(
        self, rhs: np.ndarray, row_factor: np.ndarray, changed: np.ndarray
    ) -> np.ndarray | None:
        """The system of the current held DOFs and ``row_factor`` from the LU of the
        factorized one (:attr:`factored`), or None if the result fails its residual check.

        The two matrices differ in the rows ``C = changed`` and in the columns ``D ⊆ C`` of
        the DOFs held in one and free in the other: ``A₁ = A₀ + P_C R + G P_Dᵀ`` with
        ``R = (A₁ − A₀)[C, :]`` and ``G`` the columns ``D`` outside the rows ``C``. With
        ``U = [P_C, G]``, ``Vᵀ = [R; P_Dᵀ]`` (Sherman–Morrison–Woodbury)
        ``x = y − Z (I + Vᵀ Z)⁻¹ Vᵀ y``, ``[y, Z] = A₀⁻¹ [b, U]``: one solve with
        ``1 + |C| + |D|`` right-hand sides.
        """
        K = self.problem.qp.K
        held, factored = self.factored
        fixed, values = self.fixed, self.values
        if self._diagonal is None:
            self._diagonal = self.problem.qp.diagonal()  # on every rank
        diagonal = self._diagonal
        b = rhs - self._product(np.where(fixed, values, 0.0), row_factor)
        b[fixed] = diagonal[fixed] * values[fixed]
        if changed.size == 0:  # the factorized system itself, with another load
            x = self.solver.solve(b)
        else:
            swapped = changed[held[changed] != fixed[changed]]
            R = self._rows(changed, fixed, row_factor) - self._rows(changed, held, factored)
            G = self._columns(swapped, changed, fixed, row_factor)
            U = np.zeros((K.shape[0], 1 + changed.size + swapped.size), order="F")
            U[:, 0] = b
            U[changed, 1 + np.arange(changed.size)] = 1.0
            U[:, 1 + changed.size :] = G
            Y = self.solver.solve(U)
            y, Z = Y[:, 0], Y[:, 1:]
            capacitance = np.eye(Z.shape[1]) + np.vstack([R @ Z, Z[swapped]])
            try:
                w = np.linalg.solve(capacitance, np.concatenate([R @ y, y[swapped]]))
            except np.linalg.LinAlgError:
                return None
            x = y - Z @ w
        x[fixed] = values[fixed]
        product = self._product(np.where(fixed, 0.0, x), row_factor)
        product[fixed] = diagonal[fixed] * x[fixed]
        if not update_accepted(float(np.abs(b - product).max()), b, diagonal, x):
            return None
        return x

    def _product(self, v: np.ndarray, row_factor: np.ndarray) -> np.ndarray:
        """``K v`` with ``σ s'`` times the normal row's product subtracted on slipping
        rows: the product of the system's free rows with ``v`` (held columns not zeroed)."""
        p, qp = self.problem, self.problem.qp
        Kv = qp.ranks.sum(qp.K @ v)
        out = Kv.copy()
        out[p.tangent_2d] -= row_factor[p.tangent_2d] * Kv[p.normal]
        return out

    def _rows(self, dofs: np.ndarray, fixed: np.ndarray, row_factor: np.ndarray) -> np.ndarray:
        """The rows ``dofs`` of the system of ``fixed`` and ``row_factor``, dense."""
        K, total = self.problem.qp.K, self.problem.qp.ranks.sum  # each row on one rank
        rows = total(K[dofs].toarray())
        slipping = np.flatnonzero(row_factor[dofs] != 0)
        if slipping.size:
            normal_rows = total(K[self.normal_of[dofs[slipping]]].toarray())
            rows[slipping] -= row_factor[dofs[slipping], None] * normal_rows
        rows[:, fixed] = 0.0  # held columns (a free row's own diagonal is free)
        held = np.flatnonzero(fixed[dofs])
        rows[held] = 0.0
        rows[held, dofs[held]] = self._diagonal[dofs[held]]
        return rows

    def _columns(
        self, swapped: np.ndarray, changed: np.ndarray, fixed: np.ndarray, row_factor: np.ndarray
    ) -> np.ndarray:
        """``(n, |swapped|)``: the columns ``swapped`` of the new system minus the old one's
        outside the rows ``changed`` (rows that are the same in both): a released DOF's column
        of ``K`` (with the slipping rows' correction), a newly held one's negated."""
        K, total = self.problem.qp.K, self.problem.qp.ranks.sum  # each row on one rank
        columns = total(K[swapped].toarray())  # K symmetric: rows for columns
        slipping = np.flatnonzero(row_factor != 0)
        if slipping.size:
            columns[:, slipping] -= row_factor[slipping] * columns[:, self.normal_of[slipping]]
        columns[:, fixed] = 0.0  # held rows keep their diagonal only
        columns[:, changed] = 0.0  # those rows are in R
        columns *= np.where(fixed[swapped], -1.0, 1.0)[:, None]
        return columns.T


def _same_columns(K: sp.csr_matrix, normal: np.ndarray, tangent: np.ndarray) -> np.ndarray | None:
    """Where every tangential row ``tangent[k]`` stores the columns of its normal row
    ``normal[k]``, in the same order (a node-blocked ``K``, as assembled): the offset from
    an entry of the normal row to the same column's in the tangential row, per pair; None
    otherwise (the pattern must then be widened)."""
    start_n, start_t = K.indptr[normal], K.indptr[tangent]
    length = K.indptr[normal + 1] - start_n
    if not np.array_equal(length, K.indptr[tangent + 1] - start_t):
        return None
    normal_entries = concatenated_ranges(start_n, length)
    tangent_entries = concatenated_ranges(start_t, length)
    if not np.array_equal(K.indices[normal_entries], K.indices[tangent_entries]):
        return None
    return start_t - start_n
