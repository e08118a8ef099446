"""The primal active set fallback (signorini.algebra.primal) against enumeration."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
from linalg_problems import CYCLING_F, CYCLING_G, CYCLING_K, brute_force_qp, random_problem

from signorini.algebra import PDASConvergenceError, make_solver, superlu_solver
from signorini.algebra.active_system import ActiveSetSystem
from signorini.algebra.primal import primal_active_set
from signorini.algebra.qp import check_qp


def test_solves_the_problem_plain_pdas_cycles_on():
    qp = check_qp(sp.csr_matrix(CYCLING_K), CYCLING_F, np.arange(4), CYCLING_G)
    system = ActiveSetSystem(qp, make_solver(superlu_solver))
    history = []
    x, multiplier, active = primal_active_set(system, np.zeros(4), 1.0, 50, history)
    x_ref, multiplier_ref, active_ref = brute_force_qp(
        CYCLING_K, CYCLING_F, np.arange(4), CYCLING_G
    )
    assert np.abs(x - x_ref).max() < 1e-12
    assert np.abs(multiplier - multiplier_ref).max() < 1e-12
    assert np.array_equal(active, active_ref)
    assert history and all(step.method == "primal-active-set" for step in history)
    assert [step.iteration for step in history] == list(range(1, len(history) + 1))


@pytest.mark.parametrize("seed", range(4))
def test_any_start_reaches_the_minimizer(seed):
    rng = np.random.default_rng(seed)
    K, F, c, g, d, xd = random_problem(rng, 9, 6, 1)
    qp = check_qp(K, F, c, g, d, xd)
    system = ActiveSetSystem(qp, make_solver(superlu_solver))
    start = rng.standard_normal(9)  # infeasible in general: projected first
    x, multiplier, active = primal_active_set(system, start, 1.0, 100, [])
    x_ref, multiplier_ref, _ = brute_force_qp(K, F, c, g, d, xd)
    assert np.abs(x - x_ref).max() < 1e-9 * np.abs(x_ref).max()
    assert (multiplier >= -1e-12).all() and (multiplier[~active] == 0).all()


def test_step_bound_raises_with_the_fallback_history():
    qp = check_qp(sp.csr_matrix(CYCLING_K), CYCLING_F, np.arange(4), CYCLING_G)
    system = ActiveSetSystem(qp, make_solver(superlu_solver))
    earlier = ["pdas step"]  # steps before the fallback are not part of its failure
    with pytest.raises(PDASConvergenceError, match="did not finish in 1 steps") as info:
        primal_active_set(system, np.zeros(4), 1.0, 1, earlier)
    assert info.value.reason == "max_iter" and len(info.value.history) == 1
    assert info.value.x.shape == (4,)
