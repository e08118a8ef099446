"""P1 with friction laws, corners and nested iteration: the same solver paths as P2."""

from __future__ import annotations

import numpy as np

from signorini.contact.nested import NESTED_MIN_NDOF
from signorini.contact.solution import solve
from signorini.estimator.residual import estimate
from signorini.examples import example_6_2
from signorini.examples.paper_friction import example_6_2_coulomb, example_6_2_tresca
from signorini.examples.punch import punch
from signorini.mesh.refine import refine_uniform


def _fine(problem, times: int = 2):
    mesh = problem.mesh
    for _ in range(times):
        mesh = refine_uniform(mesh).mesh
    return mesh


def test_p1_tresca_uses_the_p1_weights_and_meets_its_law():
    """s_z = ∫ s φ_z ds with the P1 hat: 30 · Σ|e|/2; |Λ_t,z| ≤ s_z, equality where a node
    slips; KKT to round-off; η8 ≥ 0."""
    problem = example_6_2_tresca()
    r = solve(problem, _fine(problem), element="P1")
    cs = r.contact
    rows = cs.friction.index >= 0
    weight_err = np.abs(cs.friction.weight[rows] - 30.0 * cs.basis_integral[rows]).max()
    assert np.allclose(cs.basis_integral, cs.hat_integral, rtol=0, atol=1e-15)
    bound = cs.friction.slip_bound(r.contact_force, r.active)
    excess = (np.abs(r.tangential_force) - bound).max()
    kkt = r.report.kkt.columns()
    est = estimate(r)
    print(f"P1 Tresca, {r.ndof} unknowns: weight error {weight_err:.1e}, max(|Λ_t| − s_z) "
          f"{excess:.1e}, KKT {kkt}, eta_8 {est.eta_terms[7]:.3e}")  # fmt: skip
    assert weight_err < 1e-12
    assert excess < 1e-10 * bound.max()
    assert max(abs(v) for v in kkt.values()) < 1e-12
    assert np.isfinite(est.eta) and est.eta_terms[7] >= 0.0


def test_p1_coulomb_with_no_friction_is_the_frictionless_p1_solution():
    problem = example_6_2()
    mesh = _fine(problem)
    plain = solve(problem, mesh, element="P1")
    zero = solve(example_6_2_coulomb(coefficient=0.0), mesh, element="P1")
    du = np.abs(zero.u - plain.u).max() / np.abs(plain.u).max()
    a, b = estimate(plain), estimate(zero)
    print(f"Coulomb F = 0 against frictionless P1: max |du| / max |u| = {du:.1e}, "
          f"eta {b.eta:.12g} and {a.eta:.12g}")  # fmt: skip
    assert du < 1e-12
    assert abs(b.eta - a.eta) < 1e-10 * a.eta and b.eta_terms[7] == 0.0


def test_p1_and_p2_agree_on_the_frictional_contact_forces():
    """Σ Λ_z with Tresca and Coulomb: P1 and P2 on the same mesh differ by the discretisation
    error (measured 5e-4 and 6e-4 at 544 / 2112 unknowns), and P1 moves towards P2 under
    refinement."""
    for make in (example_6_2_tresca, example_6_2_coulomb):
        problem = make()
        gaps = []
        for times in (1, 2, 3):
            mesh = _fine(problem, times)
            f1 = solve(problem, mesh, element="P1").total_contact_force
            f2 = solve(problem, mesh).total_contact_force
            gaps.append(abs(f1 - f2) / f2)
        print(f"{problem.name}: |F_P1 − F_P2| / F_P2 on 1, 2, 3 refinements: {gaps}")
        assert gaps[-1] < 2e-3 and gaps[-1] < gaps[0]


def test_p1_corner_of_the_punch():
    """The punch's wall meets its contact part at a corner: two constraints at that vertex,
    both met, KKT to round-off."""
    problem = punch()
    r = solve(problem, _fine(problem, 1), element="P1")
    kkt = r.report.kkt.columns()
    un = r.contact.normal_displacement(r.u) - r.contact.gap
    print(f"punch P1: {r.contact.second.sum()} corner(s), max(u·n − ψ) {un.max():.1e}, KKT {kkt}")
    assert r.contact.second.any()
    assert un.max() < 1e-12 * np.abs(r.u).max()
    assert max(abs(v) for v in kkt.values()) < 1e-12


def test_p1_nested_iteration_gives_the_same_solution():
    problem = example_6_2()
    mesh = _fine(problem, 5)  # 33 024 unknowns: nested iteration applies
    nested = solve(problem, mesh, element="P1")
    cold = solve(problem, mesh, element="P1", nested=False)
    assert nested.ndof >= NESTED_MIN_NDOF and "nested" in nested.timings
    assert np.array_equal(nested.active, cold.active)
    assert np.abs(nested.u - cold.u).max() < 1e-12 * np.abs(cold.u).max()
    print(f"nested: {nested.report.iterations} PDAS iterations, cold {cold.report.iterations}")
    assert nested.report.iterations <= cold.report.iterations
