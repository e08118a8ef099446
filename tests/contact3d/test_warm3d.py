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
    projected_l1_jacobi,
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
    tight one, both CG runs started from the warm start itself, so next to no iterations),
    the same active set and u to 1e-12 of max|u|."""
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
        assert sum(warm.report.linear_iterations) <= 4, name


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
    """adaptive(example_6_2_3d()) to 3 000 unknowns (ten levels): after level 0 the warm
    started levels take at most 1.5 PDAS steps (= linear solves, direct) per level on the
    mean (measured 1, 1, 2, 2, 1, 1, 1, 2, 1), where cold solves of the same meshes take 3 or
    more; every level's active set is the cold solve's and u agrees to round-off."""
    levels = list(adaptive(example_6_2_3d(), max_ndof=3000, solver=DIRECT))
    assert len(levels) >= 9
    later = [level.record for level in levels[1:]]
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


def test_adaptive_hertz_3d_warm_starts_take_at_most_one_and_a_half_solves_per_level():
    """adaptive(hertz_3d(h_contact=0.2)) to 5 000 unknowns (seven levels), direct: the zone
    grows every level (6 → 48 rows), and the rule after the projected ℓ1-Jacobi sweeps still
    finds the final set, so the warm started levels take at most 1.5 linear solves on the
    mean (measured 1.0; 2.0 with the rule alone, docs/method.md); the last two levels' active
    sets are the cold solves' and u agrees to round-off."""
    levels = list(adaptive(hertz_3d(h_contact=0.2), max_ndof=5000, solver=DIRECT))
    assert len(levels) >= 6
    assert levels[-1].record.n_active > 2 * levels[1].record.n_active  # the zone grows
    assert np.mean([level.record.n_solves for level in levels[1:]]) <= 1.5
    for level in levels[-2:]:  # a loop over two levels
        warm = level.result
        cold = solve(warm.problem, warm.mesh, solver=DIRECT)
        assert cold.report.iterations >= 2
        np.testing.assert_array_equal(warm.active, cold.active)
        np.testing.assert_allclose(warm.u, cold.u, rtol=0, atol=1e-12 * np.abs(cold.u).max())


def test_projected_l1_jacobi_decreases_the_energy_to_the_bound_constrained_minimum():
    """On a random SPD box QP (a 1D Laplacian plus a random SPD part, fixed seed) the sweeps
    stay feasible, never increase ½xᵀKx − Fᵀx, keep the held DOFs, and after many sweeps
    reach the minimiser computed independently by SciPy's L-BFGS-B."""
    from scipy.optimize import minimize
    from scipy.sparse import csr_matrix, diags

    rng = np.random.default_rng(7)
    n = 30
    B = rng.standard_normal((n, n)) * 0.1
    K = csr_matrix(diags([-1.0, 2.2, -1.0], [-1, 0, 1], shape=(n, n)).toarray() + B @ B.T)
    F = rng.standard_normal(n)
    c = np.arange(0, n, 3)
    gap = rng.uniform(-0.5, 0.5, c.size)
    held = np.array([n - 1])
    x = np.zeros(n)

    def energy(y):
        return 0.5 * y @ (K @ y) - F @ y

    energies = [energy(x)]
    for _ in range(50):  # a loop over sweeps
        x = projected_l1_jacobi(K, F, c, gap, x, held, 1)
        assert (x[c] <= gap).all() and x[held[0]] == 0.0
        energies.append(energy(x))
    assert (np.diff(energies) <= 1e-12 * np.abs(energies).max()).all()
    x = projected_l1_jacobi(K, F, c, gap, x, held, 20000)
    bounds = [(None, None)] * n
    for i, g in zip(c, gap, strict=True):  # a loop over 10 bounds
        bounds[i] = (None, g)
    bounds[held[0]] = (0.0, 0.0)
    ref = minimize(
        energy, np.zeros(n), jac=lambda y: K @ y - F, method="L-BFGS-B", bounds=bounds,
        options={"ftol": 1e-15, "gtol": 1e-12, "maxiter": 10000},
    )  # fmt: skip
    np.testing.assert_allclose(x, ref.x, rtol=0, atol=1e-6)
