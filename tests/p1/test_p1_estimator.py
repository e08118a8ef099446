"""The P1 residual estimator (docs/method.md, *P1 elements and their estimator*) and P1
convergence: rates in Ndof, efficiency index, the estimator on an exact contact patch, and
the contact force of Example 6.2 against P2."""

from __future__ import annotations

import numpy as np
import pytest

from signorini.contact.solution import solve
from signorini.estimator.residual import estimate
from signorini.estimator.thirds import friction_work_thirds, third_integrals
from signorini.examples import example_6_1, example_6_2
from signorini.fem.element import P1
from signorini.loop import adaptive
from signorini.mesh.refine import refine_uniform
from tests.p1.test_p1_solve import contact_patch


def _slope(ndof, values) -> float:
    return float(np.polyfit(np.log(ndof), np.log(values), 1)[0])


def _uniform(example, element: str, levels: int):
    problem = example()
    mesh = problem.mesh
    out = []
    for _ in range(levels):
        out.append(solve(problem, mesh, element=element))
        mesh = refine_uniform(mesh).mesh
    return out


def test_p1_pieces_of_a_contact_edge_are_its_halves():
    """γ̃_p of P1 is the half of the edge next to p with the P1 hat: ∫ 1·φ = 3/8 |e|; a
    linear v is cut at its root."""
    length = np.array([2.0, 1.0])
    v = P1.facet.facet_values(np.array([[1.0, 1.0], [1.0, -1.0]]))  # 1; 1 − 2t (root at 1/2)
    out = third_integrals(v, length, None, P1.facet.hat_pieces)
    # ∫_0^{1/2} (1 − 2t)(1 − t) dt = 5/24; on the end's half v < 0: nothing
    assert np.allclose(out, [[0.75, 0.75, 0.0], [5 / 24, 0.0, 0.0]], rtol=1e-14, atol=1e-15)
    work = friction_work_thirds(
        np.array([[1.0, 1.0, 1.0]]),
        np.zeros((1, 3)),
        np.ones((1, 3)),
        np.array([1.0]),
        None,
        P1.facet.node_parts,
    )
    assert np.allclose(work, [[0.5, 0.5, 0.0]], rtol=1e-14)


@pytest.mark.parametrize("angle", [0.0, 30.0])
def test_p1_estimator_vanishes_on_the_contact_patch(angle):
    """On an affine solution in full contact every P1 term is zero: no volume residual, no
    jumps, σ_nn + p_h = 0 with p_h the P1 interpolant of Λ_z / w_z (w_z = |e|/2 per edge),
    σ_t = 0, no semi-contact node, no penetration."""
    r, p, _ = contact_patch(angle)
    est = estimate(r)
    scale = p * np.sqrt(r.mesh.h.max())
    print(f"angle {angle}: eta_k / (p h^1/2) = {est.eta_terms / scale}")
    assert est.eta < 1e-11 * scale
    paper = estimate(r, eta5_variant="paper")  # ‖σ_nn‖ alone does not vanish
    assert paper.eta_terms[4] > 0.1 * scale


def test_p1_uniform_energy_error_rate_and_efficiency_on_example_6_1():
    results = _uniform(example_6_1, "P1", 5)
    ndof = np.array([r.ndof for r in results])
    error = np.array([r.errors()["error_energy"] for r in results])
    eta = np.array([estimate(r).eta for r in results])
    eff = eta / error
    slope = _slope(ndof[2:], error[2:])
    print(f"P1 uniform, Example 6.1: Ndof {ndof.tolist()}")
    print(f"  energy error {error}, slope {slope:.4f}")
    print(f"  efficiency index eta / error {np.round(eff, 3).tolist()}")
    assert -0.55 <= slope <= -0.47, f"energy error slope {slope:.4f}"
    assert 10.0 <= eff.min() and eff.max() <= 25.0, f"efficiency indices {eff}"
    # it settles: each step changes it less (+1.3, +0.75, +0.4 measured), the last by < 3 %
    steps = np.diff(eff[1:])
    assert np.all(np.abs(steps[1:]) < 0.7 * np.abs(steps[:-1])) and eff[-1] / eff[-2] < 1.03


def test_p1_adaptive_rates_on_the_paper_examples():
    """Adaptive P1: η ~ Ndof^-1/2 on Example 6.2 (the best P1 can do), and on 6.1 the exact
    error follows η with a bounded efficiency index."""
    slopes = {}
    for example in (example_6_2, example_6_1):
        levels = list(adaptive(example(), element="P1", max_ndof=6000))
        ndof = np.array([lv.record.ndof for lv in levels])
        eta = np.array([lv.record.eta for lv in levels])
        half = len(levels) // 2
        slopes[example.__name__] = _slope(ndof[half:], eta[half:])
        assert all(lv.result.space.element is P1 for lv in levels)
        if example is example_6_1:
            error = np.array([lv.result.errors()["error_energy"] for lv in levels])
            eff = eta / error
            print(f"adaptive P1 6.1: error slope {_slope(ndof[half:], error[half:]):.3f}")
            print(f"  efficiency {np.round(eff, 2).tolist()}")
            assert 10.0 <= eff.min() and eff.max() <= 25.0
            assert -0.58 <= _slope(ndof[half:], error[half:]) <= -0.45
    print(f"adaptive P1 eta slopes: {slopes}")
    assert -0.6 <= slopes["example_6_2"] <= -0.45
    assert -0.6 <= slopes["example_6_1"] <= -0.45


@pytest.mark.slow
def test_p1_and_p2_agree_on_the_contact_force_of_example_6_2():
    """Σ Λ_z of P1 converges to the P2 value; the finest uniform P2 solution (33 024
    unknowns) is the reference, P2 on the same mesh as P1's finest is closer to it."""
    p1 = _uniform(example_6_2, "P1", 5)
    p2 = _uniform(example_6_2, "P2", 5)
    reference = p2[-1].total_contact_force
    f1 = np.array([r.total_contact_force for r in p1])
    f2 = np.array([r.total_contact_force for r in p2[:-1]])
    d1, d2 = np.abs(f1 - reference) / reference, np.abs(f2 - reference) / reference
    print(f"reference: P2 uniform, {p2[-1].ndof} unknowns: {reference:.8f}")
    for r, f, d in zip(p1, f1, d1, strict=True):
        print(f"  P1 {r.ndof:6d} unknowns: {f:.8f} (relative difference {d:.2e})")
    for r, f, d in zip(p2, f2, d2, strict=False):
        print(f"  P2 {r.ndof:6d} unknowns: {f:.8f} (relative difference {d:.2e})")
    assert np.all(np.diff(d1[1:]) < 0), d1
    assert d1[-1] < 1e-3
    assert d2[-1] < d1[-1]  # same mesh, P2 closer
