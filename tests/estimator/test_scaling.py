"""How η_h and the solution scale with Young's modulus (docs/method.md, *Estimator*, "Units").

Multiply λ, μ, f and g by c and keep the Dirichlet data and the gap: u_h is unchanged, σ(u_h),
p_z and s_z are multiplied by c, so from the formulas of (5.1)

    η_k(c) = c η_k      (k = 1 … 5: squares of stresses),
    η6(c)  = c^{1/2} η6 (η6² = s_p d_p, d_p depends on u_h only),
    η7(c)  = η7         (a norm of u_h·n − ψ),

and Λ_z(c) = c Λ_z. These hold for every c for which the data stay representable, also
where the squares of the stresses (c = 1e±300) do not.

Tolerance: c is not a power of 2, so λ, μ, f and g are rounded differently and the two
discrete problems differ by a relative O(1e-16); the solver turns that into a relative
difference of u_h of O(κ 1e-16) (measured: below 1e-14 on these meshes) and the terms,
integrals of σ(u_h), follow it (measured: below 1e-13). ``RTOL = 1e-11`` keeps a margin of
100 over that and is 1e-89 of the smallest error a wrong power of c would make.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from signorini.contact.solution import solve, stiffness_unit
from signorini.contact.system import assemble
from signorini.estimator.h_half_norm import hhalf_seminorm2_positive_part, l2_norm2_positive_part
from signorini.estimator.residual import STRESS_RANGE, estimate, stress_unit
from signorini.examples import example_6_1, example_6_2
from signorini.fem.material import Material
from signorini.loop import adaptive
from signorini.mesh.mesh import Mesh
from signorini.mesh.refine import refine_nvb
from signorini.problem import Contact, ContactProblem, Dirichlet, Neumann, ProblemError

RTOL = 1e-11
EXAMPLES = {"6.1": example_6_1, "6.2": example_6_2}
#: how η_k scales with c, k = 1 … 8
POWER = np.array([1, 1, 1, 1, 1, 0.5, 0, 0.5])


def scaled(problem, c: float):
    """``problem`` with λ, μ, the body force and the tractions multiplied by ``c``."""

    def times_c(g):
        return Neumann(lambda x, normal: c * g(x, normal))

    conditions = {
        name: times_c(cond.field()) if isinstance(cond, Neumann) else cond
        for name, cond in problem.conditions.items()
    }
    f = problem.body_force
    return dataclasses.replace(
        problem,
        material=Material.from_lame(c * problem.material.lam, c * problem.material.mu),
        conditions=conditions,
        body_force=None if f is None else (lambda x: c * f(x)),
    )


def safe_norm(v: np.ndarray) -> float:
    """Euclidean norm without overflow or underflow of the squares."""
    top = np.abs(v).max()
    return float(top * np.sqrt(np.sum((v / top) ** 2)))


def refined_mesh(problem, seed: int = 0):
    rng = np.random.default_rng(seed)
    mesh = problem.mesh
    for _ in range(3):
        mesh = refine_nvb(mesh, rng.random(mesh.n_cells) < 0.3).mesh
    return mesh


@pytest.fixture(scope="module", params=sorted(EXAMPLES))
def reference(request):
    problem = EXAMPLES[request.param]()
    mesh = refined_mesh(problem)
    result = solve(problem, mesh)
    return problem, mesh, result, estimate(result)


@pytest.mark.parametrize("c", [1e100, 1e-100, 1e300, 1e-300])
def test_eta_and_contact_force_scale_with_young_modulus(reference, c):
    problem, mesh, r0, e0 = reference
    with np.errstate(over="raise", invalid="raise", divide="raise"):
        r = solve(scaled(problem, c), mesh)
        e = estimate(r)
    np.testing.assert_allclose(r.u, r0.u, rtol=0, atol=RTOL * np.abs(r0.u).max())
    np.testing.assert_allclose(
        r.contact_force / c, r0.contact_force, rtol=0, atol=RTOL * r0.contact_force.max()
    )
    assert np.array_equal(r.active, r0.active)
    # η_k(c) = c^{a_k/2} η_k; η6 and η7 vanish on Example 6.1 (full contact)
    want = e0.eta_terms * c**POWER
    assert np.all(np.isfinite(e.eta_terms))
    np.testing.assert_allclose(e.eta_terms, want, rtol=RTOL, atol=0)
    # η_h: η1 … η5 dominate for large c, η6 and η7 for small c (when they are not zero)
    np.testing.assert_allclose(e.eta, safe_norm(want), rtol=RTOL)
    # the element indicators mark the same cells: they are proportional for the dominant terms
    assert np.all(np.isfinite(e.eta2)) and e.eta2.sum() > 0


def test_ordinary_problems_are_estimated_and_solved_in_unit_one(reference):
    problem, mesh, result, est = reference
    assert est.unit == 1.0
    assert stiffness_unit(assemble(problem, mesh).K) == 1.0


def test_stress_unit_is_one_inside_the_range_and_a_power_of_four_outside():
    lo, hi = STRESS_RANGE
    assert stress_unit(0.0) == 1.0
    assert stress_unit(lo) == stress_unit(hi) == stress_unit(1e-70) == stress_unit(1e70) == 1.0
    for s in (1e100, 1e-100, 1e300, 1e-300, 1.7e308, 5e-324):
        unit = stress_unit(s)
        mantissa, exponent = np.frexp(unit)
        assert mantissa == 0.5 and (exponent - 1) % 2 == 0
        assert 1.0 <= s / unit < 4.0


def test_solve_with_young_modulus_near_the_float_limit():
    """E = 1e307: K still fits in float64 but the mean of its diagonal (PDAS's constant c)
    does not; the system is solved in a power-of-2 unit instead."""
    problem = example_6_2()
    mesh = refined_mesh(problem)
    r0 = solve(problem, mesh)
    c = 1e307 / 500.0
    with np.errstate(over="raise", invalid="raise"):
        r = solve(dataclasses.replace(problem, material=Material.from_young(1e307, 0.3)), mesh)
    np.testing.assert_allclose(r.u, r0.u, rtol=0, atol=RTOL * np.abs(r0.u).max())
    np.testing.assert_allclose(
        r.contact_force / c, r0.contact_force, rtol=0, atol=RTOL * r0.contact_force.max()
    )
    np.testing.assert_array_equal(r.report.multiplier, r.contact_force)
    eta = estimate(r).eta_terms
    np.testing.assert_allclose(eta[:5] / c, estimate(r0).eta_terms[:5], rtol=RTOL)


def test_a_stiffness_matrix_beyond_float64_is_named():
    """E = 5e307 makes entries of K overflow: a ProblemError naming the material, not a
    solver error about a matrix the user never saw."""
    problem = example_6_2()
    huge = dataclasses.replace(problem, material=Material.from_young(5e307, 0.3))
    with pytest.raises(ProblemError, match=r"material: the stiffness matrix overflows float64"):
        solve(huge)


def test_adaptive_run_with_young_modulus_1e300_completes():
    """Example 6.2 with E = 1e300: before, η overflowed to NaN and marking refused it."""
    problem = example_6_2()
    huge = dataclasses.replace(problem, material=Material.from_young(1e300, 0.3))
    levels = list(adaptive(huge, max_ndof=1500))
    ref = list(adaptive(problem, max_ndof=1500))
    assert [lv.record.ndof for lv in levels] == [lv.record.ndof for lv in ref]
    c = 1e300 / 500.0
    for lv, lr in zip(levels, ref, strict=True):
        assert np.isfinite(lv.record.eta)
        np.testing.assert_allclose(
            lv.estimate.eta_terms[:5] / c, lr.estimate.eta_terms[:5], rtol=1e-9
        )


def moved_6_2(a: float, shift: float) -> ContactProblem:
    """Example 6.2 with its mesh, Dirichlet data and gap scaled by ``a`` and shifted by
    ``(shift, shift)``."""
    base = example_6_2()
    m = base.mesh
    # validate=False: the mesh layer's own tolerances are not under test here
    mesh = Mesh(
        m.points * a + shift, m.cells, m.boundary, m.boundary_part, m.part_names, validate=False
    )

    def gap(x):
        return a * (-0.2 + 0.5 * np.abs((x[..., 1] - shift) / a - 0.5))

    conditions = dict(base.conditions)
    conditions["left"] = Dirichlet((0.1 * a, 0.0))
    conditions["right"] = Contact(gap=gap, normal=(1.0, 0.0))
    return ContactProblem(mesh=mesh, material=base.material, conditions=conditions, name="moved")


@pytest.mark.parametrize(("a", "shift"), [(1.0, 1e9), (1e-12, 0.0), (1e12, 0.0), (1e12, 1e9)])
def test_solution_and_estimator_under_scaling_and_translation(a, shift):
    """Lengths times a: u_h and Λ_z (a force per unit thickness, σ × length) scale with a,
    σ(u_h) does not, so η1 … η6 scale with a; η7² = ‖v‖²_{L²} + |v|²_{H^{1/2}} scales as
    a³ ‖v‖²_{L²} + a² |v|²_{H^{1/2}}. A shift changes nothing (before: the H^{1/2} norm
    computed distances of quadrature points at 1e9 and η7 was off by 9e-8)."""
    r0 = solve(moved_6_2(1.0, 0.0), refined_mesh(moved_6_2(1.0, 0.0)))
    e0 = estimate(r0)
    problem = moved_6_2(a, shift)
    r = solve(problem, refined_mesh(problem))
    e = estimate(r)
    np.testing.assert_allclose(r.u / a, r0.u, rtol=0, atol=RTOL * np.abs(r0.u).max())
    np.testing.assert_allclose(
        r.contact_force / a, r0.contact_force, rtol=0, atol=RTOL * r0.contact_force.max()
    )
    assert np.array_equal(r.active, r0.active) and np.array_equal(r.classes, r0.classes)
    cs = r0.contact
    x0, x1 = r0.mesh.points[cs.facet_nodes[:, 0]], r0.mesh.points[cs.facet_nodes[:, 1]]
    v = cs.facet_normal_gap(r0.u)
    l2 = l2_norm2_positive_part(x0, x1, v)
    semi = hhalf_seminorm2_positive_part(x0, x1, v)
    l2, semi = (q[0] if isinstance(q, tuple) else q for q in (l2, semi))
    want = e0.eta_terms * a
    want[6] = a * np.sqrt(a * l2 + semi)
    np.testing.assert_allclose(e.eta_terms, want, rtol=RTOL)
