"""Coulomb's fallback where the semismooth Newton method cycles: the fixed point on the slip
bound (signorini.algebra.friction_fixed_point), against the converged coupled iteration.

The coupled iteration cycles on the pressed block of :func:`contact_problems.pressed_block`
(8 x 4 squares, 13 contact nodes) when its constant ``c`` is the mean diagonal of ``K``
(docs/method.md, *Friction*); with the default ``c`` it converges. Both give the one Coulomb
solution of this small coefficient, so the fallback is checked against an iteration that
shares nothing with it but the problem.
"""

from __future__ import annotations

from functools import cache

import numpy as np
import pytest
from contact_problems import pressed_block

from signorini.algebra.backends import make_solver
from signorini.algebra.friction import FrictionOptions, _iterate, _rule_constants, solve_friction
from signorini.algebra.friction_fixed_point import GivenBound, solve_by_fixed_point
from signorini.algebra.friction_kkt import check_friction
from signorini.algebra.friction_result import SLIP, STICK, FrictionConvergenceError
from signorini.algebra.friction_system import CoupledSystem
from signorini.algebra.inexact import InexactRule
from signorini.algebra.superlu import superlu_solver
from signorini.problem.friction import Coulomb

COEFFICIENT = 0.2


@cache
def problem():
    S = pressed_block(8, 4, shift=0.005)
    p = check_friction(
        S.K, S.F, S.normal, S.tangent, S.gap, S.dirichlet, S.dirichlet_values,
        laws=Coulomb(0.0), weight=COEFFICIENT,
    )  # fmt: skip
    return S, p


def large_c():
    """The constant of the update rule that makes the coupled iteration cycle here."""
    S, p = problem()
    return float(S.K.diagonal()[S.normal].mean())


def rel(a, b):
    return np.abs(a - b).max() / np.abs(b).max()


def test_the_coupled_iteration_cycles_there_and_converges_with_the_default_c():
    S, p = problem()
    with pytest.raises(FrictionConvergenceError, match="cycles") as err:
        with make_solver(superlu_solver, symmetric=False) as solver:
            system = CoupledSystem(p, solver)
            states = (np.zeros(p.m, bool), np.zeros(p.m, bool), np.zeros(p.m))
            _iterate(system, states, (large_c(), large_c()), 50, InexactRule(solver))
    assert err.value.reason == "cycling"
    r = solve_friction(p)
    assert r.method == "semismooth-newton" and r.kkt.max < 1e-12


def test_a_cycling_coulomb_iteration_is_finished_by_the_fixed_point():
    S, p = problem()
    reference = solve_friction(p)
    r = solve_friction(p, options=FrictionOptions(c=large_c()))
    assert r.method == "fixed-point"
    assert r.kkt.max < 1e-12, r.kkt
    assert rel(r.x, reference.x) < 1e-12, rel(r.x, reference.x)
    assert np.array_equal(r.state, reference.state)
    assert np.array_equal(r.direction, reference.direction)
    counts = np.bincount(r.state, minlength=3)
    assert counts[STICK] >= 2 and counts[SLIP] >= 2, counts
    # the laws node by node, from x alone
    lam = S.F - S.K @ r.x
    lam_n, lam_t = lam[S.normal], lam[S.tangent]
    slip = r.state == SLIP
    assert np.abs(np.abs(lam_t[slip]) - COEFFICIENT * lam_n[slip]).max() < 1e-12 * lam_n.max()
    assert r.iterations == len(r.history) and r.iterations < 40, r.history


def fixed_point_only(p, max_iter=50):
    """The fixed point with the coupled iteration always failing: its outer loop alone, at
    most ``max_iter`` outer iterations."""
    with make_solver(superlu_solver, symmetric=False) as solver:
        system = CoupledSystem(p, solver)
        inexact = InexactRule(solver)
        states = (np.zeros(p.m, bool), np.zeros(p.m, bool), np.zeros(p.m))
        try:
            _iterate(system, states, (large_c(), large_c()), 50, inexact)
        except FrictionConvergenceError as err:
            failed = err

        def iterate(system, states, rule, max_iter):
            if not isinstance(system.problem.friction.laws[0], GivenBound):
                raise FrictionConvergenceError("cycles", [], "cycling")
            return _iterate(system, states, rule, 50, inexact)  # inner: not bounded by max_iter

        rules = ((large_c(), large_c()), _rule_constants(p, None))
        options = FrictionOptions(max_iter=max_iter)
        return solve_by_fixed_point(system, failed, rules, options, iterate)


def test_the_fixed_point_alone_converges_to_the_coulomb_solution():
    S, p = problem()
    reference = solve_friction(p)
    x, states, history, _ = fixed_point_only(p)
    assert rel(x, reference.x) < 1e-7, rel(x, reference.x)  # stopped at kkt_tol 1e-8
    assert np.array_equal(states[0], reference.state != 0)


def test_a_fixed_point_that_does_not_finish_says_what_to_do():
    S, p = problem()
    with pytest.raises(FrictionConvergenceError, match="Apply the load in more steps") as err:
        fixed_point_only(p, max_iter=2)
    assert "did not reach the KKT tolerance" in str(err.value)
    assert err.value.reason == "cycling"
