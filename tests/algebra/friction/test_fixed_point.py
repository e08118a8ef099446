"""Where the frictional iteration's states cycle (signorini.algebra.friction.newton): one node at a
time, then Coulomb's fallback, the fixed point on the slip bound
(signorini.algebra.friction.fixed_point), against the converged iteration of the default c.

The iteration cycles on the pressed block of :func:`contact_problems.pressed_block` when its
constant ``c`` is large (the mean diagonal of ``K`` or a hundred times it; docs/method.md,
*Friction*); with the default ``c`` it converges. All give the one Coulomb solution of this
small coefficient, so each remedy is checked against an iteration that shares nothing with
it but the problem.
"""

from __future__ import annotations

import logging
from functools import cache

import numpy as np
import pytest
from contact_problems import pressed_block

from signorini.algebra.backends.selection import make_solver
from signorini.algebra.backends.superlu import superlu_solver
from signorini.algebra.errors import FrictionConvergenceError
from signorini.algebra.friction.fixed_point import GivenBound, solve_by_fixed_point
from signorini.algebra.friction.kkt import check_friction
from signorini.algebra.friction.newton import (
    FrictionOptions,
    _iterate,
    _rule_constants,
    solve_friction,
)
from signorini.algebra.friction.result import SLIP, STICK
from signorini.algebra.friction.system import CoupledSystem
from signorini.algebra.inexact import InexactRule
from signorini.problem.friction_laws import Coulomb, Tresca

COEFFICIENT = 0.2


@cache
def problem(nx=8, shift=0.005):
    S = pressed_block(nx, nx // 2, shift=shift)
    p = check_friction(
        S.K, S.F, S.normal, S.tangent, S.gap, S.dirichlet, S.dirichlet_values,
        laws=Coulomb(0.0), weight=COEFFICIENT,
    )  # fmt: skip
    return S, p


def mean_diagonal(nx=8):
    """The constant of the update rule that makes the coupled iteration cycle here."""
    S, p = problem(nx)
    return float(S.K.diagonal()[S.normal].mean())


def rel(a, b):
    return np.abs(a - b).max() / np.abs(b).max()


def check_solution(S, r, reference):
    """``r`` is ``reference``'s solution and meets Coulomb's laws node by node."""
    assert r.kkt.max < 1e-12, r.kkt
    assert rel(r.x, reference.x) < 1e-12, rel(r.x, reference.x)
    assert np.array_equal(r.state, reference.state)
    assert np.array_equal(r.direction, reference.direction)
    counts = np.bincount(r.state, minlength=3)
    assert counts[STICK] >= 1 and counts[SLIP] >= 2, counts
    lam = S.F - S.K @ r.x
    lam_n, lam_t = lam[S.normal], lam[S.tangent]
    slip = r.state == SLIP
    assert np.abs(np.abs(lam_t[slip]) - COEFFICIENT * lam_n[slip]).max() < 1e-12 * lam_n.max()
    assert r.iterations == len(r.history)


def test_a_cycling_iteration_goes_on_one_node_at_a_time(caplog):
    S, p = problem()
    reference = solve_friction(p)
    assert reference.method == "semismooth-newton" and reference.iterations < 10
    with caplog.at_level(logging.INFO, logger="signorini.algebra.friction.newton"):
        r = solve_friction(p, options=FrictionOptions(c=mean_diagonal()))
    assert "one node at a time" in caplog.text
    assert r.method == "semismooth-newton"
    check_solution(S, r, reference)


def test_where_one_node_at_a_time_does_not_finish_the_fixed_point_does():
    S, p = problem(16)
    reference = solve_friction(p)
    r = solve_friction(p, options=FrictionOptions(c=100 * mean_diagonal(16)))
    assert r.method == "fixed-point"
    check_solution(S, r, reference)


def fixed_point_only(p, max_iter=50):
    """The fixed point with the coupled iteration always failing: its outer loop alone, at
    most ``max_iter`` outer iterations."""
    with make_solver(superlu_solver, symmetric=False) as solver:
        system = CoupledSystem(p, solver)
        inexact = InexactRule(solver)
        states = (np.zeros(p.m, bool), np.zeros(p.m, bool), np.zeros(p.m))
        with pytest.raises(FrictionConvergenceError) as err:  # a start: 3 iterations
            _iterate(system, states, (mean_diagonal(), mean_diagonal()), 3, inexact)
        failed = err.value

        def iterate(system, states, rule, max_iter):
            if not isinstance(system.problem.friction.laws[0], GivenBound):
                raise FrictionConvergenceError("cycles", [], "cycling")
            return _iterate(system, states, rule, 50, inexact)  # inner: not bounded by max_iter

        rules = ((mean_diagonal(), mean_diagonal()), _rule_constants(p, None))
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


def test_classical_tresca_that_cycles_finishes_one_node_at_a_time(caplog):
    """Classical Tresca (a convex problem) with a constant c a hundred times the mean
    diagonal: the slip directions flip back and forth, and one node at a time, a reversing
    slip sticking first, ends at the minimiser the default c finds."""
    S = pressed_block(8, 4, shift=0.02)
    system = (S.K, S.F, S.normal, S.tangent, S.gap, S.dirichlet, S.dirichlet_values)
    free = check_friction(*system, laws=Tresca(0.0), weight=0.0)
    bound = 0.3 * solve_friction(free).multiplier_n.max()
    p = check_friction(*system, laws=Tresca(0.0), weight=bound)
    reference = solve_friction(p)
    with caplog.at_level(logging.INFO, logger="signorini.algebra.friction.newton"):
        r = solve_friction(
            p, options=FrictionOptions(c=100 * float(S.K.diagonal()[S.normal].mean()))
        )
    assert "one node at a time" in caplog.text
    assert r.symmetric and r.method == "semismooth-newton"
    assert r.kkt.max < 1e-12, r.kkt
    assert rel(r.x, reference.x) < 1e-12, rel(r.x, reference.x)
    assert np.array_equal(r.state, reference.state)


def test_a_tresca_bound_in_contact_only_that_cycles_says_what_to_do():
    """Tresca acting only in contact jumps where Λ_n vanishes: on 16 x 8 squares it cycles
    one node at a time too, and the error names the law that does not."""
    S = pressed_block(16, 8, shift=0.005)
    system = (S.K, S.F, S.normal, S.tangent, S.gap, S.dirichlet, S.dirichlet_values)
    free = check_friction(*system, laws=Tresca(0.0), weight=0.0)
    bound = 0.3 * solve_friction(free).multiplier_n.max()
    p = check_friction(*system, laws=Tresca(0.0, everywhere=False), weight=bound)
    with pytest.raises(FrictionConvergenceError, match="one node at a time too") as err:
        solve_friction(p)
    assert "Tresca(..., everywhere=True)" in str(err.value) and err.value.reason == "cycling"
    classical = solve_friction(check_friction(*system, laws=Tresca(0.0), weight=bound))
    assert classical.kkt.max < 1e-12
