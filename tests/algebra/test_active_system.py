"""One active set's linear system: refactorization or Woodbury update
(signorini.algebra.active_system)."""

from __future__ import annotations

import numpy as np
import pytest
from linalg_problems import random_problem

from signorini.algebra import available_backends, make_solver, solve_pdas
from signorini.algebra.active_system import ActiveSetSystem
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
    solver = make_solver(backend)
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


@pytest.mark.parametrize("backend", BACKEND_LIST)
def test_low_rank_updates_agree_with_refactorization(backend):
    """Small active-set changes reuse the factorization (Woodbury) with the same result."""
    rng = np.random.default_rng(21)
    used = 0
    for _ in range(6):
        K, F, c, g, d, xd = random_problem(rng, 120, 12, 6, dense=False)
        exact = solve_pdas(K, F, c, g, d, xd, backend=backend, max_update=0)
        updated = solve_pdas(K, F, c, g, d, xd, backend=backend, max_update=12)
        assert exact.n_updates == 0
        assert updated.n_factorizations + updated.n_updates == updated.iterations
        assert np.array_equal(updated.active, exact.active)
        scale = np.abs(exact.x).max()
        np.testing.assert_allclose(updated.x, exact.x, rtol=0, atol=1e-10 * scale)
        assert updated.kkt.max < 1e-10
        used += updated.n_updates
    assert used > 0, f"{backend}: no iteration was solved by a low-rank update"
