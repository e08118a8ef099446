"""Warm starts of 3D contact (docs/method.md, *Three dimensions: warm starts*): the rows of a
warm start ``u0`` at their bound, read in the solver's variables (the transformed face
basis), are PDAS's first active set, as the contact nodes of ``u0`` are in 2D."""

from __future__ import annotations

import numpy as np
import pytest
from contact3d_problems import DIRECT

from signorini.algebra.backends.selection import SOLVERS
from signorini.algebra.pdas import solve_pdas
from signorini.contact.nested import (
    WARM_START_RTOL,
    round_off_scale,
    warm_active_set,
    warm_rule_active_set,
)
from signorini.contact.solution import solve
from signorini.contact.system import assemble
from signorini.examples.hertz3d import hertz_3d
from signorini.examples.paper3d import example_6_2_3d
from signorini.loop import adaptive
from signorini.mesh.refine import refine_uniform


@pytest.mark.parametrize("alpha", [None, 0.0], ids=["b", "a"])
def test_a_warm_start_from_the_discrete_solution_takes_one_pdas_step(alpha):
    """hertz_3d(h_contact=0.2): cold, PDAS takes 3 steps; started from its own solution, one
    step (direct) or the inexact rule's two solves (amg: a loose one, then the confirming
    tight one), the same active set and u to 1e-12 of max|u|."""
    problem = hertz_3d(h_contact=0.2, face_alpha=alpha)
    cold = solve(problem, solver=DIRECT)
    assert cold.report.iterations >= 3 and cold.active.sum() >= 4
    scale = np.abs(cold.u).max()
    for name, steps in (("scipy", 1), ("amg", 2)):  # a loop over two linear solvers
        warm = solve(problem, solver=SOLVERS[name], u0=cold.u)
        assert warm.report.iterations == warm.report.n_solves == steps, name
        np.testing.assert_array_equal(warm.active, cold.active)
        np.testing.assert_allclose(warm.u, cold.u, rtol=0, atol=1e-12 * scale)
        assert warm.report.kkt.max <= 1e-10


def test_the_warm_active_set_is_read_in_the_solvers_variables():
    """Under (b) a row is active where its transformed variable meets ψ̃ (``ỹ_dof = ψ̃``),
    not where ``u(z)·n_z = ψ(z)``: the warm active set of the solution is its active set
    (6 rows), while the Cartesian test finds only the rows inside the zone (1 of them)."""
    cold = solve(hertz_3d(h_contact=0.2), solver=DIRECT)
    cs = cold.contact
    np.testing.assert_array_equal(warm_active_set(cs, cold.u), cold.active)
    gap = np.einsum("kc,kc->k", cold.u[cs.node], cs.direction) - cs.psi
    cartesian = gap >= -WARM_START_RTOL * round_off_scale(cold.u, cs.psi)
    assert cartesian.sum() < cold.active.sum() and not (cartesian & ~cold.active).any()


def test_a_prolongated_warm_start_saves_pdas_steps_under_refinement():
    """example-6.2-3d refined once uniformly: started from the coarse solution prolongated
    (exact for nested P2 spaces), PDAS reaches the cold solve's solution in fewer steps
    (measured 2 against 4). The first active set is PDAS's rule at the prolongated solution
    (the refined mesh's residual as the force): it misses fewer of the final rows than the
    rows at their bound do (measured 12 against 24 of 41, the zone grows), and PDAS from it
    takes fewer steps than from those rows (2 against 3)."""
    problem = example_6_2_3d()
    coarse = solve(problem, solver=DIRECT)
    refinement = refine_uniform(problem.mesh)
    u0 = coarse.space.prolongate(coarse.u, refinement)
    cold = solve(problem, refinement.mesh, solver=DIRECT)
    warm = solve(problem, refinement.mesh, solver=DIRECT, u0=u0)
    assert warm.report.iterations < cold.report.iterations
    np.testing.assert_array_equal(warm.active, cold.active)
    np.testing.assert_allclose(warm.u, cold.u, rtol=0, atol=1e-12 * np.abs(cold.u).max())
    a = assemble(problem, refinement.mesh)
    held = (a.dirichlet, a.dirichlet_values)
    rule = warm_rule_active_set(a.contact, u0, (a.K, a.F), held)
    at_bound = warm_active_set(a.contact, u0)
    assert rule.sum() == warm.report.history[0].n_active
    assert (cold.active & ~rule).sum() < (cold.active & ~at_bound).sum()
    steps = {}
    for name, first in (("rule", rule), ("at bound", at_bound)):  # a loop over two starts
        res = solve_pdas(
            a.K, a.F, a.contact.constrained_dofs, a.contact.gap, *held, active0=first,
            solver=DIRECT,
        )  # fmt: skip
        np.testing.assert_array_equal(res.active, cold.active)
        steps[name] = res.iterations
    assert steps["rule"] < steps["at bound"]


def test_adaptive_3d_warm_starts_take_at_most_one_and_a_half_pdas_steps_per_level():
    """adaptive(example_6_2_3d()) to 900 unknowns (five levels): after level 1 the warm
    started levels take at most 1.5 PDAS steps (= linear solves, direct) per level on the
    mean (measured 1, 2, 1), where cold solves of the same meshes take 3 or more (3, 3, 4);
    every level's active set is the cold solve's and u agrees to round-off."""
    levels = list(adaptive(example_6_2_3d(), max_ndof=900, solver=DIRECT))
    assert len(levels) >= 5
    later = [level.record for level in levels[2:]]
    assert np.mean([r.pdas_iterations for r in later]) <= 1.5
    assert np.mean([r.n_solves for r in later]) <= 1.5
    cold_steps = []
    for level in levels:  # a loop over levels
        warm = level.result
        cold = solve(warm.problem, warm.mesh, solver=DIRECT)
        np.testing.assert_array_equal(warm.active, cold.active)
        np.testing.assert_allclose(warm.u, cold.u, rtol=0, atol=1e-12 * np.abs(cold.u).max())
        cold_steps.append(cold.report.iterations)
    assert np.mean(cold_steps[2:]) >= 3
