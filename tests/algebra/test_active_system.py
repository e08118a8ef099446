"""One active set's linear system: refactorization or bordered update
(signorini.algebra.active_system)."""

from __future__ import annotations

import re

import numpy as np
import pytest
import scipy.sparse as sp
from linalg_problems import p2_elasticity, random_problem

from signorini.algebra import (
    SOLVERS,
    FactorizationError,
    IllConditionedWarning,
    PDASOptions,
    SingularSystemError,
    available_backends,
    make_solver,
    solve_pdas,
)
from signorini.algebra.active_system import FORWARD_RTOL, FORWARD_WARN, ActiveSetSystem
from signorini.algebra.qp import check_qp

BACKEND_LIST = available_backends()


def reference_solution(qp, active):
    """Dense solve of the equality problem with ``x_d = x_D`` and ``x_c = g`` on ``active``."""
    K = qp.K.toarray()
    n = K.shape[0]
    x = np.zeros(n)
    fixed = np.zeros(n, dtype=bool)
    fixed[qp.dirichlet] = True
    x[qp.dirichlet] = qp.dirichlet_values
    fixed[qp.constrained[active]] = True
    x[qp.constrained[active]] = qp.gap[active]
    free = ~fixed
    x[free] = np.linalg.solve(K[np.ix_(free, free)], qp.F[free] - K[np.ix_(free, fixed)] @ x[fixed])
    return x


@pytest.mark.parametrize("backend", BACKEND_LIST)
def test_small_changes_update_large_changes_refactorize(backend):
    rng = np.random.default_rng(31)
    qp = check_qp(*random_problem(rng, 80, 10, 4, dense=False))
    solver = make_solver(SOLVERS[backend])
    system = ActiveSetSystem(qp, solver, max_update=2)
    sets = [np.zeros(10, dtype=bool)]
    sets.append(sets[-1].copy())
    sets[-1][[1, 4]] = True  # 2 changes: low-rank update
    sets.append(sets[-1].copy())
    sets[-1][[0, 2, 3]] = True  # 3 changes: refactorization
    expected = [(1, 0), (1, 1), (2, 1)]  # (factorizations, updates) after each solve
    for active, counts in zip(sets, expected, strict=True):
        x, multiplier = system.solve(active)
        reference = reference_solution(qp, active)
        assert np.abs(x - reference).max() < 1e-10 * np.abs(reference).max()
        assert np.allclose(multiplier, qp.F[qp.constrained] - qp.K[qp.constrained] @ x, atol=0)
        assert (solver.n_factorizations, system.n_updates) == counts
    assert solver.n_analyses == 1
    assert system.time_elimination > 0


class CountingSolver:
    """A solver that records the number of right-hand sides of each solve."""

    def __init__(self, solver):
        self.inner, self.columns = solver, []

    def __getattr__(self, name):
        return getattr(self.inner, name)

    def solve(self, b):
        self.columns.append(1 if b.ndim == 1 else b.shape[1])
        return self.inner.solve(b)


@pytest.mark.parametrize("backend", BACKEND_LIST)
def test_bordered_update_frees_and_fixes_with_k_plus_one_right_hand_sides(backend):
    """An update that frees 2 DOFs and fixes 2 others: one solve with 5 right-hand sides
    (not the 2k + 1 = 9 of a Woodbury correction), the solution of the new system to
    round-off, then a further change from the same factor."""
    rng = np.random.default_rng(5)
    qp = check_qp(*random_problem(rng, 90, 12, 4, dense=False))
    solver = CountingSolver(make_solver(SOLVERS[backend]))
    system = ActiveSetSystem(qp, solver, max_update=4)
    first = np.zeros(12, dtype=bool)
    first[[0, 3, 5, 8]] = True
    system.solve(first)
    second = first.copy()
    second[[3, 8]] = False  # freed
    second[[1, 10]] = True  # fixed
    third = second.copy()
    third[1] = False  # 3 changes against the factorized set (first): still an update
    for active in (second, third):
        x, multiplier = system.solve(active)
        reference = reference_solution(qp, active)
        assert np.abs(x - reference).max() < 1e-12 * np.abs(reference).max()
        assert np.allclose(multiplier, qp.F[qp.constrained] - qp.K[qp.constrained] @ x, atol=0)
    assert solver.columns == [1, 5, 4]
    assert (solver.n_factorizations, system.n_updates) == (1, 2)


@pytest.mark.parametrize("backend", BACKEND_LIST)
def test_low_rank_updates_agree_with_refactorization(backend):
    """Small active-set changes reuse the factorization (bordered update) with the same
    result."""
    rng = np.random.default_rng(21)
    used = 0
    for _ in range(6):
        K, F, c, g, d, xd = random_problem(rng, 120, 12, 6, dense=False)
        exact = solve_pdas(
            K, F, c, g, d, xd, solver=SOLVERS[backend], options=PDASOptions(max_update=0)
        )
        updated = solve_pdas(
            K, F, c, g, d, xd, solver=SOLVERS[backend], options=PDASOptions(max_update=12)
        )
        assert exact.n_updates == 0
        assert updated.n_factorizations + updated.n_updates == updated.iterations
        assert np.array_equal(updated.active, exact.active)
        scale = np.abs(exact.x).max()
        np.testing.assert_allclose(updated.x, exact.x, rtol=0, atol=1e-10 * scale)
        assert updated.kkt.max < 1e-10
        used += updated.n_updates
    assert used > 0, f"{backend}: no iteration was solved by a low-rank update"


