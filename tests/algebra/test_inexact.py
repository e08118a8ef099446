"""The inexact active set stopping rule (signorini.algebra.inexact) with an iterative solver
simulated exactly: SuperLU's solution plus the solution of a residual of exactly ``rtol / 2``
relative size, so every solve is a valid iterative solve to its tolerance and no better.
No PETSc needed; the CG + GAMG backend itself is tested in tests/parallel/test_gamg.py."""

from __future__ import annotations

from functools import cache

import numpy as np
import pytest
import scipy.sparse as sp
from contact_problems import pressed_block
from linalg_problems import CYCLING_F, CYCLING_G, CYCLING_K, brute_force_qp

from signorini.algebra import (
    PDASConvergenceError,
    PDASOptions,
    SingularSystemError,
    solve_pdas,
    superlu_solver,
)
from signorini.algebra.backends.superlu import SuperLUSolver
from signorini.algebra.friction.kkt import check_friction
from signorini.algebra.friction.newton import FrictionOptions, solve_friction
from signorini.algebra.inexact import CONFIRM_RTOL, KKT_RTOL
from signorini.problem.friction_laws import Tresca

LOOSE = 1e-6


class InexactSolver(SuperLUSolver):
    """An SPD solver whose solves have the relative residual ``‖b − A x‖₂ = slack · rtol ·
    ‖b‖₂ / 2`` exactly (a deterministic direction); records the ``rtol`` of every solve."""

    backend = "inexact"

    def __init__(self, rtol: float = LOOSE, slack: float = 1.0) -> None:
        super().__init__(check_symmetry=False)
        self.rtol = rtol
        self.slack = slack
        self.used: list[float] = []
        self._rng = np.random.default_rng(0)

    def _solve(self, b):
        x = super()._solve(b)
        if self.rtol is None:
            return x
        r = self._rng.standard_normal(b.shape)
        r *= 0.5 * self.slack * self.rtol * np.linalg.norm(b) / np.linalg.norm(r)
        self.used.append(self.rtol)
        return x + super()._solve(r)


@cache
def block():
    """16 x 8 squares, 1122 DOFs, 33 contact nodes."""
    return pressed_block(16, 8, shift=0.01)


def pdas(solver):
    S = block()
    return solve_pdas(S.K, S.F, S.normal, S.gap, S.dirichlet, S.dirichlet_values, solver=solver)


def test_an_inexact_pdas_confirms_the_exact_active_set_with_one_tight_solve():
    exact = pdas(superlu_solver)
    solver = InexactSolver()
    result = pdas(solver)
    assert np.array_equal(result.active, exact.active) and exact.active.sum() >= 5
    # the same path, and the repeated set solved once more, tightly (no low-rank updates)
    assert result.iterations == exact.iterations + 1 and result.n_updates == 0
    assert solver.used == [LOOSE] * exact.iterations + [CONFIRM_RTOL]
    assert result.history[-1].n_added == result.history[-1].n_removed == 0
    assert solver.rtol == LOOSE  # the solver gets its own tolerance back
    # the reported KKT residuals are those of the tight solve: within the stated bound
    assert result.kkt.max <= KKT_RTOL, result.kkt
    assert np.abs(result.x - exact.x).max() <= 1e-10 * np.abs(exact.x).max()


def test_an_exact_solver_takes_the_exact_path():
    exact = pdas(superlu_solver)
    solver = InexactSolver()
    solver.rtol = None  # a direct solver: no confirming solve, bordered updates allowed
    result = pdas(solver)
    assert result.iterations == exact.iterations and np.array_equal(result.x, exact.x)
    assert result.n_updates == exact.n_updates > 0  # the bordered updates are used


def test_a_solve_beyond_its_tolerance_is_refused():
    with pytest.raises(SingularSystemError, match="exceeds its tolerance 1e-06"):
        pdas(InexactSolver(slack=100.0))  # residual 50 rtol: more than the slack of 10


def test_an_inexact_tresca_iteration_confirms_its_states():
    S = block()
    bound = 0.1 * pdas(superlu_solver).multiplier.max()
    args = (S.K, S.F, S.normal, S.tangent, S.gap, S.dirichlet, S.dirichlet_values)
    problem = check_friction(*args, laws=Tresca(0.0), weight=bound)
    exact = solve_friction(problem, options=FrictionOptions(), solver=superlu_solver)
    solver = InexactSolver()
    result = solve_friction(problem, options=FrictionOptions(), solver=solver)
    assert np.array_equal(result.state, exact.state) and np.array_equal(
        result.direction, exact.direction
    )
    assert len(np.unique(exact.state)) == 3  # out of contact, stick and slip all occur
    assert result.iterations == exact.iterations + 1
    assert solver.used[-1] == CONFIRM_RTOL and set(solver.used[:-1]) == {LOOSE}
    assert result.kkt.max <= KKT_RTOL, result.kkt
    assert solver.rtol == LOOSE


def test_a_cycle_of_loose_solves_is_retried_with_tight_ones_then_falls_back():
    """The 4-unknown system on which PDAS cycles (tests/algebra/test_pdas.py): a cycle met
    with loose solves may be their error, so the iteration goes on with tight solves; the
    cycle is reported only when it repeats with those, and the fallback then finishes with
    tight solves at the primal active set method's exact solution."""
    K = sp.csr_matrix(CYCLING_K)
    with pytest.raises(PDASConvergenceError, match="cycles") as exact:
        solve_pdas(K, CYCLING_F, np.arange(4), CYCLING_G)
    solver = InexactSolver()
    with pytest.raises(PDASConvergenceError, match="cycles") as inexact:
        solve_pdas(K, CYCLING_F, np.arange(4), CYCLING_G, solver=solver)
    n = len(exact.value.history)
    assert len(inexact.value.history) > n and solver.used[: n - 1] == [LOOSE] * (n - 1)
    assert solver.used[-1] == CONFIRM_RTOL and solver.rtol == LOOSE
    solver.used.clear()
    result = solve_pdas(
        K, CYCLING_F, np.arange(4), CYCLING_G, options=PDASOptions(fallback=True), solver=solver
    )
    x_ref, _, active_ref = brute_force_qp(CYCLING_K, CYCLING_F, np.arange(4), CYCLING_G)
    assert result.method == "primal-active-set" and np.array_equal(result.active, active_ref)
    assert np.abs(result.x - x_ref).max() < 1e-12 * np.abs(x_ref).max()
    assert solver.used[-1] == CONFIRM_RTOL and result.kkt.max <= KKT_RTOL