def _block_on_a_spring(spring):
    """A clamped P2 block and a second block held only by a spring ``spring`` times the
    identity, loaded downwards: its displacement is about 1e-3 / spring."""
    K1, xy = p2_elasticity(2, 2)
    n1 = K1.shape[0]
    K = sp.block_diag([K1, K1 + spring * sp.eye(n1)], format="csr")
    left = np.flatnonzero(xy[:, 0] < 1e-12)
    d = np.r_[2 * left, 2 * left + 1]
    F = np.zeros(2 * n1)
    F[n1 + 1 :: 2] = -1e-3
    return K1, K, F, d


@pytest.mark.parametrize("backend", BACKEND_LIST)
def test_near_singular_solve_is_reported(backend):
    # a spring of 1e-14: singular in double precision. PARDISO factorizes it (a round-off
    # pivot) and its solve is backward stable, but iterative refinement's estimate of the
    # forward error is 1: refused; SuperLU finds a non-positive pivot
    K1, K, F, d = _block_on_a_spring(1e-14)
    with pytest.raises(FactorizationError, match="singular|not positive definite") as info:
        solve_pdas(K, F, np.zeros(0, dtype=int), np.zeros(0), d, 0.0, solver=SOLVERS[backend])
    err = info.value
    assert err.backend == backend
    assert "no Dirichlet condition" in str(err)
    if isinstance(err, SingularSystemError):
        estimate = float(re.search(r"estimated relative error of (\S+) ", str(err)).group(1))
        assert estimate > 0.5 and err.residual > 1e-4  # PARDISO: 1.0, MUMPS (petsc): 0.83
    # the held block alone is solved, its residual checked and far below the bound
    n1 = K1.shape[0]
    result = solve_pdas(
        K1, np.ones(n1), np.zeros(0, dtype=int), np.zeros(0), d, solver=SOLVERS[backend]
    )
    assert result.kkt.stationarity < 1e-14


def test_an_ill_conditioned_solve_is_refined_and_warned_about():
    """A spring of 3e-13 (condition number about 3e13): the residual max|b - A x| / max|b| is
    far above SOLVE_RTOL (refused before), the backward error at round-off; the solution is
    kept, with a warning of its estimated error, and the backends agree within it. Its
    equilibrium residual, relative to the forces, reads 5e-3 (honest: the former scale
    max |K||x| read 3e-16), and a second warning says so.

    The estimated error is round-off amplified by the condition number, which grows like
    1 / spring: with 1e-12 it read 0.012 (SuperLU) and 0.0098 (PARDISO), on the edge of
    FORWARD_WARN = 0.01, warned about on some CPUs and not on others. The spring puts it at
    the geometric middle of the window (FORWARD_WARN, FORWARD_RTOL] instead, a factor √10
    from either end (read 0.023 and 0.037)."""
    window = np.sqrt(FORWARD_RTOL / FORWARD_WARN)
    spring = 1e-12 / window
    _, K, F, d = _block_on_a_spring(spring)
    solutions = []
    for backend in BACKEND_LIST:
        with pytest.warns(IllConditionedWarning) as record:
            result = solve_pdas(
                K, F, np.zeros(0, dtype=int), np.zeros(0), d, 0.0, solver=SOLVERS[backend]
            )
        messages = [str(w.message) for w in record]
        solve_warning = next(m for m in messages if "may be off by up to" in m)
        estimate = float(solve_warning.split("up to ")[1].split()[0])
        assert FORWARD_WARN < estimate <= FORWARD_RTOL
        assert any("meets its KKT conditions only to" in m for m in messages)
        solutions.append((result.x, estimate))
        # the floating block moves by the load over the spring, to the estimated error
        assert abs(np.abs(result.x).max() * spring / 1e-3 - 1.0) < estimate
        assert 1e-3 < result.kkt.stationarity < 1e-1
        assert result.kkt.round_off_scale > 1e12 * result.kkt.force_scale
    for x, estimate in solutions[1:]:
        error = np.abs(x - solutions[0][0]).max() / np.abs(x).max()
        assert error < estimate


@pytest.mark.parametrize("backend", BACKEND_LIST)
@pytest.mark.parametrize("case", ["floating block", "thin strip"])
def test_failed_factorization_names_the_usual_causes(backend, case):
    if case == "floating block":  # exactly singular: a second block without Dirichlet DOFs
        K1, xy = p2_elasticity(4, 4)
        K = sp.block_diag([K1, K1], format="csr")
    else:  # a 1 x 1e-4 strip clamped at one end: singular in double precision
        K, xy = p2_elasticity(16, 1, 288.46, 192.31, height=1e-4)
    left = np.flatnonzero(xy[:, 0] < 1e-12)
    d = np.r_[2 * left, 2 * left + 1]
    F = np.zeros(K.shape[0])
    F[1::2] = -1e-3
    with pytest.raises(FactorizationError) as info:
        solve_pdas(K, F, np.zeros(0, dtype=int), np.zeros(0), d, 0.0, solver=SOLVERS[backend])
    message = str(info.value)
    # a failed factorization, or (PARDISO on the strip) a factorization whose solve fails
    # the residual check
    assert message.startswith(
        (
            "the stiffness matrix with the Dirichlet and active DOFs eliminated is not positive "
            "definite in floating point: ",
            "the linear system is singular or too ill-conditioned: ",
        )
    )
    assert "no Dirichlet condition" in message and "refused from 2000" in message
    assert info.value.backend == backend
